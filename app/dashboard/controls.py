"""The dashboard's controls column: the published cases, the operating point, the short circuit,
the creep model and the downloads.

The case's quantities become the dashboard's parameters (:func:`case_parameters`) and its
controls (:class:`Controls`) by one loop over their declarations
(:data:`app.results.case.QUANTITIES`: label, unit, range, step, format, default): a slider per
number, a select per choice, an "automatic" switch for a quantity that may be automatic.
Controls are built per dashboard (never shared class attributes) and write into its parameters
on ``value_throttled`` (slider release / keyboard step), so a drag triggers one computation; while
an operating-point slider is held, its ``value`` asks for a preview
(:mod:`app.dashboard.drag_preview`).  Each control has a CSS class (``ctl-<parameter>``,
``case-stable``/``case-unstable``): Panel puts the label into the Bokeh model's title, and tests
and scripts find the controls by their class.
"""

from __future__ import annotations

from functools import partial

import panel as pn
import param

from app.results.case import Quantity
from app.results.preview import PREVIEWED

PUBLISHED_SPEED_KMH = 120.0  # the speed of the study's two published cases [km/h]
PUBLISHED_CASES = {"stable": 0.005, "unstable": 0.014}  # their creepage s0 [-]
# the sections of the controls column and the roles of the quantities in each
SECTIONS = (("### Operating point", ("point", "override", "set")),
            ("### Short circuit M_C(t)", ("short_circuit", "horizon")))


def automatic_name(q: Quantity) -> str:
    """The dashboard's switch of a quantity that may be automatic (``dt`` -> ``dt_auto``)."""
    return f"{q.name}_auto"


def case_parameters(quantities) -> dict[str, param.Parameter]:
    """The dashboard's parameters of ``quantities``: a number within the dashboard's range (its
    default the declared one; the set's value is set per dashboard) or a choice, and a switch
    for a quantity that may be automatic (on by default)."""
    parameters: dict[str, param.Parameter] = {}
    for q in quantities:
        if q.choice:
            parameters[q.name] = param.Selector(default=q.default, objects=list(q.choices),
                                                doc=q.doc)
            continue
        if q.automatic:
            parameters[automatic_name(q)] = param.Boolean(True, doc=f"{q.label} automatic: "
                                                                    f"{q.automatic}")
        default = q.default if q.default is not None else min(max(0.0, q.low), q.high)
        parameters[q.name] = param.Number(default, bounds=q.bounds, doc=f"{q.doc} [{q.unit}]")
    return parameters


class ControlSlider(pn.widgets.FloatSlider):
    """A control slider that hands a released value on at once.  Panel holds every browser
    event of a widget for ``_debounce`` ms (50 by default) to batch events that arrive
    together; a released slider sends ``value`` and ``value_throttled`` within a millisecond,
    so 5 ms still batches them, and a slider step reaches the model ≈ 45 ms earlier (server
    timeline of one s0 step: event received → the dashboard's watcher 52 ms)."""

    _debounce = 5


class Controls:
    """The controls column of one dashboard (``column``); ``sliders``: parameter -> slider.

    ``dashboard``: its ``case_type`` (the quantities), their parameters, ``state()``,
    ``warn(text)``, ``run_locked(function)``, ``show_published_case(s0)`` and ``drag_preview``
    (:class:`app.dashboard.drag_preview.DragPreview`); ``creep_controls``: the nonlinear view's controls;
    ``downloads``: the download buttons."""

    def __init__(self, dashboard, creep_controls: list, downloads: list):
        self.dashboard = dashboard
        quantities = dashboard.case_type.quantities
        self.sliders = {q.name: self._slider(q) for q in quantities if not q.choice}
        self.switches: dict[str, pn.widgets.Widget] = {}  # "automatic" switches, choices
        for q in quantities:
            if q.choice:
                self.switches[q.name] = pn.widgets.Select.from_param(
                    dashboard.param[q.name], label=q.label, css_classes=[f"ctl-{q.name}"],
                    sizing_mode="stretch_width")
            elif q.automatic:
                self.switches[q.name] = self._automatic(q)
        cases = []
        for key, s0 in PUBLISHED_CASES.items():
            button = pn.widgets.Button(label=f"Published case s0 = {s0} ({key})",
                                       color="success" if key == "stable" else "danger",
                                       css_classes=[f"case-{key}"], sizing_mode="stretch_width")
            button.on_click(lambda _event, s0=s0: dashboard.show_published_case(s0))
            cases.append(button)
        column = [f"### Published cases ({PUBLISHED_SPEED_KMH:g} km/h)", *cases]
        for title, roles in SECTIONS:
            column.append(title)
            # the numbers of the section in declaration order, then its choices (the rail)
            for q in sorted((q for q in quantities if q.role in roles), key=lambda q: q.choice):
                if q.name in self.switches:
                    column.append(self.switches[q.name])
                if q.name in self.sliders:
                    column.append(self.sliders[q.name])
        self.column = pn.Column(*column, *creep_controls, "### Downloads", *downloads,
                                width=300)

    def _automatic(self, q: Quantity) -> pn.widgets.Checkbox:
        """The switch of a quantity that may be automatic; its slider is off while it is on."""
        dashboard, name = self.dashboard, automatic_name(q)
        slider = self.sliders[q.name]
        slider.disabled = getattr(dashboard, name)
        dashboard.param.watch(lambda e: setattr(slider, "disabled", e.new), name)
        return pn.widgets.Checkbox.from_param(dashboard.param[name],
                                              label=f"{q.symbol} automatic "
                                                    f"({q.automatic})",
                                              css_classes=[f"ctl-{name}"])

    def _slider(self, q: Quantity) -> ControlSlider:
        dashboard, name = self.dashboard, q.name
        widget = ControlSlider(label=q.slider_label, start=q.low, end=q.high, step=q.step,
                               value=getattr(dashboard, name), format=q.format,
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
