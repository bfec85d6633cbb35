"""A locomotive's route or duty for a fatigue life: the time it runs at each speed in a year, the
annual distance, and the short circuits a year with the operating points they happen at.

    route = load_route("assets/routes/mixed_passenger_200.toml")
    route.seconds_per_year          # (bins,) running time in each speed bin [s/year]
    route.edges                     # (bins + 1,) the bins' edges [m/s]

**The file** (TOML; speeds in km/h, distances in km)::

    name = "…"
    source = "…"                    # where the numbers come from, or the reasoning
    annual_distance_km = 250000

    [speeds]                        # a histogram of the running time …
    edges_kmh = [0, 10, 20, …, 200]
    share = [0.05, 0.04, …]         # of the running time per bin (normalised to 1)
    # … or samples of a representative run, binned:
    # csv = "trip.csv"              # columns t_s,v_kmh (a header line), t increasing
    # bin_kmh = 5

    [track]                         # optional: the track's random irregularity
    spectrum = "low"                # a spectrum of model.analysis.track_spectrum

    [wheel_polygon]                 # optional: every wheel's polygon
    amplitudes_um = "20=30"         # order = radial amplitude [µm], …

    [short_circuit]                 # optional
    per_year = 0.1                  # ID1's motor short-circuits per year
    s0 = 0.005                      # the creepage it happens at [-]
    v_kmh = [80, 120, 200]          # the speeds …
    share = [0.3, 0.5, 0.2]         # … and their shares of the events (normalised to 1)

**From a histogram to time.**  The running time a year is the annual distance over the mean speed
of the histogram (``Σ share_b v_b`` with ``v_b`` the bin's centre); bin b gets ``share_b`` of it.
Within a bin the speed is taken as uniformly distributed: a resonance inside the bin gets the time
its width of speed gets, as when the locomotive passes through it.  **From samples**: each interval
of the CSV counts its duration at the mean of its two speeds, in bins of ``bin_kmh`` from 0 to the
highest speed; the run's distance ``∫ v dt`` scales it to the annual distance.

A file that is not one of these — a missing or negative number, edges not increasing, shares that
do not sum to a positive number, an unknown key — is refused with a one-line :class:`RouteError`
naming the entry.  SI inside: speeds in m/s, times in s.
"""

from __future__ import annotations

import csv
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from model.mechanics.operating_point import KMH

SECONDS_PER_YEAR = 365.25 * 24 * 3600.0  # [s]: the ceiling of running time a year
TOP_KEYS = {"name", "source", "annual_distance_km", "speeds", "short_circuit", "track",
            "wheel_polygon"}
SPEED_KEYS = {"edges_kmh", "share", "csv", "bin_kmh"}
EVENT_KEYS = {"per_year", "s0", "v_kmh", "share"}


class RouteError(ValueError):
    """A route file the life computation cannot use (one-line message naming the entry)."""


@dataclass(frozen=True)
class ShortCircuitEvents:
    """Short circuits of ID1's motor over a year and where they happen."""

    per_year: float  # events a year [1/year]
    s0: float  # creepage [-]
    v: tuple[float, ...]  # speeds [m/s]
    share: tuple[float, ...]  # share of the events at each speed [-], summing to 1

    def per_year_at(self) -> list[tuple[float, float]]:
        """(speed [m/s], events a year [1/year]) per speed."""
        return [(v, self.per_year * s) for v, s in zip(self.v, self.share, strict=True)]


@dataclass(frozen=True)
class Route:
    """A duty: time at speed a year, the annual distance, the events (module docstring)."""

    name: str
    source: str
    annual_distance: float  # [m/year]
    edges: np.ndarray  # (bins + 1,) speed bins' edges [m/s]
    seconds_per_year: np.ndarray  # (bins,) running time in each bin [s/year]
    short_circuit: ShortCircuitEvents | None = None
    origin: dict = field(default_factory=dict)  # how the file gave the speeds (histogram or csv)
    track: str | None = None  # the track's irregularity spectrum (model.analysis.track_spectrum)
    wheel_polygon: dict | None = None  # every wheel's polygon {order: radial amplitude [m]}

    @property
    def centres(self) -> np.ndarray:
        """(bins,) the bins' centre speeds [m/s]."""
        return 0.5 * (self.edges[:-1] + self.edges[1:])

    @property
    def running_hours_per_year(self) -> float:
        return float(self.seconds_per_year.sum() / 3600.0)

    def as_dict(self) -> dict:
        events = self.short_circuit
        return {"name": self.name, "source": self.source,
                "annual_distance_km": self.annual_distance / 1e3,
                "running_hours_per_year": self.running_hours_per_year,
                "speed_bins_kmh": [[float(a / KMH), float(b / KMH)]
                                   for a, b in zip(self.edges[:-1], self.edges[1:], strict=True)],
                "hours_per_year": [float(s / 3600.0) for s in self.seconds_per_year],
                "short_circuit": None if events is None else {
                    "per_year": events.per_year, "s0": events.s0,
                    "v_kmh": [v / KMH for v in events.v], "share": list(events.share)},
                "speeds_from": dict(self.origin), "track": self.track,
                "wheel_polygon_um": None if self.wheel_polygon is None else {
                    str(n): a * 1e6 for n, a in self.wheel_polygon.items()}}


