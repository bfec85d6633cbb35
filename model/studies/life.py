"""How long the drive's shaft sections last over a route: Miner's damage sum per section from a
list of load sources, the life in kilometres and years, and where the damage comes from.

    route = load_route("assets/routes/mixed_passenger_200.toml")
    result = route_life(parameters, route, default_sources())   # LifeOptions() by default
    result.least_life.name, result.least_life.life_km
    result.as_dict()                                # the JSON of ``bogie life --json``

**Sections**: the torsional fatigue sections of the assessment
(:func:`model.analysis.assessment.alternating_components`: axle, hollow shaft and driving shaft
of both drives), each with its DIN 743 fatigue limit τ_WK (:mod:`model.analysis.fatigue`).

**S–N curve per section** (shear stress amplitudes): through the knee (N_D, τ_WK) with the
finite-life slope k above it, ``N(τ) = N_D (τ_WK/τ)^k``: N_D = 10⁶ and k = 8, the values the FKM
guideline (Rechnerischer Festigkeitsnachweis für Maschinenbauteile) gives for shear stresses of
steel components and DIN 743's finite-life assessment takes over from it (as handbooks quote
them; not checked against the texts here).  Beyond the knee (``LifeOptions.beyond_knee``):
``"haibach"`` (default) continues with Haibach's slope 2k − 1 = 15 (FKM's "modified Miner"), so
that small cycles do damage once the large ones have started a crack; ``"elementary"``
continues with k (Miner's elementary form, the most conservative); ``"limit"`` does no damage
below τ_WK (Miner's original rule, the least conservative).

**Mean stress** as the section's check does (DIN 743-1, case 1): a cycle of amplitude τ_a about
the mean τ_m counts with the equivalent amplitude ``τ_a · τ_WK / τ_ADK(τ_m)``, the amplitude at
zero mean that uses the same share of the permissible amplitude.  Stress amplitudes of the result
are these equivalent amplitudes [Pa].

**Load sources** (each a :class:`LoadSource`: a name and a function of the :class:`LifeContext`
that gives every section its :class:`Contribution` s, damage per year; the four of
:mod:`model.studies.life_sources`; a source is one of three shapes, each with its function):

* steady oscillations at known frequencies over speed (:func:`steady_contributions`): the
  converters' ripple and the wheels' polygons (per order, its amplitude and frequency at each
  speed);
* random stationary responses over speed by their spectral moments (:func:`spectral_contributions`,
  Dirlik's damage, :mod:`model.analysis.spectral_fatigue`): the track;
* events a year with a time history each (:func:`event_contributions`, rainflow cycles): the
  short circuit.

A route's speed bin (:mod:`model.studies.route`) is a uniform distribution of speed over the bin:
a steady or random source is evaluated at speeds across the bin (for the steady ones densely
around every resonance, whose peak is far narrower than a bin) and averaged with the
trapezoidal rule.  Per bin and order a steady contribution has ``cycles`` =
the time in the bin × the order's mean frequency over the bin (f × t for a frequency linear in
speed) and ``damage`` = time × the mean of f/N(τ_eq); its ``stress_amplitude`` is the equivalent
constant amplitude that does that damage in those cycles, N⁻¹(cycles/damage), so that every
counted contribution obeys damage = cycles / N(stress_amplitude).  With ``beyond_knee =
"limit"`` only the cycles that do damage are counted.  The sources over speed count from 10
km/h (the ripple case's lowest speed); the time below does no damage from them.

**Life**: a section's damage per year D is the sum of its contributions; its life is 1/D years
and annual distance / D kilometres (inf where nothing does damage).  Units: SI (Pa, s, m/s
inside; km and km/h where a name says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from model.analysis.assessment import alternating_components, fatigue_data
from model.analysis.fatigue import TorsionalFatigue, permissible_amplitude
from model.analysis.spectral_fatigue import (
    SNCurve,
    SpectralMoments,
    dirlik_damage_rate,
    dirlik_exceedance,
    haibach_slope,
)
from model.mechanics.operating_point import KMH
from model.mechanics.parameters import Parameters
from model.studies.route import Route

KNEE_CYCLES = 1e6  # N_D of the FKM guideline's S–N curves for steel [-]
SHEAR_SLOPE = 8.0  # k of its finite-life line in shear [-]
BEYOND_KNEE = ("haibach", "elementary", "limit")
SN_SOURCE = ("FKM guideline (Rechnerischer Festigkeitsnachweis für Maschinenbauteile) for shear "
             "stresses of steel components, as DIN 743's finite-life assessment takes them: "
             "N_D = 1e6, k = 8; the fatigue limit tau_WK of DIN 743 (model.analysis.fatigue)")


class LifeError(ValueError):
    """Bad input for the life computation (one-line message)."""


@dataclass(frozen=True)
class LifeOptions:
    """The S–N curves' shape and what the sources take (SI; module docstring)."""

    knee_cycles: float = KNEE_CYCLES  # N_D [-]
    slope: float = SHEAR_SLOPE  # k above the knee [-]
    beyond_knee: str = "haibach"  # one of BEYOND_KNEE
    s0: tuple[float, ...] = (0.002, 0.005)  # ripple: creepages, as the assessment's [-]
    ripple: dict | None = None  # ripple: {Order: amplitude [N m]} (None: the set's)
    short_circuit_t_end: float = 2.0  # the short circuit's history [s]
    short_circuit_fs: float = 10_000.0  # its sampling rate [Hz]

    def __post_init__(self):
        if self.beyond_knee not in BEYOND_KNEE:
            raise LifeError(f"beyond the knee: one of {', '.join(BEYOND_KNEE)}, got "
                            f"{self.beyond_knee!r}")
        for label, value in (("knee cycles", self.knee_cycles), ("slope", self.slope)):
            if not (math.isfinite(value) and value > 0):
                raise LifeError(f"S-N curve: the {label} must be > 0, got {value!r}")

    def curve(self, fatigue_limit: float) -> SNCurve:
        """The S–N curve through (N_D, ``fatigue_limit`` [Pa])."""
        beyond = {"haibach": haibach_slope(self.slope), "elementary": self.slope,
                  "limit": None}[self.beyond_knee]
        return SNCurve(fatigue_limit, self.knee_cycles, self.slope, beyond)


