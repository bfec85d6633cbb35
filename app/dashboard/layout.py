"""The dashboard's page: its style, the tabs of the views and the views of the first tabs.

The page: the controls on the left (:mod:`app.dashboard.controls`); on the right the notices,
the status and the root locus, and under them the views, one tab each (:class:`ViewTabs`).
Only the open tab is in the browser (``pn.Tabs(dynamic=True)``, :mod:`app.dashboard.panel_fixes`),
and the views of a hidden tab are brought up to date when it is opened
(:meth:`ViewTabs.when_shown`): with every view in the page and updated at every change, the
browser re-styled and re-rendered the hidden ones too.
"""

from __future__ import annotations

import re
from functools import partial
from pathlib import Path

import panel as pn

from app.dashboard.session import served_document
from app.results.plots import STABLE, UNSTABLE

ASSETS = Path(__file__).resolve().parents[2] / "assets"  # app/dashboard/ -> project

# the peak table's column [px]: per output the pre-fault value, max, min and swing with their
# times and the swing's quasi-static and dynamic parts
PEAKS_WIDTH = 800
CSS = """
.status-box {font-size: 30px; font-weight: 700; padding: 6px 14px; border-radius: 6px;
             color: white; text-align: center; letter-spacing: 0.05em}
.status-box.ok {background: STABLE_COLOR} .status-box.bad {background: UNSTABLE_COLOR}
.verdict-box {font-size: 20px; margin-top: 6px; color: #222} .verdict-box.green {background: #c8e6c9}
.verdict-box.amber {background: #ffe0b2} .verdict-box.red {background: #ffcdd2}
.verdict-box.pending {background: #eeeeee; font-size: 14px}
.status-box.unknown {background: #888888}
.status-box.preview {opacity: 0.5; border: 2px dashed #333; font-size: 24px}
.status-box .preview-tag {display: block; font-size: 11px; font-weight: 400; letter-spacing: 0}
.preview-text {font-size: 12px; line-height: 1.4; color: #444; padding-top: 3px}
table.bogie {border-collapse: collapse; font-size: 12px; width: 100%}
table.bogie th, table.bogie td {border-bottom: 1px solid #ddd; padding: 2px 6px; text-align: right}
table.bogie td.text, table.bogie th.text {text-align: left}
table.bogie td.t {color: #666}
table.bogie.peaks td {white-space: nowrap; padding: 2px 4px} table.bogie.peaks th {padding: 2px 4px}
table.bogie td.bad {color: UNSTABLE_COLOR; font-weight: 700}
.busy-text {font-size: 13px; color: #555; font-style: italic}
""".replace("UNSTABLE_COLOR", UNSTABLE).replace("STABLE_COLOR", STABLE)

html_pane = partial(pn.pane.HTML, sizing_mode="stretch_width", stylesheets=[CSS])
bokeh_pane = partial(pn.pane.Bokeh, sizing_mode="stretch_width")


def typed_frame(columns, rows):
    """A table's pandas frame with every column's type declared: ``columns`` maps each column
    to its dtype (``"object"`` for text, ``"float64"``, ``"int64"``), ``rows`` are dicts with
    those keys.  A Panel Tabulator takes its columns' formatters from the first frame it is
    given; a table made before its data (an empty frame: every column float) drew its text
    columns as ``NaN`` ever after, and its integers as ``1.0``."""
    import pandas as pd

    return pd.DataFrame({name: pd.Series([row[name] for row in rows], dtype=dtype)
                         for name, dtype in columns.items()}, columns=list(columns))


def tab_name(title: str) -> str:
    """A view's name in the URL (``tab=``): its title in lower case, words joined by '-'."""
    return re.sub(r"[^a-z0-9]+", "-", str(title).lower()).strip("-")


class OpeningTabs(pn.Tabs):
    """Tabs that call ``opening()`` when another tab is opened, after ``active`` has changed and
    before the models of the opened tab's view are made (``pn.Tabs`` makes them in its own watcher
    of ``active``, which runs before any other watcher of it). What ``opening`` sets is then in
    the models the browser first receives: a change sent just after them can reach a view that
    is still building, and a Tabulator that is building drops new rows (it drew none, while
    its model in the browser held ten)."""

    def __init__(self, *objects, **params):
        super().__init__(*objects, **params)
        self.opening = None  # the callback (no arguments), or None

    def _update_active(self, *events):
        if self.opening is not None and any(event.name == "active" for event in events):
            self.opening()
        super()._update_active(*events)