def _number(table: dict, key: str, where: str, low: float = 0.0, strict: bool = True) -> float:
    value = table.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
            or (value <= low if strict else value < low):
        bound = f"> {low:g}" if strict else f">= {low:g}"
        raise RouteError(f"route: {where}{key} must be a number {bound}, got {value!r}")
    return float(value)


def _numbers(table: dict, key: str, where: str) -> np.ndarray:
    values = table.get(key)
    if not isinstance(values, list) or not values or not all(
            isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)
            for x in values):
        raise RouteError(f"route: {where}{key} must be a list of numbers, got {values!r}")
    return np.asarray(values, dtype=float)


def _shares(values: np.ndarray, where: str) -> np.ndarray:
    if np.any(values < 0) or not values.sum() > 0:
        raise RouteError(f"route: {where}share must be >= 0 with a positive sum")
    return values / values.sum()


def _unknown(table: dict, allowed: set, where: str) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise RouteError(f"route: unknown entry {where}{unknown[0]} (allowed: "
                         f"{', '.join(sorted(allowed))})")


def histogram_seconds(edges_kmh: np.ndarray, share: np.ndarray, annual_distance: float
                      ) -> np.ndarray:
    """Running seconds a year per bin [s/year] of a histogram (edges [km/h], shares of the
    running time) at ``annual_distance`` [m/year]: the running time is the distance over the
    mean speed Σ share_b v_b (bin centres)."""
    centres = 0.5 * (edges_kmh[:-1] + edges_kmh[1:]) * KMH
    mean_speed = float(np.sum(share * centres))
    if not mean_speed > 0:
        raise RouteError("route: the histogram's mean speed is 0: no distance is run")
    total = annual_distance / mean_speed
    if total > SECONDS_PER_YEAR:
        raise RouteError(f"route: {annual_distance / 1e3:g} km a year at a mean "
                         f"{mean_speed / KMH:.3g} km/h takes {total / 3600:.0f} h, more than a "
                         "year")
    return share * total


def samples_histogram(t_s: np.ndarray, v_kmh: np.ndarray, bin_kmh: float
                      ) -> tuple[np.ndarray, np.ndarray, float]:
    """(edges [km/h], seconds per bin [s], distance [m]) of a sampled run: each interval counts
    its duration at the mean of its ends' speeds."""
    dt = np.diff(t_s)
    v_mid = 0.5 * (v_kmh[:-1] + v_kmh[1:])
    top = max(float(v_kmh.max()), bin_kmh)
    edges = np.arange(0.0, top + bin_kmh, bin_kmh)
    if edges[-1] <= v_kmh.max():
        edges = np.append(edges, edges[-1] + bin_kmh)
    seconds, _ = np.histogram(v_mid, bins=edges, weights=dt)
    return edges, seconds, float(np.sum(dt * v_mid * KMH))


