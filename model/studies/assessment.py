"""The load cases of the assessment and the checks under them: every press fit, shaft section and
coupling of both drives (:func:`model.analysis.assessment.drive_components`) in three cases.

    result = assess(parameters)                   # AssessmentOptions() by default
    result.governing.component, result.governing.safety_factor
    result.as_dict()                              # the JSON of ``bogie assess --json``

**Load cases** (each states its horizon):

* ``short_circuit`` — ID1's motor short-circuits: the worst case over *every* fault instant in
  closed form (exactly ``bogie envelope --phase all``) over a grid of speeds and stable creepages
  (default s0 = 0.002, 0.005 at 80, 120, 200 km/h), linear creep.  After the fault the vehicle
  decelerates under the lost torque while ID2 keeps its own (its slope measures the rotor against
  the vehicle's speed, eq. 6): the loads settle to the static response of that uniform
  deceleration.  The horizon is the time after which the quasi-static part of every checked
  output stays within 1 % of that final value (:func:`settling_horizon`), at least 2 s.  Where
  the linear creep force at a wheel leaves the adhesion range (|T| > μ_max N0) anywhere on the
  grid, each check of the case says so beside its load: a real wheelset would slip there, and
  the linear load is an upper estimate.
* ``unstable_adhesion`` — the same short circuit at a creepage beyond the adhesion maximum
  (default s0 = 0.014, 120 km/h: the study's unstable case), with the creep forces of the
  nonlinear law and the anti-slip protection of ID2 at its default reaction time
  (:class:`model.analysis.nonlinear.AntiSlip`); the history's extremes over 2 s.
* ``starting`` — steady traction at a starting speed (default 5 km/h) with what the drive can
  deliver: the smaller of the motors' torque at the locomotive's starting traction force
  (``starting_traction_force`` shared by its ``driven_wheelsets``) and the adhesion limit
  2 μ_max N0 r0 / p; the static loads (no horizon), and the check says which bound governs.

**Checks**: the load of a component in a case is the largest |value| of its output over the
case's histories; safety factor = capacity / load (:mod:`model.analysis.assessment`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from model.analysis.assessment import Check, Component, drive_components, governing, verify
from model.analysis.load_peaks import GROWTH_RATE
from model.analysis.nonlinear import AntiSlip
from model.analysis.response import ResponseError, ShortCircuit
from model.mechanics.operating_point import KMH, OperatingPoint, creep_law
from model.mechanics.parameters import Parameters

LOAD_CASES = ("short_circuit", "unstable_adhesion", "starting")
DEFAULT_S0 = (0.002, 0.005)  # stable creepages of the short-circuit grid [-]
DEFAULT_V_KMH = (80.0, 120.0, 200.0)  # speeds of the short-circuit grid [km/h]
MIN_HORIZON = 2.0  # [s]: the study's window
SETTLED = 0.01  # the quasi-static part within 1 % of its final change
MAX_GRID = 60  # (s0, v) points of the short-circuit grid


class AssessmentError(ResponseError):
    """Bad input for the assessment (one-line message)."""


@dataclass(frozen=True)
class AssessmentOptions:
    """What the load cases take (SI units; defaults in the module docstring)."""

    s0: tuple[float, ...] = DEFAULT_S0  # short_circuit: creepages [-]
    v: tuple[float, ...] = tuple(x * KMH for x in DEFAULT_V_KMH)  # short_circuit: speeds [m/s]
    N0: float | None = None  # wheel force [N] (None: the set's)
    b_M: float | None = None  # motor slope [N m s/rad] (None: the set's)
    excitation: ShortCircuit = field(default_factory=ShortCircuit)  # M0, f, D (Δt: all)
    t_end: float | None = None  # short_circuit horizon [s] (None: settling_horizon)
    fs: float = 10_000.0  # sampling rate of every history [Hz]
    unstable_s0: float = 0.014  # unstable_adhesion: creepage [-]
    unstable_v: float = 120.0 * KMH  # unstable_adhesion: speed [m/s]
    unstable_t_end: float = 2.0  # unstable_adhesion: horizon [s]
    anti_slip: AntiSlip | None = None  # unstable_adhesion: ID2's protection (None: defaults)
    starting_v: float = 5.0 * KMH  # starting: speed [m/s]

    def __post_init__(self) -> None:
        for label, values in (("--s0", self.s0), ("--v", self.v)):
            if not values or len(set(values)) != len(values):
                raise AssessmentError(f"{label}: give distinct values")
        if len(self.s0) * len(self.v) > MAX_GRID:
            raise AssessmentError(f"--s0 × --v = {len(self.s0) * len(self.v)} points, at most "
                                  f"{MAX_GRID}")


@dataclass(frozen=True)
class CaseLoad:
    """The largest |value| of one output in one load case, and where it occurs."""

    value: float  # signed [N m]
    time: float  # [s] (nan: steady)
    scenario: dict  # s0, v_kmh, phase_s, …
    note: str = ""  # what qualifies the load (shown beside it in the check)


@dataclass(frozen=True)
class LoadCase:
    """A load case with its loads (output -> :class:`CaseLoad`)."""

    name: str
    description: str
    horizon: float | None  # [s] (None: steady)
    loads: dict[str, CaseLoad]
    scenario: dict  # what defines it (operating points, creep, protection)


@dataclass(frozen=True)
class Assessment:
    """Every check in every load case, and the governing one (plain data)."""

    cases: list[LoadCase]
    components: list[Component]
    checks: list[Check]
    governing: Check

    def as_dict(self) -> dict:
        g = self.governing
        return {"load_cases": [{"name": c.name, "description": c.description,
                                "horizon_s": c.horizon, "scenario": c.scenario}
                               for c in self.cases],
                "checks": [c.as_dict() for c in self.checks],
                "governing": {"component": g.component, "load_case": g.load_case,
                              "safety_factor": g.safety_factor, "required": g.required,
                              "ok": g.ok, "kind": g.kind, "output": g.output},
                "all_ok": all(c.ok for c in self.checks)}


def _operating_point(parameters: Parameters, s0: float, v: float, options: AssessmentOptions
                     ) -> OperatingPoint:
    N0 = parameters["wheel_force"] if options.N0 is None else options.N0
    b_M = parameters["motor_slope"] if options.b_M is None else options.b_M
    return OperatingPoint(s0, v, N0, b_M)


def settling_horizon(model, ops: list[OperatingPoint], outputs: list[str]) -> float:
    """The time [s] after which the quasi-static part (:func:`model.analysis.response.
    quasi_static_step`: the static response to the lost motor torque, the vehicle decelerating
    uniformly, and the slow creep-damped modes on their way to it) of every output at every
    operating point stays within 1 % of its final value, rounded up to a whole second, at least
    2 s and at most 60 s (the response's longest horizon; a point where it cannot be separated
    from the oscillation is cut there)."""
    from model.analysis.eigen import bogie_system
    from model.analysis.response import (
        MAX_T_END,
        QuasiStaticUnavailable,
        output_rows,
        quasi_static_step,
    )
    from model.mechanics.operating_point import motor_torque

    dt = 0.01
    n = round(MAX_T_END / dt) + 1
    t = np.arange(n) * dt
    latest = 0.0
    for op in ops:
        _, C, _, _ = output_rows(model, op, outputs)
        try:
            part = quasi_static_step(bogie_system(model, op), C,
                                     motor_torque(model.parameters, op), n, dt)
        except QuasiStaticUnavailable:
            return MAX_T_END
        trend = part.y
        final = np.where(np.isfinite(part.final), part.final, trend[-1])
        change = np.maximum(np.abs(trend).max(axis=0), np.abs(final))
        away = np.abs(trend - final) > SETTLED * np.maximum(change, 1e-300)
        rows = np.flatnonzero(away.any(axis=1))
        if len(rows):
            latest = max(latest, float(t[min(rows[-1] + 1, n - 1)]))
    return float(min(MAX_T_END, max(MIN_HORIZON, math.ceil(latest))))


def _largest(max_value: float, min_value: float, max_at: dict, min_at: dict) -> CaseLoad:
    if abs(max_value) >= abs(min_value):
        value, at = max_value, max_at
    else:
        value, at = min_value, min_at
    at = dict(at)
    time = at.pop("time_s", math.nan)
    return CaseLoad(float(value), float(time), at)


def short_circuit_points(parameters: Parameters, options: AssessmentOptions
                         ) -> list[OperatingPoint]:
    """The operating points of the short-circuit case's grid, each checked stable (else
    :class:`AssessmentError` naming the first that is not)."""
    from model.analysis.eigen import bogie_system
    from model.studies.maps import cached_model

    model = cached_model(parameters)
    ops = [_operating_point(parameters, s0, v, options) for s0 in options.s0 for v in options.v]
    for op in ops:
        growth = float(np.max(bogie_system(model, op).eigenvalues().real))
        if growth > GROWTH_RATE:
            raise AssessmentError(
                f"--s0 {op.s0:g} at --v {op.v_kmh:g} km/h is not stable (growth rate "
                f"{growth:.3g} 1/s): the short-circuit case takes stable creepages; beyond the "
                "adhesion maximum is the unstable_adhesion case")
    return ops


def short_circuit_case(parameters: Parameters, outputs: list[str], options: AssessmentOptions,
                       map_unordered=None, progress=None) -> LoadCase:
    """The short-circuit case: ``bogie envelope --phase all`` over the options' grid, every grid
    point stable (else :class:`AssessmentError`); its points on the study engine's
    ``map_unordered`` (default: in this process), ``progress(finished, total, elapsed [s])``
    after each (:func:`model.studies.envelope.run_envelope`)."""
    from model.studies.envelope import EnvelopeStudy, resolve_outputs, run_envelope
    from model.studies.maps import cached_model

    model = cached_model(parameters)
    ops = short_circuit_points(parameters, options)
    horizon = options.t_end if options.t_end is not None else settling_horizon(model, ops,
                                                                               outputs)
    contacts = [f"{rim}.creep_force" for rim in model.rims]
    names, units = resolve_outputs(model, ops[0], [*outputs, *contacts])
    e = options.excitation
    study = EnvelopeStudy(s0=options.s0, v=options.v, N0=(ops[0].N0,), b_M=(ops[0].b_M,),
                          outputs=names, units=units, M0=(e.M0,), f=(e.f,), D=(e.D,),
                          fault="all", t_end=horizon, fs=options.fs)
    result = run_envelope(study, parameters, map_unordered, progress)
    envelopes = {o.name: o for o in result.outputs}
    note = beyond_adhesion_note(parameters, ops[0].N0, [envelopes[c] for c in contacts])
    loads = {}
    for name in outputs:
        o = envelopes[name]
        load = _largest(o.max, o.min, o.max_at, o.min_at)
        loads[name] = CaseLoad(load.value, load.time, load.scenario, note)
    return LoadCase(
        "short_circuit",
        "short circuit of ID1's motor, worst case over every fault instant (closed form, linear "
        f"creep, as bogie envelope --phase all) over s0 = {', '.join(f'{x:g}' for x in options.s0)}"
        f" and v = {', '.join(f'{x / KMH:g}' for x in options.v)} km/h; the horizon covers the "
        "settling to the static response of the vehicle's deceleration",
        horizon, loads,
        {"s0": list(options.s0), "v_kmh": [x / KMH for x in options.v], "N0": ops[0].N0,
         "b_M": ops[0].b_M, "M0": e.M0, "f": e.f, "D": e.D, "fault_instants": "all",
         "creep": "linear", "fs": options.fs})


def beyond_adhesion_note(parameters: Parameters, N0: float, contacts) -> str:
    """What to say beside a linear short-circuit load when a wheel's linear creep force left the
    adhesion range somewhere on the grid (``contacts``: the creep forces' envelopes, whose
    extremes carry their speed), "" when none did."""
    worst = []
    for envelope in contacts:
        for value, at in ((envelope.max, envelope.max_at), (envelope.min, envelope.min_at)):
            v = at["v_kmh"] * KMH
            limit = creep_law(parameters, N0).maximum(v)[1] * N0
            if abs(value) > limit:
                worst.append((abs(value) / limit, envelope.name, value, limit, at))
    if not worst:
        return ""
    ratio, name, value, limit, at = max(worst, key=lambda w: w[0])
    wheel = name.removesuffix(".creep_force")
    return (f"linear creep beyond the adhesion limit: {wheel}'s creep force reaches "
            f"{value / 1e3:.1f} kN, {ratio:.2f} x μ_max N0 = {limit / 1e3:.1f} kN (s0 = "
            f"{at['s0']:g}, {at['v_kmh']:g} km/h): a real wheelset slips there, the linear load "
            "is an upper estimate")


def unstable_adhesion_case(parameters: Parameters, outputs: list[str],
                           options: AssessmentOptions) -> LoadCase:
    """The unstable case: nonlinear creep and ID2's anti-slip protection at its reaction time."""
    from model.analysis.fault_instant import continuity_phases
    from model.analysis.nonlinear import nonlinear_response
    from model.mechanics.operating_point import motor_torque
    from model.studies.maps import cached_model

    model = cached_model(parameters)
    op = _operating_point(parameters, options.unstable_s0, options.unstable_v, options)
    protection = AntiSlip() if options.anti_slip is None else options.anti_slip
    e = options.excitation
    excitation = ShortCircuit(M0=e.M0, f=e.f, D=e.D)  # the continuity root (physics first)
    r = nonlinear_response(model, op, excitation, options.unstable_t_end, options.fs,
                           creep="nonlinear", anti_slip=protection, outputs=outputs)
    phase = continuity_phases(motor_torque(parameters, op), e.M0, e.f)[0]
    where = {"s0": op.s0, "v_kmh": op.v_kmh, "phase_s": phase, "creep": "nonlinear",
             "anti_slip_delay_s": protection.delay}
    loads = {}
    for name in outputs:
        y = r.outputs[name]
        k = int(np.argmax(np.abs(y)))
        loads[name] = CaseLoad(float(y[k]), float(r.t[k]), dict(where))
    return LoadCase(
        "unstable_adhesion",
        f"short circuit at s0 = {op.s0:g}, beyond the adhesion maximum, {op.v_kmh:g} km/h: "
        "nonlinear creep forces (Polach's law), ID2's anti-slip protection reacting after "
        f"{protection.delay:g} s; the history's extremes",
        options.unstable_t_end, loads,
        {"s0": op.s0, "v_kmh": op.v_kmh, "N0": op.N0, "b_M": op.b_M, "M0": e.M0, "f": e.f,
         "D": e.D, "fault_instant_s": phase, "creep": "nonlinear", "anti_slip": "on",
         "anti_slip_delay_s": protection.delay, "fs": options.fs})


