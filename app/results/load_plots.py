"""Bokeh figures of the design loads (dashboard and report): the worst case over every fault
instant against time, the load collective, the rainflow matrix and the map of an envelope's peak
over two axes of a scenario grid.

Like :mod:`app.results.plots`: each ``*Plot`` owns its figures and sources, built once, and an
``update(…)`` method that only replaces source data.  One drive part is shown at a time, ID1 and
ID2 side by side; SI units in every label (torques [N m], the gear mesh force [N]).
"""

from __future__ import annotations

import numpy as np
from bokeh.models import ColorBar, ColumnDataSource, HoverTool, LinearColorMapper, LogColorMapper
from bokeh.palettes import Viridis256

from app.results.compute import PART_LABELS, ResponseView, SpectraView, WorstCaseView
from app.results.plots import new_figure

DRIVES = ("ID1", "ID2")
BAND, EDGE, AT_DT, NONLINEAR = "#9ecae1", "#08519c", "#222222", "#d62728"
DRIVE_COLORS = {"ID1": "#1f77b4", "ID2": "#ff7f0e"}
BEYOND_HIGH, BEYOND_LOW = "#d62728", "#1f1f7a"  # heat-map cells above / below the colour scale
OUTLIER_FACTOR = 10.0  # a cell this many 5-95 % spreads beyond the 95 % (5 %) value is an outlier


def quantity_label(part: str, unit: str) -> str:
    """An axis label of a drive part's load, e.g. ``disc clutch torque [N m]``."""
    return f"{PART_LABELS.get(part, part)} [{unit}]"


class WorstCasePlot:
    """Per drive: the max and the min over every fault instant Δt at each time (a band), the
    history at the dashboard's Δt and, with nonlinear creep on, the nonlinear history."""

    def __init__(self):
        self.figures: dict[str, object] = {}
        self.sources: dict[str, ColumnDataSource] = {}
        self.nonlinear: dict[str, ColumnDataSource] = {}
        shared_x = None
        for drive in DRIVES:
            fig = new_figure(f"{drive}", "t [s]", "load",
                             **({"x_range": shared_x} if shared_x else {}))
            shared_x = shared_x or fig.x_range
            source = ColumnDataSource({"t": [], "upper": [], "lower": [], "at_dt": []},
                                      name=f"worst-case-{drive}")
            band = "min … max over every Δt"  # one legend entry: the band and its edges
            fig.varea("t", "lower", "upper", source=source, fill_color=BAND, fill_alpha=0.45,
                      legend_label=band)
            fig.line("t", "upper", source=source, color=EDGE, line_width=1.2, legend_label=band)
            fig.line("t", "lower", source=source, color=EDGE, line_width=1.2, legend_label=band)
            fig.line("t", "at_dt", source=source, color=AT_DT, line_width=1.0, alpha=0.8,
                     legend_label="at the Response tab's Δt (linear)")
            nonlinear = ColumnDataSource({"t": [], "y": []}, name=f"worst-case-nonlinear-{drive}")
            fig.line("t", "y", source=nonlinear, color=NONLINEAR, line_width=1.0, alpha=0.8,
                     legend_label="nonlinear creep")
            # under the plot: inside, it hid the curves that span the whole horizon
            legend = fig.legend[0]
            legend.orientation = "horizontal"
            legend.click_policy = "hide"
            legend.label_text_font_size = "10px"
            fig.add_layout(legend, "below")
            fig.height = 360
            self.figures[drive], self.sources[drive], self.nonlinear[drive] = fig, source, nonlinear

    def update(self, worst: WorstCaseView, part: str, nonlinear: ResponseView | None = None
               ) -> None:
        """Show drive part ``part`` (e.g. "disc_clutch.torque") of ``worst``; ``nonlinear``: the
        nonlinear history to overlay (None: none)."""
        for drive in DRIVES:
            name = f"{drive}.{part}"
            t, upper, lower, at_dt = worst.plot[name]
            self.sources[drive].data = {"t": t, "upper": upper, "lower": lower, "at_dt": at_dt}
            if nonlinear is not None:
                tn, yn = nonlinear.plot[name]
                self.nonlinear[drive].data = {"t": tn, "y": yn}
            elif len(self.nonlinear[drive].data["t"]):
                self.nonlinear[drive].data = {"t": [], "y": []}
            fig = self.figures[drive]
            cut = (f" (linear growth: to {worst.plot_cut:.3f} s)"
                   if worst.plot_cut is not None else "")
            fig.title.text = f"{drive} {PART_LABELS[part]}, every fault instant{cut}"
            fig.yaxis.axis_label = quantity_label(part, worst.units[name])

    @property
    def figure_list(self) -> list:
        return [self.figures[drive] for drive in DRIVES]


