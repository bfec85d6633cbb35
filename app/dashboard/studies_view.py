"""The "Studies" view: a stability map over s0 × v at the dashboard's N0, b_M and rail condition.

It asks the server's study queue (:mod:`app.services.study_queue`) for a :class:`model.studies.maps.MapStudy`;
the server runs it on the engine its operator chose (:mod:`app.services.settings`), into a Zarr
store of the server's studies folder (:mod:`model.studies.store`), when its turn comes.  The view
shows the queue position, then the progress without blocking the session (a periodic callback
of the served session polls the ticket), and draws the heat map of the largest real part with
the stability limit s0*(v) over it.  A finished store (from here or from ``bogie study map``
written into the folder) is opened by picking its name from the server's list, and so is an
uncertainty result (``bogie uncertainty --speeds … --out FILE``): its 5–95 % band of s0*(v) is
drawn over the map when it belongs to the parameter set and the conditions on screen
(:mod:`app.dashboard.uncertainty_band`), else a notice says why not.  Bad input (an empty range, too many
points, a name not in the list, a store that is not a map) shows a notice and keeps the
previous map.  No notice names a server path or address.

The dashboard holds it as its ``studies`` view; it reads the dashboard's ``N0`` [kN], ``b_M``,
``rail`` and bundled parameter set when a study starts.
"""

from __future__ import annotations

import html
import logging
import secrets
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import panel as pn
from bokeh.models import ColorBar, ColumnDataSource, LinearColorMapper
from bokeh.palettes import RdBu10

from app.dashboard.queued_study import QueuedStudyControls
from app.dashboard.session import served_document
from app.dashboard.uncertainty_band import BandLayer, UncertaintyBand, band_mismatch, read_band
from app.results import compute
from app.results.case import Case
from app.results.plots import new_figure
from app.services.study_queue import StudyQueue, StudyTicket, study_queue
from model.mechanics.operating_point import KMH

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class MapView:
    """What the heat map shows (plain data read from a store)."""

    s0: np.ndarray  # (n_s0,) [-]
    v_kmh: np.ndarray  # (n_v,) [km/h]
    largest_real_part: np.ndarray  # (n_s0, n_v) [1/s], nan where not computed yet
    s0_limit: np.ndarray  # (n_v,) [-], nan: none in range / not yet
    finished: int  # s0-lines written
    total: int  # s0-lines of the study
    attrs: dict  # the store's attributes (hash, code version, arguments)
    N0: float = float("nan")  # wheel force of the slice [N]
    b_M: float = float("nan")  # motor slope of the slice [N m s/rad]


def read_map(path: str | Path, n0_index: int = 0, bm_index: int = 0,
             name: str | None = None) -> MapView:
    """The (s0, v) slice of a map store at the given N0 and b_M indices (raises ValueError if the
    path is not a map store; the message calls it ``name``, default its path)."""
    import xarray as xr

    path = Path(path)
    name = str(path) if name is None else name
    if not (path / "zarr.json").is_file():
        raise ValueError(f"'{name}' is not a Zarr store")
    # read on the session's main thread (every poll of a running study): numpy arrays, not Dask
    # ones, and only the variables shown: 0.05-0.07 s against 0.3-0.9 s for the whole store
    # through Dask, time in which no session's slider change is answered
    with xr.open_zarr(str(path), consolidated=False, chunks=None) as dataset:
        if dataset.attrs.get("study") != "map":
            raise ValueError(f"'{name}' is not a stability-map store")
        dataset = dataset[["largest_real_part", "s0_limit", "chunk_done"]]
        # a store of ``bogie study map --motor-bandwidth LIST`` has a dimension per f_c: its first
        extra = {name: 0 for name in ("motor_bandwidth",) if name in dataset.dims}
        sliced = dataset.isel(N0=n0_index, b_M=bm_index, **extra).load()
        done = dataset["chunk_done"].values
        growth = np.where(sliced["chunk_done"].values[None, :] == 1,
                          sliced["largest_real_part"].values, np.nan)
        return MapView(sliced["s0"].values, sliced["v_kmh"].values, growth,
                       np.where(sliced["chunk_done"].values == 1, sliced["s0_limit"].values,
                                np.nan), int((done == 1).sum()), int(done.size),
                       dict(dataset.attrs), float(sliced["N0"].values), float(sliced["b_M"].values))