@dataclass(frozen=True)
class Section:
    """A shaft section under torsional fatigue: its DIN 743 data and its S–N curve."""

    name: str  # e.g. "ID1 driving shaft"
    output: str  # its section torque
    fatigue: TorsionalFatigue
    sn: SNCurve

    def equivalent_amplitude(self, amplitude, mean) -> np.ndarray:
        """τ_eq = τ_a τ_WK / τ_ADK(τ_m) [Pa] of torque amplitudes ``amplitude`` about the means
        ``mean`` [N m] (inf where the mean leaves no permissible amplitude)."""
        W_t = self.fatigue.section_modulus
        tau_a = np.abs(np.asarray(amplitude, dtype=float)) / W_t
        means = np.broadcast_to(np.asarray(mean, dtype=float) / W_t, tau_a.shape)
        permissible = np.array([permissible_amplitude(self.fatigue, m) for m in means.ravel()]
                               ).reshape(tau_a.shape)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(tau_a == 0, 0.0, tau_a * self.fatigue.tau_WK / permissible)


def sections_of(parameters: Parameters, options: LifeOptions) -> list[Section]:
    """The torsional fatigue sections of both drives with their S–N curves."""
    sections = []
    for component in alternating_components(parameters):
        if component.kind == "torsional_fatigue":
            data = fatigue_data(component)
            sections.append(Section(component.name, component.output, data,
                                    options.curve(data.tau_WK)))
    return sections


