"""The 5–95 % uncertainty band of the stability limit s0*(v), drawn where s0*(v) is drawn over v.

An uncertainty result is the JSON file ``bogie uncertainty --speeds LIST --out FILE`` or
``bogie study uncertainty … --out FILE`` writes (:meth:`model.studies.uncertainty.UncertaintyResult.
as_dict`, format ``bogie-uncertainty-2``).  It carries what it belongs to: the parameter set's
hash (:func:`model.mechanics.parameters.parameter_hash`), the operating conditions (wheel force N0 [N],
motor slope b_M [N m s/rad] — sampled when ``motor_slope`` is an uncertain parameter, then its
nominal value —, rail condition), the speeds of s0* [km/h], the sample count and the method
(prior ranges or linearized posterior).  The band is drawn only when all of that matches the
set and conditions on screen (:func:`band_mismatch`); otherwise the view says which item does
not match and why.  The server opens the file by its path in its studies folder; a browser only
picks its name from the server's list (:mod:`app.services.studies_folder`) and never writes the server's
disk; messages call the file by that name.  Nothing here computes physics.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from bokeh.models import ColumnDataSource

from app.services.studies_folder import MAX_RESULT_BYTES as MAX_BYTES  # larger result files: not read
from model.studies.uncertainty import RESULT_FORMAT

BAND_COLOR = "#7b3294"  # purple: not in the map's red-blue palette


@dataclass(frozen=True)
class UncertaintyBand:
    """The s0*(v) distribution of an uncertainty result (plain data)."""

    name: str  # the file's name (in the server's studies folder)
    method: str  # "prior" or "posterior" ("" in a result without provenance)
    base_samples: int  # n
    runs: int  # model runs
    speeds_kmh: np.ndarray  # (k,) [km/h]
    p5: np.ndarray  # (k,) s0* 5th percentile [-] (nan: no sample had a limit)
    p50: np.ndarray  # (k,) median [-]
    p95: np.ndarray  # (k,) 95th percentile [-]
    nominal: np.ndarray  # (k,) s0* of the set itself [-]
    parameters_hash: str  # "" in a result without provenance
    wheel_force: float  # N0 [N] (nan: not recorded)
    motor_slope: float  # nominal b_M [N m s/rad] (nan: not recorded)
    motor_slope_sampled: bool
    rail: str

    @property
    def label(self) -> str:
        return f"s0* 5–95 % ({self.method}, n = {self.base_samples}) [-]"


def _number(value) -> float:
    return math.nan if value is None else float(value)


def read_band(path: str | Path, name: str | None = None) -> UncertaintyBand:
    """The s0*(v) band of an uncertainty result file (raises ValueError: not a file, not JSON,
    not an uncertainty result, no s0* outputs; the messages call it ``name``, default its
    path)."""
    path = Path(str(path).strip())
    name = str(path) if name is None else name
    if not path.is_file():
        raise ValueError(f"'{name}' is not a file")
    if path.stat().st_size > MAX_BYTES:
        raise ValueError(f"'{name}' is larger than {MAX_BYTES // 1_000_000} MB")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ValueError(f"'{name}' is not JSON ({error.__class__.__name__})") from None
    if not isinstance(data, dict) or not isinstance(data.get("outputs"), list):
        raise ValueError(f"'{name}' is not an uncertainty result (no 'outputs')")
    limits = [o for o in data["outputs"] if isinstance(o, dict)
              and str(o.get("name", "")).startswith("s0_limit_")]
    if not limits:
        raise ValueError(f"'{name}' has no stability-limit outputs (s0_limit_<v>)")
    try:
        speeds = np.array([float(o["name"][len("s0_limit_"):]) for o in limits])
        p5, p50, p95, nominal = (np.array([_number(o.get(key)) for o in limits])
                                 for key in ("p5", "p50", "p95", "nominal"))
        conditions = data.get("conditions") or {}
        order = np.argsort(speeds)
        return UncertaintyBand(
            name, str(data.get("method", "")) if data.get("format") == RESULT_FORMAT else "",
            int(data.get("base_samples", 0)), int(data.get("runs", 0)), speeds[order], p5[order],
            p50[order], p95[order], nominal[order], str(data.get("parameters_hash", "")),
            _number(conditions.get("wheel_force_N")),
            _number(conditions.get("motor_slope_Nms_per_rad")),
            bool(conditions.get("motor_slope_sampled", False)),
            str(conditions.get("rail", "")))
    except (KeyError, TypeError, ValueError) as error:
        raise ValueError(f"'{name}': malformed uncertainty result ({error})") from None


def band_mismatch(band: UncertaintyBand, parameters_hash: str, N0: float, b_M: float,
                  rail: str | None) -> str | None:
    """Why ``band`` does not belong to the set and conditions on screen (None: it does).
    ``N0`` [N], ``b_M`` [N m s/rad]; ``rail`` None when the screen's creep law is only known
    through the parameter hash (an opened map store)."""
    if not band.parameters_hash or band.method not in ("prior", "posterior"):
        return ("the result does not say which parameter set and conditions it belongs to "
                "(written before results carried them); re-run `bogie uncertainty --speeds … "
                "--out FILE`")
    reasons = []
    if rail is not None and band.rail != rail:
        reasons.append(f"rail condition: result '{band.rail}', screen '{rail}'")
    if band.parameters_hash != parameters_hash:
        reasons.append(f"parameter set: result {band.parameters_hash[:12]}…, screen "
                       f"{parameters_hash[:12]}… (another set, or the set was re-calibrated)")
    if not math.isclose(band.wheel_force, N0, rel_tol=1e-9):
        reasons.append(f"wheel force N0: result {band.wheel_force / 1e3:g} kN, screen "
                       f"{N0 / 1e3:g} kN")
    if not math.isclose(band.motor_slope, b_M, rel_tol=1e-9):
        what = "sampled around " if band.motor_slope_sampled else ""
        reasons.append(f"motor slope b_M: result {what}{band.motor_slope:g} N m s/rad, screen "
                       f"{b_M:g} N m s/rad")
    return "; ".join(reasons) or None


class BandLayer:
    """The band (``varea``) and its median (dashed) on a figure with v [km/h] on x and s0 [-] on
    y; empty until :meth:`update` gets a matching band."""

    def __init__(self, figure, name: str = "s0-band"):
        self.source = ColumnDataSource({"v": [], "low": [], "high": [], "median": []},
                                       name=name)
        self.area = figure.varea("v", "low", "high", source=self.source, fill_color=BAND_COLOR,
                                 fill_alpha=0.35, hatch_pattern="/", hatch_color=BAND_COLOR,
                                 hatch_alpha=0.6, legend_label="s0* 5–95 % band [-]")
        self.median = figure.line("v", "median", source=self.source, line_color=BAND_COLOR,
                                  line_dash="dashed", line_width=1.5,
                                  legend_label="s0* median [-]")
        self.legend = figure.legend[0]
        self.band: UncertaintyBand | None = None

    @property
    def shown(self) -> bool:
        return len(self.source.data["v"]) > 0

    def update(self, band: UncertaintyBand | None) -> None:
        """Draw ``band`` (speeds where every percentile is finite) or clear it (None)."""
        self.band = band
        if band is None:
            self.source.data = {"v": [], "low": [], "high": [], "median": []}
            return
        ok = np.isfinite(band.p5) & np.isfinite(band.p95) & np.isfinite(band.p50)
        self.source.data = {"v": band.speeds_kmh[ok], "low": band.p5[ok], "high": band.p95[ok],
                            "median": band.p50[ok]}
        for item in self.legend.items:
            if self.area in item.renderers:
                item.label = {"value": band.label}
