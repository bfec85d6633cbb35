"""A grid envelope of the drive parts' loads, asked of the server's study engine from the Design
loads tab.

Two axes of the scenario grid are varied (s0, v, N0, b_M, M0, f or D: a range and a point count
each, bounded like the dashboard's sliders); the other quantities are the dashboard's current
ones (its parameter set, rail, N0, b_M, excitation, simulated time and creep model, with the
anti-slip protection when the nonlinear creep model is on).  The fault instant is treated as
chosen: the two **continuity roots** per period (physics first) or **every fault instant** (the
closed form, linear creep only: explicitly conservative).  The view asks the server's study
queue (:mod:`app.services.study_queue`) for a :class:`model.studies.envelope.EnvelopeStudy`; the
server runs it when its turn comes, on the engine its operator chose, into a store it names in
its studies folder.  The size limit (``max_study_points``) counts scenarios (grid points ×
fault instants), and a session runs one study at a time (a map of the Studies tab or an
envelope).

While it runs the view shows the queue position, then the progress and the partial heat map; at
the end a **heat map of the peak** (max or min of a chosen drive part) over the two axes and a
**table per drive part**: the max and the min, the scenario of each, and a link that opens that
scenario in the dashboard (:func:`app.dashboard.url_state.scenario_query`).  Finished envelope
stores (from here or from ``bogie envelope --out`` written into the folder) are opened by picking
their name from the server's list.  Bad input shows a notice and keeps what is on screen; no
notice names a server path.
"""

from __future__ import annotations

import html
import json
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import panel as pn

from app.dashboard.queued_study import QueuedStudyControls
from app.dashboard.session import served_document
from app.dashboard.url_state import fit_phase, scenario_query
from app.results import compute
from app.results.case import Case
from app.results.load_plots import EnvelopeMapPlot
from app.results.tables import format_load
from app.services.study_queue import StudyQueue, StudyTicket, study_queue

log = logging.getLogger(__name__)
# the quantities an envelope varies -> (slider step, slider format) of its range controls; the
# label, unit, dashboard parameter and SI factor are the quantity's (app.results.case)
AXIS_STEPS = {"s0": (0.0005, "0.0000"), "v": (5.0, "0"), "N0": (5.0, "0"), "b_M": (250.0, "0"),
              "M0": (5.0, "0"), "f": (5.0, "0"), "D": (0.005, "0.000")}
# axis -> (label, display unit, dashboard parameter, SI value per display unit, slider step,
# slider format)
AXES = {name: (Case.quantity(name).label, Case.quantity(name).unit, name, Case.quantity(name).si,
               *steps) for name, steps in AXIS_STEPS.items()}
DEFAULT_RANGES = {"s0": (0.002, 0.012), "v": (60.0, 200.0), "N0": (80.0, 120.0),
                  "b_M": (1000.0, 5000.0), "M0": (25.0, 100.0), "f": (50.0, 150.0),
                  "D": (0.02, 0.1)}
FAULTS = {"continuity roots (physical: 2 instants per period)": "roots",
          "every fault instant (closed form, linear creep: conservative)": "all"}
STATISTICS = {"max": "max", "min": "min"}


def axis_label(axis: str) -> str:
    """An axis's label with its display unit, e.g. ``speed v [km/h]``."""
    label, unit = AXES[axis][:2]
    return f"{label} [{unit}]"


@dataclass(frozen=True)
class EnvelopeData:
    """What an envelope store holds, loaded (plain data; nan where no chunk is written yet)."""

    study: object  # model.studies.envelope.EnvelopeStudy (from the store's arguments)
    arrays: dict[str, np.ndarray] = field(repr=False)  # max, min, time_of_*, phase_of_*, …
    finished: int  # chunks written
    total: int  # chunks of the study
    attrs: dict  # the store's attributes (hash, code version, arguments)

    @property
    def complete(self) -> bool:
        return self.finished == self.total

    def axis_values(self, axis: str) -> np.ndarray:
        """The grid's values along ``axis`` in display units (AXES)."""
        return np.asarray(getattr(self.study, axis), dtype=float) / AXES[axis][3]

    @property
    def varying(self) -> list[str]:
        """The axes (of AXES) with more than one value."""
        return [axis for axis in AXES if len(getattr(self.study, axis)) > 1]