@dataclass(frozen=True)
class Contribution:
    """One source's share of a section's damage a year."""

    source: str  # "ripple", "short_circuit", …
    v_kmh: float | None  # the speed bin's centre [km/h]; None for events
    damage: float  # Miner's damage a year [1/year]
    cycles: float | None = None  # counted cycles a year [1/year] (a random source's: its peaks)
    stress_amplitude: float | None = None  # the equivalent amplitude τ_eq [Pa] of those cycles
    detail: dict = field(default_factory=dict)  # e.g. order and f_hz, events a year

    def as_dict(self) -> dict:
        out = {"source": self.source, "v_kmh": self.v_kmh, "damage": self.damage}
        if self.cycles is not None:
            out.update(cycles=self.cycles, stress_amplitude=self.stress_amplitude)
        return {**out, **self.detail}


def counted(source: str, v_kmh: float | None, cycles: float, damage: float, curve: SNCurve,
            detail: dict) -> Contribution | None:
    """A contribution of ``cycles`` counted cycles doing ``damage`` (a year), its amplitude the
    equivalent N⁻¹(cycles/damage); None without cycles or damage."""
    if not (cycles > 0 and damage > 0):
        return None
    if not math.isfinite(damage):
        raise LifeError(f"{source}: a steady mean torque alone reaches a section's yield limit "
                        "(no permissible amplitude is left): no fatigue life to compute")
    return Contribution(source, v_kmh, float(damage), float(cycles),
                        curve.amplitude_at(cycles / damage), detail)


@dataclass(frozen=True)
class LifeContext:
    """What a source needs: the set, the route, the sections and the options."""

    parameters: Parameters
    route: Route
    sections: list[Section]
    options: LifeOptions
    notes: list[str] = field(default_factory=list)  # what a source left out, and why


class LoadSource(Protocol):
    """A source of damage: ``name`` and ``contributions(context)`` -> {section output: list of
    :class:`Contribution`}, damage a year."""

    name: str

    def contributions(self, context: LifeContext) -> dict[str, list[Contribution]]: ...


# --- the three shapes of a source ------------------------------------------------------------


def bin_weights(v: np.ndarray, low: float, high: float) -> tuple[np.ndarray, np.ndarray]:
    """(indices of the speeds ``v`` [m/s] in [low, high], their trapezoidal weights summing to 1):
    the mean over a uniform distribution of speed on the interval."""
    inside = np.flatnonzero((v >= low * (1 - 1e-12)) & (v <= high * (1 + 1e-12)))
    if len(inside) < 2:
        raise LifeError(f"no speeds computed in {low / KMH:g}…{high / KMH:g} km/h")
    x = v[inside]
    w = np.zeros(len(x))
    dx = np.diff(x)
    w[:-1] += dx / 2
    w[1:] += dx / 2
    return inside, w / (x[-1] - x[0])


def steady_contributions(source: str, section: Section, route: Route, v: np.ndarray,
                         mean: np.ndarray, amplitude: np.ndarray, frequency_hz: np.ndarray,
                         labels: list[str], floor: float = 0.0) -> list[Contribution]:
    """Per route bin and order: the cycles and damage a year of steady oscillations of torque
    ``amplitude`` (orders, V) [N m] at ``frequency_hz`` (orders, V) [Hz; nan: none] about
    ``mean`` (V,) [N m] at the speeds ``v`` (V,) [m/s], which hold every bin's edges (from
    ``floor`` [m/s] up: a bin's time below it does no damage) — module docstring."""
    out = []
    tau = section.equivalent_amplitude(amplitude, mean[None, :])
    limited = section.sn.slope_beyond_knee is None
    for low, high, seconds in zip(route.edges[:-1], route.edges[1:], route.seconds_per_year,
                                  strict=True):
        start = max(low, floor)
        if seconds <= 0 or high <= start:
            continue
        time = seconds * (high - start) / (high - low)
        idx, w = bin_weights(v, start, high)
        centre = 0.5 * (low + high)
        for k, label in enumerate(labels):
            f = np.nan_to_num(frequency_hz[k, idx], nan=0.0)
            N = section.sn.cycles_to_failure(tau[k, idx])
            damaging = np.isfinite(N) if limited else np.ones(len(idx), dtype=bool)
            cycles = time * float(np.sum(w * f * damaging))
            with np.errstate(divide="ignore"):
                damage = time * float(np.sum(w * f / N))
            f_centre = float(np.interp(centre, v, np.nan_to_num(frequency_hz[k], nan=0.0)))
            c = counted(source, centre / KMH, cycles, damage, section.sn,
                        {"order": label, "f_hz": f_centre, "seconds": time})
            if c is not None:
                out.append(c)
    return out


