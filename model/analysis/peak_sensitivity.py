"""Peak drive loads' sensitivities: central differences of the closed-form short-circuit
response at the nominal peak's sample (envelope theorem: the peak is stationary in time)."""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from model.analysis.response import short_circuit_response
from model.analysis.sensitivity import SensitivityError
from model.mechanics.assembly import build_model
from model.mechanics.operating_point import OperatingPoint
from model.mechanics.parameters import SCHEMA, Parameters

PEAK_LOADS = ("ID1.disc_clutch.torque", "ID2.disc_clutch.torque",
              "ID1.driving_shaft.torque", "ID2.driving_shaft.torque")
PEAK_STEP = 1e-3  # relative central-difference step of the peak-load sensitivities


@dataclass(frozen=True)
class PeakLoadSensitivity:
    """d(peak total load)/dp after the short circuit (plain data)."""

    operating_point: OperatingPoint
    outputs: tuple[str, ...]  # load names
    peaks: np.ndarray  # signed peak totals [N m]
    peak_times: np.ndarray  # [s]
    names: tuple[str, ...]  # parameters
    values: np.ndarray  # their values
    derivatives: np.ndarray  # len(names) x len(outputs) [N m per unit]
    seconds: float  # wall time of the whole computation [s]

    @property
    def normalized(self) -> np.ndarray:
        """p/peak · d peak/dp [-]."""
        return self.values[:, None] * self.derivatives / self.peaks[None, :]


def peak_load_sensitivities(parameters: Parameters, op: OperatingPoint,
                            names: Iterable[str] | None = None, step: float = PEAK_STEP,
                            t_end: float = 0.5, fs: float = 10_000.0, progress=None) -> PeakLoadSensitivity:
    """Sensitivities of the peak ID1/ID2 disc-clutch and driving-shaft torques (totals) to each
    parameter by central differences of the closed-form response, evaluated **at the nominal
    peak's sample** (envelope theorem: the peak is stationary in time, so moving its time changes
    it only at second order, while the maximum over a grid would jump from sample to sample).

    Step ``step`` relative (10⁻³): the truncation error is O(step²) ≈ 10⁻⁶ relative, the closed
    form's own error (≈ 10⁻⁷ of the response, docs/response.md) divided by the step ≈ 10⁻⁴.
    Cost: two model assemblies, eigendecompositions and responses per parameter.

    Example (parameters x outputs):
        >>> from model import default_operating_point, load_parameters, peak_load_sensitivities
        >>> p = load_parameters(); peaks = peak_load_sensitivities(p, default_operating_point(p), names=["gear_ratio"])
        >>> peaks.normalized.shape
        (1, 4)
    """


    start = time.perf_counter()
    wanted = list(SCHEMA) if names is None else list(names)
    for name in wanted:
        if name not in SCHEMA:
            raise SensitivityError(f"unknown parameter '{name}'")
    nominal = short_circuit_response(build_model(parameters), op, t_end=t_end, fs=fs,
                                     outputs=list(PEAK_LOADS))
    samples = [round(nominal.peak_times[name] * fs) for name in PEAK_LOADS]
    peaks = np.array([nominal.peaks[name] for name in PEAK_LOADS])
    rows = []
    for done, name in enumerate(wanted):
        value = parameters[name]
        h = step * abs(value) if value != 0 else step
        side = []
        for sign in (1.0, -1.0):
            values = dict(parameters.values)
            values[name] = value + sign * h
            moved = Parameters(values, parameters.notes, parameters.source)
            moved_op = op
            if name == "wheel_force" and op.N0 == value:
                moved_op = OperatingPoint(op.s0, op.v, value + sign * h, op.b_M)
            if name == "motor_slope" and op.b_M == value:
                moved_op = OperatingPoint(op.s0, op.v, op.N0, value + sign * h)
            response = short_circuit_response(build_model(moved), moved_op, t_end=t_end, fs=fs,
                                              outputs=list(PEAK_LOADS))
            side.append([response.outputs[load][k] for load, k in zip(PEAK_LOADS, samples,
                                                                       strict=True)])
        rows.append((np.array(side[0]) - np.array(side[1])) / (2 * h))
        if progress is not None:
            progress(done + 1, len(wanted))
    return PeakLoadSensitivity(op, PEAK_LOADS, peaks,
                               np.array([nominal.peak_times[n] for n in PEAK_LOADS]), tuple(wanted),
                               np.array([parameters[n] for n in wanted]), np.array(rows),
                               time.perf_counter() - start)
