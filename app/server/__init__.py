"""``bogie serve``: the dashboard served to a review group (docs/security.md).

:mod:`.serve` builds a dashboard per session and applies the operator's settings.  May use every
other part of ``app`` but the command line.
"""
