"""The study's Fig. 6 from the root locus: Im λ [Hz] and Re λ [1/s] of the tracked complex
branches, and the real eigenvalues [1/s], against the swept parameter (s0 at the current speed,
or v at the current creepage), with the stability limit marked.

Compute, then plot: :func:`fig6_series` reshapes a :class:`app.results.compute.LocusResult` into plain
arrays (tested without Bokeh); :class:`Fig6Plot` owns three Bokeh figures and only replaces
their data.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from bokeh.models import ColumnDataSource, Label, Span
from bokeh.palettes import Category10_10

from app.results.compute import LocusResult
from app.results.locus_geometry import broken_columns
from app.results.plots import UNSTABLE, new_figure

FIG6_MAX_DAMPING = 0.3  # complex branches shown: damping ratio below this somewhere on the sweep
REAL_TOL = 1e-9  # |Im λ| below this [1/s]: a real eigenvalue


@dataclass(frozen=True)
class Fig6Series:
    """Fig. 6 data of one sweep (NaN where a branch is not of the kind plotted, or jumps)."""

    parameter: str  # "s0" [-] or "v" [km/h]
    x: list[np.ndarray]  # per complex branch: swept values (with NaN at breaks)
    im_hz: list[np.ndarray]  # per complex branch: Im λ [Hz]
    re: list[np.ndarray]  # per complex branch: Re λ [1/s]
    real_x: list[np.ndarray]  # per real branch: swept values
    real: list[np.ndarray]  # per real branch: the real eigenvalue [1/s]
    crossing: float | None  # swept value where the largest tracked real part turns positive


def fig6_series(locus: LocusResult) -> Fig6Series:
    """Split the tracked branches of ``locus`` into complex (Im > 0, lightly damped somewhere:
    ζ < FIG6_MAX_DAMPING) and real ones; parts of a branch of the other kind become NaN."""
    lam = locus.eigenvalues
    n_branches = lam.shape[1]
    values = np.repeat(np.asarray(locus.values, dtype=float)[:, None], n_branches, axis=1)
    is_real = np.abs(lam.imag) < REAL_TOL
    zeta = -lam.real / np.maximum(np.abs(lam), 1e-300)
    complex_branches = [b for b in range(n_branches)
                        if np.any(~is_real[:, b] & (zeta[:, b] < FIG6_MAX_DAMPING))]
    real_branches = [b for b in range(n_branches) if np.any(is_real[:, b])]
    jumps = locus.jumps

    def pick(branches, series, mask):
        data = np.where(mask, series, np.nan)[:, branches]
        return broken_columns(data, None if jumps is None else jumps[:, branches])

    x_c = pick(complex_branches, values, ~is_real)
    x_r = pick(real_branches, values, is_real)
    growth = lam.real.max(axis=1)
    crossing = None
    turns = np.flatnonzero((growth[:-1] <= 0) & (growth[1:] > 0))
    if len(turns):
        i = int(turns[0])
        fraction = -growth[i] / (growth[i + 1] - growth[i])
        crossing = float(locus.values[i] + fraction * (locus.values[i + 1] - locus.values[i]))
    return Fig6Series(locus.parameter, x_c,
                      pick(complex_branches, np.abs(lam.imag) / (2 * math.pi), ~is_real),
                      pick(complex_branches, lam.real, ~is_real), x_r,
                      pick(real_branches, lam.real, is_real), crossing)


class Fig6Plot:
    """Three figures in the layout of the study's Fig. 6 (names ``fig6-im``, ``fig6-re``,
    ``fig6-real``); the stability limit as a red dashed line."""

    def __init__(self):
        self.sources = {}
        self.limits = []
        self.labels = []
        specs = (("fig6-im", "Im λ [Hz] of the complex branches", "Im λ [Hz]"),
                 ("fig6-re", "Re λ [1/s] of the complex branches", "Re λ [1/s]"),
                 ("fig6-real", "Real eigenvalues [1/s]", "λ [1/s]"))
        self.figures = []
        shared_x = None
        for name, title, y_label in specs:
            fig = new_figure(title, "creepage s0 [-]", y_label,
                             **({"x_range": shared_x} if shared_x else {}))
            shared_x = shared_x or fig.x_range
            fig.name = name
            fig.height = 300
            source = ColumnDataSource({"xs": [], "ys": [], "color": []}, name=f"{name}-data")
            fig.multi_line("xs", "ys", source=source, line_color="color", line_width=1.5)
            if name != "fig6-im":
                fig.add_layout(Span(location=0.0, dimension="width", line_color="#777777",
                                    line_dash="dotted"))
            limit = Span(location=0.0, dimension="height", line_color=UNSTABLE,
                         line_dash="dashed", line_width=2, visible=False)
            label = Label(x=0.0, y=5, y_units="screen", text="", text_color=UNSTABLE,
                          text_font_size="11px", visible=False)
            fig.add_layout(limit)
            fig.add_layout(label)
            self.sources[name] = source
            self.limits.append(limit)
            self.labels.append(label)
            self.figures.append(fig)
        self._limit: tuple[str, float | None] = ("s0", None)  # s0*(v) of the current speed
        self._series: Fig6Series | None = None

    def update_locus(self, locus: LocusResult) -> None:
        series = fig6_series(locus)
        self._series = series
        colors = [Category10_10[i % 10] for i in range(len(series.x))]
        real_colors = [Category10_10[i % 10] for i in range(len(series.real_x))]
        self.sources["fig6-im"].data = {"xs": series.x, "ys": series.im_hz, "color": colors}
        self.sources["fig6-re"].data = {"xs": series.x, "ys": series.re, "color": colors}
        self.sources["fig6-real"].data = {"xs": series.real_x, "ys": series.real,
                                          "color": real_colors}
        x_label = "creepage s0 [-]" if locus.parameter == "s0" else "speed v [km/h]"
        for fig in self.figures:
            fig.xaxis.axis_label = x_label
            fig.title.text = fig.title.text.split(" — ")[0] + (
                " — over s0 at the current speed" if locus.parameter == "s0"
                else " — over v at the current creepage")
        # lightly damped branches decide the view of Re; heavily damped ones stay reachable
        re = np.concatenate([r for r in series.re if r.size]) if series.re else np.zeros(1)
        re = re[np.isfinite(re)]
        fig_re = self.figures[1]
        if re.size:
            fig_re.y_range.start = float(max(re.min(), -15.0)) - 0.5
            fig_re.y_range.end = float(max(re.max(), 0.5)) + 0.5
        self._show_limit()

    def update_limit(self, s0_limit: float | None) -> None:
        """The stability limit s0*(v) at the current speed (shown on the sweep over s0)."""
        self._limit = ("s0", s0_limit)
        self._show_limit()

    def _show_limit(self) -> None:
        series = self._series
        if series is None:
            return
        if series.parameter == "s0":
            at, text = self._limit[1], "s0*"
        else:
            at, text = series.crossing, "unstable from (sweep)"
        for limit, label in zip(self.limits, self.labels, strict=True):
            limit.visible = label.visible = at is not None
            if at is not None:
                limit.location = at
                label.x = at
                label.text = f" {text} = {at:.4f}" if series.parameter == "s0" \
                    else f" {text} {at:.1f} km/h"
