"""The design-variant view: a parameter editor, TOML upload/download, and the variant beside the
baseline (eigenvalues, s0*(v), peak loads; differences highlighted).

The variant lives in the session only (the dashboard's ``variant`` parameter, :mod:`app.results.variants`);
an uploaded file is read from the browser's upload in memory and never written to disk.  Invalid
input (a value out of bounds, NaN, a malformed or oversized file) gives a notice and changes
nothing.
"""

from __future__ import annotations

import html
import io
import math
from dataclasses import dataclass

import numpy as np
import panel as pn
from bokeh.models import ColumnDataSource

from app.dashboard.jobs import ViewJob
from app.dashboard.session import served_document
from app.results import compute
from app.results.case import CaseBase
from app.results.plots import UNSTABLE, new_figure
from app.results.variants import (
    EDITABLE,
    MAX_UPLOAD_BYTES,
    VariantError,
    apply_variant,
    changes_from_toml,
    decode,
    differences,
    dumps_variant,
    encode,
    review_range,
    set_hash,
    set_key,
)
from app.services.thread_pools import SIDE_VIEW_POOL
from model.mechanics.parameters import SCHEMA, ParameterError
from model.studies.calibration_bounds import parameter_rows

LIMIT_SPEEDS_KMH = (40.0, 80.0, 120.0, 160.0, 200.0)  # speeds of the s0*(v) comparison [km/h]
CHANGED = 0.005  # relative difference highlighted in the comparison table


@dataclass(frozen=True)
class Side:
    """One side of the comparison at the dashboard's operating point."""

    key: str  # set key (app.results.variants)
    point: compute.PointResult
    response: compute.ResponseView
    limits: dict[float, float | None]  # v [km/h] -> s0*(v) [-] (None: none in the range)


def side(state: CaseBase, key: str, speeds=LIMIT_SPEEDS_KMH) -> Side:
    """Eigenvalues, response and s0*(v) of the set ``key`` at ``state``'s operating point (all
    from the results cache of :mod:`app.results.compute`)."""
    case = state.replace(set_key=key)
    limits = {}
    for v in sorted({*speeds, state.v}):
        limits[v] = compute.limit_result(case.replace(v=v)).s0_limit
    return Side(key, compute.point_result(case), compute.response_result(case), limits)


def _cell(base: float | None, variant: float | None, spec: str, scale: float = 1.0) -> str:
    """Two cells (base, variant) and the difference; the variant cell highlighted when it
    differs by more than CHANGED relative to the larger magnitude."""
    if base is None or variant is None:
        text = lambda x: "—" if x is None else format(x * scale, spec)  # noqa: E731
        changed = (base is None) != (variant is None)
        return (f"<td>{text(base)}</td><td class=\"{'changed' if changed else ''}\">"
                f"{text(variant)}</td><td></td>")
    delta = variant - base
    size = max(abs(base), abs(variant), 1e-300)
    changed = abs(delta) > CHANGED * size
    return (f"<td>{base * scale:{spec}}</td><td class=\"{'changed' if changed else ''}\">"
            f"{variant * scale:{spec}}</td><td>{delta * scale:+{spec}}</td>")


