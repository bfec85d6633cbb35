"""The self-contained HTML report (``bogie report``, the dashboard's download).

Built from results (:mod:`app.results`): the same cached results, figures and tables as the
dashboard.  May use :mod:`app.results` and ``model``.
"""
