"""What the views that run studies on the server's queue share (the Studies tab's maps, the
Design loads tab's grid envelopes): following a ticket (its status line, progress and store while
it runs), stopping it, waiting for it.

A view that mixes :class:`QueuedStudyControls` in builds its common widgets with
:meth:`~QueuedStudyControls._build_queue_controls`, holds ``queue``, ``owner``, ``ticket``,
``_conditions`` (the study's conditions shown after the status), ``_read_at`` (chunks finished
when the running store was last read) and ``_poller``, and defines
``_show_running_store(ticket)`` (read and show the store, set ``_read_at``), ``_reject(message)``
and ``_after_end()`` (refresh the folder's lists).
"""

from __future__ import annotations

import html

import panel as pn

from app.dashboard.session import served_document
from app.services.study_queue import FAILED, WAITING, wait_until_ended

POLL_MS = 500  # progress refresh of a served session [ms]


class QueuedStudyControls:
    """Following, stopping and waiting for the session's one study on the queue."""

    UNIT = "chunks"  # what a chunk of the study is, in its status line
    WHAT = "study"  # how a failure notice names it

    def _build_queue_controls(self, css: str, counted: str, start_label: str, store_label: str,
                              open_label: str, refresh_description: str) -> None:
        """The widgets of every view that runs studies on the queue, with the CSS classes
        ``{css}-where``, ``-start``, ``-stop``, ``-store``, ``-open``, ``-refresh``, ``-progress``,
        ``-status``, ``-notice``: where studies run and the server's limits (``counted``: what
        the maximum counts, e.g. "points (s0 × v)"), start and stop, the list of finished stores
        in the server's studies folder (``store_label``) with open and refresh, the progress,
        the status line and the notice of a refused request."""
        settings = self.queue.settings
        running = settings.max_running_studies
        self.where = pn.pane.HTML(
            f"runs on {html.escape(settings.engine_description, quote=False)}; at most "
            f"{settings.max_study_points} {counted}, {running} stud{'y' if running == 1 else 'ies'} "
            "at a time, one per session (the server's settings)", css_classes=[f"{css}-where"],
            sizing_mode="stretch_width")
        self.start_button = pn.widgets.Button(label=start_label, color="primary",
                                              css_classes=[f"{css}-start"], width=140)
        self.stop_button = pn.widgets.Button(label="Stop", css_classes=[f"{css}-stop"], width=80,
                                             disabled=True)
        self.store_select = pn.widgets.Select(label=store_label, options=[],
                                              css_classes=[f"{css}-store"], width=360)
        self.open_button = pn.widgets.Button(label=open_label, css_classes=[f"{css}-open"],
                                             width=130)
        self.refresh_button = pn.widgets.Button(label="↻", css_classes=[f"{css}-refresh"],
                                                width=45, description=refresh_description)
        self.progress = pn.indicators.Progress(value=0, max=1, css_classes=[f"{css}-progress"],
                                               width=360, visible=False)
        self.status = pn.pane.HTML("", css_classes=[f"{css}-status"], sizing_mode="stretch_width")
        self.notice = pn.pane.Alert("", alert_type="danger", visible=False,
                                    css_classes=[f"{css}-notice"], sizing_mode="stretch_width")

    def _follow(self) -> None:
        """Show the new ticket now and, when served, every POLL_MS until it ends."""
        self.poll()
        doc = served_document()
        if doc is not None:
            self._poller = pn.state.add_periodic_callback(self.poll, period=POLL_MS)

    def stop(self) -> None:
        """Stop this session's study: a waiting one leaves the queue, a running one stops after
        the chunk in progress (the store keeps the finished ones)."""
        if self.ticket is not None:
            self.queue.stop(self.ticket, self.owner)
            self.poll()

    def wait(self, timeout: float | None = None) -> None:
        """Wait for this session's study to end (tests, scripts); ``timeout`` [s]."""
        if self.ticket is not None:
            wait_until_ended(self.ticket, timeout)

    @property
    def outcome(self) -> str | None:
        """"done", "stopped", "failed", "dropped" once the study ended, else None."""
        ticket = self.ticket
        return ticket.state if ticket is not None and ticket.ended.is_set() else None

    def poll(self) -> None:
        """Show the queue position or the progress, and the store as far as it is written (a
        periodic callback when served; the store is read again only when it has grown)."""
        ticket = self.ticket
        if ticket is None:
            return
        line, ended = self.queue.status_line(ticket, self.UNIT)
        self.progress.value = min(ticket.finished, self.progress.max)
        self.status.object = f"{line} — {self._conditions}"
        if ticket.state == WAITING:
            return
        if ticket.finished != self._read_at or ended:
            self._show_running_store(ticket)
        if ended:
            if ticket.state == FAILED:
                self._reject(f"the {self.WHAT} failed: {ticket.message}")
            self.start_button.disabled, self.stop_button.disabled = False, True
            self._after_end()
            if self._poller is not None:
                self._poller.stop()
                self._poller = None