def comparison_html(base: Side, variant: Side, v_kmh: float) -> str:
    """The variant beside the baseline: stability, the lowest complex pairs, the peak loads."""
    rows = [
        f"<tr><td class='text'>s0*(v) at {v_kmh:g} km/h [-]</td>"
        + _cell(base.limits.get(v_kmh), variant.limits.get(v_kmh), ".5f") + "</tr>",
        "<tr><td class='text'>largest Re λ [1/s]</td>"
        + _cell(base.point.max_real_part, variant.point.max_real_part, ".4f") + "</tr>",
        "<tr><td class='text'>verdict</td>"
        f"<td>{'STABLE' if base.point.stable else 'UNSTABLE'}</td>"
        f"<td class=\"{'changed' if base.point.stable != variant.point.stable else ''}\">"
        f"{'STABLE' if variant.point.stable else 'UNSTABLE'}</td><td></td></tr>",
    ]
    for a, b in zip(base.point.modes, variant.point.modes, strict=False):
        rows.append(f"<tr><td class='text'>ν = {a.number}: Re [1/s]</td>"
                    + _cell(a.eigenvalue.real, b.eigenvalue.real, ".4f") + "</tr>")
        rows.append(f"<tr><td class='text'>ν = {a.number}: Im [Hz]</td>"
                    + _cell(a.im_hz, b.im_hz, ".3f") + "</tr>")
    for name in base.response.peaks:
        unit = base.response.units[name]
        rows.append(f"<tr><td class='text'>peak {html.escape(name)} [{unit}]</td>"
                    + _cell(base.response.peaks[name], variant.response.peaks[name], ",.0f")
                    + "</tr>")
    return ("<b>Variant beside the baseline</b> (highlighted: differs by more than "
            f"{CHANGED:.1%})"
            '<table class="bogie"><tr><th class="text">quantity</th><th>baseline</th>'
            "<th>variant</th><th>variant − baseline</th></tr>" + "".join(rows) + "</table>")


def bounds_html(rows) -> str:
    """The calibrated parameters of a set with their bounds and whether the value sits on one
    (the rows of :func:`model.studies.calibration_bounds.parameter_rows`; SI units)."""
    lines = "".join(
        f"<tr><td class='text'>{html.escape(r['name'])}</td><td>{r['value']:.4g}</td>"
        f"<td>{r['lower']:.4g} … {r['upper']:.4g}</td><td class='text'>{html.escape(r['unit'])}"
        f"</td><td class='{'bad' if r['on_bound'] else ''}'>{'yes' if r['on_bound'] else 'no'}"
        "</td></tr>" for r in rows)
    return ("<b>Fitted by bogie calibrate</b> (bogie parameters lists them too)"
            '<table class="bogie"><tr><th class="text">parameter</th><th>value</th><th>bounds</th>'
            '<th class="text">unit</th><th>on a bound</th></tr>' + lines + "</table>")


