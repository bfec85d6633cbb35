"""Calibration (model updating) of the uncertain parameters against the published results.

The free parameters are searched on their logarithms, each within physically plausible bounds
(:data:`FREE_PARAMETERS`, with the reason for each bound).  Targets:

* the imaginary parts of the first ten complex pairs of Table 1 at s0 = 0.005, 120 km/h, each
  matched to the model's mode *by its character* (Table 2: which components move in which
  direction and phase, :data:`MODE_SIGNATURES`; optimal one-to-one assignment), not by its rank;
  and the 298.4 Hz driving-shaft mode (largest strain share of ID1's driving shaft);
* the operating data: M(s0, v) = 12 800 N m at s0 = 0.005 and at s0 = 0.014, and
  M_ad = 0.52·10⁵ N m at 120 km/h;
* the stability limit 0.0082 at 120 km/h.  In the fit its proxy, the creepage of the creep
  maximum, is used (the drivetrain spin of ID1 has no other damping than the creep, so its real
  eigenvalue crosses zero exactly where ∂μ/∂s = 0); the true limit is computed by root finding
  on the calibrated model and reported;
* reported, not fitted: the largest (divergent) real eigenvalue at s0 = 0.014 (+7.031 1/s).

Stages: A — creep law (μ0, A, B) and gear ratio p to the operating data (least squares, exactly
determined); B — the structural parameters to the frequencies by a compass (pattern) search with
a soft-L1 loss (:func:`frequency_cost`): the character matching makes the residuals jump where two
modes trade places, which stalls a gradient method; C — the three modes governed by one spring
each are polished by scaling that spring.  B and C run twice: first with the yaw dampers at their
estimate, then with them free (:data:`SECOND_PASS`).

The published targets live here, as *targets* of the fit; the model never reads them.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares, linear_sum_assignment

from .assembly import build_model
from .eigen import eigen_analysis
from .modes import characterize, wheelset_yaw_fraction
from .operating_point import KMH, OperatingPoint, adhesion_moment, creep_law, motor_torque
from .parameters import CALIBRATED_FILE, ESTIMATE_FILE, Parameters, load_parameters, save_parameters
from .stability import stability_limit

V_REF = 120 * KMH  # [m/s]
S0_STABLE, S0_UNSTABLE = 0.005, 0.014

# --- published targets (Zeman & Hlaváč; see shared/spec/reference-results.md) -------------------
TABLE1_IM_HZ = (1.262, 2.694, 5.425, 5.449, 6.176, 8.503, 8.583, 9.183, 12.208, 12.58)
# Re of the same ten pairs at s0 = 0.005 [1/s]: targets of the literature tests by rank (issue
# 11); the calibration does not fit them yet
TABLE1_RE = (-0.032, -0.041, -0.199, -0.056, -1.583, -0.164, -0.289, -3.282, -3.958, -4.010)
DRIVING_SHAFT_HZ = 298.4
MOTOR_TORQUE = 12_800.0  # [N m] at both creepages
ADHESION_MOMENT = 0.52e5  # [N m]
STABILITY_LIMIT = 0.0082  # [-] at 120 km/h
DIVERGENCE_RATE = 7.031  # [1/s], largest real eigenvalue at s0 = 0.014


def _share(character, component: str, axes: tuple[str, ...]) -> float:
    kinetic = character.kinetic.get(component, 0.0)
    directions = character.directions.get(component, {})
    return kinetic * sum(directions.get(axis, 0.0) for axis in axes)


def _in_phase(character, a: str, b: str, axis: str) -> float:
    return 0.5 * (1 + character.phase_cosine(a, b, axis))


_TMS = ("ID1.stator", "ID2.stator")
_GEARS = ("ID1.gear", "ID2.gear")


def _pitch_with_frame(c, component: str) -> float:
    """1 if ``component`` pitches in phase with the frame, 0 against it, 0.5 if either does not
    pitch."""
    return _in_phase(c, "BF", component, "ry")


# Table 2 characters as scores in [0, 1] (kinetic/strain energy shares, phase factors); each
# signature takes the mode's character and its wheelset yaw fractions
MODE_SIGNATURES: tuple[tuple[str, Callable], ...] = (
    ("vertical of CB in phase with BF and TMs", lambda c, yaw: _share(c, "CB", ("z",))),
    ("torsion of ID1 rotor with gears, DC twisting",
     lambda c, yaw: c.kinetic.get("ID1.rotor", 0) + c.strain.get("ID1.disc_clutch", 0)),
    # the gear housings (our stators) turn with the frame: a stator pitching against the frame on
    # its silent blocks is a different mode
    ("torsion of both gears and BF pitch, gearing",
     lambda c, yaw: (_share(c, "BF", ("ry",))
                     + sum(_share(c, part, ("ry",)) for part in _TMS + _GEARS)
                     + c.strain.get("ID1.gear_mesh", 0) + c.strain.get("ID2.gear_mesh", 0))
     * _pitch_with_frame(c, "ID1.stator") * _pitch_with_frame(c, "ID2.stator")),
    ("vertical of BF with both TMs in phase",
     lambda c, yaw: (_share(c, "BF", ("z",)) + sum(_share(c, tm, ("z",)) for tm in _TMS))
     * _in_phase(c, "BF", "ID1.stator", "z") * _in_phase(c, "BF", "ID2.stator", "z")),
    ("lateral and roll of BF with both TMs",
     lambda c, yaw: (_share(c, "BF", ("y", "rx")) + sum(_share(c, tm, ("y", "rx")) for tm in _TMS))
     * _in_phase(c, "BF", "ID1.stator", "y") * _in_phase(c, "BF", "ID2.stator", "y")),
    ("lateral of both TMs in opposite phase",
     lambda c, yaw: sum(_share(c, tm, ("y", "rz")) for tm in _TMS)
     * (1 - _in_phase(c, "ID1.stator", "ID2.stator", "y"))),
    # longitudinal-pitch: the wheelset translates (and rolls); longitudinal-yaw: its journals
    # move longitudinally in opposite phase
    ("longitudinal-pitch of WS2",
     lambda c, yaw: _share(c, "ID2.wheelset", ("x", "ry")) * (1 - yaw["ID2"])),
    ("longitudinal-pitch of WS1",
     lambda c, yaw: _share(c, "ID1.wheelset", ("x", "ry")) * (1 - yaw["ID1"])),
    ("longitudinal-yaw of WS2",
     lambda c, yaw: _share(c, "ID2.wheelset", ("x", "rz")) * yaw["ID2"]),
    ("longitudinal-yaw of WS1",
     lambda c, yaw: _share(c, "ID1.wheelset", ("x", "rz")) * yaw["ID1"]),
)


@dataclass(frozen=True)
class FreeParameter:
    name: str
    low: float
    high: float
    reason: str


# stage A: creep law and gear ratio against the operating data (exactly determined)
CREEP_PARAMETERS = (
    FreeParameter("polach_mu0", 0.3, 0.8, "dry rail friction coefficient"),
    FreeParameter("polach_A", 0.2, 0.9, "Polach's A (0.4 in his presets)"),
    FreeParameter("polach_B", 0.05, 3.0, "Polach's B [s/m] (0.2–0.6 in his presets)"),
    FreeParameter("gear_ratio", 3.0, 4.06, "p <= M_ad/M = 4.06 (spec), > 3 for a 200 km/h loco"),
)
# stage B: structure against the eigenfrequencies
STRUCTURAL_PARAMETERS = (
    FreeParameter("secondary_stiffness_z", 1e5, 3e6, "flexicoil springs of a 28 t half body"),
    FreeParameter("disc_clutch_torsional_stiffness", 1e4, 1e6, "rubber disc clutch: soft torsion"),
    FreeParameter("primary_stiffness_z", 3e5, 5e6, "coil springs per axle box, 0.3–5 MN/m"),
    FreeParameter("primary_stiffness_y", 1e5, 1e7, "coil spring shear per axle box"),
    FreeParameter("primary_stiffness_x", 1e6, 5e7, "longitudinal guide (rubber bushes) 1–50 MN/m"),
    FreeParameter("silent_block_stiffness_x", 5e5, 1e8, "rubber-metal block 0.5–100 MN/m"),
    FreeParameter("silent_block_stiffness_y", 5e5, 1e8, "rubber-metal block 0.5–100 MN/m"),
    FreeParameter("silent_block_stiffness_z", 5e5, 1e8, "rubber-metal block 0.5–100 MN/m"),
    FreeParameter("rim_torsional_stiffness", 1e6, 1e9, "rubber-sprung or steel elastic wheel"),
    FreeParameter("driving_shaft_stiffness", 1e5, 1e8, "steel quill shaft rotor-pinion"),
    FreeParameter("frame_inertia_y", 1e3, 8e3, "3–4 t frame, 3–4 m long"),
    FreeParameter("frame_inertia_x", 8e2, 5e3, "3–4 t frame, ~2.2 m wide"),
    FreeParameter("frame_inertia_z", 1.8e3, 1.3e4, "I_z <= I_x + I_y (see with_constraints)"),
    FreeParameter("stator_inertia_y", 80.0, 600.0, "3 t motor and gearbox about their axis"),
    # the car body is held still in yaw (only its bounce is a coordinate), so the yaw dampers tie
    # the frame's yaw to ground: at 12 Hz they decide how strongly the two wheelsets' yaw couple
    FreeParameter("yaw_damping", 5e4, 1e6, "yaw damper of a 200 km/h loco, 0.05–1 MN s/m"),
)
FREE_PARAMETERS = CREEP_PARAMETERS + STRUCTURAL_PARAMETERS
# freed only in the second pass of stage B: from the estimate, the yaw dampers' coupling of the
# frame's pitch and yaw (they sit above the frame's centre) led the search into a minimum where
# the frame's bounce and the WS1 pitch mode miss by 3–4 %; after the first pass has placed the
# other modes, freeing them moves the wheelsets' yaw modes 9 and 10 apart as in Table 1
SECOND_PASS = ("yaw_damping",)

# a rigid body's principal inertias obey I_z <= I_x + I_y (equality for a flat body): the frame's
# yaw inertia is kept within that as the search moves its roll and pitch inertias
def with_constraints(parameters: Parameters) -> Parameters:
    """``parameters`` with the frame's yaw inertia limited to the sum of its roll and pitch
    inertias."""
    limit = parameters["frame_inertia_x"] + parameters["frame_inertia_y"]
    if parameters["frame_inertia_z"] <= limit:
        return parameters
    return parameters.replace(frame_inertia_z=float(limit))


@dataclass(frozen=True)
class TargetRow:
    name: str
    target: float
    achieved: float
    unit: str

    @property
    def error(self) -> float:
        return (self.achieved - self.target) / abs(self.target)


def match_table1_modes(model, result, max_modes: int = 30):
    """Indices (into ``result.eigenvalues``) of the modes matching Table 2's characters, by an
    optimal one-to-one assignment on the signature scores; plus all characters computed."""
    candidates = result.complex_index[:max_modes]
    shapes = [result.mode_shape(i) for i in candidates]
    characters = [characterize(model, result.eigenvalues[i], q)
                  for i, q in zip(candidates, shapes, strict=True)]
    yaws = [wheelset_yaw_fraction(model, q) for q in shapes]
    score = np.array([[signature(c, yaw) for c, yaw in zip(characters, yaws, strict=True)]
                      for _, signature in MODE_SIGNATURES])
    rows, columns = linear_sum_assignment(-score)
    matched = np.empty(len(MODE_SIGNATURES), dtype=int)
    matched[rows] = candidates[columns]
    return matched, characters


def driving_shaft_mode(model, result) -> int:
    """Index of the mode with the largest strain share in ID1's driving shaft."""
    part = model.stiffness_parts["ID1.driving_shaft"]
    best, best_share = -1, -1.0
    for i in result.complex_index:
        q = result.mode_shape(i)
        x = q[part.index]
        share = np.real(np.conj(x) @ part.matrix @ x) / np.real(np.conj(q) @ model.K @ q)
        if share > best_share:
            best, best_share = i, share
    return int(best)


