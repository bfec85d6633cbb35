"""What the ripple load case of the assessment computes: both converters' torque ripple in normal
running, the steady forced response of every checked section over the speed range
(:func:`model.studies.assessment.ripple_case` makes the load case of it).

    sweep = ripple_sweep(model, [op], speeds, ripple_amplitudes(parameters), load_excitation(),
                         ["ID1.driving_shaft.torque"])
    envelope_loads(sweep)["ID1.driving_shaft.torque"].alternating   # (V,) amplitude [N m]

**The excitation.**  Each traction motor's air-gap torque carries a ripple ``A_k cos(2π f_k(v)
t)`` at the orders k of the parameter set (``ripple_el6_amplitude``, ``ripple_el12_amplitude``:
the 6th and 12th harmonics of the motor's electrical frequency, :func:`ripple_amplitudes`), or at
the orders and amplitudes of ``AssessmentOptions.ripple`` (any :class:`Order`, a fixed frequency
too); both motors at the same orders and amplitudes.  The orders' frequencies follow the speed
(:mod:`model.mechanics.excitation`, the motor's pole pairs and the pinion's teeth of
``AssessmentOptions.ripple_drive``); a frequency above the model's range (1 kHz) is left out at
that speed (its share is 0 there).

**The speeds.**  The grid ``AssessmentOptions.ripple_v`` (default 10…200 km/h, the locomotive's
top speed, every 10 km/h) plus the speeds where an order drives a resonance of a mode the motors
drive hardest, found for each motor and each creepage by
:func:`model.analysis.campbell.resonant_speeds` (a golden-section search in speed): a lightly
damped resonance is narrower in speed than any grid, and its peak is a grid point.  Every point of
the grid before refinement is checked stable at every creepage (else :class:`RippleCaseError`).

**Per checked section** (an output of :func:`model.studies.assessment.assessed_outputs`), at each
speed v and creepage s0 of ``AssessmentOptions.s0`` (the short-circuit case's, default 0.002 and
0.005):

* the **mean**: the steady traction's static load at (s0, v) (both motors at M(s0, v),
  :func:`model.mechanics.outputs.static_deflection`);
* the **alternating amplitude**: per order ``A_k (|H_ID1(f_k; v)| + |H_ID2(f_k; v)|)`` — the two
  motors' contributions added as magnitudes, i.e. at the worst relative phase of the two
  converters, which the model does not know — summed over the orders (the largest the steady state
  reaches, when the orders' peaks coincide); ``H`` the frequency response from a motor's torque,
  solved directly from the dynamic stiffness (both motors' torques in one solve per speed and
  order), as :func:`model.analysis.campbell.ripple_response` does for one motor.

Over the creepages the case keeps, per speed, the mean of largest magnitude and the largest
amplitude (with its orders' shares), each from its own creepage: an envelope.  Every operating
point is linearized at its creepage.  **The motors as the model has them**: only ID2's motor has
the falling slope b_M (in the study ID1's is the one that short-circuits), filtered by the
converter's torque control ``motor_bandwidth`` of the set as in every response; ID1's motor is a
pure torque source, i.e. a converter that holds its torque (and its ripple) against the drive's
motion.  The slope damps ID2's driving-shaft mode, so ID1's sections carry the larger,
conservative amplitudes of the two.  Steady state: no horizon.
Units: SI (speeds in m/s inside, km/h where a name says so).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from model.analysis.assessment import AlternatingLoad
from model.analysis.campbell import MOTOR_INPUTS, REFINE_RTOL, resonant_speeds
from model.analysis.load_peaks import GROWTH_RATE
from model.mechanics.assembly import BogieModel
from model.mechanics.excitation import DriveExcitation, Order
from model.mechanics.operating_point import KMH, OperatingPoint
from model.mechanics.parameters import Parameters

# parameter of the set -> the order its amplitude drives (each converter)
RIPPLE_PARAMETERS = {"ripple_el6_amplitude": Order("el", 6.0),
                     "ripple_el12_amplitude": Order("el", 12.0)}


def ripple_amplitudes(parameters: Parameters) -> dict[Order, float]:
    """The converters' ripple of the parameter set: {order: amplitude [N m]} per motor."""
    return {order: parameters[name] for name, order in RIPPLE_PARAMETERS.items()}


@dataclass(frozen=True)
class RippleSweep:
    """Both motors' steady ripple responses and the steady traction over one speed grid, per
    creepage (the raw material of the case)."""

    v: np.ndarray  # (V,) speeds [m/s], the refined grid
    refined: np.ndarray  # the speeds the resonance search added [m/s]
    s0: tuple[float, ...]  # creepages [-]
    orders: tuple[Order, ...]
    ripple: np.ndarray  # (orders,) each converter's amplitude [N m]
    frequencies_hz: np.ndarray  # (orders, V) [Hz]; nan beyond the model's range
    names: tuple[str, ...]  # the outputs
    by_motor: np.ndarray  # (s0, motors, orders, outputs, V) steady amplitude [N m]; 0 beyond range
    mean: np.ndarray  # (s0, outputs, V) the steady traction's load [N m]

    @property
    def alternating_by_order(self) -> np.ndarray:
        """(s0, orders, outputs, V): the motors' contributions added as magnitudes [N m]."""
        return self.by_motor.sum(axis=1)


