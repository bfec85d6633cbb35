"""A dashboard's served session: its Bokeh document, its URL query, and showing results with its lock.

Served, the dashboard's computations run on worker threads without the session's document lock
(several reviewers on one server do not queue behind each other); what they produce is shown by
a function scheduled on the session's next tick (:func:`post`), which runs with the lock and
under one Bokeh hold.  Without a server (tests, scripts) there is no session: everything runs at
once.
"""

from __future__ import annotations

import logging
from functools import partial

import panel as pn
from panel.io.state import set_curdoc

log = logging.getLogger(__name__)


def served_document():
    """The Bokeh document of the served session being built or updated (None without a server)."""
    doc = pn.state.curdoc
    return doc if doc is not None and doc.session_context is not None else None


def session_query() -> dict:
    """The URL query arguments of the served session being built ({} without a server)."""
    if served_document() is None:
        return {}
    return dict(pn.state.session_args or {})


def post(doc, function, *args) -> None:
    """``function(*args)`` on the session's next tick, with its document lock; nothing if the
    session has ended meanwhile (a closed browser tab: its document is destroyed, and Bokeh
    raised AttributeError on scheduling into it)."""
    if doc.session_context is None or getattr(doc.session_context, "destroyed", False):
        return
    try:
        doc.add_next_tick_callback(partial(run_with_hold, doc, function, *args))
    except (AttributeError, RuntimeError):
        log.debug("session ended: result not shown")


def run_with_hold(doc, function, *args) -> None:
    """``function(*args)`` as the current code of ``doc`` (which holds its lock), its changes
    under one Bokeh hold: all changes of one result go to the browser in one go and are rendered
    once (Panel's ``hold`` bypasses the document lock and lost the changes of a session whose
    websocket was not connected yet)."""
    with set_curdoc(doc):
        held = doc.callbacks.hold_value is not None
        if not held:
            doc.hold("combine")
        try:
            function(*args)
        finally:
            if not held:
                doc.unhold()


def run_locked(function, *args) -> None:
    """``function(*args)`` with the session's document lock: served, on the next tick (a Panel
    widget callback may run without the lock; changing Bokeh models there raised
    "_pending_writes should be non-None"); otherwise at once."""
    doc = served_document()
    if doc is None:
        function(*args)
    else:
        post(doc, function, *args)