def operating_rows(parameters: Parameters) -> list[TargetRow]:
    """Operating-data targets (no eigen-analysis needed)."""
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    rows = [TargetRow(f"M(s0={s0}) motor torque", MOTOR_TORQUE,
                      motor_torque(parameters, OperatingPoint(s0, V_REF, N0, b_M)), "N m")
            for s0 in (S0_STABLE, S0_UNSTABLE)]
    rows.append(TargetRow("M_ad adhesion moment", ADHESION_MOMENT,
                          adhesion_moment(parameters, V_REF, N0), "N m"))
    rows.append(TargetRow("creep maximum s (stability-limit proxy)", STABILITY_LIMIT,
                          creep_law(parameters, N0).maximum(V_REF)[0], "-"))
    return rows


def frequency_rows(parameters: Parameters, model=None) -> list[TargetRow]:
    """Table 1 imaginary parts (matched by character) and the driving-shaft mode; ``model`` is
    the model built from ``parameters`` if the caller has it already."""
    model = build_model(parameters) if model is None else model
    stable = eigen_analysis(model, OperatingPoint(S0_STABLE, V_REF, parameters["wheel_force"],
                                                  parameters["motor_slope"]))
    matched, _ = match_table1_modes(model, stable)
    rows = [TargetRow(f"Im λ{k} [{MODE_SIGNATURES[k - 1][0]}]", target,
                      stable.eigenvalues[index].imag / (2 * np.pi), "Hz")
            for k, (index, target) in enumerate(zip(matched, TABLE1_IM_HZ, strict=True), start=1)]
    ds = driving_shaft_mode(model, stable)
    rows.append(TargetRow("Im λ58 [ID1 driving shaft twisting]", DRIVING_SHAFT_HZ,
                          stable.eigenvalues[ds].imag / (2 * np.pi), "Hz"))
    return rows