class ViewTabs:
    """The views of a dashboard, one tab each, and the updates that wait for a hidden tab."""

    def __init__(self, *views: tuple[str, object]):
        """``views``: (title, view) pairs; more are added with :meth:`add`."""
        self.tabs = OpeningTabs(*views, dynamic=True, css_classes=["views"],
                                sizing_mode="stretch_width")
        self.names = [tab_name(title) for title, _view in views]
        self._pending: dict[tuple[str, str], tuple] = {}  # (tab, what) -> (function, args)

    def add(self, title: str, view) -> None:
        """One more view, in a tab of its own at the end."""
        self.tabs.append((title, view))
        self.names.append(tab_name(title))

    def on_opening(self, callback) -> None:
        """``callback()`` whenever a tab is opened, before its view's models are made (so the
        updates it applies reach the browser with the view)."""
        self.tabs.opening = callback

    @property
    def shown(self) -> str:
        """The name of the open tab."""
        return self.names[self.tabs.active]

    def when_shown(self, tab: str, function, *args) -> None:
        """``function(*args)`` now if the view's tab is open or the dashboard is not served,
        else when the tab is opened (of several calls of one function for a hidden tab, the last
        one)."""
        if served_document() is None or self.shown == tab:
            self._pending.pop((tab, function.__name__), None)
            function(*args)
        else:
            self._pending[tab, function.__name__] = (function, args)

    def flush(self, tab: str) -> None:
        """Apply the updates the view ``tab`` missed while hidden, in the order they came."""
        for key in [key for key in self._pending if key[0] == tab]:
            function, args = self._pending.pop(key)
            function(*args)


# --- the views of the first tabs (the dashboard's own results) -----------------------------------

def response_view(creep_plot, peaks, response_plots):
    """The "Response" tab: creep characteristic, peak table and the time histories."""
    return pn.Column(
        pn.Row(bokeh_pane(creep_plot.figure), pn.Column(peaks, width=PEAKS_WIDTH),
               sizing_mode="stretch_width"),
        pn.Row(*(bokeh_pane(f) for f in response_plots.figures[:2]), sizing_mode="stretch_width"),
        pn.Row(*(bokeh_pane(f) for f in response_plots.figures[2:]), sizing_mode="stretch_width"),
        sizing_mode="stretch_width")


def fig6_view(fig6):
    """The "Fig. 6" tab: the root locus's eigenvalues against the swept parameter."""
    return pn.Column(
        pn.pane.Markdown("Lightly damped complex branches (ζ < 0.3 somewhere on the "
                         "sweep) and the real eigenvalues of the root locus above, "
                         "against the swept parameter; red dashed: the stability limit "
                         "(s0*(v) over s0, the sweep's first unstable speed over v)."),
        pn.Row(*(bokeh_pane(f) for f in fig6.figures[:2]), sizing_mode="stretch_width"),
        pn.Row(bokeh_pane(fig6.figures[2]), sizing_mode="stretch_width"),
        sizing_mode="stretch_width")


def modes_view(eigen_table, click, mode_select, mode_plot):
    """The "Modes" tab: Table 1 and Table 2 layouts, the mode choice and the mode shape."""
    return pn.Column(
        "#### Eigenvalues (layout of Table 1) and modes (layout of Table 2)",
        pn.Row(pn.Column(eigen_table, width=420),
               pn.Column("**Modes** (dominant motion from kinetic/strain energy "
                         "shares; click a row, or a point of the root locus)",
                         click.table.table, sizing_mode="stretch_width"),
               sizing_mode="stretch_width"),
        "#### Mode shape",
        mode_select, click.detail,
        pn.Row(*(bokeh_pane(f) for f in mode_plot.figures), sizing_mode="stretch_width"),
        sizing_mode="stretch_width")


def schematic_view():
    """The "Schematic" tab: the bogie's drawing (assets/schematic.svg)."""
    schematic = ASSETS / "schematic.svg"
    return (pn.pane.SVG(schematic, width=640) if schematic.is_file()
            else pn.pane.Markdown("*(schematic missing)*"))