class RippleCaseError(ValueError):
    """Bad input for the ripple case (one-line message)."""


def ripple_sweep(model: BogieModel, points: list[OperatingPoint],
                 speeds: np.ndarray | tuple[float, ...], ripple: dict[Order, float],
                 drive: DriveExcitation, outputs: list[str], extra_speeds=None) -> RippleSweep:
    """The responses of the ripple case (module docstring) before the envelope over creepages:
    ``points`` one operating point per creepage (its s0, N0 and b_M; the speed is replaced by
    each of ``speeds`` [m/s], the grid before refinement), each converter's ``ripple``
    {order: amplitude [N m]}, the motor's pole pairs and the pinion's teeth ``drive``.  An
    unstable point of the grid is refused (:class:`RippleCaseError`).  ``extra_speeds`` [m/s]
    (e.g. a route's, between the grid's ends) join the refined grid: computed, not checked for
    stability one by one, as the refinement's own speeds."""
    from model.analysis.eigen import bogie_system
    from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ, input_force, output_indices
    from model.mechanics.operating_point import damping_matrix
    from model.mechanics.outputs import static_deflection

    orders = tuple(ripple)
    coarse = np.asarray(speeds, dtype=float)
    for op in points:
        for speed in coarse:
            growth = float(np.max(bogie_system(model, replace(op, v=float(speed)))
                                  .eigenvalues().real))
            if growth > GROWTH_RATE:
                raise RippleCaseError(
                    f"ripple case: s0 = {op.s0:g} is not stable at {speed / KMH:g} km/h (growth "
                    f"rate {growth:.3g} 1/s): a forced response needs stable points; take smaller "
                    "creepages or a lower top speed")
    found = [resonant_speeds(model, op, coarse, orders, drive, motor)
             for op in points for motor in MOTOR_INPUTS]
    refined = distinct_speeds(np.concatenate([np.asarray(f, dtype=float) for f in found]))
    extra = np.zeros(0) if extra_speeds is None else np.asarray(extra_speeds, dtype=float)
    v = np.unique(np.concatenate([coarse, refined, extra]))
    frequencies = np.array([order.frequency_hz(v, model.parameters, drive) for order in orders])
    frequencies[(frequencies > MODEL_FREQUENCY_LIMIT_HZ) | (frequencies <= 0)] = np.nan
    forces = np.column_stack([input_force(model, motor)[0] for motor in MOTOR_INPUTS])
    amplitudes = np.array([ripple[o] for o in orders], dtype=float)
    by_motor = np.zeros((len(points), len(MOTOR_INPUTS), len(orders), len(outputs), len(v)))
    mean = np.empty((len(points), len(outputs), len(v)))
    for a, op in enumerate(points):
        for i, speed in enumerate(v):
            point = replace(op, v=float(speed))
            matrices, rows = output_indices(model, point, outputs)
            mean[a, :, i] = (matrices.C_q @ static_deflection(model, point))[rows]
            damping = damping_matrix(model, point)
            for k in np.flatnonzero(np.isfinite(frequencies[:, i])):
                w = 2 * np.pi * frequencies[k, i]
                q = np.linalg.solve(-w * w * model.M + 1j * w * damping + model.K, forces)
                H = (matrices.C_q[rows] + 1j * w * matrices.C_v[rows]) @ q  # (outputs, motors)
                by_motor[a, :, k, :, i] = amplitudes[k] * np.abs(H).T
    names = tuple(outputs)
    return RippleSweep(v, refined, tuple(op.s0 for op in points), orders, amplitudes, frequencies,
                       names, by_motor, mean)


def distinct_speeds(speeds: np.ndarray) -> np.ndarray:
    """The speeds [m/s] sorted, one of each cluster closer than the resonance search's own
    resolution (:data:`model.analysis.campbell.REFINE_RTOL` of the speed): the same peak found
    for another creepage or motor is one grid point."""
    kept: list[float] = []
    for speed in np.sort(speeds):
        if not kept or speed - kept[-1] > REFINE_RTOL * speed:
            kept.append(float(speed))
    return np.array(kept)


def envelope_loads(sweep: RippleSweep) -> dict[str, AlternatingLoad]:
    """Per output over the speeds: the mean of largest magnitude and the largest amplitude (with
    its orders' shares) over the creepages, each with the creepage it comes from."""
    by_order = sweep.alternating_by_order  # (s0, orders, outputs, V)
    total = by_order.sum(axis=1)  # (s0, outputs, V)
    speeds = np.arange(len(sweep.v))
    loads = {}
    for j, name in enumerate(sweep.names):
        at_mean = np.argmax(np.abs(sweep.mean[:, j, :]), axis=0)  # (V,) creepage index
        at_amplitude = np.argmax(total[:, j, :], axis=0)
        scenarios = tuple({"s0": sweep.s0[b], "s0_mean": sweep.s0[a]}
                          for a, b in zip(at_mean, at_amplitude, strict=True))
        loads[name] = AlternatingLoad(
            sweep.v, sweep.mean[at_mean, j, speeds], total[at_amplitude, j, speeds], sweep.orders,
            sweep.ripple, sweep.frequencies_hz, by_order[at_amplitude, :, j, speeds].T, scenarios)
    return loads
