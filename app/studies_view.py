"""The "Studies" view: a stability map over s0 × v at the dashboard's N0, b_M and rail condition.

It starts a :class:`model.study.MapStudy` on the study engine (a local Dask cluster, a cluster
at an address, or this process), writes it into a Zarr store (:mod:`model.study_store`), shows
its progress without blocking the session (the study runs on a background thread; a periodic
callback of the served session polls it), and draws the heat map of the largest real part with
the stability limit s0*(v) over it.  A finished store (from here or from ``bogie study map``)
can be opened, and so can an uncertainty result (``bogie uncertainty --speeds … --out FILE``):
its 5–95 % band of s0*(v) is drawn over the map when it belongs to the parameter set and the
conditions on screen (:mod:`app.uncertainty_band`), else a notice says why not.  Bad input (an
empty range, fewer than two points, a path that is not a map store) shows a notice and keeps the
previous map.

Hooked into :class:`app.dashboard.BogieDashboard` with one section (marked "issue 13"); it reads
the dashboard's ``N0`` [kN], ``b_M``, ``rail`` and parameter file when a study starts.
"""

from __future__ import annotations

import html
import os
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import panel as pn
from bokeh.models import ColorBar, ColumnDataSource, LinearColorMapper
from bokeh.palettes import RdBu10

from model.operating_point import KMH

from . import compute
from .plots import _figure
from .uncertainty_band import BandLayer, UncertaintyBand, band_mismatch, read_band

WHERE = {"local Dask cluster": "local", "Dask cluster at the address": "address",
         "this process (no Dask)": "serial"}
POLL_MS = 500  # progress refresh of a served session [ms]


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


