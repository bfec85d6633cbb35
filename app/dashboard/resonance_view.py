"""The Resonances view: where the drive resonates (docs/resonance.md).

* the Campbell diagram over the dashboard's speeds at its creepage, wheel force and motor slope:
  the modes a motor's torque drives coloured by their damping ratio, the excitation orders, the
  crossings marked (hover: the mode's description, the crossing's severity); a tapped point of a
  mode shows that mode at that speed in the Modes view (``dashboard.show_mode``);
* the frequency response of the chosen output at the dashboard's operating point, from a motor's
  torque or from a wheel's rail–wheel surface deviation ``IDk.rimNN.irregularity``;
* the forced response of that output over speed to a motor torque ripple, and to polygonal
  wheels (no default polygon: the model has no sourced amplitude);
* its power spectral density under the random vertical track at the dashboard's operating point
  (the ERRI/ORE low-level spectrum), its RMS and the spectrum's source.

Settings (CSS classes ``ctl-resonance-*``): the rippling motor, the FRF's input, the output, the
orders, fixed frequencies, the ripple and the wheel polygon as text (the command line's
syntax).  A text the model does not take shows the dashboard's notice and keeps the previous
one.  The computations run on the side-view worker threads when served (the diagram takes
seconds, the polygon's and the track's responses longer) and are shown when ready; nothing here
computes physics.
"""

from __future__ import annotations

import html
import logging

import panel as pn

from app.dashboard.jobs import ViewJob
from app.results import compute, resonance
from app.results.resonance_plots import (
    CampbellPlot,
    FrfPlot,
    PolygonPlot,
    RipplePlot,
    TrackPlot,
)
from app.results.tables import crossings_html
from app.services.thread_pools import FIRST_ANSWER_POOL, SIDE_VIEW_POOL
from model.analysis.campbell import MOTOR_INPUTS
from model.analysis.track_spectrum import LOW
from model.mechanics.excitation import DEFAULT_ORDERS, parse_amplitudes, parse_orders

log = logging.getLogger(__name__)
# the results of the view: kind -> the function of its key (a case record and the settings)
RESULTS = {"frf": resonance.frf_result, "campbell": resonance.campbell_result,
           "ripple": resonance.ripple_result, "polygon": resonance.polygon_result,
           "track": resonance.track_result}
NO_POLYGON = ("forced response to polygonal wheels: type a polygon order=µm (e.g. 20=30); no "
              "default, the model has no sourced amplitude (docs/resonance.md)")
TRACK_SOURCE = (f"<b>Random track</b>: the vertical profile spectrum S(Ω) = A_v Ω_c² / ((Ω² + "
                f"Ω_r²)(Ω² + Ω_c²)), A_v = {LOW.A_v:g} m² rad/m, Ω_c = {LOW.omega_c:g} rad/m, "
                f"Ω_r = {LOW.omega_r:g} rad/m, wavelengths {LOW.wavelength_min:g}…"
                f"{LOW.wavelength_max:g} m, both rails alike, the rear wheelset a wheelbase later; "
                f"source: {html.escape(LOW.source)}.")

