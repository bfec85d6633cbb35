"""The load cases of the assessment and the checks under them: every press fit, shaft section and
coupling of both drives (:func:`model.analysis.assessment.drive_components`) in three rare events,
and under the converters' steady torque ripple (:func:`model.analysis.assessment.
alternating_components`) in normal running.

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

* ``ripple`` — both converters' torque ripple at the orders and amplitudes of the parameter set
  (``ripple_el6_amplitude``, ``ripple_el12_amplitude``) or of ``AssessmentOptions.ripple``, in
  steady running over 10…200 km/h on a grid refined at every resonance, at the short-circuit
  case's creepages: each section's mean (the steady traction) and alternating amplitude (the two
  motors' responses added as magnitudes — the worst relative phase — and summed over the orders);
  steady, no horizon (:mod:`model.studies.ripple_case`).

**Checks**: the load of a component in a case is the largest |value| of its output over the
case's histories; safety factor = capacity / load (:mod:`model.analysis.assessment`).  Under the
ripple: press-fit slip under mean + amplitude, torsional fatigue (DIN 743, simplified) and the
couplings' permissible vibratory torque, each at its worst speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from model.analysis.assessment import (
    AlternatingLoad,
    Check,
    Component,
    alternating_components,
    drive_components,
    governing,
    verify,
    verify_alternating,
)
from model.analysis.load_peaks import GROWTH_RATE
from model.analysis.nonlinear import AntiSlip
from model.analysis.response import ResponseError, ShortCircuit
from model.mechanics.excitation import DriveExcitation, Order
from model.mechanics.operating_point import KMH, OperatingPoint, creep_law
from model.mechanics.parameters import Parameters
from model.studies.ripple_case import (
    RippleCaseError,
    RippleSweep,
    envelope_loads,
    ripple_amplitudes,
    ripple_sweep,
)
from model.studies.running_case import (
    DEFAULT_RANDOM_MULTIPLE,
    DEFAULT_RUNNING_S0,
    DEFAULT_RUNNING_V,
    DEFAULT_WHEEL_POLYGON,
    RunningCaseError,
    running_check,
    running_loads,
    running_sweep,
)

LOAD_CASES = ("short_circuit", "unstable_adhesion", "starting", "ripple")
OPTIONAL_CASES = ("running",)  # computed when asked for (options.cases; bogie assess --running)
DEFAULT_S0 = (0.002, 0.005)  # stable creepages of the short-circuit grid [-]
DEFAULT_V_KMH = (80.0, 120.0, 200.0)  # speeds of the short-circuit grid [km/h]
MIN_HORIZON = 2.0  # [s]: the study's window
SETTLED = 0.01  # the quasi-static part within 1 % of its final change
MAX_GRID = 60  # (s0, v) points of the short-circuit grid
# ripple: the speed grid before its refinement at the resonances, 10…200 km/h (the locomotive's
# top speed) every 10 km/h [m/s]
DEFAULT_RIPPLE_V = tuple(float(x) * KMH for x in np.linspace(10.0, 200.0, 20))
MAX_RIPPLE_SPEEDS = 200  # speeds of that grid


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
    ripple: dict[Order, float] | None = None  # ripple: each converter's {order: amplitude [N m]}
    #                                           (None: the set's, ripple_case.ripple_amplitudes)
    ripple_v: tuple[float, ...] = DEFAULT_RIPPLE_V  # ripple: speeds before refinement [m/s]
    ripple_drive: DriveExcitation | None = None  # ripple: pole pairs, pinion teeth (None: the file's)
    cases: tuple[str, ...] = LOAD_CASES  # the load cases assess() computes, in this order
    running_s0: tuple[float, ...] = DEFAULT_RUNNING_S0  # running: creepages [-]
    running_v: tuple[float, ...] = DEFAULT_RUNNING_V  # running: speeds [m/s]
    wheel_polygon: dict[int, float] | None = None  # running: {order: radial amplitude [m]}
    #                                                (None: DEFAULT_WHEEL_POLYGON)
    track: str = "low"  # running: the track spectrum (model.analysis.track_spectrum.SPECTRA)
    random_multiple: float = DEFAULT_RANDOM_MULTIPLE  # running: the random part as k × RMS

    def __post_init__(self) -> None:
        for label, values in (("--s0", self.s0), ("--v", self.v)):
            if not values or len(set(values)) != len(values):
                raise AssessmentError(f"{label}: give distinct values")
        if len(self.s0) * len(self.v) > MAX_GRID:
            raise AssessmentError(f"--s0 × --v = {len(self.s0) * len(self.v)} points, at most "
                                  f"{MAX_GRID}")
        if self.ripple is not None:
            check_ripple(self.ripple)
        speeds = np.asarray(self.ripple_v, dtype=float)
        if not (speeds.ndim == 1 and 2 <= len(speeds) <= MAX_RIPPLE_SPEEDS
                and np.all(np.isfinite(speeds)) and speeds[0] > 0 and np.all(np.diff(speeds) > 0)):
            raise AssessmentError(f"ripple speeds: give 2 to {MAX_RIPPLE_SPEEDS} increasing speeds "
                                  "above 0")
        unknown = [name for name in self.cases if name not in LOAD_CASES + OPTIONAL_CASES]
        if not self.cases or unknown or len(set(self.cases)) != len(self.cases):
            raise AssessmentError(f"load cases: give distinct names of "
                                  f"{', '.join(LOAD_CASES + OPTIONAL_CASES)}"
                                  + (f" (not {', '.join(map(str, unknown))})" if unknown else ""))


def check_ripple(ripple: dict) -> None:
    """Refuse a ripple that is not {Order: amplitude [N m] in [0, 1e7]} with at least one order,
    or a fixed frequency beyond the model's range (:class:`AssessmentError`, one line)."""
    from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ

    if not ripple:
        raise AssessmentError("ripple: give at least one order=amplitude (e.g. el:6=256)")
    for order, amplitude in ripple.items():
        if not isinstance(order, Order):
            raise AssessmentError(f"ripple: {order!r} is not an excitation order (e.g. el:6)")
        if isinstance(amplitude, bool) or not isinstance(amplitude, int | float) or not (
                math.isfinite(amplitude) and 0 <= amplitude <= 1e7):
            raise AssessmentError(f"ripple: the amplitude of {order.name} must be a number in "
                                  f"[0, 1e7] N m, got {amplitude!r}")
        if order.family == "fixed" and order.order > MODEL_FREQUENCY_LIMIT_HZ:
            raise AssessmentError(f"ripple: fixed frequency {order.order:g} Hz is beyond the "
                                  f"model's range of {MODEL_FREQUENCY_LIMIT_HZ:g} Hz")


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
    loads: dict[str, CaseLoad] | dict[str, AlternatingLoad]
    scenario: dict  # what defines it (operating points, creep, protection)
    alternating: bool = False  # True: the loads are AlternatingLoad, checked by
    #                            alternating_components (press fits, fatigue, vibratory torque)
    checks: tuple = ()  # checks the case made itself (the running case: with its RMS and orders)


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


