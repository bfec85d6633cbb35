"""A workaround of one Panel behaviour the dashboard runs into (Panel 1.9).

Only the open tab of the dashboard's views is in the browser (``pn.Tabs(dynamic=True)``).  A
markup pane (HTML, Markdown, Alert) of a tab that was closed keeps the Bokeh model it had there,
detached from the document.  When the pane's text changes, Panel updates that model too and
computes its properties without a document: it then takes Panel's CDN as the address of the
stylesheets, and rewrites the stylesheet objects that every pane of the session shares — the
next render asks the CDN for ``loading.css``, which fails on an offline machine (seen as
``net::ERR_NAME_NOT_RESOLVED`` in the browser's console).  A detached model is not on any
page, and the pane renders a fresh one when its tab is opened again, so it is skipped here.
"""

from __future__ import annotations

from panel.pane.markup import HTMLBasePane

_original_update = HTMLBasePane._update


def _update_attached_only(self, ref: str, model) -> None:
    if model.document is None:  # a model of a closed tab: not on the page
        return
    _original_update(self, ref, model)


def skip_detached_markup_models() -> None:
    """Install the workaround (idempotent)."""
    HTMLBasePane._update = _update_attached_only