def read_map(path: str | Path, n0_index: int = 0, bm_index: int = 0) -> MapView:
    """The (s0, v) slice of a map store at the given N0 and b_M indices (raises ValueError if the
    path is not a map store)."""
    import xarray as xr

    path = Path(path)
    if not (path / "zarr.json").is_file():
        raise ValueError(f"'{path}' is not a Zarr store")
    with xr.open_zarr(str(path), consolidated=False) as dataset:
        if dataset.attrs.get("study") != "map":
            raise ValueError(f"'{path}' is not a stability-map store")
        sliced = dataset.isel(N0=n0_index, b_M=bm_index).load()
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
        self.figure = _figure("Stability map: largest real part [1/s]", "speed v [km/h]",
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
        self.band = BandLayer(self.figure, name="study-s0-band")  # issue 12: uncertainty band
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


class StudiesView(pn.viewable.Viewer):
    """Start a stability map at the dashboard's current N0, b_M and rail; follow it; open one."""

    def __init__(self, dashboard, folder: str | Path | None = None, **params):
        super().__init__(**params)
        self.dashboard = dashboard
        self.folder = Path(folder) if folder else Path(tempfile.gettempdir()) / "bogie-studies"
        self.map: MapView | None = None  # last map shown
        self.path: Path | None = None  # store of the running / last study
        self.error = ""
        self._thread: threading.Thread | None = None
        self._progress = (0, 0, 0.0)  # finished, total, elapsed [s] (written by the thread)
        self._outcome: str | None = None  # set by the thread when it ends
        self._stop = threading.Event()
        self._poller = None
        self.s0_range = pn.widgets.RangeSlider(label="creepage s0 [-]", start=0.0005, end=0.03,
                                               value=(0.001, 0.02), step=0.0005, format="0.0000",
                                               css_classes=["study-s0"])
        self.s0_points = pn.widgets.IntInput(label="s0 points", value=40, start=1, end=2000,
                                             css_classes=["study-s0-points"], width=110)
        self.v_range = pn.widgets.RangeSlider(label="speed v [km/h]", start=10.0, end=250.0,
                                              value=(40.0, 250.0), step=5.0, format="0",
                                              css_classes=["study-v"])
        self.v_points = pn.widgets.IntInput(label="v points", value=20, start=1, end=2000,
                                            css_classes=["study-v-points"], width=110)
        self.where = pn.widgets.Select(label="run on", options=list(WHERE),
                                       value=("Dask cluster at the address"
                                              if os.environ.get("DASK_SCHEDULER_ADDRESS")
                                              else "local Dask cluster"),
                                       css_classes=["study-where"], width=230)
        self.address = pn.widgets.TextInput(label="scheduler address",
                                            value=os.environ.get("DASK_SCHEDULER_ADDRESS", ""),
                                            placeholder="tcp://host:8786",
                                            css_classes=["study-address"], width=230)
        self.start_button = pn.widgets.Button(label="Start map", color="primary",
                                              css_classes=["study-start"], width=120)
        self.stop_button = pn.widgets.Button(label="Stop", css_classes=["study-stop"], width=80,
                                             disabled=True)
        self.store_path = pn.widgets.TextInput(label="store (.zarr)", placeholder="/path/map.zarr",
                                               css_classes=["study-store"], width=360)
        self.open_button = pn.widgets.Button(label="Open store", css_classes=["study-open"],
                                             width=120)
        self.progress = pn.indicators.Progress(value=0, max=1, css_classes=["study-progress"],
                                               width=360, visible=False)
        self.status = pn.pane.HTML("", css_classes=["study-status"], sizing_mode="stretch_width")
        self.notice = pn.pane.Alert("", alert_type="danger", visible=False,
                                    css_classes=["study-notice"], sizing_mode="stretch_width")
        self.plot = StudyMapPlot()
        # issue 12: an uncertainty result's s0*(v) band over the map (app/uncertainty_band.py)
        self.uncertainty: UncertaintyBand | None = None
        self.uncertainty_path = pn.widgets.TextInput(
            label="uncertainty result (.json, bogie uncertainty --speeds … --out)",
            placeholder="/path/uncertainty.json", css_classes=["study-uncertainty"], width=360)
        self.uncertainty_button = pn.widgets.Button(label="Open result",
                                                    css_classes=["study-open-uncertainty"],
                                                    width=120)
        self.uncertainty_button.on_click(
            lambda _event: self.open_uncertainty(self.uncertainty_path.value))
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
        self.start_button.on_click(lambda _event: self.start())
        self.stop_button.on_click(lambda _event: self.stop())
        self.open_button.on_click(lambda _event: self.open(self.store_path.value))
        self.layout = pn.Column(
            self.notice,
            pn.Row(self.s0_range, self.s0_points, self.v_range, self.v_points,
                   sizing_mode="stretch_width"),
            pn.Row(self.where, self.address, self.start_button, self.stop_button),
            pn.Row(self.store_path, self.open_button),
            pn.Row(self.uncertainty_path, self.uncertainty_button),
            self.progress, self.status, self.band_notice, self.band_status,
            pn.pane.Bokeh(self.plot.figure, sizing_mode="stretch_width"),
            sizing_mode="stretch_width", css_classes=["studies-view"])

    def __panel__(self):
        return self.layout

    # --- input -------------------------------------------------------------------------------

    def _reject(self, message: str) -> None:
        self.error = message
        self.notice.object = f"**Study not started/opened:** {html.escape(message)}"
        self.notice.visible = True

    def study(self):
        """The map study of the current controls and dashboard state (raises ValueError)."""
        from model.study import MapStudy

        d = self.dashboard
        if self.s0_points.value is None or self.s0_points.value < 1:
            raise ValueError("s0 points must be at least 1")
        if self.v_points.value is None or self.v_points.value < 1:
            raise ValueError("v points must be at least 1")
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
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> None:
        """Start a map in the background (the session stays responsive)."""
        if self.running:
            return
        try:
            study = self.study()
            parameters = compute.parameters(self.dashboard._params_path, self.dashboard.rail)
        except ValueError as error:
            self._reject(str(error.args[0] if error.args else error))
            return
        where = WHERE[self.where.value]
        address = self.address.value.strip() or None
        if where == "address" and not address:
            self._reject("give the scheduler address (tcp://host:port) or run locally")
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        self.path = self.folder / f"map-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}-{id(self):x}.zarr"
        self.notice.visible, self.error = False, ""
        self._progress, self._outcome = (0, len(study.chunks()), 0.0), None
        self._stop.clear()
        self.start_button.disabled, self.stop_button.disabled = True, False
        self.progress.visible, self.progress.max, self.progress.value = True, len(study.chunks()), 0
        self.status.object = (f"starting on {self.where.value} — N0 = {self.dashboard.N0:g} kN, "
                              f"b_M = {self.dashboard.b_M:g} N m s/rad, rail "
                              f"{self.dashboard.rail}; store {html.escape(str(self.path))}")
        self._thread = threading.Thread(target=self._run, args=(study, parameters, where, address),
                                        name="bogie-study", daemon=True)
        self._thread.start()
        doc = pn.state.curdoc
        if doc is not None and doc.session_context is not None:
            self._poller = pn.state.add_periodic_callback(self.poll, period=POLL_MS)

    def _run(self, study, parameters, where: str, address: str | None) -> None:
        from model.study_engine import StudyEngine, serial_map_unordered
        from model.study_store import run_into_store

        def progress(finished, total, elapsed):
            self._progress = (finished, total, elapsed)
            if self._stop.is_set():
                raise KeyboardInterrupt  # leaves the finished chunks in the store

        engine = None
        try:
            if where == "serial":
                mapper = serial_map_unordered
            else:
                engine = StudyEngine(address if where == "address" else None)
                engine.start()
                mapper = engine.map_unordered
            run_into_store(study, parameters, self.path, mapper, progress=progress)
            self._outcome = "done"
        except KeyboardInterrupt:
            self._outcome = "stopped"
        except Exception as error:  # shown in the view; the session stays alive
            self._outcome = f"failed: {str(error).splitlines()[0] if str(error) else type(error).__name__}"
        finally:
            if engine is not None:
                engine.close()

    def stop(self) -> None:
        """Stop after the chunk in progress (the store keeps the finished ones)."""
        self._stop.set()

    def wait(self, timeout: float | None = None) -> None:
        """Wait for the running study (tests, scripts)."""
        if self._thread is not None:
            self._thread.join(timeout)

    def poll(self) -> None:
        """Show the progress and the lines finished so far (periodic callback when served)."""
        finished, total, elapsed = self._progress
        self.progress.value = min(finished, self.progress.max)
        left = ""
        if 0 < finished < total:
            left = f", ~{elapsed / finished * (total - finished):.0f} s left"
        self.status.object = f"{finished}/{total} s0-lines, {elapsed:.0f} s{left}"
        if self.path is not None and (self.path / "zarr.json").is_file():
            try:
                self._show(read_map(self.path))
            except (ValueError, OSError, KeyError):
                pass  # the store is being created: next poll
        if self._outcome is not None and not self.running:
            if self._outcome.startswith("failed"):
                self._reject(f"the study {self._outcome}")
            self.status.object = (f"{self._outcome}: {finished}/{total} s0-lines in "
                                  f"{elapsed:.1f} s — store {html.escape(str(self.path))}")
            self.start_button.disabled, self.stop_button.disabled = False, True
            if self._poller is not None:
                self._poller.stop()
                self._poller = None

    # --- opening -------------------------------------------------------------------------------

    def open(self, path: str) -> None:
        """Show a finished (or partial) map store; a bad path shows a notice, the map stays."""
        try:
            view = read_map(Path(path.strip()))
        except (ValueError, OSError, KeyError) as error:
            self._reject(str(error))
            return
        self.notice.visible, self.error = False, ""
        self._show(view)
        self.status.object = (f"opened {html.escape(path)}: {view.finished}/{view.total} s0-lines; "
                              f"parameters {view.attrs.get('parameters_hash', '')[:12]}…, code "
                              f"{html.escape(str(view.attrs.get('code_version', '')))}")

    def _show(self, view: MapView) -> None:
        self.map = view
        self.plot.update(view)
        self.check_band()

    # --- the uncertainty band (issue 12) ---------------------------------------------------------

    def open_uncertainty(self, path: str) -> None:
        """Open an uncertainty result; a bad file shows a notice and the previous band stays."""
        try:
            band = read_band(path)
        except (ValueError, OSError) as error:
            self.band_notice.object = (f"**Uncertainty result not opened (previous one kept):** "
                                       f"{html.escape(str(error))}")
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
        from model.parameters import parameter_hash

        d = self.dashboard
        # the set's hash with the result's creep law (a different rail is its own reason)
        rail = self.uncertainty.rail if self.uncertainty is not None else d.rail
        parameters = compute.parameters(d._params_path, rail if rail in compute.RAIL_CONDITIONS
                                        else d.rail)
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
            self.band_notice.object = (f"**Uncertainty band not drawn** ({html.escape(band.path)} "
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
