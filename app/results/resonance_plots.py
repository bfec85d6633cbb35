"""Bokeh figures of the resonances (dashboard and report alike): the Campbell diagram, the
frequency response of one output, the forced response to a ripple or to polygonal wheels over
speed, the power spectral density under the random track.  Built once, then
fed with the plain results of :mod:`app.results.resonance`; nothing here computes physics.
"""

from __future__ import annotations

import numpy as np
from bokeh.models import (
    ColorBar,
    ColumnDataSource,
    HoverTool,
    LinearColorMapper,
    Range1d,
    Span,
    TapTool,
)
from bokeh.palettes import Category10_10, Viridis256

from app.results.plots import UNSTABLE, new_figure
from app.results.resonance import CampbellView, RippleView
from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ, FrequencyResponse
from model.analysis.track_spectrum import RandomResponse
from model.analysis.wheel_excitation import PolygonResponse

ZETA_RANGE = (0.0, 0.1)  # colour scale of the damping ratio [-]; below 0 (growing): red
F_RANGE = (1.0, MODEL_FREQUENCY_LIMIT_HZ)  # [Hz] the diagram's frequency axis (log)


class CampbellPlot:
    """Modes over speed coloured by their damping ratio, the order lines, the crossings (figure
    ``campbell``).  The mode points' source (name ``campbell-modes``) can be tapped:
    :attr:`modes` ``.selected``."""

    def __init__(self, height: int = 460):
        self.figure = new_figure("Campbell diagram: eigenfrequencies over speed, excitation orders",
                                 "speed v [km/h]", "frequency [Hz]", y_axis_type="log",
                                 y_range=Range1d(*F_RANGE), x_range=Range1d(0, 250))
        self.figure.height = height
        self.figure.name = "campbell"
        self.mapper = LinearColorMapper(palette=Viridis256[::-1], low=ZETA_RANGE[0],
                                        high=ZETA_RANGE[1], low_color=UNSTABLE)
        self.curves = ColumnDataSource({"xs": [], "ys": []}, name="campbell-curves")
        self.figure.multi_line("xs", "ys", source=self.curves, color="#bbbbbb", line_width=1)
        self.lines = ColumnDataSource({"xs": [], "ys": [], "label": [], "color": []},
                                      name="campbell-orders")
        self.figure.multi_line("xs", "ys", source=self.lines, color="color", line_dash="dashed",
                               line_width=1.5, legend_field="label")
        self.modes = ColumnDataSource({"v": [], "f": [], "zeta": [], "name": [], "re": [],
                                       "im": []}, name="campbell-modes")
        points = self.figure.scatter("v", "f", source=self.modes, size=5,
                                     color={"field": "zeta", "transform": self.mapper},
                                     line_color=None, nonselection_alpha=0.6,
                                     selection_line_color="black")
        self.crossings = ColumnDataSource({"v": [], "f": [], "zeta": [], "mode": [], "order": [],
                                           "output": [], "severity": [], "size": []},
                                          name="campbell-crossings")
        marks = self.figure.scatter("v", "f", source=self.crossings, marker="diamond",
                                    size="size", fill_color="white", line_color="black",
                                    line_width=1.5)
        self.figure.add_tools(
            HoverTool(renderers=[points], tooltips=[("mode", "@name"), ("v", "@v{0.0} km/h"),
                                                    ("f", "@f{0.000} Hz"), ("ζ", "@zeta{0.0000}")]),
            HoverTool(renderers=[marks], tooltips=[
                ("crossing", "@order × @mode"), ("v", "@v{0.00} km/h"), ("f", "@f{0.000} Hz"),
                ("ζ", "@zeta{0.0000}"), ("largest torque", "@severity{0.000} N m/N m in @output")]),
            TapTool(renderers=[points]))
        self.figure.add_layout(ColorBar(color_mapper=self.mapper, title="damping ratio ζ [-] "
                                        "(red: growing)", width=10), "right")
        legend = self.figure.legend[0]
        legend.label_text_font_size = "9pt"
        self.figure.add_layout(legend, "right")  # beside the plot: it hides no crossing
        self.speed = Span(location=np.nan, dimension="height", line_color="black",
                          line_dash="dotted")
        self.figure.add_layout(self.speed)

    def update(self, view: CampbellView) -> None:
        v = view.v_kmh
        xs, ys, data = [], [], {key: [] for key in self.modes.data}
        for mode in view.modes:
            shown = (mode.f_hz >= F_RANGE[0]) & (mode.f_hz <= F_RANGE[1])
            if not shown.any():
                continue
            xs.append(np.where(shown, v, np.nan))
            ys.append(np.where(shown, mode.f_hz, np.nan))
            data["v"] += list(v[shown])
            data["f"] += list(mode.f_hz[shown])
            data["zeta"] += list(mode.zeta[shown])
            data["name"] += [mode.name] * int(shown.sum())
            data["re"] += list(mode.eigenvalues.real[shown])
            data["im"] += list(np.abs(mode.eigenvalues.imag[shown]))
        self.modes.selected.indices = []
        self.modes.data = data
        self.curves.data = {"xs": xs, "ys": ys}
        colors = [Category10_10[i % 10] for i in range(len(view.orders))]
        self.lines.data = {"xs": [v for _ in view.orders],
                           "ys": [np.where((line >= F_RANGE[0]) & (line <= F_RANGE[1]), line,
                                           np.nan) for _, _, line in view.orders],
                           "label": [label for _, label, _ in view.orders], "color": colors}
        severity = np.array([c.severity for c in view.crossings])
        size = 8 + 4 * np.log10(np.maximum(severity, 1e-3) / 1e-3) if len(severity) else []
        self.crossings.data = {
            "v": [c.v_kmh for c in view.crossings], "f": [c.f_hz for c in view.crossings],
            "zeta": [c.zeta for c in view.crossings], "mode": [c.mode for c in view.crossings],
            "order": [c.label for c in view.crossings],
            "output": [c.worst_output for c in view.crossings], "severity": list(severity),
            "size": list(np.clip(size, 6, 30))}
        self.figure.x_range.start, self.figure.x_range.end = float(v[0]), float(v[-1])

    def mark_speed(self, v_kmh: float) -> None:
        """The dashboard's speed as a dotted vertical line [km/h]."""
        self.speed.location = float(v_kmh)