class LoadCollectivePlot:
    """The load collective (cumulative exceedance diagram) of one drive part, ID1 and ID2: the
    cycles H with a range at least ΔM (logarithmic) against ΔM."""

    def __init__(self, title: str = "Load collective"):
        self.title = title
        self.figure = new_figure(title, "cycles with a range ≥ ΔM, H [-]", "range ΔM",
                                 x_axis_type="log")
        self.sources = {}
        for drive in DRIVES:
            source = ColumnDataSource({"H": [], "range": []}, name=f"collective-{drive}")
            self.figure.step("H", "range", source=source, mode="before",
                             color=DRIVE_COLORS[drive], line_width=1.5, legend_label=drive)
            self.figure.scatter("H", "range", source=source, color=DRIVE_COLORS[drive], size=3)
            self.sources[drive] = source
        self.figure.legend.location = "top_right"
        self.figure.legend.click_policy = "hide"

    def update(self, spectra: SpectraView, part: str) -> None:
        """Show drive part ``part`` of ``spectra``."""
        unit = ""
        for drive in DRIVES:
            spectrum = spectra.spectra[f"{drive}.{part}"]
            unit = spectrum.unit
            self.sources[drive].data = {"H": np.asarray(spectrum.exceedance_count, dtype=float),
                                        "range": np.asarray(spectrum.exceedance_range,
                                                            dtype=float)}
        self.figure.title.text = f"{self.title}: {PART_LABELS[part]}"
        self.figure.yaxis.axis_label = f"range Δ of the {quantity_label(part, unit)}"


class RainflowMatrixPlot:
    """The rainflow matrix of one drive part, ID1 and ID2: cycles per (mean, range) bin."""

    def __init__(self):
        self.figures, self.sources, self.mappers = {}, {}, {}
        for drive in DRIVES:
            fig = new_figure(f"{drive}: rainflow matrix", "mean", "range")
            fig.height = 300
            mapper = LogColorMapper(palette=Viridis256, low=0.5, high=1.0, nan_color="white")
            source = ColumnDataSource({"image": [np.full((1, 1), np.nan)], "x": [0.0],
                                       "y": [0.0], "dw": [1.0], "dh": [1.0]},
                                      name=f"rainflow-{drive}")
            fig.image(image="image", x="x", y="y", dw="dw", dh="dh", source=source,
                      color_mapper=mapper)
            fig.add_layout(ColorBar(color_mapper=mapper, title="cycles [-]"), "right")
            fig.add_tools(HoverTool(tooltips=[("cycles", "@image")]))
            fig.xaxis.ticker.desired_num_ticks = 4
            self.figures[drive], self.sources[drive], self.mappers[drive] = fig, source, mapper

    def update(self, spectra: SpectraView, part: str) -> None:
        for drive in DRIVES:
            name = f"{drive}.{part}"
            counts, range_edges, mean_edges = spectra.matrices[name]
            unit = spectra.spectra[name].unit
            image = np.where(counts > 0, counts, np.nan)  # rows: range bins, columns: mean bins
            self.sources[drive].data = {
                "image": [image], "x": [float(mean_edges[0])], "y": [float(range_edges[0])],
                "dw": [float(mean_edges[-1] - mean_edges[0])],
                "dh": [float(range_edges[-1] - range_edges[0])]}
            self.mappers[drive].high = max(1.0, float(np.nanmax(image, initial=1.0)))
            fig = self.figures[drive]
            fig.title.text = f"{drive}: rainflow matrix of the {PART_LABELS[part]}"
            fig.xaxis.axis_label = f"cycle mean [{unit}]"
            fig.yaxis.axis_label = f"cycle range [{unit}]"

    @property
    def figure_list(self) -> list:
        return [self.figures[drive] for drive in DRIVES]