class VariantView(pn.viewable.Viewer):
    """Editor and comparison for one dashboard (one per session)."""

    def __init__(self, dashboard, **params):
        super().__init__(**params)
        self.dashboard = dashboard
        self._job = ViewJob(SIDE_VIEW_POOL, dashboard.alive, "variant comparison")
        self.base_name = dashboard.base_key
        self.base = compute.parameters(self.base_name)
        self.inputs: dict[str, pn.widgets.FloatInput] = {}
        # the calibration's bounds of the baseline's fitted parameters (as bogie parameters)
        self.bounds = {row["name"]: row for row in parameter_rows(self.base)
                       if row["lower"] is not None}
        cards = []
        for index, (group, names) in enumerate(EDITABLE.items()):
            widgets = []
            for name in names:
                unit, description, (low, high, _) = SCHEMA[name]
                low, high = review_range(self.base, name)
                fitted = self.bounds.get(name)
                widget = pn.widgets.FloatInput(
                    label=f"{name} [{unit}]" + (" (on a calibration bound)"
                                                if fitted and fitted["on_bound"] else ""),
                    value=self.base[name], width=280,
                    description=f"{description}; allowed {low:.4g} … {high:.4g} {unit}; "
                                f"baseline {self.base[name]:.6g} {unit}"
                                + (f"; calibrated within {fitted['lower']:.4g} … "
                                   f"{fitted['upper']:.4g} {unit}" if fitted else ""),
                    css_classes=[f"var-{name}"])
                self.inputs[name] = widget
                widgets.append(widget)
            cards.append(pn.Card(*widgets, title=group, collapsed=index > 0, width=310))
        cards.append(pn.Card(pn.pane.HTML(bounds_html(self.bounds.values()),
                                          css_classes=["variant-bounds"]),
                             title="Calibration bounds of the baseline", collapsed=True,
                             width=310))
        apply = pn.widgets.Button(label="Apply variant", color="primary",
                                  css_classes=["var-apply"], width=150)
        # with the session's document lock: a new variant may clear the s0*(v) sources, and a
        # button's callback may run without the lock (app/dashboard/studies_view.py says when)
        apply.on_click(lambda _event: dashboard.run_locked(self.apply_inputs))
        reset = pn.widgets.Button(label="Back to the baseline", css_classes=["var-reset"],
                                  width=150)
        reset.on_click(lambda _event: dashboard.run_locked(self.set_changes, {}))
        self.upload = pn.widgets.FileInput(accept=".toml", css_classes=["var-upload"],
                                           multiple=False)
        self.upload.param.watch(self._on_upload, "value")
        download = pn.widgets.FileDownload(callback=self._download, filename="variant.toml",
                                           label="variant (TOML)", css_classes=["var-download"],
                                           width=300)
        compare = pn.widgets.Button(label="Compare with the baseline",
                                    css_classes=["var-compare"], width=300)
        compare.on_click(lambda _event: self.compare())
        self.summary = pn.pane.HTML("", sizing_mode="stretch_width",
                                    css_classes=["variant-summary"])
        self.table = pn.pane.HTML("", sizing_mode="stretch_width",
                                  css_classes=["variant-comparison"],
                                  stylesheets=[".changed {background: #fff3b0; "
                                               "font-weight: 700}"])
        self.limits_figure = new_figure("Stability limit s0*(v): baseline and variant",
                                        "speed v [km/h]", "s0* [-]")
        self.limits_figure.name = "variant-limits"
        self.limit_sources = {}
        for label, color, dash in (("baseline", "#555555", "solid"),
                                   ("variant", UNSTABLE, "dashed")):
            source = ColumnDataSource({"v": [], "s0": []}, name=f"variant-limits:{label}")
            self.limits_figure.line("v", "s0", source=source, color=color, line_dash=dash,
                                    line_width=2, legend_label=label)
            self.limits_figure.scatter("v", "s0", source=source, color=color, size=7)
            self.limit_sources[label] = source
        self.limits_figure.legend.location = "top_right"  # s0* falls with v: top right is free
        self.comparison: tuple[Side, Side] | None = None
        # the comparison (s0*(v) at five speeds for both sets: seconds) is computed when the
        # view is shown or asked for, not for every session opened with a variant in its link
        self.shown = False
        self._stale = False
        self._layout = pn.Row(
            pn.Column("#### Parameters of the variant (SI units)", *cards,
                      pn.Row(apply, reset),
                      f"Upload a parameter set (TOML, at most {MAX_UPLOAD_BYTES // 1000} kB; "
                      "kept in this session only, never stored on the server):",
                      self.upload, download, width=330),
            pn.Column(self.summary, compare, self.table,
                      pn.pane.Bokeh(self.limits_figure, sizing_mode="stretch_width"),
                      sizing_mode="stretch_width"),
            sizing_mode="stretch_width")
        dashboard.param.watch(self._on_variant, "variant")
        self._on_variant()

    def __panel__(self):
        return self._layout

    # --- editing -------------------------------------------------------------------------------

    @property
    def changes(self) -> dict[str, float]:
        return decode(self.dashboard.variant)

    def set_changes(self, changes: dict[str, float]) -> bool:
        """Make ``changes`` the session's variant (validated first: on a fault a notice, and the
        previous variant stays); returns whether it was applied."""
        try:
            apply_variant(self.base, changes)
        except (VariantError, ParameterError) as error:
            self.dashboard.warn(f"Variant not applied (previous one kept): {error}")
            return False
        self.dashboard.clear_warning()
        self.dashboard.variant = encode(changes)
        return True

    def apply_inputs(self) -> bool:
        """The editor's values as the variant (the values that differ from the baseline; values
        of an uploaded set that the editor does not show are kept)."""
        changes = {k: v for k, v in self.changes.items() if k not in self.inputs}
        for name, widget in self.inputs.items():
            value = widget.value
            unit = SCHEMA[name][0]
            if value is None or isinstance(value, bool) or not isinstance(value, int | float):
                self.dashboard.warn(f"Variant not applied (previous one kept): {name} [{unit}] "
                                    "needs a number")
                return False
            if not math.isfinite(value):
                self.dashboard.warn(f"Variant not applied (previous one kept): {name} [{unit}] "
                                    f"must be finite, got {value}")
                return False
            if float(value) != self.base[name]:
                changes[name] = float(value)
        return self.set_changes(changes)

    def _on_upload(self, event) -> None:
        data = event.new
        if data is None:
            return
        try:
            if not isinstance(data, bytes):
                raise VariantError("the upload is not a file")
            changes = changes_from_toml(data, self.base)
        except VariantError as error:
            self.dashboard.warn(f"Uploaded set not used (previous one kept): {error}")
            return
        self.set_changes(changes)

    def _download(self):
        parameters = compute.parameters(self.dashboard.set_key)
        return io.StringIO(dumps_variant(parameters, self.base_name, self.changes))

    def _on_variant(self, *_events) -> None:
        changes = self.changes
        for name, widget in self.inputs.items():
            widget.value = changes.get(name, self.base[name])
        parameters = compute.parameters(self.dashboard.set_key)
        diff = differences(self.base, parameters)
        listed = "".join(f"<li>{html.escape(n)}: {a:.6g} → <b>{b:.6g}</b> {SCHEMA[n][0]}</li>"
                         for n, (a, b) in diff.items())
        self.summary.object = (
            f"<b>Parameter set:</b> {html.escape(self.base_name or 'calibrated (bundled)')}"
            f"{' — variant' if diff else ' — baseline'}, hash <code>{set_hash(parameters)}</code>"
            + (f"<ul style='font-size:12px'>{listed}</ul>" if diff else
               "<div style='font-size:12px'>no differences from the baseline</div>"))
        if diff:
            self._stale = True
            if self.shown:
                self.compare()
            else:
                self.table.object = ("<i>Open this tab or press “Compare with the baseline” to "
                                     "compute the comparison.</i>")
        else:
            self.table.object = ""
            for source in self.limit_sources.values():
                source.data = {"v": [], "s0": []}

    # --- comparison ------------------------------------------------------------------------------

    def on_shown(self, shown: bool) -> None:
        """The dashboard opened (or left) this view's tab: compare if a variant awaits it."""
        self.shown = shown
        if shown and self._stale and self.dashboard.variant:
            self.compare()

    def compare(self) -> None:
        """Compute both sides at the current operating point and show them (served: on a worker
        thread, shown when ready if the dashboard has not moved on; otherwise at once)."""
        self._stale = False
        state = self.dashboard.state()
        base_key = set_key(self.base_name, {})
        if served_document() is not None:
            self.table.object = "<i>⏳ comparing with the baseline…</i>"
        self._job.start(state, lambda: (side(state, base_key), side(state, state.set_key)),
                        self._show, self._failed)

    def _failed(self, _state, error: BaseException) -> None:
        self.table.object = ""
        self.dashboard.warn(f"Comparison failed: {error}")

    def _show(self, state, sides: tuple[Side, Side]) -> None:
        if self.dashboard.state() != state:
            return  # the dashboard has moved on
        self.comparison = sides
        base, variant = sides
        self.table.object = comparison_html(base, variant, state.v)
        for label, s in (("baseline", base), ("variant", variant)):
            speeds = [v for v, s0 in s.limits.items() if s0 is not None]
            self.limit_sources[label].data = {
                "v": np.array(speeds), "s0": np.array([s.limits[v] for v in speeds])}
