"""What the wheels' surface deviations do to the drive in steady running: the four wheels' inputs
with their phases, and the steady response over speed to out-of-round (polygonal) wheels.

**The four wheels.**  A deviation met by the front wheelset (ID1's, at x = +wheelbase/2, the
running direction +x) reaches the rear one (ID2's) a wheelbase later: at angular frequency ω the
rear wheels' inputs lag by ``ω · wheelbase / v`` (:func:`wheel_phases`, from the rims' places in
the model).  The two wheels of one wheelset are in phase (a wheelset's two wheels are re-profiled
together and wear alike; a rail irregularity under both rails alike).

**The steady response** at one frequency: ``H_j(iω)`` from each wheel's deviation
``IDk.rimNN.irregularity`` [m] (:mod:`model.mechanics.irregularity`, the running system), solved
directly from the running system's dynamic stiffness with the four wheels' forces as four
right-hand sides of one factorization; the wheels together give ``Σ_j H_j e^(i φ_j)`` per metre.

**Polygonal wheels.**  A polygon of order n (n waves around the circumference, amplitude a [m] of
the radius) on a wheel of radius r0 rolling at v excites at ``f = n v / (2π r0)``.  Every wheel
carries the same polygon (order and amplitude), the wheels' phases as above; each output's steady
amplitude is ``a_n |Σ_j H_j(2π f_n) e^(i φ_j)|`` per order, and the sum over the orders is the
largest the steady state reaches (:func:`polygon_response`).  A lightly damped resonance is
narrower in speed than any grid: every local maximum of the grid's normalized response is refined
by golden-section search in speed.

Linear, about the operating point of each speed (creepage s0 fixed); no contact filter (a
polygon's wavelength, 2π r0 / n, is long against the contact patch for the orders that reach the
model's 1 kHz), no loss of contact (the deviation's force must stay below the static wheel force).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from model.analysis.eigen import non_neutral, running_system
from model.analysis.frequency_response import (
    MODEL_FREQUENCY_LIMIT_HZ,
    golden_section_maximum,
    output_indices,
)
from model.mechanics.assembly import BogieModel
from model.mechanics.irregularity import irregularity_forces
from model.mechanics.operating_point import KMH, OperatingPoint, damping_matrix

REFINE_RTOL = 1e-6  # the speed search's relative width
MAX_POLYGON_ORDER = 200  # orders above this are refused (a typo, not a polygon)
MAX_POLYGON_AMPLITUDE = 5e-3  # [m]: a 5 mm radial deviation is a wheel to be re-profiled, not run


class WheelExcitationError(ValueError):
    """Bad input for a wheel excitation (one-line message)."""


def wheel_phases(model: BogieModel, omega: float, v: float) -> np.ndarray:
    """The four wheels' phases [rad] (order of ``model.rims``) of a deviation the front wheelset
    meets at phase 0: ``−ω (x_front − x_j) / v`` with the rims' longitudinal places x_j [m]."""
    x = np.array([model.positions[rim][0] for rim in model.rims])
    return -omega * (x.max() - x) / v


class WheelTransfer:
    """The running system's pieces at one operating point, for H_j(2π f) from each wheel's
    deviation at many frequencies (the matrices are formed once)."""

    def __init__(self, model: BogieModel, op: OperatingPoint, rows: np.ndarray | None = None):
        forces = irregularity_forces(model, op)
        matrices, all_rows = output_indices(model, op)
        rows = all_rows if rows is None else rows
        self.model, self.op = model, op
        self.M, self.K = model.M + forces.M_c, model.K + forces.K_c
        self.B = damping_matrix(model, op) + forces.B_c
        self.G = (forces.G_q, forces.G_v, forces.G_a)
        self.C_q, self.C_v = matrices.C_q[rows], matrices.C_v[rows]

    def wheels(self, f_hz: float) -> np.ndarray:
        """H_j(2π f) (p x 4 complex) [output unit per m]: the dynamic stiffness solved once with
        the four wheels' generalized forces ``G_q + iω G_v − ω² G_a``."""
        s = 2j * math.pi * f_hz
        G_q, G_v, G_a = self.G
        q = np.linalg.solve(s * s * self.M + s * self.B + self.K, G_q + s * G_v + s * s * G_a)
        return (self.C_q + s * self.C_v) @ q

    def combined(self, f_hz: float) -> tuple[np.ndarray, np.ndarray]:
        """(Σ_j H_j(2π f) e^(i φ_j) (p complex), the phases φ_j [rad]) (:func:`wheel_phases`)."""
        phases = wheel_phases(self.model, 2 * math.pi * f_hz, self.op.v)
        return self.wheels(f_hz) @ np.exp(1j * phases), phases


