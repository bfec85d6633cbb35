"""Which parameter moves what, live: a tornado chart of normalized sensitivities at the
dashboard's current operating point (:mod:`model.analysis.sensitivity`).

Targets (a radio group, CSS class ``ctl-sensitivity-target``):

* growth rate of the selected mode ν: ``p · ∂Re λ/∂p`` [1/s] (change of the growth rate per
  relative change of the parameter; Re λ itself may be near zero, so it is not divided by it);
* damping ratio of the selected mode: ``p · ∂ζ/∂p`` [-];
* frequency of the selected mode: ``p/Im λ · ∂Im λ/∂p`` [-];
* stability limit: ``p/s0* · ds0*/dp`` [-] at the current speed.

The parameters' rows are partial derivatives at the shown operating point (the sliders fix s0,
v, N0, b_M; their own rows are included).  The computation (one left/right null-vector solve per
mode and cheap products per parameter; the derivative matrices once per parameter set, seconds)
runs on the dashboard's worker threads when served and is shown when ready; the status and the
other results never wait for it.  Nothing here computes physics: it calls :mod:`model`.
"""

from __future__ import annotations

import html
import logging
from dataclasses import dataclass

import numpy as np
import panel as pn
from bokeh.models import ColumnDataSource, FactorRange
from bokeh.plotting import figure

from app.dashboard.jobs import ViewJob
from app.results import compute
from app.results.case import Case, CaseBase
from app.services.thread_pools import SIDE_VIEW_POOL
from model.analysis.sensitivity import eigen_sensitivities, limit_sensitivity

log = logging.getLogger(__name__)
TARGETS = {"growth rate of mode ν": "growth", "damping ratio of mode ν": "damping",
           "frequency of mode ν": "frequency", "stability limit s0*": "limit"}
BARS = 12  # parameters shown, largest first
POSITIVE, NEGATIVE = "#c0392b", "#2e86c1"


@dataclass(frozen=True)
class SensitivityData:
    """Sensitivities at one dashboard point (plain data)."""

    key: Case  # the point
    names: tuple[str, ...]  # parameters, then s0, v, N0, b_M
    values: np.ndarray  # their values [SI]
    derivatives: np.ndarray  # len(names) x modes, dλ/dp [1/s per unit]
    eigenvalues: np.ndarray  # the modes (the dashboard's ν = 1 … 10) [1/s]
    descriptions: tuple[str, ...]
    notes: tuple[str, ...]
    limit_names: tuple[str, ...] | None  # None: no stability limit at this speed
    limit_normalized: np.ndarray | None  # p/s0* ds0*/dp [-]
    limit_note: str


def sensitivity_data(case: CaseBase) -> SensitivityData:
    """All sensitivities the chart can show at the case's point (kept in the results cache)."""
    point = case.point()

    def compute_data() -> SensitivityData:
        model = compute.model_for(point)
        op = point.operating_point()
        sens = eigen_sensitivities(model, op)
        limit = compute.limit_result(point)
        names = normalized = None
        note = f"no stability limit at {point.v:g} km/h ({limit.message})"
        if limit.s0_limit is not None:
            result = limit_sensitivity(model, op.v, op.N0, op.b_M, s0_limit=limit.s0_limit)
            names, normalized, note = result.names, result.normalized, result.note
        return SensitivityData(point, sens.names, sens.values, sens.derivatives,
                               sens.eigenvalues, sens.descriptions, sens.notes, names,
                               normalized, note)
    return compute.cached("sensitivities", point, compute_data)


