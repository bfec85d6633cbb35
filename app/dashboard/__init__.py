"""The Panel dashboard: :class:`.dashboard.BogieDashboard` and its views.

The dashboard owns the parameters, the last valid results and the first answers (status, root
locus, time histories); its pieces: :mod:`.controls` (the controls column and the parameters of
the case's quantities), :mod:`.stages` (the computations of a change), :mod:`.scheduler` (when
and where they run), :mod:`.jobs` (the one way a view computes off the event loop),
:mod:`.layout` (the page and the tabs), :mod:`.downloads`, :mod:`.session` (the served
session's document).  Each view (modes, nonlinear creep, sensitivity, studies,
variant, uncertainty band, design loads with its grid envelope, resonances) gets the dashboard object and
talks to it through its small public interface (``state()``: the case record, ``alive()``, ``post()``,
``run_locked()``, ``warn()``, ``clear_warning()``, ``when_shown()``, ``flush_view()``,
``base_key``, ``set_key``, ``study_owner``, ``show_history()``, ``show_mode()``); no view imports
:mod:`.dashboard`.  May use :mod:`app.report`, :mod:`app.results`, :mod:`app.services`
and ``model``; never the server or the command line.
"""