class EnvelopeMapPlot:
    """The peak of one output over two axes of a scenario grid (a heat map), the largest
    (or smallest) marked."""

    def __init__(self):
        self.figure = new_figure("Envelope", "axis 1", "axis 2")
        self.figure.height = 380
        self.mapper = LinearColorMapper(palette=Viridis256, low=0.0, high=1.0,
                                        nan_color="#eeeeee", high_color=BEYOND_HIGH,
                                        low_color=BEYOND_LOW)
        self.beyond = 0  # cells beyond the colour scale (update)
        self.image = ColumnDataSource({"image": [np.full((1, 1), np.nan)], "x": [0.0],
                                       "y": [0.0], "dw": [1.0], "dh": [1.0]}, name="envelope-map")
        self.figure.image(image="image", x="x", y="y", dw="dw", dh="dh", source=self.image,
                          color_mapper=self.mapper)
        self.colorbar = ColorBar(color_mapper=self.mapper, title="peak")
        self.figure.add_layout(self.colorbar, "right")
        self.figure.add_tools(HoverTool(tooltips=[("peak", "@image{0,0.[000]}")]))
        self.points = ColumnDataSource({"x": [], "y": []})
        self.figure.scatter("x", "y", source=self.points, color="white", size=3, alpha=0.6)
        self.extreme = ColumnDataSource({"x": [], "y": []})  # the title says what the star is
        self.figure.scatter("x", "y", source=self.extreme, marker="star", size=16,
                            color="white", line_color="black")

    def update(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, x_label: str, y_label: str,
               title: str, value_label: str, largest: bool = True) -> None:
        """Show ``z`` (len(y) x len(x), nan: not computed) over the grid ``x``, ``y`` (increasing;
        one value: a cell of unit width)."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        z = np.asarray(z, dtype=float)
        dx = (x[-1] - x[0]) / (len(x) - 1) if len(x) > 1 else max(abs(x[0]) * 0.1, 1e-9)
        dy = (y[-1] - y[0]) / (len(y) - 1) if len(y) > 1 else max(abs(y[0]) * 0.1, 1e-9)
        self.image.data = {"image": [z], "x": [x[0] - dx / 2], "y": [y[0] - dy / 2],
                           "dw": [x[-1] - x[0] + dx], "dh": [y[-1] - y[0] + dy]}
        finite = z[np.isfinite(z)]
        low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        self.beyond = 0
        if finite.size >= 4:
            # a few cells far beyond the others (the linear growth of unstable points) would
            # flatten the rest: the scale spans the 5-95 % range, cells beyond it get the
            # beyond-the-scale colours and are counted (``beyond``)
            p5, p95 = (float(x) for x in np.percentile(finite, [5, 95]))
            spread = max(p95 - p5, 1e-12 * max(abs(p5), abs(p95), 1.0))
            if high - p95 > OUTLIER_FACTOR * spread:
                high = p95
            if p5 - low > OUTLIER_FACTOR * spread:
                low = p5
            self.beyond = int(np.sum((finite > high) | (finite < low)))
        if high <= low:
            high = low + max(abs(low) * 1e-6, 1e-12)
        self.mapper.low, self.mapper.high = low, high
        gx, gy = np.meshgrid(x, y)
        self.points.data = {"x": gx.ravel(), "y": gy.ravel()}
        if finite.size:
            flat = np.where(np.isfinite(z), z, -np.inf if largest else np.inf)
            j, i = np.unravel_index(int(np.argmax(flat) if largest else np.argmin(flat)), z.shape)
            self.extreme.data = {"x": [x[i]], "y": [y[j]]}
        else:
            self.extreme.data = {"x": [], "y": []}
        self.figure.title.text = f"{title} (★: the {'largest' if largest else 'smallest'})"
        self.figure.xaxis.axis_label = x_label
        self.figure.yaxis.axis_label = y_label
        self.colorbar.title = value_label