class FrfPlot:
    """|H| (log–log) and phase of one output, its peaks marked."""

    def __init__(self):
        self.magnitude = new_figure("frequency response", "frequency [Hz]", "|H|",
                                    x_axis_type="log", y_axis_type="log")
        self.phase = new_figure("phase", "frequency [Hz]", "phase [deg]", x_axis_type="log",
                                x_range=self.magnitude.x_range)
        self.phase.height = 200
        self.magnitude.name, self.phase.name = "frf-magnitude", "frf-phase"
        self.source = ColumnDataSource({"f": [], "abs": [], "phase": []}, name="frf")
        self.peaks = ColumnDataSource({"f": [], "abs": [], "gain": []}, name="frf-peaks")
        self.magnitude.line("f", "abs", source=self.source, color="#1f77b4")
        marks = self.magnitude.scatter("f", "abs", source=self.peaks, size=7, color=UNSTABLE)
        self.magnitude.add_tools(HoverTool(renderers=[marks], tooltips=[
            ("peak", "@f{0.000} Hz"), ("|H|", "@abs{0.000}"), ("× static", "@gain")]))
        self.phase.line("f", "phase", source=self.source, color="#555555")

    def update(self, frf: FrequencyResponse, output: str) -> None:
        row = frf.output(output)
        unit = f"{frf.units[row]}/{frf.input_unit}"
        self.source.data = {"f": frf.f_hz[1:], "abs": frf.magnitude[row, 1:],
                            "phase": frf.phase_deg[row, 1:]}
        peaks = frf.peaks[row]
        self.peaks.data = {"f": [p.f_hz for p in peaks], "abs": [p.abs for p in peaks],
                           "gain": ["—" if p.amplification is None else f"{p.amplification:.3g}"
                                    for p in peaks]}
        op = frf.operating_point
        self.magnitude.title.text = (f"{output} at s0 = {op.s0:g}, v = {op.v_kmh:g} km/h "
                                     f"(static gain {abs(frf.static_gain[row]):.4g})"
                                     + ("" if frf.stable else
                                        " — unstable point: no steady state"))
        self.magnitude.yaxis.axis_label = f"|H| [{unit}] from {frf.input}"


