"""Contact: the wheel–rail creep laws, with no knowledge of the bogie.

Holds Hertz's contact ellipse and Kalker's linear creep coefficients, Polach's law of the
longitudinal creep force μ(s, v) (its value and its tangent, scalar or array), and the rail
presets (dry, wet).  May use numpy and scipy only: nothing else of ``model`` and nothing of
``app``.  The operating point that puts these laws into the bogie's equations is in
:mod:`model.mechanics.operating_point`.
"""