def read_envelope(path: str | Path, name: str) -> EnvelopeData:
    """An envelope store's peaks (raises ValueError naming it ``name`` if it is not one)."""
    import xarray as xr

    from model.studies.envelope import EnvelopeStudy

    path = Path(path)
    if not (path / "zarr.json").is_file():
        raise ValueError(f"'{name}' is not a Zarr store")
    with xr.open_zarr(str(path), consolidated=False, chunks=None) as dataset:  # numpy, not Dask
        if dataset.attrs.get("study") != "envelope":
            raise ValueError(f"'{name}' is not a design-load envelope store")
        arguments = json.loads(dataset.attrs.get("arguments", "{}"))
        arguments.pop("kind", None)
        study = EnvelopeStudy(**{k: tuple(v) if isinstance(v, list) else v
                                 for k, v in arguments.items()})
        arrays = {name_: dataset[name_].values for name_ in study.store_layout().variables}
        done = dataset["chunk_done"].values
        return EnvelopeData(study, arrays, int((done == 1).sum()), int(done.size),
                            dict(dataset.attrs))


def peak_map(data: EnvelopeData, output: str, statistic: str, x_axis: str, y_axis: str
             ) -> np.ndarray:
    """The max (``statistic`` "max") or min over every other dimension of ``output``'s peaks, as
    a len(y) x len(x) array over the two axes (nan: not computed yet)."""
    dims = data.study.scenario_dims
    values = data.arrays[statistic][list(data.study.outputs).index(output)]
    keep = [dims.index(x_axis), dims.index(y_axis)]
    others = tuple(i for i in range(values.ndim) if i not in keep)
    reduce = np.fmax.reduce if statistic == "max" else np.fmin.reduce  # nan: not yet, no warning
    reduced = reduce(values, axis=others) if others else values
    # reduced has the kept dimensions in their store order
    return reduced if keep[0] > keep[1] else reduced.T


def envelope_rows(data: EnvelopeData):
    """The envelope (:func:`model.studies.envelope.envelope`) over the finished scenarios (None if
    none is finished)."""
    from model.studies.envelope import envelope

    arrays = dict(data.arrays)
    finished = np.isfinite(arrays["max"])
    if not finished.any():
        return None
    arrays["max"] = np.where(finished, arrays["max"], -np.inf)
    arrays["min"] = np.where(np.isfinite(arrays["min"]), arrays["min"], np.inf)
    return envelope(data.study, arrays)