def evaluate(parameters: Parameters) -> list[TargetRow]:
    """All calibration targets with the values the model achieves."""
    model = build_model(parameters)
    unstable = eigen_analysis(model, OperatingPoint(S0_UNSTABLE, V_REF, parameters["wheel_force"],
                                                    parameters["motor_slope"]), vectors=False)
    return [*frequency_rows(parameters, model), *operating_rows(parameters),
            TargetRow("largest real eigenvalue at s0=0.014 (not fitted)", DIVERGENCE_RATE,
                      float(unstable.real.max()), "1/s")]


def _fit(start: Parameters, free: tuple[FreeParameter, ...], residual: Callable,
         max_evaluations: int, progress: Callable, label: str) -> Parameters:
    names = [f.name for f in free]
    low, high = np.log([f.low for f in free]), np.log([f.high for f in free])
    x0 = np.clip(np.log([start[name] for name in names]), low + 1e-9, high - 1e-9)
    count, began = [0], time.perf_counter()

    def fun(x: np.ndarray) -> np.ndarray:
        count[0] += 1
        r = residual(start.replace(**dict(zip(names, np.exp(x).tolist(), strict=True))))
        if count[0] % 25 == 0:
            progress(f"  {label}: evaluation {count[0]}, cost {0.5 * r @ r:.3e} "
                     f"({time.perf_counter() - began:.0f} s)")
        return r

    solution = least_squares(fun, x0, bounds=(low, high), diff_step=1e-4, max_nfev=max_evaluations)
    return start.replace(**dict(zip(names, np.exp(solution.x).tolist(), strict=True)))


