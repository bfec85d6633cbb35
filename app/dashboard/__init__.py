"""The Panel dashboard: :class:`.dashboard.BogieDashboard` and its views.

The dashboard owns the controls, the state and the first answers (status, root locus, time
histories); each view (modes, nonlinear creep, sensitivity, studies, variant, uncertainty band)
talks to it through its small public interface (``state()``, ``post()``, ``warn()``,
``alive()``, ``params_path``, ``set_key``).  May use :mod:`app.report`, :mod:`app.results`,
:mod:`app.services` and ``model``; never the server or the command line.
"""