class EnvelopeGrid(QueuedStudyControls):
    """Ask the server for a grid envelope at the dashboard's point; follow it; open a finished
    one.  The dashboard provides ``param`` (its parameters and their bounds), ``nonlinear`` (the
    creep switch and the anti-slip key in use), ``base_key``, ``set_key``, ``study_owner``,
    ``variant`` and ``run_locked``."""

    UNIT, WHAT = "chunks", "envelope"

    def __init__(self, dashboard, queue: StudyQueue | None = None):
        self.dashboard = dashboard
        self.queue = queue or study_queue()
        # the session's claim on its study: shared with the Studies tab (one study per session)
        self.owner = dashboard.study_owner
        self.data: EnvelopeData | None = None  # the envelope shown
        self.ticket: StudyTicket | None = None
        self.error = ""
        self._poller = None
        self._read_at = -1  # chunks finished when the running store was last read
        self._variant = ""  # the variant of the study shown (its links open it)
        self._study_axes = ("s0", "v")  # the axes of the study started here
        self._axes = ("s0", "v")  # the heat map's axes
        settings = self.queue.settings
        axes = {axis_label(axis): axis for axis in AXES}
        self.axis_x = pn.widgets.Select(label="axis 1", options=axes, value="s0", width=230,
                                        css_classes=["loads-axis-x"])
        self.axis_y = pn.widgets.Select(label="axis 2", options=axes, value="v", width=230,
                                        css_classes=["loads-axis-y"])
        self.range_x = pn.widgets.RangeSlider(label="axis 1 range", css_classes=["loads-range-x"],
                                              **self._range_settings("s0"))
        self.range_y = pn.widgets.RangeSlider(label="axis 2 range", css_classes=["loads-range-y"],
                                              **self._range_settings("v"))
        self.points_x = pn.widgets.IntInput(label="axis 1 points", value=6, start=1,
                                            end=settings.max_study_points, width=110,
                                            css_classes=["loads-points-x"])
        self.points_y = pn.widgets.IntInput(label="axis 2 points", value=8, start=1,
                                            end=settings.max_study_points, width=110,
                                            css_classes=["loads-points-y"])
        self.fault = pn.widgets.Select(label="fault instant", options=FAULTS, value="roots",
                                       width=420, css_classes=["loads-fault"])
        self._build_queue_controls("loads", "scenarios (grid points × fault instants)",
                                   "Start envelope", "finished envelope (server's studies folder)",
                                   "Open envelope", "update the list")
        parts = {f"{name.split('.')[0]} {compute.PART_LABELS[name.split('.', 1)[1]]}": name
                 for name in compute.DRIVE_PARTS}
        self.map_output = pn.widgets.Select(label="heat map of", options=parts,
                                            value="ID1.disc_clutch.torque", width=260,
                                            css_classes=["loads-map-output"])
        self.map_statistic = pn.widgets.RadioButtonGroup(options=STATISTICS, value="max",
                                                         css_classes=["loads-map-statistic"])
        self.plot = EnvelopeMapPlot()
        self.map_note = pn.pane.HTML("", css_classes=["loads-map-note"],
                                     sizing_mode="stretch_width")
        self.table = pn.pane.HTML("", css_classes=["loads-envelope-table"],
                                  sizing_mode="stretch_width")
        self.axis_x.param.watch(lambda e: self._rebound(self.range_x, e.new), "value")
        self.axis_y.param.watch(lambda e: self._rebound(self.range_y, e.new), "value")
        self.map_output.param.watch(lambda _e: self.show_map(), "value")
        self.map_statistic.param.watch(lambda _e: self.show_map(), "value")
        # a button's callback may run without the session's document lock: dashboard.run_locked
        locked = dashboard.run_locked
        self.start_button.on_click(lambda _event: locked(self.start))
        self.stop_button.on_click(lambda _event: locked(self.stop))
        self.open_button.on_click(lambda _event: locked(self.open, self.store_select.value))
        self.refresh_button.on_click(lambda _event: self.refresh_list())
        self.layout = pn.Column(
            self.notice,
            pn.Row(self.axis_x, self.range_x, self.points_x, sizing_mode="stretch_width"),
            pn.Row(self.axis_y, self.range_y, self.points_y, sizing_mode="stretch_width"),
            pn.Row(self.fault, self.start_button, self.stop_button, sizing_mode="stretch_width"),
            self.where,
            pn.Row(self.store_select, self.open_button, self.refresh_button),
            self.progress, self.status,
            pn.Row(self.map_output, self.map_statistic),
            pn.pane.Bokeh(self.plot.figure, sizing_mode="stretch_width"), self.map_note,
            self.table, sizing_mode="stretch_width", css_classes=["loads-grid"])
        self.refresh_list()
        doc = served_document()
        if doc is not None:
            # a closed session's waiting study is dropped, its running one stops after its chunk
            doc.on_session_destroyed(lambda _context: self.queue.drop_owner(self.owner))

    # --- input -------------------------------------------------------------------------------

    def _bounds(self, axis: str) -> tuple[float, float]:
        """The axis's range in display units: the dashboard's slider bounds."""
        return tuple(float(x) for x in self.dashboard.param[AXES[axis][2]].bounds)

    def _range_settings(self, axis: str) -> dict:
        low, high = self._bounds(axis)
        return {"start": low, "end": high, "value": DEFAULT_RANGES[axis], "step": AXES[axis][4],
                "format": AXES[axis][5]}

    def _rebound(self, slider, axis: str) -> None:
        if axis in AXES:
            slider.param.update(**self._range_settings(axis))

    def _reject(self, message: str) -> None:
        self.error = message
        self.notice.object = (f"**Envelope not started/opened:** "
                              f"{html.escape(message, quote=False)}")
        self.notice.visible = True

    def refresh_list(self) -> None:
        """The finished envelope stores of the server's studies folder."""
        try:
            names = self.queue.folder.names("envelope")
        except OSError as error:
            log.error("the studies folder cannot be listed: %s", error)
            names = []
        self.store_select.options = names

    def _axis_values(self, axis: str, span, points) -> np.ndarray:
        """The grid along ``axis`` in display units (raises ValueError)."""
        low, high = (float(x) for x in span)
        bottom, top = self._bounds(axis)
        if not (np.isfinite(low) and np.isfinite(high) and bottom <= low <= high <= top):
            raise ValueError(f"the {axis_label(axis)} range must lie in [{bottom:g}, {top:g}]")
        if points > 1 and not low < high:
            raise ValueError(f"the {axis_label(axis)} range is empty")
        return np.linspace(low, high, points) if points > 1 else np.array([low])

    def study(self):
        """The envelope study of the controls and the dashboard's state (raises ValueError)."""
        from model.studies.envelope import EnvelopeStudy, resolve_outputs

        d = self.dashboard
        x_axis, y_axis = self.axis_x.value, self.axis_y.value
        if x_axis not in AXES or y_axis not in AXES:
            raise ValueError("choose both axes from the lists")
        if x_axis == y_axis:
            raise ValueError("choose two different axes")
        counts = []
        for label, value in (("axis 1 points", self.points_x.value),
                             ("axis 2 points", self.points_y.value)):
            if value is None or isinstance(value, bool) or int(value) < 1:
                raise ValueError(f"{label} must be at least 1")
            counts.append(int(value))
        nonlinear = d.nonlinear.creep.value == "nonlinear"
        fault = self.fault.value
        if fault not in FAULTS.values():
            raise ValueError("choose the fault instants from the list")
        if fault == "all" and nonlinear:
            raise ValueError("every fault instant needs linear creep (the closed form is a "
                             "superposition): choose the continuity roots, or switch the creep "
                             "model to linear")
        scenarios = counts[0] * counts[1] * (2 if fault == "roots" else 1)
        limit = self.queue.settings.max_study_points
        if scenarios > limit:  # checked before the grid is made (a doctored client's 10⁹)
            raise ValueError(f"{scenarios} scenarios asked; the server runs studies of at most "
                             f"{limit} scenarios (grid points × fault instants)")
        grid = {axis: np.array([float(getattr(d, AXES[axis][2]))]) for axis in AXES}
        grid[x_axis] = self._axis_values(x_axis, self.range_x.value, counts[0])
        grid[y_axis] = self._axis_values(y_axis, self.range_y.value, counts[1])
        si = {axis: tuple(float(x) for x in grid[axis] * AXES[axis][3]) for axis in AXES}
        # the dashboard's set (its variant included); the study applies the rail's creep law
        case = d.state()
        parameters = compute.parameters(d.set_key, "calibrated", case.overrides())
        model = compute.model_for(case)
        creep = "nonlinear" if nonlinear else "linear"
        first = case.replace(**{q.name: grid[q.name][0]
                                for q in case.of_role("point")}).operating_point()
        outputs, units = resolve_outputs(model, first, list(compute.DRIVE_PARTS), creep)
        protection = {}
        if nonlinear:
            enabled, delay, threshold, rate = d.nonlinear.valid
            protection = ({"anti_slip": ("on",), "anti_slip_delay": (delay,),
                           "anti_slip_threshold": threshold, "anti_slip_rate": rate}
                          if enabled else {"anti_slip": ("off",)})
        study = EnvelopeStudy(
            s0=si["s0"], v=si["v"], N0=si["N0"], b_M=si["b_M"], outputs=outputs, units=units,
            rail=(d.rail,), M0=si["M0"], f=si["f"], D=si["D"], fault=fault, creep=creep,
            t_end=float(d.t_end), fs=compute.sampling_rate(max(si["f"])), **protection)
        return study, parameters

    # --- running -----------------------------------------------------------------------------

    @property
    def running(self) -> bool:
        """Whether this view's envelope is waiting or running."""
        return self.ticket is not None and not self.ticket.ended.is_set()

    def start(self) -> None:
        """Ask the server for the envelope (it runs in the background; the session stays
        responsive)."""
        if self.running:
            return
        try:
            study, parameters = self.study()
            ticket = self.queue.submit(self.owner, study, parameters)
        except ValueError as error:  # StudyRefused and DesignLoadError are ValueErrors
            self._reject(str(error.args[0] if error.args else error))
            return
        self.ticket, self._read_at = ticket, -1
        self._study_axes = (self.axis_x.value, self.axis_y.value)
        self._variant = self.dashboard.variant
        self.notice.visible, self.error = False, ""
        self.start_button.disabled, self.stop_button.disabled = True, False
        self.progress.visible, self.progress.max, self.progress.value = True, ticket.total, 0
        self._conditions = (f"{study.scenarios} scenarios, {study.creep} creep, rail "
                            f"{study.rail[0]}; store {html.escape(ticket.name)}")
        self._follow()

    def _after_end(self) -> None:
        self.refresh_list()

    def _show_running_store(self, ticket: StudyTicket) -> None:
        path = self.queue.folder.root / ticket.name
        if (path / "zarr.json").is_file():
            try:
                data = read_envelope(path, ticket.name)
            except (ValueError, OSError, KeyError):
                return  # the store is being created: next poll
            self._read_at = data.finished
            self._show(data, axes=self._study_axes)

    # --- opening -------------------------------------------------------------------------------

    def open(self, name) -> None:
        """Show an envelope store of the folder's list; a name not in the list, or a store that is
        not an envelope, shows a notice and the envelope on screen stays."""
        try:
            path = self.queue.folder.path(name, "envelope")
            data = read_envelope(path, name)
        except (ValueError, OSError, KeyError, TypeError) as error:
            self._reject(str(error) if isinstance(error, ValueError) else
                         f"the store could not be read ({type(error).__name__})")
            return
        self.notice.visible, self.error = False, ""
        self._variant = ""
        self._show(data)
        self.status.object = (f"opened {html.escape(name)}: {data.finished}/{data.total} chunks, "
                              f"{data.study.scenarios} scenarios; parameters "
                              f"{data.attrs.get('parameters_hash', '')[:12]}…, code "
                              f"{html.escape(str(data.attrs.get('code_version', '')))}")

    # --- showing -------------------------------------------------------------------------------

    def _show(self, data: EnvelopeData, axes: tuple[str, str] | None = None) -> None:
        """Show ``data`` over ``axes`` (default: its first two varying axes)."""
        if axes is None:
            varying = data.varying
            first = varying[0] if varying else "s0"
            second = varying[1] if len(varying) > 1 else ("v" if first != "v" else "s0")
            axes = (first, second)
        self.data, self._axes = data, axes
        self.show_map()
        self.show_table()

    def show_map(self) -> None:
        """Draw the heat map of the chosen drive part and statistic."""
        data = self.data
        if data is None:
            return
        output, statistic = self.map_output.value, self.map_statistic.value
        if output not in data.study.outputs or statistic not in STATISTICS:
            return
        x_axis, y_axis = self._axes
        z = peak_map(data, output, statistic, x_axis, y_axis)
        unit = data.study.units[list(data.study.outputs).index(output)]
        drive, part = output.split(".", 1)
        word = "largest" if statistic == "max" else "smallest"
        self.plot.update(data.axis_values(x_axis), data.axis_values(y_axis), z,
                         axis_label(x_axis), axis_label(y_axis),
                         f"{word} {drive} {compute.PART_LABELS[part]} [{unit}] over the "
                         f"scenarios of each grid point ({data.study.fault}, {data.study.creep} "
                         "creep)", f"{statistic} [{unit}]", largest=statistic == "max")
        beyond = self.plot.beyond
        self.map_note.object = "" if not beyond else (
            f"<div style='font-size:12px'>{beyond} cell(s) lie far beyond the others and are "
            "drawn above (red) or below (dark blue) the colour scale"
            + (" — with linear creep, the growth of unstable points" if data.study.creep ==
               "linear" else "") + "; hover shows their values.</div>")

    def _link_variant(self, data: EnvelopeData) -> str | None:
        """The variant the links carry so that they open the store's parameter set: that of
        the study started here, the dashboard's or none (the bundled set); None if it is neither
        (another parameter file)."""
        from model.mechanics.parameters import parameter_hash

        stored = data.attrs.get("parameters_hash")
        base = self.dashboard.base_key
        for variant in dict.fromkeys((self._variant, self.dashboard.variant, "")):
            key = f"{base}|{variant}" if variant else base
            try:
                if parameter_hash(compute.parameters(key, "calibrated")) == stored:
                    return variant
            except ValueError:  # a variant that no longer applies
                continue
        return None

    def show_table(self) -> None:
        """The table per drive part: max and min, the scenario of each, links that open it."""
        data = self.data
        result = envelope_rows(data)
        if result is None:
            self.table.object = "<i>no scenario finished yet</i>"
            return
        variant = self._link_variant(data)
        rows = []
        for o in result.outputs:
            cells = []
            for value, at in ((o.max, o.max_at), (o.min, o.min_at)):
                query = scenario_query(at, data.study.t_end, variant or "")
                phase = fit_phase(at["phase_s"], 1.0 / at["f"])
                where = (f"s0 = {at['s0']:.5g}, v = {at['v_kmh']:.4g} km/h, N0 = "
                         f"{at['n0'] / 1e3:.4g} kN, b_M = {at['bm']:.5g}, M0 = "
                         f"{at['m0'] / 1e3:.4g} kN m, f = {at['f']:.4g} Hz, D = "
                         f"{at['decay']:.4g}, Δt = {at['phase_s']:.6f} s, t = {at['time_s']:.4f} s")
                if phase is None:
                    where += (" (Δt outside the dashboard's ±10 ms: the link leaves Δt "
                              "automatic, the first continuity root)")
                cells.append(f"<td><b>{format_load(value)}</b></td><td class='text'>{html.escape(where)}"
                             f" <a href='?{html.escape(query)}' target='_blank'>open</a></td>")
            drive, part = o.name.split(".", 1)
            rows.append(f"<tr><td class='text'>{drive} {compute.PART_LABELS[part]} [{o.unit}]</td>"
                        + "".join(cells) + "</tr>")
        notes = [f"over {'all' if data.complete else 'the finished'} scenarios "
                 f"({data.finished}/{data.total} chunks), fault instants: {data.study.fault}, "
                 f"{data.study.creep} creep"]
        if data.study.creep != "linear":
            protection = "/".join(data.study.anti_slip) + (
                f", delay {'/'.join(f'{x:g}' for x in data.study.anti_slip_delay)} s"
                if "on" in data.study.anti_slip else "")
            notes.append("the links open the operating point and the short circuit; switch the "
                         f"creep model to {data.study.creep} (anti-slip {protection}) to see the "
                         "same history")
        if result.truncated:
            notes.append(f"{result.truncated} scenario(s) grew beyond 1e250 (unstable, linear): "
                         "their peaks end where the time grid was cut")
        if variant is None:
            notes.append("computed with another parameter set than the dashboard's (bundled or "
                         f"with its variant; hash {str(data.attrs.get('parameters_hash'))[:12]}…): "
                         "the links open the scenario with the bundled set")
        self.table.object = (
            '<table class="bogie envelope"><tr><th class="text">drive part</th><th>max</th>'
            '<th class="text">scenario of the max</th><th>min</th>'
            '<th class="text">scenario of the min</th></tr>' + "".join(rows) + "</table>"
            f"<div style='font-size:12px'>{html.escape('; '.join(notes))}</div>")