def spectral_contributions(source: str, section: Section, route: Route, v: np.ndarray,
                           at_speed, floor: float = 0.0) -> list[Contribution]:
    """Per route bin: the damage a year of a stationary Gaussian torque whose spectral moments
    and mean at speed ``v[i]`` [m/s] are ``at_speed(i)`` -> (:class:`SpectralMoments` of the
    torque [N² m², …], mean [N m]), or None where there is no stationary response (a bin holding
    such a speed is left out): Dirlik's damage rate of the stress, its moments scaled by the
    square of the mean-stress correction's τ_eq per N m, averaged over the bin (trapezoidal rule
    over the speeds ``v`` in it, which hold its edges); ``cycles`` the peaks (one rainflow cycle
    per peak; below a fatigue limit without a slope beyond it, the peaks whose amplitude reaches
    the limit), the amplitude the equivalent one."""
    out = []
    for low, high, seconds in zip(route.edges[:-1], route.edges[1:], route.seconds_per_year,
                                  strict=True):
        start = max(low, floor)
        if seconds <= 0 or high <= start:
            continue
        time = seconds * (high - start) / (high - low)
        idx, w = bin_weights(v, start, high)
        points = [at_speed(int(i)) for i in idx]
        if any(p is None for p in points):
            continue
        damage = cycles = 0.0
        for (moments, mean), weight in zip(points, w, strict=True):
            if not (moments.m0 > 0 and moments.m2 > 0 and moments.m4 > 0):
                continue  # no response at this speed
            per_torque = float(section.equivalent_amplitude(1.0, mean))  # τ_eq per N m [1/m³]
            stress = SpectralMoments(*(m * per_torque**2 for m in (
                moments.m0, moments.m1, moments.m2, moments.m4)))
            damage += time * weight * dirlik_damage_rate(stress, section.sn)
            share = 1.0 if section.sn.slope_beyond_knee is not None else dirlik_exceedance(
                section.sn.fatigue_limit, stress)  # only the damaging cycles are counted
            cycles += time * weight * moments.peak_rate * share
        c = counted(source, 0.5 * (low + high) / KMH, cycles, damage, section.sn,
                    {"seconds": time, "method": "Dirlik"})
        if c is not None:
            out.append(c)
    return out


AMPLITUDE_CLASSES_PER_OCTAVE = 4  # classes of an event's counted amplitudes


