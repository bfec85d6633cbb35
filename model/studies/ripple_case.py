"""The ripple load case of the assessment: both converters' torque ripple in normal running, the
steady forced response of every checked section over the speed range.

    case = ripple_case(parameters, assessed_outputs(parameters), AssessmentOptions())
    case.loads["ID1.driving_shaft.torque"].alternating      # (V,) amplitude over speed [N m]

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
the grid before refinement is checked stable at every creepage (else :class:`AssessmentError`).

**Per checked section** (an output of :func:`model.studies.assessment.assessed_outputs`), at each
speed v and creepage s0 of ``AssessmentOptions.s0`` (the short-circuit case's, default 0.002 and
0.005):

* the **mean**: the steady traction's static load at (s0, v) (both motors at M(s0, v),
  :func:`model.mechanics.outputs.static_deflection`);
* the **alternating amplitude**: per order ``A_k (|H_ID1(f_k; v)| + |H_ID2(f_k; v)|)`` — the two
  motors' contributions added as magnitudes, i.e. at the worst relative phase of the two
  converters, which the model does not know — summed over the orders (the largest the steady state
  reaches, when the orders' peaks coincide); ``H`` the frequency response from a motor's torque,
  solved directly (:func:`model.analysis.campbell.ripple_response`).

Over the creepages the case keeps, per speed, the mean of largest magnitude and the largest
amplitude (with its orders' shares), each from its own creepage: an envelope.  Every operating
point is linearized at its creepage; the converters' torque control (``motor_bandwidth`` of the
set) enters as it enters every response, through the model.  Steady state: no horizon.
Units: SI (speeds in m/s inside, km/h where a name says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from model.analysis.assessment import AlternatingLoad
from model.analysis.campbell import MOTOR_INPUTS, resonant_speeds, ripple_response
from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ
from model.analysis.load_peaks import GROWTH_RATE
from model.mechanics.excitation import DriveExcitation, Order, load_excitation
from model.mechanics.operating_point import KMH, OperatingPoint
from model.mechanics.parameters import Parameters
from model.studies.assessment import AssessmentError, AssessmentOptions, LoadCase, operating_point

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


def ripple_sweep(parameters: Parameters, outputs: list[str], options: AssessmentOptions
                 ) -> RippleSweep:
    """The responses of the ripple case (module docstring) before the envelope over creepages."""
    from model.analysis.eigen import bogie_system
    from model.mechanics.outputs import output_matrices, static_deflection
    from model.studies.maps import cached_model

    model = cached_model(parameters)
    drive = options.ripple_drive if options.ripple_drive is not None else load_excitation()
    ripple = options.ripple if options.ripple is not None else ripple_amplitudes(parameters)
    orders = tuple(ripple)
    coarse = np.asarray(options.ripple_v, dtype=float)
    points = [operating_point(parameters, s0, float(coarse[0]), options) for s0 in options.s0]
    for op in points:
        for speed in coarse:
            growth = float(np.max(bogie_system(model, replace(op, v=float(speed)))
                                  .eigenvalues().real))
            if growth > GROWTH_RATE:
                raise AssessmentError(
                    f"ripple case: s0 = {op.s0:g} is not stable at {speed / KMH:g} km/h (growth "
                    f"rate {growth:.3g} 1/s): a forced response needs stable points; take smaller "
                    "creepages or a lower top speed")
    found = [resonant_speeds(model, op, coarse, orders, drive, motor)
             for op in points for motor in MOTOR_INPUTS]
    refined = np.unique(np.concatenate([np.asarray(f, dtype=float) for f in found]))
    v = np.unique(np.concatenate([coarse, refined]))
    by_motor = np.zeros((len(points), len(MOTOR_INPUTS), len(orders), len(outputs), len(v)))
    mean = np.empty((len(points), len(outputs), len(v)))
    frequencies = np.full((len(orders), len(v)), np.nan)
    names: tuple[str, ...] = ()
    for a, op in enumerate(points):
        for m, motor in enumerate(MOTOR_INPUTS):
            response = ripple_response(model, op, v, ripple, drive, motor, outputs, refine=False)
            by_motor[a, m] = np.nan_to_num(response.by_order, nan=0.0)
            frequencies, names = response.frequencies_hz, response.names
        for i, speed in enumerate(v):
            point = replace(op, v=float(speed))
            matrices = output_matrices(model, point)
            values = matrices.C_q @ static_deflection(model, point)
            mean[a, :, i] = [values[matrices.index(name)] for name in names]
    return RippleSweep(v, refined, tuple(options.s0), orders,
                       np.array([ripple[o] for o in orders], dtype=float), frequencies, names,
                       by_motor, mean)


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


def ripple_case(parameters: Parameters, outputs: list[str], options: AssessmentOptions
                ) -> LoadCase:
    """The ripple case (module docstring): an :class:`AlternatingLoad` per output, checked by
    :func:`model.analysis.assessment.alternating_components`."""
    sweep = ripple_sweep(parameters, outputs, options)
    loads = envelope_loads(sweep)
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
        "magnitudes (the worst relative phase) and summed over the orders"
        + (f"; {', '.join(beyond)} beyond the model's {MODEL_FREQUENCY_LIMIT_HZ:g} Hz at the "
           "highest speeds, left out there" if beyond else ""))
    scenario = {"s0": list(sweep.s0), "v_kmh": [float(x) for x in coarse_kmh],
                "v_kmh_refined": [float(x) for x in sweep.refined / KMH],
                "orders": [{"order": o.name, "amplitude": float(a)}
                           for o, a in zip(sweep.orders, sweep.ripple, strict=True)],
                "motors": list(MOTOR_INPUTS), "phase": "worst (magnitudes added)",
                "N0": first.N0, "b_M": first.b_M,
                "motor_bandwidth": parameters["motor_bandwidth"], "creep": "linear"}
    return LoadCase("ripple", description, None, loads, scenario, alternating=True)


def check_ripple(ripple: dict) -> None:
    """Refuse a ripple that is not {Order: amplitude ≥ 0 [N m]} with at least one order, or a fixed
    frequency beyond the model's range (:class:`AssessmentError`, one line)."""
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


__all__ = ["RIPPLE_PARAMETERS", "DriveExcitation", "OperatingPoint", "RippleSweep",
           "check_ripple", "envelope_loads", "ripple_amplitudes", "ripple_case", "ripple_sweep"]