# stage B: the matched-mode residuals jump where two modes trade their characters, so a gradient
# method stalls on the first such edge; a compass (pattern) search on the logarithms steps over it.
# Loss: soft-L1 with the 3 % acceptance as its scale, which prefers meeting many targets to
# spreading the error evenly over all of them
PATTERN_STEPS = (0.3, 0.1, 0.03)  # [log units]: factors 1.35, 1.105, 1.03
LOSS_SCALE = 0.03
MIN_IMPROVEMENT = 0.002  # relative cost decrease a step must bring (no creeping by tiny steps)


def frequency_cost(rows: list[TargetRow]) -> float:
    """Soft-L1 loss of the log frequency errors (≈ squared error below the 3 % scale, linear
    above it)."""
    r = np.array([math.log(max(row.achieved, 1e-9) / row.target) for row in rows]) / LOSS_SCALE
    return float(2 * LOSS_SCALE**2 * np.sum(np.sqrt(1 + r**2) - 1))


def _pattern_search(start: Parameters, free: tuple[FreeParameter, ...], cost: Callable,
                    max_evaluations: int, progress: Callable, label: str) -> Parameters:
    """Compass search in log space within the bounds: try each parameter up and down by the
    current step, accept the first improvement (by at least ``MIN_IMPROVEMENT``); shrink the
    step when none improves."""
    start = with_constraints(start)
    best, best_cost, count = start, cost(start), 1
    began = time.perf_counter()
    for step in PATTERN_STEPS:
        improved = True
        while improved and count < max_evaluations:
            improved = False
            for f in free:
                for direction in (1.0, -1.0):
                    value = best[f.name] * math.exp(direction * step)
                    if not f.low <= value <= f.high or count >= max_evaluations:
                        continue
                    trial = with_constraints(best.replace(**{f.name: value}))
                    trial_cost, count = cost(trial), count + 1
                    if trial_cost < (1 - MIN_IMPROVEMENT) * best_cost:
                        best, best_cost, improved = trial, trial_cost, True
                        break
        progress(f"  {label}: step {step:g}, cost {best_cost:.3e}, {count} evaluations "
                 f"({time.perf_counter() - began:.0f} s)")
    return best


# stage C: modes governed by one spring each (frequency ∝ √k): car body bounce by the secondary
# vertical springs, ID1's rotor torsion by the disc clutch, the pinion mode by the driving shaft
SINGLE_SPRING_MODES = ((0, "secondary_stiffness_z"), (1, "disc_clutch_torsional_stiffness"),
                       (10, "driving_shaft_stiffness"))