def starting_case(parameters: Parameters, outputs: list[str], options: AssessmentOptions
                  ) -> LoadCase:
    """Steady traction at the starting speed with what the drive can deliver: the motors' torque
    at the starting traction force F (``starting_traction_force`` / ``driven_wheelsets`` per
    wheelset, F r0 / (n p) per motor) or at the adhesion limit 2 μ_max N0 r0 / p, whichever is
    smaller; the static loads at the creepage where μ(s0) gives that torque (on the rising
    branch of the creep law)."""
    from scipy.optimize import brentq

    from model.mechanics.outputs import output_matrices, static_deflection
    from model.studies.maps import cached_model

    model = cached_model(parameters)
    N0 = parameters["wheel_force"] if options.N0 is None else options.N0
    v = options.starting_v
    law = creep_law(parameters, N0)
    s_max, mu_max = law.maximum(v)
    r0, n = parameters["wheel_radius"], parameters["driven_wheelsets"]
    force = parameters["starting_traction_force"]
    mu_motors = force / (n * 2 * N0)  # per wheel: F / (2 n N0)
    if mu_motors < mu_max:
        s0 = brentq(lambda s: float(law.mu(s, v)) - mu_motors, s_max * 1e-9, s_max, xtol=1e-15,
                    rtol=1e-14)
        bound = "motors"
        words = (f"the motors' torque at the starting traction force {force / 1e3:g} kN over "
                 f"{n:g} driven wheelsets ({force * r0 / n / 1e3:.1f} kN m per wheelset, below "
                 f"the adhesion limit {2 * mu_max * N0 * r0 / 1e3:.1f} kN m)")
    else:
        s0, bound = s_max, "adhesion"
        words = (f"the adhesion limit 2 μ_max N0 r0 (μ_max = {mu_max:.3g}, "
                 f"{2 * mu_max * N0 * r0 / 1e3:.1f} kN m per wheelset, below the motors' "
                 f"{force * r0 / n / 1e3:.1f} kN m at the starting traction force)")
    op = _operating_point(parameters, s0, v, options)
    mu = float(law.mu(s0, v))
    matrices = output_matrices(model, op)
    values = matrices.C_q @ static_deflection(model, op)
    where = {"s0": s0, "v_kmh": op.v_kmh, "mu": mu, "mu_max": mu_max, "bound": bound}
    note = f"starting torque bounded by {'the motors' if bound == 'motors' else 'adhesion'}"
    loads = {name: CaseLoad(float(values[matrices.index(name)]), math.nan, dict(where), note)
             for name in outputs}
    return LoadCase(
        "starting",
        f"steady traction at {op.v_kmh:g} km/h with {words}; steady, no horizon",
        None, loads, {"s0": s0, "v_kmh": op.v_kmh, "N0": N0, "mu": mu, "mu_max": mu_max,
                      "bound": bound, "starting_traction_force": force,
                      "driven_wheelsets": n})


