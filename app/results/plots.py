"""Bokeh figures of the dashboard: built once per session, then fed with results.

Each ``*Plot`` class owns its figure and data sources and has an ``update(result)`` method that
only replaces source data (cheap to send to the browser).  Results come from
:mod:`app.results.compute`; nothing here computes physics.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from bokeh.models import (
    BoxAnnotation,
    ColorBar,
    ColumnDataSource,
    HoverTool,
    Label,
    LinearColorMapper,
    Range1d,
    Span,
    TapTool,
)
from bokeh.palettes import Category10_10, Viridis256
from bokeh.plotting import figure

from app.results.compute import (
    FORCES,
    N_COMPLEX_TABLE,
    RESPONSE_OUTPUTS,
    TORQUES,
    LimitResult,
    LocusResult,
    PointResult,
    ResponseView,
)
from app.results.locus_geometry import broken_columns

UNSTABLE = "#c0392b"
STABLE = "#1e8449"
TOOLS = "pan,wheel_zoom,box_zoom,reset,save"


def new_figure(title: str, x_label: str, y_label: str, **kwargs):
    """A Bokeh figure in the style every view shares: pan/zoom/reset/save tools, the page's
    width, 320 px high, no Bokeh logo (axis labels with their units; keyword arguments as for
    :func:`bokeh.plotting.figure`)."""
    fig = figure(title=title, tools=TOOLS, sizing_mode="stretch_width", height=320,
                 x_axis_label=x_label, y_axis_label=y_label, **kwargs)
    fig.toolbar.logo = None
    return fig


class SeriesSource:
    """Several named (x, y) series in one Bokeh source: columns ``"<x>:<name>"`` and
    ``"<y>:<name>"``, each series on its own points, padded with NaN to the longest (a line
    ends at the first NaN of its own columns).  A change of all series reaches the browser as one
    message, drawn once (one source per series sent one message each: eleven per slider step
    for the time histories).  ``name=`` names the Bokeh source (browser tests find it)."""

    def __init__(self, names, name: str, x: str = "t", y: str = "y"):
        self.names, self.x, self.y = tuple(names), x, y
        self.source = ColumnDataSource({self.column(axis, series): []
                                        for series in self.names for axis in (x, y)}, name=name)

    def column(self, axis: str, series: str) -> str:
        return f"{axis}:{series}"

    def line(self, fig, series: str, **kwargs):
        """A line glyph of ``series`` on ``fig`` (keyword arguments as for ``fig.line``)."""
        return fig.line(self.column(self.x, series), self.column(self.y, series),
                        source=self.source, **kwargs)

    def update(self, series: dict[str, tuple[np.ndarray, np.ndarray]]) -> None:
        """Show these series (others: none) in one change of the source."""
        length = max((len(x) for x, _ in series.values()), default=0)
        empty = np.full(length, np.nan)
        data = {}
        for name in self.names:
            for axis, values in zip((self.x, self.y), series.get(name, (empty, empty)),
                                    strict=True):
                values = np.asarray(values)  # float32 stays float32: half the bytes to send
                values = values if values.dtype.kind == "f" else values.astype(float)
                pad = np.full(length - len(values), np.nan, dtype=values.dtype)
                data[self.column(axis, name)] = np.concatenate([values, pad])
        self.source.data = data  # numpy: binary buffers, not JSON

    def clear(self) -> None:
        """Show no series (nothing is sent when none is shown already)."""
        if any(len(column) for column in self.source.data.values()):
            self.update({})

    def series(self, name: str) -> dict[str, np.ndarray]:
        """One series as shown, without the padding: ``{x: …, y: …}``."""
        x = np.asarray(self.source.data[self.column(self.x, name)], dtype=float)
        y = np.asarray(self.source.data[self.column(self.y, name)], dtype=float)
        keep = ~np.isnan(x)
        return {self.x: x[keep], self.y: y[keep]}


class RootLocusPlot:
    """Eigenvalues in the complex plane: tracked branches coloured by the swept parameter, the
    current point's eigenvalues highlighted, the unstable half-plane shaded."""

    def __init__(self):
        self.figure = new_figure("Root locus", "Re λ [1/s]", "Im λ [Hz]",
                                 x_range=Range1d(-6.0, 2.5), y_range=Range1d(0.0, 14.0))
        self.figure.name = "root-locus"
        fig = self.figure
        fig.add_layout(BoxAnnotation(left=0.0, fill_color=UNSTABLE, fill_alpha=0.08,
                                     line_alpha=0.0))
        fig.add_layout(Span(location=0.0, dimension="height", line_color=UNSTABLE,
                            line_dash="dashed"))
        fig.add_layout(Label(x=0.1, y=0.5, x_units="data", y_units="data", text="unstable",
                             text_color=UNSTABLE, text_font_size="11px"))
        self.mapper = LinearColorMapper(palette=Viridis256, low=0.0, high=1.0)
        self.lines = ColumnDataSource({"xs": [], "ys": []})
        self.points = ColumnDataSource({"x": [], "y": [], "value": [], "zeta": []},
                                       name="locus_points")
        self.current = ColumnDataSource({"x": [], "y": [], "mode": [], "zeta": [],
                                         "description": []}, name="locus_current")
        # a dragged slider's preview of the point (app.results.preview), lighter than the point
        self.preview = ColumnDataSource({"x": [], "y": []}, name="locus_preview")
        fig.multi_line("xs", "ys", source=self.lines, line_color="#999999", line_alpha=0.6)
        sweep = fig.scatter("x", "y", source=self.points, size=6,
                            color={"field": "value", "transform": self.mapper}, line_alpha=0.0)
        # the point's markers and a held slider's preview on the overlay layer: a new point
        # repaints them alone, not the thousands of the sweep's points and lines (a repaint of
        # the whole plot per preview made a dragged handle lag behind the mouse)
        now = fig.scatter("x", "y", source=self.current, size=13, marker="diamond",
                          fill_color="#ff7f0e", line_color="black", legend_label="current point",
                          level="overlay")
        fig.scatter("x", "y", source=self.preview, size=13, marker="diamond",
                    fill_color="#ff7f0e", fill_alpha=0.35, line_color="#ff7f0e",
                    line_dash="dashed", legend_label="preview (slider held)", level="overlay")
        fig.legend.location = "top_left"
        fig.legend.label_text_font_size = "10px"
        self.colorbar = ColorBar(color_mapper=self.mapper, title="s0 [-]", width=10)
        fig.add_layout(self.colorbar, "right")
        fig.add_tools(HoverTool(renderers=[now], tooltips=[
            ("mode", "@mode"), ("λ", "@x{0.000} ± i @y{0.000} Hz"), ("ζ", "@zeta{0.0000}"),
            ("shape", "@description")]))
        self.sweep_hover = HoverTool(renderers=[sweep], tooltips=[
            ("s0", "@value{0.0000}"), ("λ", "@x{0.000} ± i @y{0.000} Hz"), ("ζ", "@zeta{0.0000}")])
        fig.add_tools(self.sweep_hover)
        # click-through: a tapped diamond or sweep point selects that mode (app.dashboard.modes_view)
        fig.add_tools(TapTool(renderers=[now, sweep]))

    def zoom(self, low_modes: bool) -> None:
        """Fit the view: all tracked eigenvalues, or only the low, lightly damped modes."""
        x = list(self.current.data["x"]) + list(self.points.data["x"])
        if low_modes or not x:
            self.figure.x_range.start, self.figure.x_range.end = -5.0, 2.0
            self.figure.y_range.start, self.figure.y_range.end = 0.0, 14.0
            return
        low, high = min(min(x), -1.0), max(max(x), 1.0)
        pad = 0.05 * (high - low)
        self.figure.x_range.start, self.figure.x_range.end = low - pad, high + pad
        self.figure.y_range.start, self.figure.y_range.end = 0.0, 20.5

    def update_point(self, result: PointResult) -> None:
        lam = np.array([m.eigenvalue for m in result.modes])
        self.current.data = {"x": lam.real.tolist(), "y": (lam.imag / (2 * math.pi)).tolist(),
                             "mode": [m.number for m in result.modes],
                             "zeta": [m.damping_ratio for m in result.modes],
                             "description": [m.description for m in result.modes]}

    def update_preview(self, eigenvalues: np.ndarray | None) -> None:
        """The previewed point's eigenvalues [1/s] (the lowest N_COMPLEX_TABLE complex ones, as
        the current point shows), or none (None: the full answer replaced the preview)."""
        if eigenvalues is None:
            if len(self.preview.data["x"]):
                self.preview.data = {"x": [], "y": []}
            return
        lam = np.asarray(eigenvalues)
        lam = lam[np.isfinite(lam) & (lam.imag > 1e-9)]
        lam = lam[np.argsort(lam.imag)][:N_COMPLEX_TABLE]
        self.preview.data = {"x": lam.real, "y": lam.imag / (2 * math.pi)}

    def update_locus(self, locus: LocusResult) -> None:
        lam = locus.eigenvalues  # (points, branches)
        x, y = lam.real, lam.imag / (2 * math.pi)
        value = np.repeat(locus.values[:, None], lam.shape[1], axis=1)
        zeta = -lam.real / np.maximum(np.abs(lam), 1e-300)
        # numpy arrays travel to the browser as binary buffers (lists as JSON text: 10x slower);
        # lines are broken (NaN) where a branch jumps instead of crossing the plane straight
        self.lines.data = {"xs": broken_columns(x, locus.jumps),
                           "ys": broken_columns(y, locus.jumps)}
        # "value" colours the points; the column named after the swept parameter ("s0" or "v")
        # carries the same numbers for readers of the data (tests, scripts)
        self.points.selected.indices = []
        self.points.data = {"x": x.ravel(), "y": y.ravel(), "value": value.ravel(),
                            locus.parameter: value.ravel(), "zeta": zeta.ravel()}
        self.mapper.low, self.mapper.high = float(locus.values[0]), float(locus.values[-1])
        label = "s0 [-]" if locus.parameter == "s0" else "v [km/h]"
        self.colorbar.title = label
        self.sweep_hover.tooltips = [(label, "@value{0.0000}" if locus.parameter == "s0"
                                      else "@value{0}"),
                                     ("λ", "@x{0.000} ± i @y{0.000} Hz"), ("ζ", "@zeta{0.0000}")]
        sweep = (f"{len(locus.values)} points" if locus.dense
                 else f"{len(locus.values)} points, dense sweep computing…")
        self.figure.title.text = (f"Root locus over creepage s0 (current speed; {sweep})"
                                  if locus.parameter == "s0"
                                  else f"Root locus over speed v (current creepage; {sweep})")