def operating_point(parameters: Parameters, s0: float, v: float, options: AssessmentOptions
                    ) -> OperatingPoint:
    """The operating point (s0 [-], v [m/s]) with the options' wheel force and motor slope (the
    set's where they are None)."""
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
    ops = [operating_point(parameters, s0, v, options) for s0 in options.s0 for v in options.v]
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
    beyond = beyond_adhesion(parameters, ops[0].N0, [envelopes[c] for c in contacts])
    note = "" if beyond is None else (
        f"linear creep beyond the adhesion limit: {beyond['wheel']}'s creep force reaches "
        f"{beyond['force'] / 1e3:.1f} kN, {beyond['ratio']:.2f} x μ_max N0 = "
        f"{beyond['limit'] / 1e3:.1f} kN (s0 = {beyond['s0']:g}, {beyond['v_kmh']:g} km/h): a "
        "real wheelset slips there, the linear load is an upper estimate")
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
         "creep": "linear", "fs": options.fs, "beyond_adhesion": beyond})


def beyond_adhesion(parameters: Parameters, N0: float, contacts) -> dict | None:
    """Where a wheel's linear creep force left the adhesion range the furthest on the grid
    (``contacts``: the creep forces' envelopes, whose extremes carry their speed): the wheel, its
    force and the limit μ_max N0 [N], their ratio, s0 and v_kmh; None when none did."""
    worst = []
    for envelope in contacts:
        for value, at in ((envelope.max, envelope.max_at), (envelope.min, envelope.min_at)):
            v = at["v_kmh"] * KMH
            limit = creep_law(parameters, N0).maximum(v)[1] * N0
            if abs(value) > limit:
                worst.append((abs(value) / limit, envelope.name, value, limit, at))
    if not worst:
        return None
    ratio, name, value, limit, at = max(worst, key=lambda w: w[0])
    return {"wheel": name.removesuffix(".creep_force"), "force": float(value),
            "limit": float(limit), "ratio": float(ratio), "s0": float(at["s0"]),
            "v_kmh": float(at["v_kmh"])}


