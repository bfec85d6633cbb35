"""The dashboard's controls column: the published cases, the operating point, the short circuit,
the creep model and the downloads.

Controls are built per dashboard (never shared class attributes) and write into its parameters
on ``value_throttled`` (slider release / keyboard step), so a drag triggers one computation; while
an operating-point slider is held, its ``value`` asks for a preview
(:mod:`app.dashboard.drag_preview`).  Each
control has a CSS class (``ctl-<parameter>``, ``case-stable``/``case-unstable``): Panel puts the
label into the Bokeh model's title, and tests and scripts find the controls by their class.
"""

from __future__ import annotations

from functools import partial

import panel as pn

from app.results.preview import PREVIEWED

PUBLISHED_SPEED_KMH = 120.0  # the speed of the study's two published cases [km/h]
PUBLISHED_CASES = {"stable": 0.005, "unstable": 0.014}  # their creepage s0 [-]

# parameter -> (label with unit, step, number format)
SLIDERS = {
    "s0": ("creepage s0 [-]", 0.0001, "0.0000"),
    "v": ("speed v [km/h]", 5.0, "0"),
    "N0": ("wheel force N0 [kN]", 1.0, "0"),
    "b_M": ("motor slope b_M [N m s/rad]", 100.0, "0"),
    "M0": ("short circuit M0 [kN m]", 1.0, "0"),
    "f": ("frequency f [Hz]", 1.0, "0"),
    "D": ("decay D [-]", 0.005, "0.000"),
    "dt": ("time shift Δt [ms]", 0.05, "0.00"),
    "t_end": ("simulated time [s]", 0.1, "0.0"),
}


class ControlSlider(pn.widgets.FloatSlider):
    """A control slider that hands a released value on at once.  Panel holds every browser
    event of a widget for ``_debounce`` ms (50 by default) to batch events that arrive
    together; a released slider sends ``value`` and ``value_throttled`` within a millisecond,
    so 5 ms still batches them, and a slider step reaches the model ≈ 45 ms earlier (server
    timeline of one s0 step: event received → the dashboard's watcher 52 ms)."""

    _debounce = 5


class Controls:
    """The controls column of one dashboard (``column``); ``sliders``: parameter -> slider.

    ``dashboard``: its parameters (:data:`SLIDERS`, ``dt_auto``, ``rail``), ``state()``,
    ``warn(text)``, ``run_locked(function)``, ``show_published_case(s0)`` and ``drag_preview``
    (:class:`app.dashboard.drag_preview.DragPreview`); ``creep_controls``: the nonlinear view's controls;
    ``downloads``: the download buttons."""

    def __init__(self, dashboard, creep_controls: list, downloads: list):
        self.dashboard = dashboard
        self.sliders = {name: self._slider(name, *spec) for name, spec in SLIDERS.items()}
        sliders = self.sliders
        sliders["dt"].disabled = dashboard.dt_auto
        dashboard.param.watch(lambda e: setattr(sliders["dt"], "disabled", e.new), "dt_auto")
        dt_auto = pn.widgets.Checkbox.from_param(dashboard.param.dt_auto,
                                                 label="Δt automatic (continuous torque)",
                                                 css_classes=["ctl-dt_auto"])
        rail = pn.widgets.Select.from_param(dashboard.param.rail, label="rail condition (creep law)",
                                            css_classes=["ctl-rail"], sizing_mode="stretch_width")
        cases = []
        for key, s0 in PUBLISHED_CASES.items():
            button = pn.widgets.Button(label=f"Published case s0 = {s0} ({key})",
                                       color="success" if key == "stable" else "danger",
                                       css_classes=[f"case-{key}"], sizing_mode="stretch_width")
            button.on_click(lambda _event, s0=s0: dashboard.show_published_case(s0))
            cases.append(button)
        self.column = pn.Column(
            f"### Published cases ({PUBLISHED_SPEED_KMH:g} km/h)", *cases,
            "### Operating point", sliders["s0"], sliders["v"], sliders["N0"], sliders["b_M"],
            rail,
            "### Short circuit M_C(t)", sliders["M0"], sliders["f"], sliders["D"], dt_auto,
            sliders["dt"], sliders["t_end"],
            *creep_controls,
            "### Downloads", *downloads, width=300)

    def _slider(self, name: str, label: str, step: float, fmt: str = "0[.]000") -> ControlSlider:
        dashboard = self.dashboard
        p = dashboard.param[name]
        widget = ControlSlider(label=label, start=p.bounds[0], end=p.bounds[1], step=step,
                               value=getattr(dashboard, name), format=fmt,
                               css_classes=[f"ctl-{name}"], sizing_mode="stretch_width")
        widget.param.watch(partial(self._set_control, name), "value_throttled")
        if name in PREVIEWED:  # the operating point: a preview follows the held slider
            widget.param.watch(lambda event: dashboard.drag_preview.request(name, event.new),
                               "value")
        dashboard.param.watch(lambda event: setattr(widget, "value", event.new), name)
        return widget

    def _set_control(self, name: str, event) -> None:
        """A slider's released value into the parameter; a value the parameter refuses (out
        of its bounds, NaN, not a number: only a doctored client sends one) gives a notice and
        changes nothing."""
        dashboard = self.dashboard
        dashboard.drag_preview.release()
        before = dashboard.state()
        try:
            setattr(dashboard, name, event.new)
        except (ValueError, TypeError) as error:
            dashboard.warn(f"{name}: value {str(event.new)[:40]} not used: {str(error)[:200]}")
        if dashboard.state() == before:  # nothing to compute: the preview goes at once
            dashboard.run_locked(dashboard.drag_preview.end)