class CreepPlot:
    """μ(s) at the current speed with the operating point, the maximum and s0* marked."""

    def __init__(self):
        self.figure = new_figure("Creep characteristic μ(s) at the current speed", "creepage s [-]",
                                 "adhesion coefficient μ [-]")
        fig = self.figure
        self.curve = ColumnDataSource({"s": [], "mu": []})
        self.point = ColumnDataSource({"s": [], "mu": []})
        self.preview = ColumnDataSource({"s": [], "mu": []}, name="creep_preview")
        fig.line("s", "mu", source=self.curve, line_width=2, legend_label="μ(s, v)")
        fig.scatter("s", "mu", source=self.point, size=11, fill_color="#ff7f0e",
                    line_color="black", legend_label="operating point s0", level="overlay")
        # the point and the preview on the overlay layer: an s0 step repaints them alone (both
        # lie inside the curve's span, so the ranges' fit does not move with them)
        fig.scatter("s", "mu", source=self.preview, size=11, fill_color="#ff7f0e",
                    fill_alpha=0.35, line_color="#ff7f0e", line_dash="dashed",
                    legend_label="preview (slider held)", level="overlay")
        self.limit = Span(location=0.0, dimension="height", line_color=UNSTABLE,
                          line_dash="dashed", line_width=2, visible=False)
        self.maximum = Span(location=0.0, dimension="height", line_color="#777777",
                            line_dash="dotted")
        # left of the line: the legend sits bottom right, the curve high above
        self.limit_label = Label(x=0.0, y=0.02, text="s0*", text_color=UNSTABLE, visible=False,
                                 text_align="right")
        fig.add_layout(self.limit)
        fig.add_layout(self.maximum)
        fig.add_layout(self.limit_label)
        fig.legend.location = "bottom_right"
        fig.y_range.start = 0.0

    def update_point(self, result: PointResult) -> None:
        shown = self.curve.data
        if not (np.array_equal(shown["s"], result.creep_s)
                and np.array_equal(shown["mu"], result.creep_mu)):
            # μ(s, v) depends on v and the creep law, not on s0: not sent again on an s0 step
            self.curve.data = {"s": result.creep_s, "mu": result.creep_mu}
        s0 = result.case.s0
        self.point.data = {"s": [s0], "mu": [result.mu0]}
        self.maximum.location = result.s_max

    def update_preview(self, s0: float | None, mu0: float = math.nan) -> None:
        """A dragged slider's previewed operating point (s0 [-], μ [-]), or none (None)."""
        if s0 is None:
            if len(self.preview.data["s"]):
                self.preview.data = {"s": [], "mu": []}
            return
        self.preview.data = {"s": [s0], "mu": [mu0]}

    def update_limit(self, limit: LimitResult | None) -> None:
        ok = limit is not None and limit.s0_limit is not None
        self.limit.visible = self.limit_label.visible = ok
        if ok:
            self.limit.location = limit.s0_limit
            self.limit_label.x = limit.s0_limit
            self.limit_label.text = f"s0* = {limit.s0_limit:.4f} "