def unstable_adhesion_case(parameters: Parameters, outputs: list[str],
                           options: AssessmentOptions) -> LoadCase:
    """The unstable case: nonlinear creep and ID2's anti-slip protection at its reaction time."""
    from model.analysis.fault_instant import continuity_phases
    from model.analysis.nonlinear import nonlinear_response
    from model.mechanics.operating_point import motor_torque
    from model.studies.maps import cached_model

    model = cached_model(parameters)
    op = operating_point(parameters, options.unstable_s0, options.unstable_v, options)
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
    op = operating_point(parameters, s0, v, options)
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


def ripple_case(parameters: Parameters, outputs: list[str], options: AssessmentOptions
                ) -> LoadCase:
    """The ripple case (:mod:`model.studies.ripple_case`): an
    :class:`~model.analysis.assessment.AlternatingLoad` per output over the options' speeds
    (``ripple_v``, refined at the resonances) and creepages (``s0``, each checked stable at every
    speed, else :class:`AssessmentError`), under the options' ripple (``ripple``; None: the set's)
    of both converters."""
    return ripple_load_case(ripple_case_sweep(parameters, outputs, options), parameters, options)


def ripple_of(parameters: Parameters, options: AssessmentOptions) -> dict[Order, float]:
    """The ripple case's {order: amplitude [N m]} per converter: the options' or the set's
    (:func:`model.studies.ripple_case.ripple_amplitudes`)."""
    return options.ripple if options.ripple is not None else ripple_amplitudes(parameters)


def ripple_case_sweep(parameters: Parameters, outputs: list[str], options: AssessmentOptions,
                      ripple: dict[Order, float] | None = None) -> RippleSweep:
    """The ripple case's sweep (:func:`model.studies.ripple_case.ripple_sweep`) over the options'
    speeds and creepages at ``ripple`` {order: amplitude [N m]} (None: :func:`ripple_of`); a
    creepage not stable at every speed raises :class:`AssessmentError`."""
    from model.mechanics.excitation import load_excitation
    from model.studies.maps import cached_model

    points = [operating_point(parameters, s0, options.ripple_v[0], options) for s0 in options.s0]
    drive = options.ripple_drive if options.ripple_drive is not None else load_excitation()
    ripple = ripple_of(parameters, options) if ripple is None else ripple
    try:
        return ripple_sweep(cached_model(parameters), points, options.ripple_v, ripple, drive,
                            outputs)
    except RippleCaseError as error:
        raise AssessmentError(str(error)) from None


