"""What every interface shows: cached results as plain data, and the figures and tables of them.

:mod:`.case` (the case record: each quantity of the operating point, the short circuit and the
horizon declared once), :mod:`.cache` (the one results cache, bounded in bytes),
:mod:`.compute` (the dashboard's and the report's computations, kept across sessions),
:mod:`.resonance` (those of the Campbell diagram, the frequency response and the forced
response), :mod:`.variants` (design variants of the bundled set), :mod:`.plots`,
:mod:`.eigenvalue_sweep` and :mod:`.resonance_plots` (Bokeh figures fed with results),
:mod:`.tables` (HTML tables of results).  May use ``model`` only.
"""