class ModalWheels:
    """Σ_j H_j(2π f) e^(i φ_j) at many frequencies from the running system's modal form (the
    cached eigendecomposition: a few microseconds a frequency, against a dense solve of the
    dynamic stiffness each), each wheel's H_j as
    :func:`model.analysis.frequency_response.irregularity_transfer` forms it; where the modal
    sum's rounding estimate exceeds ``MODAL_TOLERANCE`` of an output's scale, those frequencies
    are solved directly (:class:`WheelTransfer`), as the frequency response does.  The scale is
    each output's largest value on the first frequencies asked (a caller's grid over its band;
    later calls, one frequency each, are judged against it)."""

    def __init__(self, model: BogieModel, op: OperatingPoint, rows: np.ndarray | None = None):
        from model.analysis.frequency_response import irregularity_transfer
        from model.mechanics.irregularity import irregularity_inputs

        matrices, all_rows = output_indices(model, op)
        rows = all_rows if rows is None else rows
        self.model, self.op = model, op
        self.transfers = [irregularity_transfer(model, op, name, matrices, rows)
                          for name in irregularity_inputs(model)]
        self.direct = WheelTransfer(model, op, rows)
        self.direct_points = 0  # frequencies solved directly so far
        self.scale: np.ndarray | None = None  # (p, 1) each output's largest |Σ H_j e^(iφ_j)|

    def combined(self, f_hz) -> np.ndarray:
        """Σ_j H_j(2π f) e^(i φ_j) (p x F complex) [output unit per m] at ``f_hz`` [Hz] (> 0)."""
        from model.analysis.frequency_response import MODAL_TOLERANCE

        f = np.atleast_1d(np.asarray(f_hz, dtype=float))
        phases = wheel_phases(self.model, 2 * math.pi * f[:, None], self.op.v).T  # 4 x F
        H = sum(t(f) * np.exp(1j * phases[j])[None, :] for j, t in enumerate(self.transfers))
        estimate = sum(t.rounding_estimate(f) for t in self.transfers)
        if self.scale is None:
            self.scale = np.abs(H).max(axis=1, keepdims=True)
        for k in np.flatnonzero(np.any(estimate > MODAL_TOLERANCE * self.scale, axis=0)):
            H[:, k] = self.direct.combined(float(f[k]))[0]
            self.direct_points += 1
        return H


def wheel_responses(model: BogieModel, op: OperatingPoint, f_hz: float,
                    rows: np.ndarray | None = None) -> np.ndarray:
    """H_j(2π f) of the chosen output rows (default all) from each wheel's deviation [output unit
    per m] (p x 4 complex): :meth:`WheelTransfer.wheels`."""
    return WheelTransfer(model, op, rows).wheels(f_hz)


