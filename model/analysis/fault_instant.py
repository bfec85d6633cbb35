"""The short-circuit response at every fault instant at once, in closed form (linear creep).

``M_C(t) = −M(s0,v) H(t) − M0 e^(−Dωt) sin[ω(t − Δt)]``: the fault instant Δt moves only the
phase φ = ωΔt of the oscillation; the fault itself, and the start of the decay, stay at t = 0
(:class:`model.analysis.response.ShortCircuit`).

**Superposition (why three responses give every Δt).**  With ``e^(−σt)`` (σ = Dω) the oscillating
part is ``−M0 e^(−σt) sin(ωt − φ) = M0 cos φ · [−e^(−σt) sin ωt] + M0 sin φ · [e^(−σt) cos ωt]``:
for every φ a combination of the *same* two inputs, with the step unchanged.  The linear system
maps it to ``y(t; φ) = y_s(t) + M0 [cos φ · y_c(t) + sin φ · y_q(t)]`` exactly (neither the decay
nor the time origin depends on φ).  At each t the largest value over φ of ``a + b cos φ + c sin φ``
is ``a + √(b² + c²)``, at ``φ = atan2(c, b)``; the smallest is ``a − √(b² + c²)`` at φ + π.  Three
closed-form evaluations (:func:`model.analysis.response.solve_linear`) per operating point give the
continuous worst case, and any grid of phases and amplitudes M0 is a linear combination of them.
(With nonlinear creep there is no superposition: phases are a grid, one nonlinear run each.)

The physical fault instants are the two per period at which the total motor torque is continuous,
``sin φ = M(s0,v)/M0`` (:func:`continuity_phases`; ``bogie response`` takes the first).

API::

    family = phase_families(model, op, [(90.0, 0.04)], t_end=2.0, fs=10_000.0)[0]
    family.totals(M0=50_000.0, dt=0.0004)       # = short_circuit_response(...).outputs, N x p
    worst = worst_fault_instant(family, 50_000.0)
    worst.upper, worst.lower                    # max / min over Δt of each total at each t
    worst.peaks.max, worst.peaks.phase_of_max   # per output, and the Δt [s] that gives it
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model.analysis.eigen import bogie_system
from model.analysis.response import (
    ResponseError,
    ShortCircuit,
    output_rows,
    solve_linear,
    time_grid_points,
)
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import OperatingPoint, motor_torque


class DesignLoadError(ResponseError):
    """Bad input for a design-load computation (one-line message)."""


# --- fault instants --------------------------------------------------------------------------------

def wrap_shift(phase: np.ndarray | float, omega: float) -> np.ndarray | float:
    """The time shift Δt = φ/ω [s] of a phase φ [rad] taken into (−π, π]: Δt in (−T/2, T/2]."""
    wrapped = phase - 2 * np.pi * np.ceil((np.asarray(phase) - np.pi) / (2 * np.pi))
    return wrapped / omega


def continuity_phases(step: float, M0: float, f: float) -> tuple[float, float]:
    """The two fault instants Δt [s] in (−T/2, T/2] (T = 1/f) at which the total motor torque is
    continuous, ``sin(ωΔt) = M/M0`` with ``step`` = M(s0, v) [N m], M0 [N m], f [Hz]: φ1 =
    asin(M/M0) (the one :meth:`model.analysis.response.ShortCircuit.shift` takes) and φ2 = π − φ1.  The two
    coincide at ωΔt = ±π/2 when |M| ≥ M0; (0, 0) when M0 = 0 (no oscillation, Δt is void)."""
    if M0 == 0.0:
        return 0.0, 0.0
    omega = 2 * math.pi * f
    first = ShortCircuit(M0=M0, f=f).shift(step)
    return first, float(wrap_shift(math.pi - omega * first, omega))


# --- the three-term family over the fault instant ---------------------------------------------------

@dataclass
class PhaseFamily:
    """Every short-circuit response at one operating point and one (f, D), for any amplitude M0 and
    fault instant Δt: ``total(t) = steady + step(t) + M0 [cos(ωΔt) cos_part(t) + sin(ωΔt)
    sin_part(t)]`` (module docstring).  Arrays are N x p (time x output)."""

    t: np.ndarray  # time points [s]
    names: tuple[str, ...]  # output names
    units: dict[str, str]  # name -> SI unit
    steady: np.ndarray  # pre-fault value of each output [unit]
    step: np.ndarray  # N x p: perturbation by the step −M(s0, v) H(t) [unit]
    cos_part: np.ndarray  # N x p: perturbation by −e^(−σt) sin ωt, per N m of M0 [unit/(N m)]
    sin_part: np.ndarray  # N x p: perturbation by e^(−σt) cos ωt, per N m of M0 [unit/(N m)]
    f: float  # frequency of the oscillating part [Hz]
    D: float  # its decay [-]
    motor_torque: float  # M(s0, v) before the fault [N m]
    operating_point: OperatingPoint
    methods: tuple[str, str, str]  # closed-form evaluation of step, cos and sin parts
    truncated_at: float | None  # [s] if the grid was cut (growth beyond 1e250), else None
    highest_excited_hz: float | None  # max(f, highest mode with > 1 % of an output) [Hz]

    @property
    def omega(self) -> float:
        """ω = 2π f [rad/s]."""
        return 2 * math.pi * self.f

    def totals(self, M0: float, dt: float) -> np.ndarray:
        """Totals (N x p) for amplitude ``M0`` [N m] and fault instant ``dt`` [s]."""
        phase = self.omega * dt
        return self.steady + self.step + M0 * (math.cos(phase) * self.cos_part
                                               + math.sin(phase) * self.sin_part)

    def continuity_phases(self, M0: float) -> tuple[float, float]:
        """:func:`continuity_phases` at this operating point [s]."""
        return continuity_phases(self.motor_torque, M0, self.f)


def phase_families(model: BogieModel, op: OperatingPoint, excitations, t_end: float = 2.0,
                   fs: float = 10_000.0, outputs: list[str] | None = None,
                   method: str = "auto") -> list[PhaseFamily]:
    """A :class:`PhaseFamily` for each ``(f [Hz], D [-])`` of ``excitations`` at ``op``: one
    closed-form evaluation of the step (shared) and two per (f, D), on the time grid of
    :func:`model.analysis.response.short_circuit_response` (``t_end`` [s], ``fs`` [Hz], ``outputs``,
    ``method`` as there)."""
    excitations = [(float(f), float(D)) for f, D in excitations]
    if not excitations:
        raise DesignLoadError("no excitation (f, D) given")
    for f, D in excitations:
        ShortCircuit(f=f, D=D)  # validates
    n_points = time_grid_points(t_end, fs)
    names, C, units, steady = output_rows(model, op, outputs)
    system = bogie_system(model, op)
    step = motor_torque(model.parameters, op)
    dt = 1.0 / fs

    def solve(u0: float, a: complex, mu: complex):
        info: dict = {}
        y, used, _ = solve_linear(system, C, u0, a, mu, n_points, dt, method, info)
        return y, used, info.get("mode_hz")

    mus = [complex(-D * 2 * math.pi * f, 2 * math.pi * f) for f, D in excitations]
    y_step, step_method, step_hz = solve(-step, 0j, mus[0])
    families = []
    for (f, D), mu in zip(excitations, mus, strict=True):
        # Re(i e^(μt)) = −e^(−σt) sin ωt and Re(1·e^(μt)) = e^(−σt) cos ωt
        y_cos, cos_method, cos_hz = solve(0.0, 1j, mu)
        y_sin, sin_method, sin_hz = solve(0.0, 1.0 + 0j, mu)
        valid = min(len(y_step), len(y_cos), len(y_sin))
        modes = [x for x in (step_hz, cos_hz, sin_hz) if x is not None]
        t = np.arange(valid) * dt
        families.append(PhaseFamily(
            t=t, names=tuple(names), units=units,
            steady=np.array([steady[name] for name in names]),
            step=y_step[:valid], cos_part=y_cos[:valid], sin_part=y_sin[:valid], f=f, D=D,
            motor_torque=step, operating_point=op,
            methods=(step_method, cos_method, sin_method),
            truncated_at=None if valid == n_points else float(t[-1]),
            highest_excited_hz=max(f, *modes) if len(modes) == 3 else None))
    return families


# --- peaks of histories -------------------------------------------------------------------------------

@dataclass(frozen=True)
class HistoryPeaks:
    """Max and min over the time grid of each output (arrays of length p, output order)."""

    max: np.ndarray  # largest total [unit]
    min: np.ndarray  # smallest total [unit]
    time_of_max: np.ndarray  # [s]
    time_of_min: np.ndarray  # [s]
    phase_of_max: np.ndarray  # fault instant Δt of the history that has the max [s]
    phase_of_min: np.ndarray  # … the min [s]


def history_peaks(t: np.ndarray, totals: np.ndarray, phase: float) -> HistoryPeaks:
    """:class:`HistoryPeaks` of histories ``totals`` (N x p) at times ``t`` [s], all with the
    fault instant ``phase`` [s]."""
    k_max, k_min = np.argmax(totals, axis=0), np.argmin(totals, axis=0)
    columns = np.arange(totals.shape[1])
    full = np.full(totals.shape[1], float(phase))
    return HistoryPeaks(totals[k_max, columns], totals[k_min, columns], t[k_max], t[k_min],
                        full, full.copy())


@dataclass
class WorstFaultInstant:
    """The worst case over every fault instant Δt, at each time (closed form; N x p arrays)."""

    t: np.ndarray  # time points [s]
    names: tuple[str, ...]
    units: dict[str, str]
    M0: float  # amplitude [N m]
    upper: np.ndarray | None  # max over Δt of each total [unit] (None unless histories asked)
    lower: np.ndarray | None  # min over Δt [unit]
    phase_of_upper: np.ndarray | None  # the Δt that gives upper, in (−T/2, T/2] [s]
    phase_of_lower: np.ndarray | None  # … lower [s]
    peaks: HistoryPeaks  # max of upper, min of lower over t, and the Δt of each [s]


def worst_fault_instant(family: PhaseFamily, M0: float, histories: bool = True
                        ) -> WorstFaultInstant:
    """Max and min over every fault instant of each output at each time, for amplitude ``M0``
    [N m]: ``a ± √(b² + c²)`` with a = steady + step, b = M0·cos_part, c = M0·sin_part, the max
    at ωΔt = atan2(c, b), the min at ωΔt + π.  ``histories``: keep the N x p curves (else only
    the peaks)."""
    b, c = M0 * family.cos_part, M0 * family.sin_part
    radius = np.hypot(b, c)
    base = family.steady + family.step
    upper, lower = base + radius, base - radius
    columns = np.arange(base.shape[1])
    k_max, k_min = np.argmax(upper, axis=0), np.argmin(lower, axis=0)
    omega = family.omega
    phase_max = np.arctan2(c[k_max, columns], b[k_max, columns])
    phase_min = np.arctan2(c[k_min, columns], b[k_min, columns]) + np.pi
    peaks = HistoryPeaks(upper[k_max, columns], lower[k_min, columns], family.t[k_max],
                         family.t[k_min], wrap_shift(phase_max, omega),
                         wrap_shift(phase_min, omega))
    if not histories:
        return WorstFaultInstant(family.t, family.names, family.units, M0, None, None, None,
                                 None, peaks)
    phase_upper = np.arctan2(c, b)
    return WorstFaultInstant(family.t, family.names, family.units, M0, upper, lower,
                             wrap_shift(phase_upper, omega),
                             wrap_shift(phase_upper + np.pi, omega), peaks)