def assess(parameters: Parameters, options: AssessmentOptions | None = None,
           map_unordered=None, progress=None) -> Assessment:
    """The three load cases and every check under them.  The short-circuit case's grid runs on
    the study engine's ``map_unordered`` (default: in this process) with ``progress(finished,
    total, elapsed [s])`` after each point; the other two cases are single runs here."""
    options = AssessmentOptions() if options is None else options
    outputs = assessed_outputs(parameters)
    return assessment_of(parameters, [
        short_circuit_case(parameters, outputs, options, map_unordered, progress),
        unstable_adhesion_case(parameters, outputs, options),
        starting_case(parameters, outputs, options)])


def assessed_outputs(parameters: Parameters) -> list[str]:
    """The outputs whose loads the checks take (each drive component's section torque)."""
    return list(dict.fromkeys(c.output for c in drive_components(parameters)))


def assessment_of(parameters: Parameters, cases: list[LoadCase]) -> Assessment:
    """Every check of the set's drive components under ``cases`` (computed by the case functions
    above with :func:`assessed_outputs`; a caller may keep a case that its inputs leave unchanged,
    as the dashboard keeps the unstable case while only the short circuit's creepage moves)."""
    components = drive_components(parameters)
    checks = []
    for case in cases:
        for component in components:
            load = case.loads[component.output]
            checks.append(verify(component, case.name, load.value, load.value, load.time,
                                 load.scenario, load.note))
    return Assessment(cases, components, checks, governing(checks))