def ranked(data: SensitivityData, target: str, mode: int) -> tuple[list[str], np.ndarray, str]:
    """(names, values, axis label) of the BARS largest normalized sensitivities, largest last
    (bottom-up in the chart) for a target and a mode ν (1-based)."""
    if target == "limit":
        if data.limit_names is None:
            return [], np.zeros(0), "p/s0* · ds0*/dp [-]"
        names, values, label = data.limit_names, data.limit_normalized, "p/s0* · ds0*/dp [-]"
    else:
        k = min(max(mode, 1), len(data.eigenvalues)) - 1
        lam, d = data.eigenvalues[k], data.derivatives[:, k]
        if target == "growth":
            values, label = data.values * d.real, "p · ∂Re λ/∂p [1/s]"
        elif target == "damping":
            a = abs(lam)
            values = -data.values * (d.real * a**2 - lam.real * np.real(np.conj(lam) * d)) / a**3
            label = "p · ∂ζ/∂p [-]"
        else:
            values, label = data.values * d.imag / lam.imag, "p/Im λ · ∂Im λ/∂p [-]"
        names = data.names
    values = np.nan_to_num(np.asarray(values, dtype=float))
    order = np.argsort(-np.abs(values))[:BARS][::-1]
    return [names[i] for i in order], values[order], label


class SensitivityView:
    """The tornado chart, its target selector and a note; ``panel`` is the layout to insert."""

    def __init__(self, alive=lambda: True):
        """``alive()``: whether the session still wants results (its requests are dropped once
        it has ended)."""
        self.data: SensitivityData | None = None
        self.mode = 1
        self._job = ViewJob(SIDE_VIEW_POOL, alive, "sensitivities")
        self.target = pn.widgets.RadioButtonGroup(options=TARGETS, value="growth",
                                                  css_classes=["ctl-sensitivity-target"])
        self.source = ColumnDataSource({"name": [], "value": [], "color": []})
        self.figure = figure(y_range=FactorRange(), height=330, sizing_mode="stretch_width",
                             tools="save", toolbar_location=None)
        self.figure.hbar(y="name", right="value", height=0.7, color="color", source=self.source)
        self.figure.xaxis.axis_label = "p · ∂Re λ/∂p [1/s]"
        self.note = pn.pane.HTML("", sizing_mode="stretch_width", css_classes=["sensitivity-note"])
        self.target.param.watch(lambda _event: self.show(), "value")
        self.panel = pn.Column("### Which parameter moves what (sensitivities at this point)",
                               self.target, self.note,
                               pn.pane.Bokeh(self.figure, sizing_mode="stretch_width"),
                               sizing_mode="stretch_width", css_classes=["sensitivity-view"])

    def request(self, state: CaseBase) -> None:
        """Compute for the dashboard's point ``state.point()`` (on its worker threads when
        served, else at once) and show when ready, if the point is still the current one."""
        key = state.point()
        if self.data is not None and self.data.key == key:
            self._job.want(key)
            self.show()
            return
        self.note.object = "<i>computing sensitivities…</i>"
        self._job.start(key, lambda: sensitivity_data(key), self._apply, self._failed)

    def _failed(self, _key, error: BaseException) -> None:
        log.warning("sensitivities failed: %s", error)
        self.note.object = f"<i>sensitivities not available: {html.escape(str(error))}</i>"

    def _apply(self, _key, data: SensitivityData) -> None:
        self.data = data
        self.show()

    def show(self, mode: int | None = None) -> None:
        """Redraw for the selected target and mode ν (1-based)."""
        if mode is not None:
            self.mode = mode
        data = self.data
        if data is None:
            return
        names, values, label = ranked(data, self.target.value, self.mode)
        self.figure.y_range.factors = list(names)
        self.source.data = {"name": list(names), "value": values,
                            "color": [POSITIVE if v > 0 else NEGATIVE for v in values]}
        self.figure.xaxis.axis_label = label
        if self.target.value == "limit":
            text = html.escape(data.limit_note)
        else:
            k = min(max(self.mode, 1), len(data.eigenvalues)) - 1
            lam = data.eigenvalues[k]
            text = (f"mode ν = {k + 1}: Re λ = {lam.real:+.4f} 1/s, {lam.imag / (2 * np.pi):.3f} Hz "
                    f"— {html.escape(data.descriptions[k])}. Red: a larger parameter raises it.")
        self.note.object = f"<div style='font-size:12px'>{text}</div>"
