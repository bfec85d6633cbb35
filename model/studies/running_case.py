"""What the running load case of the assessment computes: normal running over the speed range
with everything that alternates — the converters' torque ripple, polygonal wheels and the random
track — on the steady traction's mean (:func:`model.studies.assessment.running_case` makes the
load case of it).

Per checked section (an output of :func:`model.studies.assessment.assessed_outputs`), at each
speed v of the grid and creepage s0:

* the **mean**: the steady traction's static load (both motors at M(s0, v));
* the **ripple**: both converters' ripple at the ripple case's orders and amplitudes, the two
  motors' responses added as magnitudes (the worst relative phase), summed over the orders
  (:mod:`model.studies.ripple_case`, on the study's system: the motors' torques do not change the
  wheel force);
* the **wheel polygon**: ``Σ_n a_n |Σ_j H_j(2π f_n) e^(i φ_j)|``, ``f_n = n v / (2π r0)``, every
  wheel with the same polygon, a wheelset's wheels in phase, the rear wheelset a wheelbase later
  (:mod:`model.analysis.wheel_excitation`, on the running system): the check's ``amplitude``;
* the **random track**: the RMS of the section's torque under the track spectrum
  (:mod:`model.analysis.track_spectrum`), counted as ``random_multiple`` times the RMS (default 3:
  a Gaussian process exceeds 3σ in 0.27 % of the time, and its peaks beyond it are rare);

and the alternating amplitude the checks take is ``ripple + amplitude + random_multiple · rms``
(all at their worst relative phase: added as magnitudes).  Press fits against ``|mean| +
alternating`` (slip at the peak), the shafts' DIN 743 fatigue with that amplitude about the mean,
the couplings' T_KW against it (:func:`model.analysis.assessment.verify_alternating`).  The
deterministic parts are the steady state, the random one stationary: a point of the grid
(creepage, speed) whose running system has a growing mode has neither, so it is left out of the
checks and listed (``RunningSweep.unstable``, the load case's description and ``unstable`` in its
scenario: a finding of its own, the running system's stability limit); a grid without one stable
point is refused (:class:`RunningCaseError`).

**The random part's spectral fatigue damage** (beside the verdict, which is DIN 743's amplitude
check): for a shaft's fatigue check, the Miner damage per hour of the random torque alone at the
check's speed by Dirlik's method and the narrow-band bound (:mod:`model.analysis.spectral_fatigue`)
against an S–N curve in torque amplitude through the permissible amplitude T_ADK about the mean
at N_D = 10⁶ cycles with the slope k = 8 for shear stress and Haibach's 2k − 1 = 15 below the knee
(FKM guideline, the torsion of steel; :data:`RANDOM_SN_SLOPE`, :data:`RANDOM_SN_KNEE`).  It
says how much the random track alone uses up per hour of running at that speed; the
deterministic amplitudes on top of it are not in that number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from model.analysis.assessment import AlternatingLoad, Check, Component, verify_alternating
from model.analysis.campbell import MOTOR_INPUTS
from model.analysis.eigen import non_neutral, running_system
from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ, input_force, output_indices
from model.analysis.track_spectrum import TrackSpectrum, random_response
from model.analysis.wheel_excitation import WheelTransfer, polygon_frequency_hz
from model.mechanics.assembly import BogieModel
from model.mechanics.excitation import DriveExcitation, Order
from model.mechanics.operating_point import KMH, OperatingPoint, damping_matrix
from model.mechanics.outputs import static_deflection

DEFAULT_RANDOM_MULTIPLE = 3.0  # the random part counted as 3 × RMS
DEFAULT_RUNNING_S0 = (0.002, 0.005)  # [-]: the ripple case's creepages (the running system of the
# bundled set is stable at both over 20…250 km/h; at 0.007 it grows from about 175 km/h)
DEFAULT_RUNNING_V = tuple(float(x) * KMH for x in np.linspace(20.0, 200.0, 10))  # [m/s]
# the wheel polygon of the running case: order 20 is the ≈ 200 mm wavelength of high-power AC
# locomotives' polygonal wear on 1250 mm wheels (docs/resonance.md, its sources); 30 µm is an
# assumed radial amplitude, not a measured one (none was available in a form to cite)
DEFAULT_WHEEL_POLYGON = {20: 30e-6}
RANDOM_SN_SLOPE = 8.0  # k of the S–N curve for shear stress (FKM guideline, steel)
RANDOM_SN_KNEE = 1e6  # N_D [cycles] at the permissible amplitude


class RunningCaseError(ValueError):
    """Bad input for the running case (one-line message)."""


@dataclass(frozen=True)
class RunningSweep:
    """The running case's responses over one speed grid, per creepage."""

    v: np.ndarray  # (V,) [m/s]
    s0: tuple[float, ...]
    names: tuple[str, ...]  # the outputs
    mean: np.ndarray  # (s0, outputs, V) steady traction's load [N m]
    ripple: np.ndarray  # (s0, outputs, V) the converters' ripple amplitude [N m]
    ripple_orders: tuple[Order, ...]
    ripple_amplitudes: np.ndarray  # (ripple orders,) per converter [N m]
    polygon_orders: tuple[int, ...]
    polygon_amplitudes: np.ndarray  # (polygon orders,) radial amplitude [m]
    polygon: np.ndarray  # (s0, polygon orders, outputs, V) each order's share [N m]
    polygon_hz: np.ndarray  # (polygon orders, V) [Hz]; nan beyond the model's range
    phases_deg: np.ndarray  # (polygon orders, 4) the wheels' phases [deg]
    inputs: tuple[str, ...]  # the wheels' inputs
    rms: np.ndarray  # (s0, outputs, V) the random track's RMS [N m]
    moments: np.ndarray  # (s0, outputs, V, 4) its spectral moments m0, m1, m2, m4
    random_multiple: float
    spectrum: TrackSpectrum
    unstable: tuple[dict, ...] = ()  # the points left out: {"s0", "v_kmh", "growth" [1/s]}

    def alternating(self) -> np.ndarray:
        """(s0, outputs, V): ripple + polygon + random_multiple · rms [N m] (nan at the
        unstable points)."""
        return self.ripple + self.polygon.sum(axis=1) + self.random_multiple * self.rms


