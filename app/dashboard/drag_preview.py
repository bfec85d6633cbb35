"""The verdict follows the hand: while an operating-point slider (s0, v, N0, b_M) is dragged, the
stability status, the point's markers on the root locus and on the creep characteristic (with
s0*) and the leading eigenvalue show a preview of the held value, in a lighter style, until the
release's full answer replaces it.

A slider sends its ``value`` while it is dragged and ``value_throttled`` when it is released
(:mod:`app.dashboard.controls`).  Each ``value`` asks for a preview (:mod:`app.results.preview`:
what is known already, at most one reduced eigenproblem, never a dense eigen-analysis).  The
previews of a session never queue: one runs at a time on the preview pool
(:data:`app.services.thread_pools.PREVIEW_POOL`, below the first answers' priority) and only the
newest value waits (:class:`app.dashboard.jobs.ViewJob`).  A release, a full answer
or a rejection ends the drag: a preview still running is not shown.  Previews start with a
slider's second value before its release: a keyboard step sends one value and its release, and
gets no preview, only its full answer.
"""

from __future__ import annotations

import html
import math
from functools import partial

from app.dashboard.jobs import ViewJob
from app.dashboard.session import served_document
from app.dashboard.stages import MODEL_ERRORS
from app.results.case import CaseBase
from app.results.preview import PREVIEWED, Preview, describe, preview
from app.services.thread_pools import PREVIEW_POOL


class DragPreview:
    """The previews of one dashboard's dragged sliders.

    The dashboard provides ``state()``, ``alive()``, ``shown_locus``, its parameters, ``status``
    (the status pane), ``details`` (the committed point's numbers, faded during a preview),
    ``locus_plot`` and ``creep_plot``; it calls :meth:`request` for a dragged
    value, :meth:`release` when a slider is let go, and :meth:`end` when a full answer or a
    rejection is shown."""

    def __init__(self, dashboard):
        self.dashboard = dashboard
        self._job = ViewJob(PREVIEW_POOL, dashboard.alive, "preview")
        self._drag = 0  # the drag a preview belongs to: a release or a full answer ends it
        self._saved_status: str | None = None  # the status the previews cover while shown
        self._preview_html = ""  # the status pane's text while a preview is shown
        self._waiting: tuple[str, float] | None = None  # the newest dragged value, not yet asked
        self._moves = 0  # values sent since the last release
        self.shown = 0  # previews shown in this session (the browser test counts its own)

    def request(self, name: str, value) -> None:
        """A preview of the operating point with ``name`` (one of PREVIEWED) at the dragged
        ``value`` (display units); nothing if the value is the parameter's (a release or a
        keyboard step: the full answer follows) or not a value the parameter takes.

        Served, previews start with the second value a slider sends before its release: a
        keyboard step sends one value and its release (a few milliseconds apart; on a loaded
        server Panel may hand them on as two events), a drag sends a value per move.  The value
        is taken up on the session's next tick (the newest one then), after a release that
        arrived with it."""
        doc = served_document()
        if doc is None:
            self._request(None, name, value)
            return
        self._moves += 1
        if self._moves < 2:
            return
        waiting, self._waiting = self._waiting, (name, value)
        if waiting is None:
            doc.add_next_tick_callback(partial(self._fire, doc))

    def _fire(self, doc) -> None:
        waiting, self._waiting = self._waiting, None
        if waiting is not None:
            self._request(doc, *waiting)

    def _request(self, doc, name: str, value) -> None:
        dashboard = self.dashboard
        if name not in PREVIEWED:
            return
        low, high = dashboard.param[name].bounds
        try:
            value = float(value)
        except (TypeError, ValueError):
            return
        if not (math.isfinite(value) and low <= value <= high):
            return  # only a doctored client sends one; its release gets the notice
        committed = dashboard.state()
        state = committed.replace(**{name: value})
        if state == committed:  # dragged back to the value on screen (or released there)
            self.end()
            return
        drag = self._drag
        shown = dashboard.shown_locus
        sweep = shown[0] if shown is not None else dashboard.sweep(state)
        self._job.start((drag, name, state), partial(self._compute, name, state, sweep),
                        lambda _key, result: self._show(drag, name, state, result), doc=doc)

    def release(self) -> None:
        """The slider is let go (or stepped by a key): previews not yet shown are dropped."""
        self._drag += 1
        self._moves = 0
        self._waiting = None
        self._job.forget()

    def end(self) -> None:
        """A full answer (or a rejection) is shown: the preview is taken down (call with the
        session's lock)."""
        self.release()
        if self._saved_status is None:
            return
        if self.dashboard.status.object == self._preview_html:
            self.dashboard.status.object = self._saved_status
        self._saved_status = None
        self.dashboard.details.styles = {}
        self.dashboard.locus_plot.update_preview(None)
        self.dashboard.creep_plot.update_preview(None)

    # --- computing and showing --------------------------------------------------------------------

    @staticmethod
    def _compute(name: str, state: CaseBase, sweep) -> Preview | None:
        """The preview (None: the point is invalid)."""
        try:
            return preview(state, sweep, name)
        except MODEL_ERRORS:
            return None

    def _show(self, drag: int, name: str, state: CaseBase, result: Preview | None) -> None:
        dashboard = self.dashboard
        if result is None or drag != self._drag or dashboard.state() == state:
            return
        if self._saved_status is None:  # the drag's first preview: the details are the
            self._saved_status = dashboard.status.object  # committed point's, shown faded
            dashboard.details.styles = {"opacity": "0.45"}
        self._preview_html = status_html(result, name)
        dashboard.status.object = self._preview_html
        dashboard.locus_plot.update_preview(result.eigenvalues)
        dashboard.creep_plot.update_preview(result.s0, result.mu0)
        self.shown += 1


def status_html(result: Preview, dragged: str) -> str:
    """The status pane's preview: the verdict in a lighter box marked "preview", the dragged
    value and the margin to the limit, the leading eigenvalue, the source.  ``data-verdict``
    (stable, unstable, unknown) and ``data-s0`` carry the same for readers of the page."""
    if result.stable is None:
        word, kind, verdict = "NOT KNOWN YET", "unknown", "unknown"
    elif result.stable:
        word, kind, verdict = "STABLE", "ok", "stable"
    else:
        word, kind, verdict = "UNSTABLE", "bad", "unstable"
    lines = "<br>".join(html.escape(line) for line in describe(result, dragged))
    return (f'<div class="status-box {kind} preview" data-verdict="{verdict}" '
            f'data-s0="{result.s0:.7g}" data-v="{result.v_kmh:g}">{word}'
            f'<span class="preview-tag">preview — release for the full answer</span></div>'
            f'<div class="preview-text">{lines}</div>')