def ripple_load_case(sweep: RippleSweep, parameters: Parameters, options: AssessmentOptions
                     ) -> LoadCase:
    """The ripple case of a computed sweep (:func:`model.studies.ripple_case.ripple_sweep` with the
    options' speeds and creepages): the envelope over the creepages, what defines the case."""
    from model.analysis.campbell import MOTOR_INPUTS
    from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ

    first = operating_point(parameters, sweep.s0[0], float(sweep.v[0]), options)
    coarse_kmh = np.asarray(options.ripple_v) / KMH
    ripple_words = ", ".join(f"{o.name} = {a:g} N m" for o, a in zip(sweep.orders, sweep.ripple,
                                                                      strict=True))
    beyond = [o.name for o, row in zip(sweep.orders, sweep.frequencies_hz, strict=True)
              if np.any(~np.isfinite(row))]
    description = (
        f"both converters' torque ripple ({ripple_words} per motor) in steady running over "
        f"{coarse_kmh[0]:g}…{coarse_kmh[-1]:g} km/h ({len(coarse_kmh)} speeds and "
        f"{len(sweep.refined)} at the resonances) at s0 = "
        f"{', '.join(f'{x:g}' for x in sweep.s0)}: each section's mean is the steady traction's "
        "load (the largest over the creepages), its amplitude the two motors' responses added as "
        "magnitudes (the worst relative phase) and summed over the orders; ID1's motor a pure "
        "torque source, ID2's on its slope b_M (as in the model)"
        + (f"; {', '.join(beyond)} beyond the model's {MODEL_FREQUENCY_LIMIT_HZ:g} Hz at the "
           "highest speeds, left out there" if beyond else ""))
    scenario = {"s0": list(sweep.s0), "v_kmh": [float(x) for x in coarse_kmh],
                "v_kmh_refined": [float(x) for x in sweep.refined / KMH],
                "orders": [{"order": o.name, "amplitude": float(a)}
                           for o, a in zip(sweep.orders, sweep.ripple, strict=True)],
                "motors": list(MOTOR_INPUTS), "phase": "worst (magnitudes added)",
                "N0": first.N0, "b_M": first.b_M,
                "motor_bandwidth": parameters["motor_bandwidth"], "creep": "linear"}
    return LoadCase("ripple", description, None, envelope_loads(sweep), scenario,
                    alternating=True)


def running_case(parameters: Parameters, outputs: list[str], options: AssessmentOptions
                 ) -> LoadCase:
    """The running case (:mod:`model.studies.running_case`): mean traction, both converters'
    ripple (the ripple case's orders and amplitudes), the wheel polygon and the random track over
    ``options.running_v`` at ``options.running_s0``, each running system checked stable (the
    unstable points left out and named in the description and the scenario's ``unstable``; none
    stable: :class:`AssessmentError`); its checks made here, with the RMS and the polygon's
    orders."""
    from model.analysis.track_spectrum import TrackSpectrumError, track_spectrum
    from model.mechanics.excitation import load_excitation
    from model.studies.maps import cached_model

    polygon = DEFAULT_WHEEL_POLYGON if options.wheel_polygon is None else options.wheel_polygon
    try:
        spectrum = track_spectrum(options.track)
    except TrackSpectrumError as error:
        raise AssessmentError(str(error)) from None
    drive = options.ripple_drive if options.ripple_drive is not None else load_excitation()
    ripple = ripple_of(parameters, options)
    points = [operating_point(parameters, s0, options.running_v[0], options)
              for s0 in options.running_s0]
    try:
        sweep = running_sweep(cached_model(parameters), points, options.running_v, outputs, ripple,
                              drive, polygon, spectrum, options.random_multiple)
    except RunningCaseError as error:
        raise AssessmentError(str(error)) from None
    loads = running_loads(sweep)
    checks = tuple(running_check(c, sweep, loads[c.output])
                   for c in alternating_components(parameters))
    v_kmh = np.asarray(options.running_v) / KMH
    words = ", ".join(f"order {n} = {a * 1e6:g} µm" for n, a in zip(
        sweep.polygon_orders, sweep.polygon_amplitudes, strict=True))
    description = (
        f"normal running over {v_kmh[0]:g}…{v_kmh[-1]:g} km/h ({len(v_kmh)} speeds) at s0 = "
        f"{', '.join(f'{x:g}' for x in sweep.s0)}: the steady traction's mean, plus both "
        f"converters' ripple ({', '.join(o.name for o in sweep.ripple_orders)}, magnitudes "
        f"added), plus polygonal wheels ({words}; every wheel, the rear wheelset a wheelbase "
        f"later), plus {sweep.random_multiple:g} × the RMS under the random track "
        f"({spectrum.name}: {spectrum.source}); the parts added as magnitudes (the worst phase); "
        "on the running system (the creep force following the wheel force)"
        + unstable_words(sweep.unstable))
    first = points[0]
    scenario = {"s0": list(sweep.s0), "v_kmh": [float(x) for x in v_kmh],
                "wheel_polygon": [{"order": int(n), "input_amplitude": float(a)}
                                  for n, a in zip(sweep.polygon_orders, sweep.polygon_amplitudes,
                                                  strict=True)],
                "ripple": [{"order": o.name, "amplitude": float(a)}
                           for o, a in zip(sweep.ripple_orders, sweep.ripple_amplitudes,
                                           strict=True)],
                "track": {"name": spectrum.name, "A_v": spectrum.A_v, "omega_c": spectrum.omega_c,
                          "omega_r": spectrum.omega_r, "source": spectrum.source},
                "random_multiple": sweep.random_multiple, "N0": first.N0, "b_M": first.b_M,
                "creep": "linear", "unstable": [dict(u) for u in sweep.unstable]}
    return LoadCase("running", description, None, loads, scenario, alternating=True,
                    checks=checks)