class ResponsePlots:
    """Torques of both drives with ±M_ad, disc clutch forces, and M_C(t)."""

    def __init__(self):
        # every series (each min/max-decimated on its own time points) in one source
        self.sources = SeriesSource((*RESPONSE_OUTPUTS, "M_C"), name="response")
        self.torque = {}
        self.ad_spans = []
        shared_x = None
        for drive in ("ID1", "ID2"):
            fig = new_figure(f"{drive}: torques", "t [s]", "torque [N m]",
                             **({"x_range": shared_x} if shared_x else {}))
            shared_x = shared_x or fig.x_range
            for quantity, color in zip(TORQUES, ("#1f77b4", "#d62728"), strict=True):
                label = {"driving_shaft.torque": "driving shaft M_DS",
                         "disc_clutch.torque": "disc clutch M_xDC"}[quantity]
                self.sources.line(fig, f"{drive}.{quantity}", color=color, legend_label=label)
            for sign in (1, -1):
                span = Span(location=0.0, dimension="width", line_color="black",
                            line_dash="dashed")
                fig.add_layout(span)
                self.ad_spans.append((sign, span))
            fig.legend.location = "top_right"
            fig.legend.click_policy = "hide"
            fig.legend.label_text_font_size = "10px"
            self.torque[drive] = fig
        self.forces = new_figure("Disc clutch forces (ID1 —, ID2 - -)", "t [s]",
                                 "force [N]", x_range=shared_x)
        for quantity, color in zip(FORCES, Category10_10[2:5], strict=True):
            axis = quantity[-1]
            self.sources.line(self.forces, f"ID1.{quantity}", color=color,
                              legend_label=f"F_{axis} ID1")
            self.sources.line(self.forces, f"ID2.{quantity}", color=color, line_dash="dashed",
                              legend_label=f"F_{axis} ID2")
        self.forces.legend.click_policy = "hide"
        self.forces.legend.label_text_font_size = "10px"
        self.excitation = new_figure("Short-circuit torque M_C(t) on ID1's rotor", "t [s]",
                                     "M_C [N m]", x_range=shared_x)
        self.sources.line(self.excitation, "M_C", color="black")
        self.ad_label = Label(x=60, y=5, x_units="screen", y_units="screen", text="",
                              text_font_size="10px")
        self.torque["ID1"].add_layout(self.ad_label)

    @property
    def figures(self):
        return [self.torque["ID1"], self.torque["ID2"], self.forces, self.excitation]

    def update(self, response: ResponseView) -> None:
        self.sources.update(response.plot)
        for sign, span in self.ad_spans:
            span.location = sign * response.M_ad
        self.ad_label.text = f"dashed: ±M_ad = ±{response.M_ad:,.0f} N m"
        for fig in self.figures[:3]:
            fig.title.text = fig.title.text.split(" — ")[0] + (
                f" — UNSTABLE: growth, shown to {response.plot_cut:.3f} s"
                if response.plot_cut is not None else "")


