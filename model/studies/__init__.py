"""Studies: many analyses at once, and what is fitted or compared with them.

Stability maps and s0*(v) curves (:mod:`.maps`; one s0-line of a map: :mod:`.s0_line`), their
Zarr stores (:mod:`.store`), the Dask engine that runs them (:mod:`.engine`, the only module of
``model`` that imports dask), the Monte-Carlo/Sobol uncertainty study and the linearized
posterior (:mod:`.uncertainty`, :mod:`.posterior`), the calibration against the published tables
(:mod:`.calibration`; its targets :mod:`.calibration_targets`, its free parameters and their
bounds :mod:`.calibration_bounds`) and the comparison of two parameter sets (:mod:`.compare`).
May use every other wing of ``model``; never ``app``.
"""