class ResonanceView:
    """The view, its settings and plots; ``layout`` is what the dashboard's tab shows."""

    def __init__(self, dashboard):
        self.dashboard = dashboard
        self.campbell_plot = CampbellPlot()
        self.frf_plot = FrfPlot()
        self.ripple_plot = RipplePlot()
        self.polygon_plot = PolygonPlot()
        self.polygon_plot.clear(NO_POLYGON)
        self.track_plot = TrackPlot()
        self.frf_input = pn.widgets.Select(label="FRF input",
                                           options=list(resonance.frf_inputs(dashboard.base_key)),
                                           value=MOTOR_INPUTS[0], width=220,
                                           css_classes=["ctl-resonance-frf-input"])
        outputs = [name for name, _ in resonance.output_names(dashboard.base_key)]
        self.input = pn.widgets.Select(label="rippling motor (input)",
                                       options=list(MOTOR_INPUTS), width=200,
                                       css_classes=["ctl-resonance-input"])
        self.output = pn.widgets.Select(label="output (FRF and forced response)", options=outputs,
                                        value=resonance.DEFAULT_OUTPUT, width=280,
                                        css_classes=["ctl-resonance-output"])
        self.orders = pn.widgets.TextInput(label="excitation orders", value=DEFAULT_ORDERS,
                                           width=330, css_classes=["ctl-resonance-orders"])
        self.fixed = pn.widgets.TextInput(label="fixed frequencies [Hz]", value="",
                                          placeholder="e.g. 450, 900", width=160,
                                          css_classes=["ctl-resonance-fixed"])
        self.ripple = pn.widgets.TextInput(label="torque ripple order=amplitude [N m]",
                                           value=resonance.DEFAULT_RIPPLE, width=230,
                                           css_classes=["ctl-resonance-ripple"])
        self.polygon = pn.widgets.TextInput(label="wheel polygon order=µm", value="",
                                            placeholder="e.g. 20=30", width=170,
                                            css_classes=["ctl-resonance-polygon"])
        # the texts in use (the last ones the model took)
        self.settings = {"orders": DEFAULT_ORDERS, "fixed": (), "ripple": resonance.DEFAULT_RIPPLE,
                         "polygon": ""}
        self.note = pn.pane.HTML("", sizing_mode="stretch_width",
                                 css_classes=["resonance-note"])
        self.track_source = pn.pane.HTML(TRACK_SOURCE, sizing_mode="stretch_width",
                                         css_classes=["resonance-track-source"])
        self.table = pn.pane.HTML("", sizing_mode="stretch_width",
                                  css_classes=["resonance-crossings"])
        self.campbell: resonance.CampbellView | None = None  # on screen
        self.frf = None
        self.ripple_view: resonance.RippleView | None = None
        self.polygon_view = None  # PolygonResponse on screen (None: no polygon given)
        self.track = None  # RandomResponse on screen
        self._state = None  # the dashboard state of the last request
        self.shown = False  # the view's tab is open (it computes only then)
        self._shown: dict[str, tuple] = {}  # kind -> key of the result on screen
        self._jobs = {kind: ViewJob(SIDE_VIEW_POOL, dashboard.alive, f"resonances ({kind})")
                      for kind in RESULTS}
        self._tapped = ViewJob(FIRST_ANSWER_POOL, dashboard.alive, "tapped mode")
        for widget in (self.orders, self.fixed, self.ripple, self.polygon):
            widget.param.watch(self._on_text, "value")
        self.input.param.watch(self._on_motor, "value")
        self.frf_input.param.watch(lambda _e: self._recompute(), "value")
        self.output.param.watch(lambda _e: self._redraw(), "value")
        self.campbell_plot.modes.selected.on_change("indices", self._on_tap)
        self.layout = pn.Column(
            pn.pane.Markdown("### Where the drive resonates (docs/resonance.md)  \n"
                             "Campbell diagram over speed at this creepage (hover a point for "
                             "its mode, tap it for its shape in the Modes view), the frequency "
                             "response at this operating point (from a motor's torque or a "
                             "wheel's surface deviation), the forced response over speed to a "
                             "torque ripple and to polygonal wheels, the spectrum under the "
                             "random track."),
            pn.Row(self.input, self.frf_input, self.output, self.orders),
            pn.Row(self.fixed, self.ripple, self.polygon),
            self.note, pn.pane.Bokeh(self.campbell_plot.figure, sizing_mode="stretch_width"),
            self.table,
            pn.Row(pn.Column(pn.pane.Bokeh(self.frf_plot.magnitude, sizing_mode="stretch_width"),
                             pn.pane.Bokeh(self.frf_plot.phase, sizing_mode="stretch_width"),
                             sizing_mode="stretch_width"),
                   pn.pane.Bokeh(self.ripple_plot.figure, sizing_mode="stretch_width"),
                   sizing_mode="stretch_width"),
            pn.Row(pn.pane.Bokeh(self.polygon_plot.figure, sizing_mode="stretch_width"),
                   pn.pane.Bokeh(self.track_plot.figure, sizing_mode="stretch_width"),
                   sizing_mode="stretch_width"),
            self.track_source,
            sizing_mode="stretch_width", css_classes=["resonance-view"])

    # --- settings -----------------------------------------------------------------------------

    def _on_text(self, _event) -> None:
        """Take the texts the model accepts; for one it does not, the notice (previous kept)."""
        try:
            orders = self.orders.value
            parse_orders(orders)
            fixed = resonance.parse_fixed(self.fixed.value)
            ripple = self.ripple.value
            parse_amplitudes(ripple)
            polygon = resonance.check_polygon(self.polygon.value)
        except ValueError as error:
            message = error.args[0] if error.args else str(error)
            self.dashboard.warn(f"Resonances: {message} (the previous settings are kept)")
            return
        self.dashboard.clear_warning()
        new = {"orders": orders, "fixed": fixed, "ripple": ripple, "polygon": polygon}
        if new != self.settings:
            self.settings = new
            self._recompute()

    def _on_motor(self, _event) -> None:
        """Another rippling motor: the FRF follows it when its input is a motor."""
        if self.frf_input.value in MOTOR_INPUTS:
            self.frf_input.value = self.input.value  # recomputes (its watcher)
        else:
            self._recompute()

    def _recompute(self) -> None:
        if self._state is not None:
            self.request(self._state)

    # --- computing and showing ------------------------------------------------------------------

    def keys(self, state) -> dict[str, tuple]:
        """The arguments of each result for the dashboard's ``state`` (a case record) and the
        view's settings."""
        s = self.settings
        motor = self.input.value
        over_speed = state.point().without("v")  # the diagrams span the speeds
        return {"frf": (state.point(), self.frf_input.value),
                "campbell": (over_speed, s["orders"], s["fixed"], motor),
                "ripple": (over_speed, s["ripple"], motor),
                "polygon": (over_speed, s["polygon"]),
                "track": (state.point(),)}

    def on_shown(self, shown: bool) -> None:
        """The dashboard opened (or left) the view's tab: compute for its state if needed."""
        self.shown = shown
        if shown:
            self._recompute()

    def request(self, state) -> None:
        """Compute for the dashboard's ``state`` if the view is open (served: on the side-view
        threads, each result shown when ready if still wanted; otherwise at once); else only
        remember it for when the view is opened."""
        self._state = state
        if not self.shown:
            return
        self.campbell_plot.mark_speed(state.v)
        self.ripple_plot.mark_speed(state.v)
        self.polygon_plot.mark_speed(state.v)
        for kind, key in self.keys(state).items():
            job = self._jobs[kind]
            if self._shown.get(kind) == key:
                job.want(key)
                continue
            if kind == "polygon" and not key[1]:  # no polygon given: nothing to compute
                job.want(key)
                self._apply(kind, key, None)
                continue
            if job.wanted != key:
                self.note.object = ("<i>computing the resonances… (the Campbell diagram takes "
                                    "seconds, the polygon's and the track's responses up to a "
                                    "minute or two)</i>")
            job.start(key, lambda kind=kind, key=key: RESULTS[kind](*key),
                      lambda key, result, kind=kind: self._apply(kind, key, result),
                      lambda key, error, kind=kind: self._failed(kind, key, error))

    def _failed(self, kind: str, key: tuple, error: BaseException) -> None:
        log.warning("resonances (%s) failed: %s", kind, error)
        message = error.args[0] if error.args else str(error)
        self.note.object = f"<i>{kind} not shown: {html.escape(str(message))}</i>"

    def _apply(self, kind: str, key: tuple, result) -> None:
        self._shown[kind] = key
        if kind == "frf":
            self.frf = result
        elif kind == "campbell":
            self.campbell = result
            self.campbell_plot.update(result)
            self.show_crossings()
        elif kind == "ripple":
            self.ripple_view = result
        elif kind == "polygon":
            self.polygon_view = result
            if result is None:
                self.polygon_plot.clear(NO_POLYGON)
        else:
            self.track = result
        self._redraw()
        if all(self._shown.get(kind) == job.wanted for kind, job in self._jobs.items()):
            self.note.object = ""

    def show_crossings(self) -> None:
        """The crossings' table, with the ripple check each drives where the verdict on screen
        is of the diagram's point (its creepage, wheel force, motor slope and set)."""
        if self.campbell is None:
            return
        verdicts = self.dashboard.verdicts
        checks = None
        if verdicts.result is not None and self._state is not None \
                and verdicts.shown_for.point().without("v") == self._state.point().without("v"):
            checks = tuple(c for c in verdicts.result.checks
                           if c.load_case in ("ripple", "running"))
        self.table.object = crossings_html(self.campbell, checks=checks)

    def _redraw(self) -> None:
        """The FRF, the forced responses and the random track's PSD of the chosen output."""
        output = self.output.value
        if self.frf is not None and output in self.frf.names:
            self.frf_plot.update(self.frf, output)
        if self.ripple_view is not None and output in self.ripple_view.names:
            self.ripple_plot.update(self.ripple_view, output)
        if self.polygon_view is not None and output in self.polygon_view.names:
            self.polygon_plot.update(self.polygon_view, output)
        if self.track is not None and output in self.track.names:
            self.track_plot.update(self.track, output)

    # --- a tapped mode ----------------------------------------------------------------------------

    def _on_tap(self, _attr, _old, new) -> None:
        if new:
            self.dashboard.run_locked(self.show_mode, int(new[0]))

    def show_mode(self, index: int) -> None:
        """The mode of the tapped point ``index`` of the diagram at its speed, in the Modes view."""
        data = self.campbell_plot.modes.data
        state = self._state
        if state is None or not 0 <= index < len(data["v"]):
            return
        v, name = float(data["v"][index]), str(data["name"][index])
        case, re, im = state.replace(v=v), float(data["re"][index]), float(data["im"][index])
        where = f"tapped on the Campbell diagram: “{name}” at v = {v:.1f} km/h, s0 = {state.s0:g}"
        # a model rejection: say so, keep the views
        self._tapped.start((case, re, im), lambda: compute.mode_near(case, re, im),
                           lambda _key, mode: self.dashboard.show_mode(mode, where),
                           lambda _key, error: self.dashboard.warn(
                               f"Mode at the tapped point not shown: {error}"))