def running_sweep(model: BogieModel, points: list[OperatingPoint], speeds, outputs: list[str],
                  ripple: dict[Order, float], drive: DriveExcitation,
                  polygon: dict[int, float], spectrum: TrackSpectrum,
                  random_multiple: float = DEFAULT_RANDOM_MULTIPLE) -> RunningSweep:
    """The running case's responses (module docstring): ``points`` one operating point per
    creepage (the speed replaced by each of ``speeds`` [m/s])."""
    if not (math.isfinite(random_multiple) and random_multiple >= 0):
        raise RunningCaseError(f"the random multiple must be >= 0, got {random_multiple!r}")
    v = np.asarray(speeds, dtype=float)
    r0 = model.parameters["wheel_radius"]
    ripple_orders = tuple(ripple)
    ripple_amplitudes = np.array([ripple[o] for o in ripple_orders], dtype=float)
    polygon_orders = tuple(sorted(polygon))
    polygon_amplitudes = np.array([polygon[n] for n in polygon_orders], dtype=float)
    polygon_hz = np.array([polygon_frequency_hz(n, v, r0) for n in polygon_orders]).reshape(
        len(polygon_orders), len(v))
    polygon_hz[polygon_hz > MODEL_FREQUENCY_LIMIT_HZ] = np.nan
    ripple_hz = np.array([o.frequency_hz(v, model.parameters, drive) for o in ripple_orders]
                         ).reshape(len(ripple_orders), len(v))
    ripple_hz[(ripple_hz > MODEL_FREQUENCY_LIMIT_HZ) | (ripple_hz <= 0)] = np.nan
    motors = np.column_stack([input_force(model, m)[0] for m in MOTOR_INPUTS])
    shape = (len(points), len(outputs), len(v))
    mean, ripple_part, rms = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    moments = np.zeros((*shape, 4))
    polygon_part = np.zeros((len(points), len(polygon_orders), len(outputs), len(v)))
    unstable = []
    for a, op in enumerate(points):
        for i, speed in enumerate(v):
            point = replace(op, v=float(speed))
            lam = running_system(model, point).eigen[0]
            growth = float(np.max(lam[non_neutral(lam)].real))
            if growth > 0:  # no stationary response: left out, listed
                unstable.append({"s0": op.s0, "v_kmh": float(speed / KMH), "growth": growth})
                mean[a, :, i] = ripple_part[a, :, i] = rms[a, :, i] = np.nan
                moments[a, :, i, :] = np.nan
                polygon_part[a, :, :, i] = np.nan
                continue
            matrices, rows = output_indices(model, point, outputs)
            mean[a, :, i] = (matrices.C_q @ static_deflection(model, point))[rows]
            damping = damping_matrix(model, point)
            for k in np.flatnonzero(np.isfinite(ripple_hz[:, i])):
                w = 2 * np.pi * ripple_hz[k, i]
                q = np.linalg.solve(-w * w * model.M + 1j * w * damping + model.K, motors)
                H = (matrices.C_q[rows] + 1j * w * matrices.C_v[rows]) @ q
                ripple_part[a, :, i] += ripple_amplitudes[k] * np.abs(H).sum(axis=1)
            wheels = WheelTransfer(model, point, rows)
            for k in np.flatnonzero(np.isfinite(polygon_hz[:, i])):
                H, _ = wheels.combined(float(polygon_hz[k, i]))
                polygon_part[a, k, :, i] = polygon_amplitudes[k] * np.abs(H)
            random = random_response(model, point, spectrum, outputs)
            rms[a, :, i] = random.rms
            moments[a, :, i, :] = random.moments
    x = np.array([model.positions[rim][0] for rim in model.rims])
    phases = np.degrees(-np.outer(polygon_orders, x.max() - x) / r0).reshape(
        len(polygon_orders), len(x))
    if len(unstable) == len(points) * len(v):
        worst = max(unstable, key=lambda u: u["growth"])
        raise RunningCaseError(
            f"running case: no point of the grid is stable with the wheel-force coupling (growth "
            f"up to {worst['growth']:.3g} 1/s at s0 = {worst['s0']:g}, {worst['v_kmh']:g} km/h): "
            "no stationary response; take smaller creepages or a lower top speed")
    inputs = tuple(f"{rim}.irregularity" for rim in model.rims)
    return RunningSweep(v, tuple(op.s0 for op in points), tuple(outputs), mean, ripple_part,
                        ripple_orders, ripple_amplitudes, polygon_orders, polygon_amplitudes,
                        polygon_part, polygon_hz, phases, inputs, rms, moments, random_multiple,
                        spectrum, tuple(unstable))