class RipplePlot:
    """Steady amplitude of one output over speed under the ripple: each order and their sum."""

    def __init__(self):
        self.figure = new_figure("forced response to the torque ripple", "speed v [km/h]",
                                 "amplitude")
        self.figure.name = "ripple-response"
        self.source = ColumnDataSource({"xs": [], "ys": [], "label": [], "color": []},
                                       name="ripple")
        self.figure.multi_line("xs", "ys", source=self.source, color="color", line_width=2,
                               legend_field="label")
        self.figure.legend.location = "top_left"
        self.speed = Span(location=np.nan, dimension="height", line_color="black",
                          line_dash="dotted")
        self.figure.add_layout(self.speed)

    def update(self, ripple: RippleView, output: str) -> None:
        row = ripple.names.index(output)
        series = [ripple.total[row]] + [ripple.by_order[k, row] for k in range(len(ripple.orders))]
        labels = ["sum (largest steady peak)"] + [
            f"{label} = {a:g} N m" for label, a in zip(ripple.labels, ripple.amplitudes,
                                                     strict=True)]
        colors = ["black"] + [Category10_10[k % 10] for k in range(len(ripple.orders))]
        self.source.data = {"xs": [ripple.v_kmh] * len(series), "ys": series, "label": labels,
                            "color": colors}
        self.figure.title.text = f"{output} under a torque ripple of {ripple.input}"
        self.figure.yaxis.axis_label = f"steady amplitude [{ripple.units[row]}]"

    def mark_speed(self, v_kmh: float) -> None:
        self.speed.location = float(v_kmh)


class PolygonPlot:
    """Steady amplitude of one output over speed under polygonal wheels: each order and their
    sum (figure ``polygon-response``, source ``polygon``)."""

    def __init__(self):
        self.figure = new_figure("forced response to polygonal wheels", "speed v [km/h]",
                                 "amplitude")
        self.figure.name = "polygon-response"
        self.source = ColumnDataSource({"xs": [], "ys": [], "label": [], "color": []},
                                       name="polygon")
        self.figure.multi_line("xs", "ys", source=self.source, color="color", line_width=2,
                               legend_field="label")
        self.figure.legend.location = "top_left"
        self.speed = Span(location=np.nan, dimension="height", line_color="black",
                          line_dash="dotted")
        self.figure.add_layout(self.speed)

    def clear(self, title: str) -> None:
        """No polygon: an empty plot whose title says why (``title``)."""
        self.source.data = {"xs": [], "ys": [], "label": [], "color": []}
        self.figure.title.text = title
        self.figure.yaxis.axis_label = "steady amplitude"

    def update(self, polygon: PolygonResponse, output: str) -> None:
        row = polygon.names.index(output)
        v = polygon.v_kmh
        series = [polygon.total[row]] + [polygon.by_order[k, row]
                                         for k in range(len(polygon.orders))]
        labels = ["sum (largest steady peak)"] + [
            f"order {n}: {a * 1e6:g} µm" for n, a in zip(polygon.orders, polygon.amplitudes,
                                                        strict=True)]
        colors = ["black"] + [Category10_10[k % 10] for k in range(len(polygon.orders))]
        self.source.data = {"xs": [v] * len(series), "ys": series, "label": labels,
                            "color": colors}
        unstable = ("" if not polygon.unstable_kmh else
                    "\nrunning system unstable at " + ", ".join(
                        f"{x:.0f}" for x in polygon.unstable_kmh) + " km/h: no steady state")
        self.figure.title.text = (f"{output} under polygonal wheels at s0 = "
                                  f"{polygon.operating_point.s0:g}{unstable}")
        self.figure.yaxis.axis_label = f"steady amplitude [{polygon.units[row]}]"

    def mark_speed(self, v_kmh: float) -> None:
        self.speed.location = float(v_kmh)


class TrackPlot:
    """Power spectral density of one output under the random vertical track at one operating
    point, log–log (figure ``track-psd``, source ``track``); its RMS in the title."""

    def __init__(self):
        self.figure = new_figure("random track: power spectral density", "frequency [Hz]",
                                 "PSD", x_axis_type="log", y_axis_type="log")
        self.figure.name = "track-psd"
        self.source = ColumnDataSource({"f": [], "psd": []}, name="track")
        self.figure.line("f", "psd", source=self.source, color="#2ca02c", line_width=1.5)
        self.figure.add_tools(HoverTool(tooltips=[("f", "@f{0.000} Hz"), ("PSD", "@psd")]))

    def update(self, track: RandomResponse, output: str) -> None:
        row = track.output(output)
        unit = track.units[row]
        squared = f"({unit})²" if (" " in unit or "/" in unit) else f"{unit}²"
        shown = track.psd[row] > 0  # a log axis: the band's zeros (none inside) left out
        self.source.data = {"f": track.f_hz[shown], "psd": track.psd[row][shown]}
        op = track.operating_point
        self.figure.title.text = (
            f"{output}: RMS {track.rms[row]:.4g} {unit} on the random track "
            f"({track.spectrum.name} level)\nat s0 = {op.s0:g}, v = {op.v_kmh:g} km/h"
            + ("" if track.stable else
               "; running system unstable: no stationary response"))
        self.figure.yaxis.axis_label = f"PSD [{squared}/Hz]"