def read_samples(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(t [s], v [km/h]) of a ``t_s,v_kmh`` CSV file (a header line)."""
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            rows = list(csv.reader(handle))
    except OSError as error:
        raise RouteError(f"route: cannot read {path}: {error.strerror}") from None
    if not rows or [c.strip() for c in rows[0]] != ["t_s", "v_kmh"]:
        raise RouteError(f"route: {path} must start with the header line t_s,v_kmh")
    try:
        data = np.array([[float(c) for c in row] for row in rows[1:] if row], dtype=float)
    except ValueError:
        raise RouteError(f"route: {path}: every line after the header is two numbers") from None
    if data.ndim != 2 or data.shape[1] != 2 or len(data) < 2 or not np.all(np.isfinite(data)):
        raise RouteError(f"route: {path}: give at least two lines of two finite numbers")
    t, v = data[:, 0], data[:, 1]
    if np.any(np.diff(t) <= 0):
        raise RouteError(f"route: {path}: t_s must increase")
    if np.any(v < 0):
        raise RouteError(f"route: {path}: v_kmh must be >= 0")
    return t, v


def route_from_dict(data: dict, base: Path | None = None) -> Route:
    """A :class:`Route` of a parsed route file (``base``: the folder a ``csv`` path is relative
    to)."""
    _unknown(data, TOP_KEYS, "")
    name, source = data.get("name", ""), data.get("source", "")
    if not isinstance(name, str) or not isinstance(source, str) or not source.strip():
        raise RouteError("route: give name and source (where the numbers come from) as text")
    annual = _number(data, "annual_distance_km", "") * 1e3
    speeds = data.get("speeds")
    if not isinstance(speeds, dict):
        raise RouteError("route: give a [speeds] table (edges_kmh and share, or csv)")
    _unknown(speeds, SPEED_KEYS, "speeds.")
    if "csv" in speeds:
        if "edges_kmh" in speeds or "share" in speeds:
            raise RouteError("route: [speeds] takes either csv or edges_kmh and share")
        path = Path(str(speeds["csv"]))
        if base is not None and not path.is_absolute():
            path = base / path
        bin_kmh = _number(speeds, "bin_kmh", "speeds.") if "bin_kmh" in speeds else 5.0
        edges_kmh, seconds, distance = samples_histogram(*read_samples(path), bin_kmh)
        if not distance > 0:
            raise RouteError(f"route: {path}: the run covers no distance")
        seconds = seconds * annual / distance
        if seconds.sum() > SECONDS_PER_YEAR:
            raise RouteError("route: the annual distance at the run's speeds takes more than a "
                             "year")
        origin = {"csv": str(speeds["csv"]), "bin_kmh": bin_kmh,
                  "run_distance_km": distance / 1e3, "runs_per_year": annual / distance}
    else:
        edges_kmh = _numbers(speeds, "edges_kmh", "speeds.")
        share = _numbers(speeds, "share", "speeds.")
        if len(edges_kmh) < 2 or edges_kmh[0] < 0 or np.any(np.diff(edges_kmh) <= 0):
            raise RouteError("route: speeds.edges_kmh must be >= 0 and increasing, at least two")
        if len(share) != len(edges_kmh) - 1:
            raise RouteError(f"route: speeds.share needs {len(edges_kmh) - 1} values (one per "
                             f"bin), got {len(share)}")
        seconds = histogram_seconds(edges_kmh, _shares(share, "speeds."), annual)
        origin = {"histogram": True}
    events = None
    if "short_circuit" in data:
        table = data["short_circuit"]
        if not isinstance(table, dict):
            raise RouteError("route: [short_circuit] must be a table")
        _unknown(table, EVENT_KEYS, "short_circuit.")
        v = _numbers(table, "v_kmh", "short_circuit.")
        share = _numbers(table, "share", "short_circuit.") if "share" in table else \
            np.ones(len(v))
        if len(share) != len(v) or np.any(v <= 0):
            raise RouteError("route: short_circuit.v_kmh (> 0) and share need the same length")
        s0 = _number(table, "s0", "short_circuit.")
        events = ShortCircuitEvents(_number(table, "per_year", "short_circuit.", strict=False),
                                    s0, tuple(float(x) * KMH for x in v),
                                    tuple(float(x) for x in _shares(share, "short_circuit.")))
    track = polygon = None
    if "track" in data:
        table = data["track"]
        if not isinstance(table, dict) or set(table) != {"spectrum"}:
            raise RouteError("route: [track] takes spectrum = the name of a track spectrum")
        from model.analysis.track_spectrum import TrackSpectrumError, track_spectrum

        try:
            track = track_spectrum(str(table["spectrum"])).name
        except TrackSpectrumError as error:
            raise RouteError(f"route: track: {error}") from None
    if "wheel_polygon" in data:
        table = data["wheel_polygon"]
        if not isinstance(table, dict) or set(table) != {"amplitudes_um"}:
            raise RouteError('route: [wheel_polygon] takes amplitudes_um = "order=µm,…"')
        from model.analysis.wheel_excitation import WheelExcitationError, parse_polygon

        try:
            polygon = parse_polygon(str(table["amplitudes_um"]))
        except WheelExcitationError as error:
            raise RouteError(f"route: wheel_polygon: {error}") from None
    return Route(name, source, annual, np.asarray(edges_kmh, dtype=float) * KMH,
                 np.asarray(seconds, dtype=float), events, origin, track, polygon)


def load_route(path) -> Route:
    """The route of a TOML file (module docstring); :class:`RouteError` for a bad one."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise RouteError(f"route: cannot read {path}: {error.strerror}") from None
    except tomllib.TOMLDecodeError as error:
        raise RouteError(f"route: {path} is not valid TOML: {error}") from None
    return route_from_dict(data, path.parent)