def combined_response(model: BogieModel, op: OperatingPoint, f_hz: float,
                      rows: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(Σ_j H_j(2π f) e^(i φ_j) per metre of the front wheels' deviation (p complex), the phases
    φ_j [rad]) at ``op``'s speed (:func:`wheel_phases`)."""
    return WheelTransfer(model, op, rows).combined(f_hz)


def polygon_frequency_hz(order: float, v, r0: float) -> np.ndarray:
    """n v / (2π r0) [Hz] of a polygon of order n at speeds v [m/s] on wheels of radius r0 [m]."""
    return order * np.asarray(v, dtype=float) / (2 * math.pi * r0)


def parse_polygon(text: str) -> dict[int, float]:
    """``"20=30,21=12"`` (order = amplitude in µm) -> {order: amplitude [m]}.  Raises
    :class:`WheelExcitationError`."""
    polygon: dict[int, float] = {}
    tokens = [token for token in text.split(",") if token.strip()]
    if not tokens:
        raise WheelExcitationError("no wheel polygon given: write order=amplitude [µm], e.g. 20=30")
    for token in tokens:
        if token.count("=") != 1:
            raise WheelExcitationError(f"'{token.strip()}' is not order=amplitude [µm] (e.g. 20=30)")
        left, right = (part.strip() for part in token.split("="))
        try:
            order, amplitude = int(left), float(right) * 1e-6
        except ValueError:
            raise WheelExcitationError(f"'{token.strip()}': the order must be a whole number and "
                                       "the amplitude a number [µm]") from None
        if not 1 <= order <= MAX_POLYGON_ORDER:
            raise WheelExcitationError(f"polygon order {order} is not allowed: 1 to "
                                       f"{MAX_POLYGON_ORDER}")
        if not (math.isfinite(amplitude) and 0 <= amplitude <= MAX_POLYGON_AMPLITUDE):
            raise WheelExcitationError(f"'{token.strip()}': the amplitude must be in [0, "
                                       f"{MAX_POLYGON_AMPLITUDE * 1e6:g}] µm")
        if order in polygon:
            raise WheelExcitationError(f"polygon order {order} is given twice")
        polygon[order] = amplitude
    return polygon


@dataclass(frozen=True)
class PolygonResponse:
    """Steady amplitudes of the outputs over speed under polygonal wheels."""

    operating_point: OperatingPoint
    v: np.ndarray  # (V,) [m/s], the refined grid
    orders: tuple[int, ...]  # polygon orders n
    amplitudes: np.ndarray  # (orders,) radial amplitude [m]
    frequencies_hz: np.ndarray  # (orders, V) [Hz]; NaN beyond the model's range
    phases_deg: np.ndarray  # (orders, 4) the wheels' phases [deg] (speed-independent: n·wheelbase/r0)
    inputs: tuple[str, ...]  # the wheels' inputs, IDk.rimNN.irregularity
    names: tuple[str, ...]
    units: tuple[str, ...]
    by_order: np.ndarray  # (orders, outputs, V) [output unit]; NaN beyond the model's range
    total: np.ndarray  # (outputs, V): the sum over the orders
    unstable_kmh: tuple[float, ...]  # speeds of the grid's first, middle, last whose running system grows

    @property
    def v_kmh(self) -> np.ndarray:
        return self.v / KMH

    def peak(self, name: str) -> tuple[float, float]:
        """(largest total amplitude of output ``name`` [its unit], the speed [m/s] there)."""
        row = self.total[self.names.index(name)]
        i = int(np.nanargmax(row))
        return float(row[i]), float(self.v[i])


def polygon_response(model: BogieModel, op: OperatingPoint, v_values,
                     polygon: dict[int, float], outputs: list[str] | None = None,
                     refine: bool = True) -> PolygonResponse:
    """Steady amplitudes of the outputs (default all named) over the speeds [m/s] under polygonal
    wheels ``{order: radial amplitude [m]}`` (module docstring), at ``op``'s creepage, wheel
    force and motor slope."""
    if not polygon:
        raise WheelExcitationError("no wheel polygon given")
    v = np.asarray(v_values, dtype=float)
    if v.ndim != 1 or len(v) < 2 or not np.all(np.isfinite(v)) or np.any(np.diff(v) <= 0):
        raise WheelExcitationError("the speeds must be two or more increasing finite values")
    r0 = model.parameters["wheel_radius"]
    orders = tuple(sorted(polygon))
    amplitudes = np.array([polygon[n] for n in orders])
    matrices, rows = output_indices(model, op, outputs)

    def solve(speeds: np.ndarray) -> np.ndarray:
        out = np.full((len(orders), len(rows), len(speeds)), np.nan)
        for i, speed in enumerate(speeds):
            system = WheelTransfer(model, replace(op, v=float(speed)), rows)
            for k, n in enumerate(orders):
                f = float(polygon_frequency_hz(n, speed, r0))
                if 0 < f <= MODEL_FREQUENCY_LIMIT_HZ:
                    H, _ = system.combined(f)
                    out[k, :, i] = amplitudes[k] * np.abs(H)
        return out

    by_order = solve(v)
    if refine:
        extra = _resonant_speeds(v, by_order, solve)
        if len(extra):
            v = np.concatenate([v, extra])
            by_order = np.concatenate([by_order, solve(extra)], axis=2)
            order = np.argsort(v)
            v, by_order = v[order], by_order[:, :, order]
    total = np.nansum(by_order, axis=0)
    total[np.all(np.isnan(by_order), axis=0)] = np.nan
    frequencies = np.array([polygon_frequency_hz(n, v, r0) for n in orders])
    frequencies[frequencies > MODEL_FREQUENCY_LIMIT_HZ] = np.nan
    x = np.array([model.positions[rim][0] for rim in model.rims])
    phases = np.degrees(-np.outer(orders, x.max() - x) / r0)  # ω Δx / v = n Δx / r0
    unstable = []
    for speed in (v[0], v[len(v) // 2], v[-1]):
        lam = running_system(model, replace(op, v=float(speed))).eigen[0]
        if np.any(lam[non_neutral(lam)].real > 0):
            unstable.append(float(speed / KMH))
    forces_names = irregularity_forces(model, op).names
    return PolygonResponse(op, v, orders, amplitudes, frequencies, phases, forces_names,
                           tuple(matrices.names[i] for i in rows),
                           tuple(matrices.units[i] for i in rows), by_order, total,
                           tuple(unstable))


def _resonant_speeds(v: np.ndarray, by_order: np.ndarray, solve) -> np.ndarray:
    """Speeds [m/s] of the local maxima of the grid's response (each output's total over its
    largest on the grid, the largest over the outputs) refined by golden-section search between
    the maximum's neighbours."""
    total = np.nansum(by_order, axis=0)
    scale = np.nanmax(total, axis=1, keepdims=True)
    scale[~(scale > 0)] = 1.0

    def measure(values: np.ndarray) -> float:
        return float(np.nanmax(np.nansum(values, axis=0) / scale)) if np.any(np.isfinite(values)) else 0.0

    curve = np.nanmax(total / scale, axis=0)
    interior = np.flatnonzero((curve[1:-1] > curve[:-2]) & (curve[1:-1] >= curve[2:])) + 1
    found = []
    for i in interior:
        best, _ = golden_section_maximum(
            lambda x: np.array([measure(solve(np.array([float(x[0])])))]),
            np.array([v[i - 1]]), np.array([v[i + 1]]), REFINE_RTOL)
        found.append(float(best[0]))
    found_array = np.array(found)
    return found_array[~np.isin(found_array, v)]