def running_loads(sweep: RunningSweep) -> dict[str, AlternatingLoad]:
    """Per output over the speeds: the mean of largest magnitude and the largest alternating
    amplitude over the creepages (each with its creepage; the unstable points left out, a speed
    unstable at every creepage with them), as an
    :class:`~model.analysis.assessment.AlternatingLoad` (its orders: none; the running check's
    orders come from :func:`running_check`)."""
    total = sweep.alternating()
    stable = np.isfinite(sweep.mean[:, 0, :])  # (s0, V): the points with a stationary response
    speeds = np.flatnonzero(stable.any(axis=0))  # a speed stable at one creepage at least
    loads = {}
    for j, name in enumerate(sweep.names):
        at_mean = np.argmax(np.where(stable, np.abs(sweep.mean[:, j, :]), -np.inf), axis=0)[speeds]
        at_amplitude = np.argmax(np.where(stable, total[:, j, :], -np.inf), axis=0)[speeds]
        scenarios = tuple({"s0": sweep.s0[b], "s0_mean": sweep.s0[a]}
                          for a, b in zip(at_mean, at_amplitude, strict=True))
        loads[name] = AlternatingLoad(sweep.v[speeds], sweep.mean[at_mean, j, speeds],
                                      total[at_amplitude, j, speeds], (), np.zeros(0),
                                      np.zeros((0, len(speeds))), np.zeros((0, len(speeds))),
                                      scenarios)
    return loads


def running_check(component: Component, sweep: RunningSweep, load: AlternatingLoad) -> Check:
    """The check of ``component`` under the running case at its worst speed (:func:`
    verify_alternating`), with the speed's random RMS, the wheel polygon's orders (``order``,
    ``f_hz``, ``input_amplitude`` [m], ``wheels: [{input, phase_deg}]``, ``amplitude`` its share
    [N m]), the deterministic polygon ``amplitude`` and the ripple's share."""
    check = verify_alternating(component, "running", load)
    i = int(np.argmin(np.abs(sweep.v - check.v_kmh * KMH)))
    j = sweep.names.index(component.output)
    a = sweep.s0.index(check.scenario["s0"])
    orders = tuple(
        {"order": int(n), "f_hz": None if not np.isfinite(sweep.polygon_hz[k, i])
         else float(sweep.polygon_hz[k, i]),
         "input_amplitude": float(sweep.polygon_amplitudes[k]),
         "wheels": [{"input": name, "phase_deg": float(phase)}
                    for name, phase in zip(sweep.inputs, sweep.phases_deg[k], strict=True)],
         "amplitude": float(sweep.polygon[a, k, j, i])}
        for k, n in enumerate(sweep.polygon_orders))
    scenario = {**check.scenario,
                "ripple_amplitude": float(sweep.ripple[a, j, i]),
                "ripple_orders": [{"order": o.name, "amplitude": float(x)}
                                  for o, x in zip(sweep.ripple_orders, sweep.ripple_amplitudes,
                                                  strict=True)],
                "random_multiple": sweep.random_multiple}
    if component.kind == "torsional_fatigue" and check.capacity > 0:
        from model.analysis.spectral_fatigue import (
            SNCurve,
            SpectralMoments,
            dirlik_damage_rate,
            haibach_slope,
            narrow_band_damage_rate,
        )

        curve = SNCurve(check.capacity, RANDOM_SN_KNEE, RANDOM_SN_SLOPE,
                        haibach_slope(RANDOM_SN_SLOPE))
        moments = SpectralMoments(*(float(x) for x in sweep.moments[a, j, i]))
        scenario["random_damage_per_hour"] = {
            "dirlik": 3600.0 * dirlik_damage_rate(moments, curve),
            "narrow_band": 3600.0 * narrow_band_damage_rate(moments, curve),
            "sn_curve": {"amplitude_at_knee": check.capacity, "knee_cycles": RANDOM_SN_KNEE,
                         "slope": RANDOM_SN_SLOPE,
                         "slope_beyond_knee": haibach_slope(RANDOM_SN_SLOPE)}}
    return replace(check, orders=orders, rms=float(sweep.rms[a, j, i]),
                   amplitude=float(sweep.polygon[a, :, j, i].sum()), scenario=scenario)