# --- mode shapes -------------------------------------------------------------------------------

def drawing_segments(positions: dict[str, np.ndarray]) -> list[tuple[str, str]]:
    """Pairs of drawn points joined by a line: shafts, gear train, motor suspension, frame."""
    segments = []
    for drive in ("ID1", "ID2"):
        axle = sorted((n for n in positions if n.startswith(f"{drive}.ax")),
                      key=lambda n: positions[n][1])
        hollow = sorted((n for n in positions if n.startswith(f"{drive}.hs")),
                        key=lambda n: positions[n][1])
        segments += list(itertools.pairwise(axle))
        segments += list(itertools.pairwise(hollow))
        segments += [(f"{drive}.rotor", f"{drive}.pinion"), (f"{drive}.pinion", f"{drive}.gear"),
                     (f"{drive}.stator", f"{drive}.rotor")]
        segments += [(f"{drive}.stator", f"{drive}.silent_block_{k}") for k in "ABC"]
        segments += [(f"{drive}.{a}", f"{drive}.{b}") for a, b in (("hs9", "ax10"),)]
    corners = ["secondary.P1", "secondary.P3", "secondary.P4", "secondary.P2"]
    segments += list(zip(corners, corners[1:] + corners[:1], strict=True))
    segments += [("BF", "CB")]
    return [(a, b) for a, b in segments if a in positions and b in positions]


