"""Where the drive resonates: the Campbell diagram over speed, its crossings with the excitation
orders, and the forced response to a motor torque ripple over speed.

**Modes over speed.**  The eigenvalues along a speed sweep at a fixed creepage are a root locus
over v (:func:`model.analysis.locus.root_locus`: a reduced model with error control, branches
continued by MAC).  The diagram tracks the modes that a motor's torque drives (:class:`DriveModes`):
a mode j is kept where its resonant term of the frequency response, ``|R_j| / |Re λ_j|`` (the
height of its peak alone), reaches ``participation`` of the largest such term among the outputs of
the same unit (torques, forces), from either motor's torque, at any of the sweep's three exact
points (first, middle, last).  Modes the motor cannot excite cannot resonate with its orders; with
``participation = 0`` every mode below ``max_frequency_hz`` is tracked (slower: the basis is
then most of the model).  Each mode is named by its character (:mod:`model.analysis.modes`, the
Table 2 sentences) at the speed of the operating point (or the sweep's nearest); its damping ratio
is ``ζ = −Re λ / |λ|``.

**Crossings.**  An order line (:mod:`model.mechanics.excitation`) meets a mode where
``f_line(v) = Im λ(v)/2π``: on each interval of the speed grid where the difference changes sign,
the speed is the intersection of the straight line with the mode's curve interpolated linearly
between the two grid points (closed form).  Its **severity** is the amplitude of the steady-state
torque in every torque output (N m per N m of harmonic motor torque at that frequency) at that
speed and frequency, ``|H(f_c; v_c)|`` of :mod:`model.analysis.frequency_response` (solved
directly at the crossing); crossings are sorted by their largest torque.

**Forced response over speed.**  A ripple of amplitude ``A_k`` [N m] at order k gives each output
the steady amplitude ``A_k |H(f_k(v); v)|``; the sum over the orders is the largest the steady
state can reach (when the harmonics' peaks coincide).  A lightly damped mode's resonance is
narrow in speed (a half-power width of 2ζ v: 0.4 km/h for ζ = 0.002 at 90 km/h), narrower than
any sensible grid: the speeds where an order meets a resonance are found and added to the grid
(the frequency response's peaks at the middle speed give where to look; a golden-section search
in speed over ±10 % finds the largest response there).

Everything is linearized about the operating point of each speed (creepage s0 fixed): large
amplitudes that reach the creep's nonlinearity are outside it (docs/resonance.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import linear_sum_assignment

from model.analysis.eigen import bogie_system, eigen_analysis
from model.analysis.frequency_response import (
    DEFAULT_INPUT,
    MODEL_FREQUENCY_LIMIT_HZ,
    golden_section_maximum,
    input_force,
    modal_transfer,
    output_indices,
    solve_direct,
)
from model.analysis.locus import root_locus
from model.analysis.modes import characterize
from model.mechanics.assembly import BogieModel
from model.mechanics.excitation import DriveExcitation, Order
from model.mechanics.operating_point import KMH, OperatingPoint, damping_matrix
from model.mechanics.outputs import output_matrices

DEFAULT_PARTICIPATION = 0.01  # a mode is tracked if its peak reaches 1 % of the largest (DriveModes)
# The root locus's error control for the diagram: the first-order estimate ‖T(λ)x‖/‖T'(λ)x‖ of a
# Ritz value whose basis holds a few modes (and their shapes at three speeds) overstates the
# error by orders of magnitude (the Ritz value is a two-sided Rayleigh quotient: its error is
# second order in the vector's).  Measured against the dense eigenvalues on the default sweep
# (5…200 km/h, 200 speeds) of the bundled set: with a tolerance of 1e-3 on the estimate (601
# branch-points refined by Newton, 2 speeds solved densely) the largest error is 1.1e-7; with 1e-6
# nearly every speed is solved densely (scripts/bench_resonance.py prints the largest error of
# the default).
CAMPBELL_RTOL = 1e-3
CAMPBELL_FLOOR = 1.0  # [1/s] errors relative to max(|λ|, 1 1/s): real branches pass through 0
MOTOR_INPUTS = ("ID1.motor.torque", "ID2.motor.torque")
TORQUE_UNIT = "N m"
MAX_SPEEDS = 2000


class CampbellError(ValueError):
    """Bad input for a Campbell diagram or a ripple response (one-line message)."""


@dataclass(frozen=True)
class DriveModes:
    """The modes the motors' torques drive (module docstring): a hashable selection for
    :func:`model.analysis.locus.root_locus`."""

    threshold: float = DEFAULT_PARTICIPATION  # fraction of the largest resonant term [-]
    inputs: tuple[str, ...] = MOTOR_INPUTS

    def __call__(self, model: BogieModel, point: OperatingPoint, eigenvalues: np.ndarray) -> np.ndarray:
        share = participation(model, point, self.inputs)
        system_eigenvalues = bogie_system(model, point).eigen[0]
        if system_eigenvalues is not eigenvalues and not np.array_equal(system_eigenvalues,
                                                                        eigenvalues):
            raise ValueError("participation: the eigenvalues are not the point's decomposition")
        return share >= self.threshold


def participation(model: BogieModel, op: OperatingPoint,
                  inputs: tuple[str, ...] = MOTOR_INPUTS) -> np.ndarray:
    """Per eigenvalue of the point's decomposition (the order of :func:`eigen_analysis`): the
    largest ratio, over the inputs and outputs, of its resonant term ``|R_j|/|Re λ_j|`` to the
    largest resonant term among the outputs of the same unit [-] (1: the mode that dominates
    some unit's response)."""
    system = bogie_system(model, op)
    matrices = output_matrices(model, op)
    C = system.state_output(matrices.C_q, matrices.C_v)
    lam = system.eigen[0]
    damping = np.maximum(np.abs(lam.real), 1e-12 * np.abs(lam))
    units = np.array(matrices.units)
    share = np.zeros(len(lam))
    for name in inputs:
        force, _ = input_force(model, name)
        peaks = np.abs(modal_transfer(system, C, system.input_map(force)).residues) / damping
        for unit in np.unique(units):
            rows = peaks[units == unit]
            top = rows.max()
            if top > 0:
                share = np.maximum(share, rows.max(axis=0) / top)
    return share


@dataclass(frozen=True)
class CampbellMode:
    """One tracked mode over the speed grid."""

    name: str  # its character (unique within the diagram)
    eigenvalues: np.ndarray  # (V,) complex [1/s]
    reference_index: int  # the speed point where it was characterized

    @property
    def f_hz(self) -> np.ndarray:
        """|Im λ|/2π [Hz] (0 where the mode is overdamped)."""
        return np.abs(self.eigenvalues.imag) / (2 * np.pi)

    @property
    def zeta(self) -> np.ndarray:
        """Damping ratio −Re λ/|λ| [-] (negative: the mode grows)."""
        return -self.eigenvalues.real / np.abs(self.eigenvalues)


@dataclass(frozen=True)
class Crossing:
    """An order line meeting a mode."""

    mode: str  # the mode's name
    order: Order
    v: float  # speed [m/s]
    f_hz: float  # frequency [Hz]
    zeta: float  # the mode's damping ratio there [-]
    severity: dict[str, float]  # torque output -> |H| [N m per N m] at (v, f)

    @property
    def v_kmh(self) -> float:
        return self.v / KMH

    @property
    def worst(self) -> tuple[str, float]:
        """(the torque output with the largest amplitude, that amplitude [N m per N m])."""
        name = max(self.severity, key=self.severity.get)
        return name, self.severity[name]


@dataclass(frozen=True)
class CampbellDiagram:
    """Modes over speed, the order lines and their crossings."""

    operating_point: OperatingPoint  # s0, N0, b_M (and the reference speed)
    input: str  # the motor torque the severities are per unit of
    v: np.ndarray  # (V,) speeds [m/s]
    modes: tuple[CampbellMode, ...]
    orders: tuple[Order, ...]
    lines_hz: np.ndarray  # (orders, V) [Hz]
    crossings: tuple[Crossing, ...]  # by severity, largest first
    participation: float  # the selection threshold (0: every mode)
    max_frequency_hz: float  # modes with |λ| < 2π this are tracked
    basis_size: int  # the root locus's reduced basis
    dense_points: int  # speeds solved densely by the root locus
    newton_refinements: int  # branch-points the root locus refined by Newton's method

    @property
    def v_kmh(self) -> np.ndarray:
        return self.v / KMH


def check_speeds(v_values) -> np.ndarray:
    """The speed grid [m/s] checked: 2…:data:`MAX_SPEEDS` finite, increasing speeds."""
    v = np.asarray(v_values, dtype=float)
    if v.ndim != 1 or not 2 <= len(v) <= MAX_SPEEDS:
        raise CampbellError(f"the speed range needs 2 to {MAX_SPEEDS} speeds, got {v.size}")
    if not np.all(np.isfinite(v)) or np.any(np.diff(v) <= 0):
        raise CampbellError("the speeds must be finite and increasing (an empty range?)")
    return v


def campbell(model: BogieModel, op: OperatingPoint, v_values, orders: tuple[Order, ...],
             excitation: DriveExcitation, input: str = DEFAULT_INPUT,
             participation_threshold: float = DEFAULT_PARTICIPATION,
             max_frequency_hz: float = MODEL_FREQUENCY_LIMIT_HZ, rtol: float = CAMPBELL_RTOL,
             workers: int = 2) -> CampbellDiagram:
    """The Campbell diagram over the speeds ``v_values`` [m/s] at ``op``'s creepage, wheel force
    and motor slope (module docstring); severities per unit torque of ``input``.

    Example::

        >>> import numpy as np
        >>> from model import KMH, build_model, campbell, default_operating_point, load_parameters
        >>> from model.mechanics.excitation import load_excitation, parse_orders
        >>> parameters = load_parameters()
        >>> model = build_model(parameters)
        >>> speeds = np.linspace(20, 180, 9) * KMH                 # [m/s]
        >>> diagram = campbell(model, default_operating_point(parameters, v_kmh=100), speeds,
        ...                    parse_orders("el:6,mesh:1"), load_excitation())
        >>> sorted({c.order.name for c in diagram.crossings})
        ['el:6', 'mesh:1']
    """
    v = check_speeds(v_values)
    if not 0 <= participation_threshold <= 1:
        raise CampbellError(f"the participation threshold must be in [0, 1], got "
                            f"{participation_threshold!r}")
    if not 0 < max_frequency_hz <= MODEL_FREQUENCY_LIMIT_HZ:
        raise CampbellError(f"the largest frequency must be in (0, {MODEL_FREQUENCY_LIMIT_HZ:g}] "
                            f"Hz (the model's validity), got {max_frequency_hz:g}")
    for order in orders:
        if order.family == "fixed" and order.order > MODEL_FREQUENCY_LIMIT_HZ:
            raise CampbellError(f"fixed frequency {order.order:g} Hz is beyond the model's "
                                f"validity: at most {MODEL_FREQUENCY_LIMIT_HZ:g} Hz")
    _, unit = input_force(model, input)
    if unit != TORQUE_UNIT:
        raise CampbellError(f"the severity is per unit motor torque: input '{input}' is not a "
                            "motor's torque")
    select = DriveModes(participation_threshold) if participation_threshold > 0 else None
    locus = root_locus(model, op, "v", v, max_frequency_hz=max_frequency_hz, rtol=rtol,
                       workers=workers, lambda_floor=CAMPBELL_FLOOR, select=select)
    modes = _name_modes(model, op, v, _oscillating_branches(locus.eigenvalues))
    parameters = model.parameters
    lines = np.array([order.frequency_hz(v, parameters, excitation) for order in orders])
    found = []
    for mode in modes:
        for order, line in zip(orders, lines, strict=True):
            found += [(mode, order, vc, fc, zc) for vc, fc, zc in intersections(v, mode.f_hz,
                                                                                mode.zeta, line)]
    crossings = [Crossing(mode.name, order, vc, fc, zc, severity(model, op, vc, fc, input))
                 for mode, order, vc, fc, zc in found if fc <= MODEL_FREQUENCY_LIMIT_HZ]
    crossings.sort(key=lambda c: -c.worst[1] if c.severity else 0.0)
    return CampbellDiagram(op, input, v, tuple(modes), tuple(orders), lines, tuple(crossings),
                           float(participation_threshold), float(max_frequency_hz),
                           locus.basis_size, int(locus.dense_points.sum()),
                           locus.newton_refinements)


def _oscillating_branches(eigenvalues: np.ndarray) -> np.ndarray:
    """The tracked branches (columns) that oscillate somewhere, one of each conjugate pair: the
    branch whose Im is positive where it is largest in magnitude, and one with a negative Im
    there whose conjugate is not tracked where it oscillates (a pair that splits into two real
    eigenvalues along the sweep is tracked as two branches: one line).  A branch that stays real
    is no line of a Campbell diagram."""
    keep = []
    for b in range(eigenvalues.shape[1]):
        lam = eigenvalues[:, b]
        at = int(np.argmax(np.abs(lam.imag)))
        if lam.imag[at] > 0:
            keep.append(b)
        elif lam.imag[at] < 0:
            complex_points = lam.imag != 0
            others = np.delete(eigenvalues[complex_points], b, axis=1)
            distance = np.abs(others - lam[complex_points].conj()[:, None]).max(axis=0)
            if distance.min() > 1e-6 * np.abs(lam).max():
                keep.append(b)
    return eigenvalues[:, keep]


def _name_modes(model: BogieModel, op: OperatingPoint, v: np.ndarray,
                branches: np.ndarray) -> list[CampbellMode]:
    """Name each branch by its character at the speed nearest to ``op``'s (the exact eigenvalue
    nearest to the branch's there, by optimal assignment)."""
    index = int(np.argmin(np.abs(v - op.v)))
    result = eigen_analysis(model, replace(op, v=float(v[index])))
    tracked = branches[index]
    cost = np.abs(tracked[:, None] - result.eigenvalues[None, :])
    rows, columns = linear_sum_assignment(cost)
    chosen = np.empty(len(tracked), dtype=int)
    chosen[rows] = columns
    modes, seen = [], {}
    order = np.argsort(np.abs(tracked.imag))
    for b in order:
        description = characterize(model, result.eigenvalues[chosen[b]],
                                   result.mode_shape(chosen[b])).description
        seen[description] = seen.get(description, 0) + 1
        name = description if seen[description] == 1 else f"{description} #{seen[description]}"
        lam = branches[:, b].copy()
        lam.imag = np.abs(lam.imag)  # the upper eigenvalue of each pair (its conjugate is one too)
        modes.append(CampbellMode(name, lam, index))
    return modes


def intersections(v: np.ndarray, mode_hz: np.ndarray, zeta: np.ndarray,
                  line_hz: np.ndarray) -> list[tuple[float, float, float]]:
    """Where the line ``line_hz`` (straight in v, or constant) meets the mode curve ``mode_hz``
    interpolated linearly between grid speeds ``v``: [(v [m/s], f [Hz], ζ [-])], on the intervals
    where the mode oscillates at both ends (f > 0)."""
    g = mode_hz - line_hz
    out = []
    for i in range(len(v) - 1):
        if mode_hz[i] <= 0 or mode_hz[i + 1] <= 0:
            continue
        if g[i] == 0 and i > 0:
            continue  # counted as the end of the previous interval
        if g[i] * g[i + 1] > 0 or (g[i] == 0 and g[i + 1] == 0):
            continue
        t = g[i] / (g[i] - g[i + 1]) if g[i] != g[i + 1] else 0.0
        vc = v[i] + t * (v[i + 1] - v[i])
        fc = line_hz[i] + t * (line_hz[i + 1] - line_hz[i])
        zc = zeta[i] + t * (zeta[i + 1] - zeta[i])
        out.append((float(vc), float(fc), float(zc)))
    return out


def severity(model: BogieModel, op: OperatingPoint, v: float, f_hz: float,
             input: str = DEFAULT_INPUT) -> dict[str, float]:
    """|H(f; v)| of every torque output [N m per N m of ``input``] at speed v [m/s] (the other
    quantities of ``op``), solved directly."""
    point = replace(op, v=v)
    force, _ = input_force(model, input)
    matrices = output_matrices(model, point)
    rows = [i for i, unit in enumerate(matrices.units) if unit == TORQUE_UNIT]
    H = solve_direct(model, damping_matrix(model, point), force, matrices.C_q[rows],
                matrices.C_v[rows], np.array([f_hz]))[:, 0]
    return {matrices.names[i]: float(abs(h)) for i, h in zip(rows, H, strict=True)}


# --- the forced response to a torque ripple over speed ---------------------------------------

@dataclass(frozen=True)
class RippleResponse:
    """Steady-state amplitudes of the outputs over speed under a motor torque ripple."""

    operating_point: OperatingPoint
    input: str
    v: np.ndarray  # (V,) [m/s]
    orders: tuple[Order, ...]
    amplitudes: np.ndarray  # (orders,) ripple amplitude of each order [N m]
    frequencies_hz: np.ndarray  # (orders, V) [Hz]; NaN beyond the model's validity
    names: tuple[str, ...]
    units: tuple[str, ...]
    by_order: np.ndarray  # (orders, outputs, V) steady amplitude [output unit]; NaN beyond validity
    total: np.ndarray  # (outputs, V): the sum over orders (the largest the steady state reaches)

    @property
    def v_kmh(self) -> np.ndarray:
        return self.v / KMH

    def peak(self, name: str) -> tuple[float, float]:
        """(largest total amplitude of output ``name`` [its unit], the speed [m/s] there)."""
        row = self.total[self.names.index(name)]
        i = int(np.nanargmax(row))
        return float(row[i]), float(self.v[i])


def ripple_response(model: BogieModel, op: OperatingPoint, v_values,
                    ripple: dict[Order, float], excitation: DriveExcitation,
                    input: str = DEFAULT_INPUT, outputs: list[str] | None = None,
                    refine: bool = True) -> RippleResponse:
    """Steady amplitudes of the outputs (default all named) over the speeds [m/s] under the
    ripple ``{order: amplitude [N m]}`` of ``input``'s torque, solved directly at each speed and
    order frequency (frequencies above the model's validity are left out: NaN); with
    ``refine``, the speeds of the resonances are added to the grid (module docstring)."""
    v = check_speeds(v_values)
    if refine:
        v = np.unique(np.concatenate([v, resonant_speeds(model, op, v, tuple(ripple), excitation,
                                                         input)]))
    if not ripple:
        raise CampbellError("no ripple orders given")
    _, unit = input_force(model, input)
    if unit != TORQUE_UNIT:
        raise CampbellError(f"a torque ripple acts through a motor: '{input}' is not a motor's "
                            "torque")
    force, _ = input_force(model, input)
    orders = tuple(ripple)
    amplitudes = np.array([ripple[o] for o in orders], dtype=float)
    frequencies = np.array([o.frequency_hz(v, model.parameters, excitation) for o in orders])
    frequencies[(frequencies > MODEL_FREQUENCY_LIMIT_HZ) | (frequencies <= 0)] = np.nan
    matrices, rows = output_indices(model, replace(op, v=float(v[0])), outputs)
    by_order = np.full((len(orders), len(rows), len(v)), np.nan)
    for i, speed in enumerate(v):
        point = replace(op, v=float(speed))
        matrices = output_matrices(model, point)
        valid = np.flatnonzero(np.isfinite(frequencies[:, i]))
        if not len(valid):
            continue
        H = solve_direct(model, damping_matrix(model, point), force, matrices.C_q[rows],
                    matrices.C_v[rows], frequencies[valid, i])
        by_order[valid, :, i] = (amplitudes[valid, None] * np.abs(H).T)
    total = np.nansum(by_order, axis=0)
    total[np.all(np.isnan(by_order), axis=0)] = np.nan
    return RippleResponse(op, input, v, orders, amplitudes, frequencies,
                          tuple(matrices.names[i] for i in rows),
                          tuple(matrices.units[i] for i in rows), by_order, total)


REFINE_BRACKET = 0.1  # the speed search spans ±10 % around the crossing of a resonance
REFINE_RTOL = 1e-6  # … down to this relative width


def resonant_speeds(model: BogieModel, op: OperatingPoint, v: np.ndarray,
                    orders: tuple[Order, ...], excitation: DriveExcitation,
                    input: str = DEFAULT_INPUT) -> np.ndarray:
    """Speeds [m/s] inside the range of ``v`` where an order (not a fixed frequency) drives a
    mode the motors drive (:func:`participation`, at the middle speed) hardest: for each such
    mode with damped frequency f_r and each order k, the speed with the largest
    ``max_p |H_p(f_k(v); v)| / max_v |H_p|`` within ±10 % of f_r / (df_k/dv) (and not beyond
    the midpoints to the neighbouring modes), by golden-section search (direct solves; the
    output rows of the middle speed: they only locate the peak)."""
    middle = replace(op, v=float(0.5 * (v[0] + v[-1])))
    lam = bogie_system(model, middle).eigen[0]
    chosen = (participation(model, middle) >= DEFAULT_PARTICIPATION) & (lam.imag > 0)
    frequencies = np.unique(lam[chosen].imag / (2 * np.pi))
    force, _ = input_force(model, input)
    matrices = output_matrices(model, middle)
    found = []
    for order in orders:
        slope = order.per_speed_hz(model.parameters, excitation)
        if slope <= 0:
            continue
        for j, f_r in enumerate(frequencies):
            below = 0.5 * (f_r - frequencies[j - 1]) if j > 0 else np.inf
            above = 0.5 * (frequencies[j + 1] - f_r) if j + 1 < len(frequencies) else np.inf
            low = max((f_r - min(below, REFINE_BRACKET * f_r)) / slope, v[0])
            high = min((f_r + min(above, REFINE_BRACKET * f_r)) / slope, v[-1])
            if not low < high or f_r > MODEL_FREQUENCY_LIMIT_HZ:
                continue

            def response(speed: float, slope=slope) -> np.ndarray:
                point = replace(op, v=speed)
                return np.abs(solve_direct(model, damping_matrix(model, point), force,
                                           matrices.C_q, matrices.C_v,
                                           np.array([slope * speed]))[:, 0])

            ends = np.maximum(response(low), response(high))
            scale = np.where(ends > 0, ends, 1.0)
            found.append(_golden_maximum(lambda speed, f=response, s=scale: float(np.max(f(speed) / s)),
                                         low, high))
    return np.array(found)


def _golden_maximum(function, low: float, high: float) -> float:
    """The argument of the largest value of ``function`` on [low, high] (unimodal there), to a
    relative width of :data:`REFINE_RTOL` (:func:`golden_section_maximum`)."""
    best, _ = golden_section_maximum(lambda x: np.array([function(float(x[0]))]),
                                     np.array([low]), np.array([high]), REFINE_RTOL)
    return float(best[0])


def speeds_kmh(start: float, stop: float, count: int) -> np.ndarray:
    """``count`` speeds from ``start`` to ``stop`` km/h, in m/s (checked)."""
    if not (math.isfinite(start) and math.isfinite(stop)) or not start < stop:
        raise CampbellError(f"the speed range {start:g}…{stop:g} km/h is empty: start must be "
                            "below stop")
    return check_speeds(np.linspace(start, stop, count) * KMH)