class StudyMapPlot:
    """Heat map of the largest real part over (v, s0) with s0*(v) on top."""

    def __init__(self):
        self.figure = new_figure("Stability map: largest real part [1/s]", "speed v [km/h]",
                                 "creepage s0 [-]")
        self.figure.height = 380
        # an even number of colours on a range symmetric about 0: the blue/red boundary is
        # exactly Re λ = 0 (stable blue, unstable red)
        self.mapper = LinearColorMapper(palette=list(RdBu10), low=-1.0, high=1.0,
                                        nan_color="#eeeeee")
        self.image = ColumnDataSource({"image": [np.full((1, 1), np.nan)], "x": [0.0], "y": [0.0],
                                       "dw": [1.0], "dh": [1.0]})
        self.figure.image(image="image", x="x", y="y", dw="dw", dh="dh", source=self.image,
                          color_mapper=self.mapper)
        self.figure.add_layout(ColorBar(color_mapper=self.mapper, title="Re λ max [1/s]"),
                               "right")
        self.limit = ColumnDataSource({"v": [], "s0": []})
        self.figure.line("v", "s0", source=self.limit, line_color="black", line_width=2,
                         legend_label="s0*(v)")
        self.figure.scatter("v", "s0", source=self.limit, color="black", size=4)
        # an uncertainty result's 5–95 % band of s0*(v), drawn when it matches the map
        self.band = BandLayer(self.figure, name="study-s0-band")
        self.figure.legend.location = "top_right"

    def update(self, view: MapView) -> None:
        z = view.largest_real_part
        finite = z[np.isfinite(z)]
        scale = float(np.percentile(np.abs(finite), 95)) if finite.size else 1.0
        self.mapper.low, self.mapper.high = -max(scale, 1e-3), max(scale, 1e-3)
        ds = (view.s0[-1] - view.s0[0]) / max(len(view.s0) - 1, 1)
        dv = (view.v_kmh[-1] - view.v_kmh[0]) / max(len(view.v_kmh) - 1, 1)
        self.image.data = {"image": [z], "x": [view.v_kmh[0] - dv / 2],
                           "y": [view.s0[0] - ds / 2], "dw": [view.v_kmh[-1] - view.v_kmh[0] + dv],
                           "dh": [view.s0[-1] - view.s0[0] + ds]}
        found = np.isfinite(view.s0_limit)
        self.limit.data = {"v": view.v_kmh[found].tolist(), "s0": view.s0_limit[found].tolist()}