class ModeShapePlot:
    """Side (x–z) and top (x–y) view: undeformed (grey) and scaled deformed shape (colour)."""

    SCALE = 0.2  # largest drawn displacement [m] on the drawing

    def __init__(self, positions: dict[str, np.ndarray], wheel_radius: float):
        self.positions = positions
        self.segments = drawing_segments(positions)
        self.views = {}
        for name, (a, b), label in (("side", (0, 2), "z [m]"), ("top", (0, 1), "y [m]")):
            fig = new_figure(f"{'Side' if name == 'side' else 'Top'} view", "x [m]", label,
                             match_aspect=True)
            fig.height = 300
            base = ColumnDataSource(self._lines(np.zeros(3), a, b, {}))
            moved = ColumnDataSource(self._lines(np.zeros(3), a, b, {}))
            base_pts = ColumnDataSource(self._points(a, b, {}, 0.0))
            moved_pts = ColumnDataSource(self._points(a, b, {}, 0.0))
            if name == "side":
                rims = [n for n in positions if ".rim" in n]
                fig.circle([positions[n][0] for n in rims], [positions[n][2] for n in rims],
                           radius=wheel_radius, fill_alpha=0.0, line_color="#bbbbbb")
            fig.multi_line("xs", "ys", source=base, line_color="#aaaaaa", line_width=2,
                           legend_label="undeformed")
            fig.scatter("x", "y", source=base_pts, color="#aaaaaa", size=5)
            fig.multi_line("xs", "ys", source=moved, line_color="#1f77b4", line_width=2,
                           legend_label="mode (scaled)")
            moved_r = fig.scatter("x", "y", source=moved_pts, color="#1f77b4", size=6)
            fig.add_tools(HoverTool(renderers=[moved_r], tooltips=[("part", "@name")]))
            fig.legend.location = "top_left"
            fig.legend.label_text_font_size = "10px"
            self.views[name] = (fig, (a, b), moved, moved_pts)

    def _lines(self, _unused, a, b, shift):
        xs, ys = [], []
        for p, q in self.segments:
            pa = self.positions[p] + shift.get(p, 0.0)
            pb = self.positions[q] + shift.get(q, 0.0)
            xs.append([float(pa[a]), float(pb[a])])
            ys.append([float(pa[b]), float(pb[b])])
        return {"xs": xs, "ys": ys}

    def _points(self, a, b, shift, _scale):
        names = list(self.positions)
        pts = [self.positions[n] + shift.get(n, 0.0) for n in names]
        return {"x": [float(p[a]) for p in pts], "y": [float(p[b]) for p in pts], "name": names}

    @property
    def figures(self):
        return [view[0] for view in self.views.values()]

    def update(self, displacement: dict[str, np.ndarray]) -> None:
        largest = max((float(np.max(np.abs(u))) for u in displacement.values()), default=0.0)
        scale = self.SCALE / largest if largest > 0 else 0.0
        shift = {n: scale * u for n, u in displacement.items()}
        for _fig, (a, b), moved, moved_pts in self.views.values():
            moved.data = self._lines(None, a, b, shift)
            moved_pts.data = self._points(a, b, shift, scale)