def unstable_words(unstable: tuple[dict, ...]) -> str:
    """The running case's points left out for a growing mode, per creepage its speeds [km/h]
    and the largest growth rate [1/s], as a sentence ('' if none)."""
    if not unstable:
        return ""
    parts = []
    for s0 in dict.fromkeys(u["s0"] for u in unstable):
        points = [u for u in unstable if u["s0"] == s0]
        speeds = ", ".join(f"{u['v_kmh']:g}" for u in points)
        growth = max(u["growth"] for u in points)
        parts.append(f"s0 = {s0:g} at {speeds} km/h (growth up to {growth:.3g} 1/s)")
    return ("; NOT STABLE with the wheel-force coupling, so left out (no stationary response): "
            + "; ".join(parts))


def assess(parameters: Parameters, options: AssessmentOptions | None = None,
           map_unordered=None, progress=None) -> Assessment:
    """The load cases of ``options.cases`` (default all four) and every check under them.  The
    short-circuit case's grid runs on the study engine's ``map_unordered`` (default: in this
    process) with ``progress(finished, total, elapsed [s])`` after each point; the other cases
    are runs here (the ripple case: :mod:`model.studies.ripple_case`)."""
    options = AssessmentOptions() if options is None else options
    outputs = assessed_outputs(parameters)
    builders = {
        "short_circuit": lambda: short_circuit_case(parameters, outputs, options, map_unordered,
                                                    progress),
        "unstable_adhesion": lambda: unstable_adhesion_case(parameters, outputs, options),
        "starting": lambda: starting_case(parameters, outputs, options),
        "ripple": lambda: ripple_case(parameters, outputs, options),
        "running": lambda: running_case(parameters, outputs, options)}
    return assessment_of(parameters, [builders[name]() for name in options.cases])


def assessed_outputs(parameters: Parameters) -> list[str]:
    """The outputs whose loads the checks take (each drive component's section torque)."""
    return list(dict.fromkeys(c.output for c in drive_components(parameters)))


def assessment_of(parameters: Parameters, cases: list[LoadCase]) -> Assessment:
    """Every check of the set's drive components under ``cases`` (computed by the case functions
    above with :func:`assessed_outputs`; a caller may keep a case that its inputs leave unchanged,
    as the dashboard keeps the unstable case while only the short circuit's creepage moves).  An
    alternating case (``ripple``) is checked by the components under alternating load."""
    components = drive_components(parameters)
    under_alternating = alternating_components(parameters)
    checks = []
    for case in cases:
        if case.checks:
            checks += list(case.checks)
            continue
        if case.alternating:
            checks += [verify_alternating(c, case.name, case.loads[c.output])
                       for c in under_alternating]
            continue
        for component in components:
            load = case.loads[component.output]
            checks.append(verify(component, case.name, load.value, load.value, load.time,
                                 load.scenario, load.note))
    if any(case.alternating for case in cases):
        components = components + [c for c in under_alternating
                                    if c.kind not in {d.kind for d in components}]
    return Assessment(cases, components, checks, governing(checks))