def _polish(parameters: Parameters, progress: Callable, iterations: int = 8) -> Parameters:
    """Stage C: scale each single-spring mode's stiffness by (f_target/f)², a few times; a step
    is kept only if it does not raise the frequency cost (a spring that also moves a mode of
    another character could make two modes trade places)."""
    bounds = {f.name: (f.low, f.high) for f in STRUCTURAL_PARAMETERS}
    rows = frequency_rows(parameters)
    cost = frequency_cost(rows)
    for _ in range(iterations):
        changes = {}
        for index, name in SINGLE_SPRING_MODES:
            factor = (rows[index].target / rows[index].achieved) ** 2
            changes[name] = float(np.clip(parameters[name] * np.clip(factor, 0.5, 2.0), *bounds[name]))
        trial = parameters.replace(**changes)
        trial_rows = frequency_rows(trial)
        trial_cost = frequency_cost(trial_rows)
        if trial_cost > cost:
            break
        parameters, rows, cost = trial, trial_rows, trial_cost
    worst = max(abs(rows[i].error) for i, _ in SINGLE_SPRING_MODES)
    progress(f"  stage C (single-spring modes): largest error {100 * worst:.2f} %")
    return parameters


def calibrate(start: Parameters, max_evaluations: int = 600, progress: Callable = print
              ) -> tuple[Parameters, list[TargetRow]]:
    """Stage A fits the creep law and the gear ratio to the operating data (least squares);
    stage B the structure to the frequencies (pattern search, at most ``max_evaluations``
    eigen-analyses per pass); stage C polishes the single-spring modes; B and C run a second
    time with :data:`SECOND_PASS` free as well.  Returns the calibrated set and all its
    targets."""
    relative = lambda rows: np.array([row.error for row in rows])  # noqa: E731
    stage_a = _fit(start, CREEP_PARAMETERS, lambda p: relative(operating_rows(p)),
                   200, progress, "stage A (creep law, gear ratio)")
    cost = lambda p: frequency_cost(frequency_rows(p))  # noqa: E731
    first = tuple(f for f in STRUCTURAL_PARAMETERS if f.name not in SECOND_PASS)
    stage_b = _pattern_search(stage_a, first, cost, max_evaluations, progress,
                              "stage B1 (structure, yaw dampers at their estimate)")
    stage_b = _polish(stage_b, progress)
    stage_b = _pattern_search(stage_b, STRUCTURAL_PARAMETERS, cost, max_evaluations, progress,
                              "stage B2 (structure and yaw dampers)")
    stage_b = _polish(stage_b, progress)
    notes = dict(start.notes)
    for f in FREE_PARAMETERS:
        notes[f.name] = (f"calibrated by `bogie calibrate` within [{f.low:g}, {f.high:g}] "
                         f"({f.reason}); estimate {start[f.name]:g}")
    calibrated = Parameters(dict(stage_b.values), notes, "calibrated")
    return calibrated, evaluate(calibrated)


def format_table(rows: list[TargetRow], limit: float | None = None) -> str:
    lines = [f"{'target':58} {'published':>11} {'achieved':>11} {'error':>8}"]
    for row in rows:
        lines.append(f"{row.name[:58]:58} {row.target:>11.5g} {row.achieved:>11.5g} "
                     f"{100 * row.error:>7.2f}%")
    if limit is not None:
        lines.append(f"{'stability limit s0* at 120 km/h (root finding)':58} "
                     f"{STABILITY_LIMIT:>11.5g} {limit:>11.5g} "
                     f"{100 * (limit - STABILITY_LIMIT) / STABILITY_LIMIT:>7.2f}%")
    return "\n".join(lines)


def run(start_file=ESTIMATE_FILE, out_file=CALIBRATED_FILE, max_evaluations: int = 600,
        progress: Callable = print) -> list[TargetRow]:
    """The ``bogie calibrate`` command: fit, write the calibrated set, print the table."""
    start = load_parameters(start_file)
    progress(f"calibrating {len(FREE_PARAMETERS)} parameters from {start_file} …")
    calibrated, rows = calibrate(start, max_evaluations, progress)
    limit = stability_limit(build_model(calibrated), V_REF, calibrated["wheel_force"],
                            calibrated["motor_slope"]).s0_limit
    table = format_table(rows, limit)
    header = ("Calibrated parameter set (default everywhere). Produced by `bogie calibrate` from\n"
              f"{start_file.name if hasattr(start_file, 'name') else start_file}; "
              "re-run it to reproduce. Targets and results:\n" + table)
    save_parameters(calibrated, out_file, header)
    progress(table)
    progress(f"wrote {out_file}")
    return rows