def event_contributions(source: str, section: Section, histories) -> list[Contribution]:
    """The rainflow cycles of events: ``histories`` (torque history [N m], events a year) each;
    every cycle's equivalent amplitude with its own mean; the cycles grouped into classes of a
    quarter octave of amplitude (a contribution each, its amplitude the class's equivalent)."""
    from model.analysis.load_spectrum import rainflow_cycles

    amplitudes, counts = [], []
    for history, per_year in histories:
        cycles = rainflow_cycles(history)
        if len(cycles) == 0 or per_year <= 0:
            continue
        amplitudes.append(section.equivalent_amplitude(cycles[:, 0] / 2, cycles[:, 1]))
        counts.append(cycles[:, 2] * per_year)
    if not amplitudes:
        return []
    tau, n = np.concatenate(amplitudes), np.concatenate(counts)
    N = section.sn.cycles_to_failure(tau)
    keep = np.isfinite(N) & (tau > 0)
    tau, n, N = tau[keep], n[keep], N[keep]
    classes = np.floor(AMPLITUDE_CLASSES_PER_OCTAVE * np.log2(tau / section.sn.fatigue_limit))
    out = []
    for c in np.unique(classes)[::-1]:
        members = classes == c
        contribution = counted(source, None, float(n[members].sum()),
                               float(np.sum(n[members] / N[members])), section.sn,
                               {"class_tau_range": [
                                   float(section.sn.fatigue_limit * 2 ** (c / 4)),
                                   float(section.sn.fatigue_limit * 2 ** ((c + 1) / 4))]})
        if contribution is not None:
            out.append(contribution)
    return out


# --- the result ------------------------------------------------------------------------------


@dataclass(frozen=True)
class SectionLife:
    """A section's damage a year, its life and the contributions."""

    section: Section
    damage: float  # Miner's sum a year [1/year]
    life_years: float  # [year] (inf: no damage)
    life_km: float  # [km] (inf: no damage)
    contributions: list[Contribution]

    def shares(self) -> dict[str, float]:
        """Each source's share of the damage [-]."""
        out: dict[str, float] = {}
        for c in self.contributions:
            out[c.source] = out.get(c.source, 0.0) + (c.damage / self.damage if self.damage
                                                       else 0.0)
        return out

    def as_dict(self) -> dict:
        return {"name": self.section.name, "output": self.section.output,
                "damage": self.damage, "life_km": _finite(self.life_km),
                "life_years": _finite(self.life_years),
                "fatigue_limit_tau_WK": self.section.fatigue.tau_WK,
                "sn": self.section.sn.as_dict(), "source_shares": self.shares(),
                "contributions": [c.as_dict() for c in self.contributions]}


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


@dataclass(frozen=True)
class LifeResult:
    route: Route
    options: LifeOptions
    sections: list[SectionLife]
    sources: tuple[str, ...]
    notes: tuple[str, ...] = ()  # what a source left out, and why

    @property
    def least_life(self) -> SectionLife:
        return min(self.sections, key=lambda s: s.life_km)

    def as_dict(self) -> dict:
        return {"route": self.route.as_dict(), "damage_basis": "Miner's sum per year of the route",
                "sources": list(self.sources), "notes": list(self.notes),
                "sn_curves": {"source": SN_SOURCE, "beyond_knee": self.options.beyond_knee,
                              "mean_stress": "tau_eq = tau_a tau_WK / tau_ADK(tau_m), DIN 743-1 "
                                             "case 1"},
                "least_life": self.least_life.section.name if self.least_life.damage > 0
                else None,
                "sections": [s.as_dict() for s in self.sections]}


def route_life(parameters: Parameters, route: Route, sources,
               options: LifeOptions | None = None) -> LifeResult:
    """Every section's damage a year over ``route`` from ``sources`` (:class:`LoadSource` s, e.g.
    :func:`model.studies.life_sources.default_sources`: the ripple, the wheels' polygon, the
    track, the short circuit; each takes what the route gives and notes what it does not), its
    life in years and kilometres (module docstring)."""
    options = LifeOptions() if options is None else options
    context = LifeContext(parameters, route, sections_of(parameters, options), options)
    by_source = [source.contributions(context) for source in sources]
    lives = []
    for section in context.sections:
        contributions = [c for found in by_source for c in found.get(section.output, [])]
        damage = math.fsum(c.damage for c in contributions)
        years = 1.0 / damage if damage > 0 else math.inf
        lives.append(SectionLife(section, damage, years, years * route.annual_distance / 1e3,
                                 contributions))
    return LifeResult(route, options, lives, tuple(s.name for s in sources),
                      tuple(context.notes))