class StudiesView(QueuedStudyControls, pn.viewable.Viewer):
    """Ask the server for a stability map at the dashboard's current N0, b_M and rail; follow it;
    open a finished one.  Where it runs, where it is stored and how large it may be are the
    server's settings (:mod:`app.services.settings`); this view only asks (:mod:`app.services.study_queue`)
    and picks stores and results by name from the server's list (:mod:`app.services.studies_folder`)."""

    UNIT, WHAT = "s0-lines", "study"

    def __init__(self, dashboard, queue: StudyQueue | None = None, **params):
        super().__init__(**params)
        self.dashboard = dashboard
        self.queue = queue or study_queue()
        # this session's claim on its study (the dashboard's: one study per session, a map here
        # or an envelope of the Design loads tab)
        self.owner = getattr(dashboard, "study_owner", None) or secrets.token_hex(8)
        self.map: MapView | None = None  # last map shown
        self.ticket: StudyTicket | None = None  # the session's running / last study
        self._read_at = -1  # lines finished when the running store was last read
        self.error = ""
        self._poller = None
        settings = self.queue.settings
        self.s0_range = pn.widgets.RangeSlider(label="creepage s0 [-]", start=0.0005, end=0.03,
                                               value=(0.001, 0.02), step=0.0005, format="0.0000",
                                               css_classes=["study-s0"])
        self.s0_points = pn.widgets.IntInput(label="s0 points", value=40, start=1,
                                             end=settings.max_study_points,
                                             css_classes=["study-s0-points"], width=110)
        v_low, v_high = Case.quantity("v").bounds  # the dashboard's speeds
        self.v_range = pn.widgets.RangeSlider(label="speed v [km/h]", start=v_low, end=v_high,
                                              value=(40.0, v_high), step=5.0, format="0",
                                              css_classes=["study-v"])
        self.v_points = pn.widgets.IntInput(label="v points", value=20, start=1,
                                            end=settings.max_study_points,
                                            css_classes=["study-v-points"], width=110)
        self._build_queue_controls("study", "points (s0 × v)", "Start map",
                                   "finished map (server's studies folder)", "Open map",
                                   "update both lists")
        self.plot = StudyMapPlot()
        # an uncertainty result's s0*(v) band over the map (app/dashboard/uncertainty_band.py)
        self.uncertainty: UncertaintyBand | None = None
        self.uncertainty_select = pn.widgets.Select(
            label="uncertainty result (bogie uncertainty --speeds … --out, in the folder)",
            options=[], css_classes=["study-uncertainty"], width=360)
        self.uncertainty_button = pn.widgets.Button(label="Open result",
                                                    css_classes=["study-open-uncertainty"],
                                                    width=120)
        self.band_status = pn.pane.HTML("", css_classes=["study-band-status"],
                                        sizing_mode="stretch_width")
        self.band_notice = pn.pane.Alert("", alert_type="warning", visible=False,
                                         css_classes=["study-band-notice"],
                                         sizing_mode="stretch_width")
        dashboard.param.watch(lambda _event: self.check_band(), ["N0", "b_M", "rail"])
        # the same band on the Variant tab's baseline s0*(v) (the dashboard's set and sliders)
        variant_figure = getattr(getattr(dashboard, "variant_view", None), "limits_figure", None)
        self.variant_band = (BandLayer(variant_figure, name="variant-s0-band")
                             if variant_figure is not None else None)
        # a button's callback may run without the session's document lock (Panel runs a click
        # that arrives while a widget change is pending as a coroutine without it); the plots'
        # Bokeh sources may only change with the lock: dashboard.run_locked
        locked = dashboard.run_locked
        self.start_button.on_click(lambda _event: locked(self.start))
        self.stop_button.on_click(lambda _event: locked(self.stop))
        self.open_button.on_click(lambda _event: locked(self.open, self.store_select.value))
        self.uncertainty_button.on_click(
            lambda _event: locked(self.open_uncertainty, self.uncertainty_select.value))
        self.refresh_button.on_click(lambda _event: self.refresh_lists())
        self.layout = pn.Column(
            self.notice,
            pn.Row(self.s0_range, self.s0_points, self.v_range, self.v_points,
                   sizing_mode="stretch_width"),
            pn.Row(self.start_button, self.stop_button, self.where, sizing_mode="stretch_width"),
            pn.Row(self.store_select, self.open_button, self.refresh_button),
            pn.Row(self.uncertainty_select, self.uncertainty_button),
            self.progress, self.status, self.band_notice, self.band_status,
            pn.pane.Bokeh(self.plot.figure, sizing_mode="stretch_width"),
            sizing_mode="stretch_width", css_classes=["studies-view"])
        self.refresh_lists()
        doc = served_document()
        if doc is not None:
            # a closed session's waiting study is dropped, its running one stops after its chunk
            doc.on_session_destroyed(lambda _context: self.queue.drop_owner(self.owner))

    def __panel__(self):
        return self.layout

    # --- input -------------------------------------------------------------------------------

    def _reject(self, message: str) -> None:
        self.error = message
        self.notice.object = f"**Study not started/opened:** {html.escape(message, quote=False)}"
        self.notice.visible = True

    def refresh_lists(self) -> None:
        """The finished maps and uncertainty results of the server's studies folder."""
        try:
            maps, results = self.queue.folder.names("map"), self.queue.folder.names("uncertainty")
        except OSError as error:
            log.error("the studies folder cannot be listed: %s", error)
            maps, results = [], []
        self.store_select.options = maps
        self.uncertainty_select.options = results

    def study(self):
        """The map study of the current controls and dashboard state (raises ValueError)."""
        from model.studies.maps import MapStudy

        d = self.dashboard
        if self.s0_points.value is None or self.s0_points.value < 1:
            raise ValueError("s0 points must be at least 1")
        if self.v_points.value is None or self.v_points.value < 1:
            raise ValueError("v points must be at least 1")
        points = int(self.s0_points.value) * int(self.v_points.value)
        limit = self.queue.settings.max_study_points
        if points > limit:  # checked before the grid is made (a doctored client's 10⁹ points)
            raise ValueError(f"{points} points asked; the server runs studies of at most "
                             f"{limit} points (s0 points × v points)")
        (s_low, s_high), (v_low, v_high) = self.s0_range.value, self.v_range.value
        if self.s0_points.value > 1 and not s_low < s_high:
            raise ValueError("the s0 range is empty")
        if self.v_points.value > 1 and not v_low < v_high:
            raise ValueError("the speed range is empty")
        s0 = np.linspace(s_low, s_high, self.s0_points.value)
        v = np.linspace(v_low, v_high, self.v_points.value) * KMH
        return MapStudy(s0, v, [d.N0 * 1e3], [d.b_M])

    # --- running -----------------------------------------------------------------------------

    @property
    def running(self) -> bool:
        """Whether this session's study is waiting or running."""
        return self.ticket is not None and not self.ticket.ended.is_set()

    def start(self) -> None:
        """Ask the server for a map (it runs in the background; the session stays responsive)."""
        if self.running:
            return
        try:
            study = self.study()
            parameters = compute.parameters(self.dashboard.base_key, self.dashboard.rail)
            ticket = self.queue.submit(self.owner, study, parameters)
        except ValueError as error:  # StudyRefused is a ValueError
            self._reject(str(error.args[0] if error.args else error))
            return
        self.ticket, self._read_at = ticket, -1
        self.notice.visible, self.error = False, ""
        self.start_button.disabled, self.stop_button.disabled = True, False
        self.progress.visible, self.progress.max, self.progress.value = True, ticket.total, 0
        self._conditions = (f"N0 = {self.dashboard.N0:g} kN, b_M = {self.dashboard.b_M:g} "
                            f"N m s/rad, rail {self.dashboard.rail}; store "
                            f"{html.escape(ticket.name)}")
        self._follow()

    def _after_end(self) -> None:
        self.refresh_lists()

    def _show_running_store(self, ticket: StudyTicket) -> None:
        path = self.queue.folder.root / ticket.name
        if (path / "zarr.json").is_file():
            try:
                view = read_map(path, name=ticket.name)
            except (ValueError, OSError, KeyError):
                return  # the store is being created: next poll
            self._read_at = view.finished
            self._show(view)

    # --- opening -------------------------------------------------------------------------------

    def open(self, name) -> None:
        """Show a finished (or partial) map store of the folder's list; a name not in the list,
        or a store that is not a map, shows a notice and the map stays."""
        try:
            path = self.queue.folder.path(name, "map")
            view = read_map(path, name=name)
        except (ValueError, OSError, KeyError) as error:
            self._reject(str(error) if isinstance(error, ValueError) else
                         f"the store could not be read ({type(error).__name__})")
            return
        self.notice.visible, self.error = False, ""
        self._show(view)
        self.status.object = (f"opened {html.escape(name)}: {view.finished}/{view.total} "
                              f"s0-lines; parameters {view.attrs.get('parameters_hash', '')[:12]}…, "
                              f"code {html.escape(str(view.attrs.get('code_version', '')))}")

    def _show(self, view: MapView) -> None:
        self.map = view
        self.plot.update(view)
        self.check_band()

    # --- the uncertainty band of s0*(v) --------------------------------------------------------

    def open_uncertainty(self, name) -> None:
        """Open an uncertainty result of the folder's list; a name not in the list or a bad file
        shows a notice and the previous band stays."""
        try:
            band = read_band(self.queue.folder.path(name, "uncertainty"), name=name)
        except (ValueError, OSError) as error:
            reason = (str(error) if isinstance(error, ValueError) else
                      f"the result could not be read ({type(error).__name__})")
            self.band_notice.object = (f"**Uncertainty result not opened (previous one kept):** "
                                       f"{html.escape(reason, quote=False)}")
            self.band_notice.visible = True
            return
        self.uncertainty = band
        self.check_band()

    def screen_conditions(self) -> tuple[str, float, float, str | None, str]:
        """(parameter hash, N0 [N], b_M [N m s/rad], rail or None, what) of the s0*(v) on screen:
        the map shown, or else the dashboard's set and sliders."""
        if self.map is not None and self.map.attrs.get("parameters_hash"):
            return (self.map.attrs["parameters_hash"], self.map.N0, self.map.b_M, None,
                    "the map on screen")
        return self.dashboard_conditions()

    def dashboard_conditions(self) -> tuple[str, float, float, str | None, str]:
        """(parameter hash, N0 [N], b_M [N m s/rad], rail, what) of the dashboard's set."""
        from model.mechanics.parameters import parameter_hash

        d = self.dashboard
        # the set's hash with the result's creep law (a different rail is its own reason)
        rail = self.uncertainty.rail if self.uncertainty is not None else d.rail
        parameters = compute.parameters(d.base_key, rail if rail in compute.RAILS else d.rail)
        return parameter_hash(parameters), d.N0 * 1e3, d.b_M, d.rail, "the dashboard's set"

    def check_band(self) -> None:
        """Draw the opened band if it belongs to what is on screen; else clear it and say why."""
        band = self.uncertainty
        if band is None:
            return
        variant_note = ""
        if self.variant_band is not None:  # the Variant tab's baseline: the dashboard's set
            reason = band_mismatch(band, *self.dashboard_conditions()[:4])
            self.variant_band.update(band if reason is None else None)
            variant_note = ("; also on the Variant tab's baseline s0*(v)" if reason is None else
                            f"; not on the Variant tab ({html.escape(reason, quote=False)})")
        hash_, N0, b_M, rail, what = self.screen_conditions()
        reason = band_mismatch(band, hash_, N0, b_M, rail)
        if reason is not None:
            self.plot.band.update(None)
            self.band_notice.object = (f"**Uncertainty band not drawn** ({html.escape(band.name)} "
                                       f"does not match {what}): "
                                       f"{html.escape(reason, quote=False)}")
            self.band_notice.visible = True
            self.band_status.object = ""
            return
        self.plot.band.update(band)
        if self.map is None:  # no map yet: drop the placeholder image so the axes fit the band
            self.plot.image.data = {"image": [], "x": [], "y": [], "dw": [], "dh": []}
        self.band_notice.visible = False
        speeds = ", ".join(f"{v:g}" for v in band.speeds_kmh)
        self.band_status.object = (
            f"s0*(v) band: {band.method}, n = {band.base_samples} ({band.runs} model runs), "
            f"speeds {speeds} km/h; parameters {band.parameters_hash[:12]}…, N0 = "
            f"{band.wheel_force / 1e3:g} kN, b_M = {band.motor_slope:g} N m s/rad"
            + (" (sampled)" if band.motor_slope_sampled else "") + f", rail {band.rail}"
            + variant_note)
