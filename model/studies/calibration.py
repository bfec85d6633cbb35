"""Calibration (model updating) of the uncertain parameters against the published results.

The free parameters are searched on their logarithms, each within documented bounds
(:data:`FREE_PARAMETERS`, with the reason for each bound: about x3 around the estimate and within
what the part can physically be).  Targets, all at 120 km/h, N0 = 10^5 N (:func:`rank_cost`):

* **Table 1 by rank**: the k-th complex pair by imaginary part at s0 = 0.005 against the
  published k-th, k = 1…10, and it must have Table 2's k-th character (:data:`MODE_SIGNATURES`:
  energy shares, directions and phases, optimal one-to-one assignment over the lowest
  candidates).  A mode that sits at rank k with another character costs its rank's frequency
  miss, the character-matched mode's own frequency miss and a fixed penalty;
* the real parts of modes 1, 3, 4, 8, 9, 10 at s0 = 0.005 (soft; 30 % or 0.05 1/s), and of the
  wheelset modes 7–10 at s0 = 0.014 (soft, weaker); mode 2's damping is *not* a target (it
  cannot be reached with an eq.-19 creep block and physical inertias, see docs/validation.md);
* the 298.4 Hz driving-shaft mode (largest strain share of ID1's driving shaft);
* at s0 = 0.014 two positive real eigenvalues, the larger against +7.031 1/s;
* the operating data M(s0, v) = 12 800 N m at s0 = 0.005 and 0.014 and M_ad = 0.52·10⁵ N m,
  and the stability limit 0.0082: the creep law's (μ0, A, B) and the gear ratio p are solved
  for them exactly (stage A, four equations, four unknowns) inside every evaluation, for the
  creep shape (kA, kS, initial slope) the search proposes; the limit is the creep maximum unless
  a flutter mode turns unstable first, which a check just below 0.0082 rules out.

Search: compass (pattern) searches on the logarithms with a soft-L1 loss (the character
assignment makes the cost jump where modes trade places, which stalls a gradient method): stage
B1 places the ten characters (:func:`character_cost`), stage B2 minimises :func:`rank_cost`.  An
evaluation of stage B2 costs one eigen-analysis with vectors at s0 = 0.005 (characters only for the lowest
:data:`CANDIDATES` pairs), one without at 0.014 and one without just below the limit; the later
ones are skipped as soon as the partial cost exceeds the best so far.  Stages C–F
(:func:`rank_stages`) then move the modes of other characters out of the band below 12.6 Hz and
put the ten in Table 1's order, ending on B2's cost with the ranking held
(:func:`ranked_search_cost`).  Everything is deterministic (fixed move order and budgets):
``bogie calibrate`` reproduces ``assets/parameters/calibrated.toml`` byte for byte.

The published targets live here, as *targets* of the fit; the model never reads them.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares, linear_sum_assignment

from model.analysis.eigen import eigen_analysis
from model.analysis.modes import characterize, wheelset_yaw_fraction
from model.analysis.stability import stability_limit
from model.mechanics.assembly import build_model
from model.mechanics.operating_point import KMH, OperatingPoint, adhesion_moment, creep_law, motor_torque
from model.mechanics.parameters import CALIBRATED_FILE, ESTIMATE_FILE, Parameters, load_parameters, save_parameters

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
DIVERGENCE_RATES = (7.031, 0.062)  # [1/s], the two positive real eigenvalues at s0 = 0.014
# real parts [1/s] of the ten pairs at s0 = 0.005 and real/imaginary parts at s0 = 0.014
TABLE1_RE = (-0.032, -0.041, -0.199, -0.056, -1.583, -0.164, -0.289, -3.282, -3.958, -4.010)
TABLE1_UNSTABLE = ((-0.029, 1.262), (-0.060, 2.689), (0.076, 5.374), (-0.0318, 5.443),
                   (-1.583, 6.174), (-0.164, 8.505), (0.416, 9.126), (1.111, 9.535),
                   (0.911, 12.140), (0.809, 12.162))  # (Re [1/s], Im [Hz])


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
# the creep law's shape, searched with the structure (stage A re-solved for each shape): Polach's
# reduction factors within his published range (wet 0.3/0.1 … dry 1.0/0.4, kS <= kA), the initial
# slope between Kalker's value for this contact (~130) and 5x the spec's starting fit
CREEP_SHAPE_PARAMETERS = (
    FreeParameter("polach_kA", 0.3, 1.0, "Polach's range: wet 0.3 … dry 1.0"),
    FreeParameter("polach_kS", 0.1, 0.4, "Polach's range: wet 0.1 … dry 0.4; kS <= kA"),
    FreeParameter("creep_slope", 130.0, 3000.0, "Kalker's slope for this contact (~130) … 5x the "
                  "spec's starting fit (600)"),
)
# stage B: the structure, the dampers and the motor slope against Table 1.  Inertias and
# stiffnesses within about x3 of their estimate and within what the part can be; bounds that the
# previous calibration sat on (frame roll inertia 5 000, stator pitch inertia 557 kg m^2) are
# tightened to physical limits of a 3.5 t frame and a 2.6 t motor with gear housing
STRUCTURAL_PARAMETERS = (
    FreeParameter("secondary_stiffness_z", 2e5, 1.8e6, "x3 around 0.6 MN/m (1.26 Hz with 28 t)"),
    FreeParameter("disc_clutch_torsional_stiffness", 2.3e4, 2.1e5, "x3 around 7e4 N m/rad"),
    FreeParameter("primary_stiffness_z", 3.7e5, 3.3e6, "coil springs per axle box, x3 around "
                  "1.1 MN/m"),
    FreeParameter("primary_stiffness_y", 3.3e5, 1e7, "coil spring shear 0.3–1 MN/m up to a "
                  "rubber-bushed lateral guide 10 MN/m per axle box"),
    FreeParameter("primary_stiffness_x", 1.7e6, 1.5e7, "longitudinal guide (rubber bushes), x3 "
                  "around 5 MN/m"),
    FreeParameter("silent_block_stiffness_x", 2.7e6, 2.4e7, "rubber-metal block, x3 around 8 MN/m"),
    FreeParameter("silent_block_stiffness_y", 1.3e6, 1.2e7, "rubber-metal block, x3 around 4 MN/m"),
    FreeParameter("silent_block_stiffness_z", 2.7e6, 2.4e7, "rubber-metal block, x3 around 8 MN/m"),
    FreeParameter("rim_torsional_stiffness", 6.7e6, 6e7, "rubber-sprung wheel, x3 around "
                  "2e7 N m/rad"),
    FreeParameter("driving_shaft_stiffness", 2.1e6, 1.9e7, "steel quill shaft, x3 around "
                  "6.4 MN m/rad"),
    # a 3.5 t frame: side members (~60 % of the mass) at y = ±1.0 m over x = ±1.75 m, cross
    # members (~40 %) near the centre: I_x ≈ 2 100 + 600, I_y ≈ 2 100 + 800 kg m^2; with all
    # the mass at the outer edges (the physical limit) I_x ≈ 3 500 · 1.1² ≈ 4 200 kg m^2
    FreeParameter("frame_inertia_x", 900.0, 3200.0, "3.5 t frame 2.2 m wide: ~2 700 kg m^2 for "
                  "side members at ±1.0 m; x½ … 1.2x"),
    FreeParameter("frame_inertia_y", 1200.0, 5000.0, "3.5 t frame 3.5 m long: ~2 900 kg m^2; "
                  "x½ … 1.7x"),
    FreeParameter("frame_inertia_z", 1800.0, 8000.0, "I_z <= I_x + I_y (see with_constraints)"),
    # 2.6 t: a 0.7 m motor (cylinder, m r²/2 ≈ 160 kg m^2) plus a gear housing reaching to the axle
    FreeParameter("stator_inertia_y", 90.0, 400.0, "2.6 t motor (~160 kg m^2 as a 0.7 m "
                  "cylinder) with its gear housing towards the axle (~150 kg m^2)"),
    # the car body is held still in x and yaw, so the yaw dampers tie the frame to ground
    FreeParameter("yaw_damping", 5e4, 1e6, "yaw damper of a 200 km/h loco, 0.05–1 MN s/m"),
    FreeParameter("yaw_damper_height", 0.05, 0.6, "between the axle height and the car body "
                  "floor; decides how the yaw dampers couple the frame's pitch"),
    FreeParameter("primary_damping_z", 200.0, 3e4, "primary vertical damper per axle box, up to "
                  "a typical 30 kN s/m"),
    FreeParameter("secondary_damping_z", 200.0, 3e4, "secondary vertical damper per spring, up "
                  "to a typical 30 kN s/m"),
    FreeParameter("secondary_damping_y", 2e3, 1e5, "secondary lateral damper per side"),
    FreeParameter("rotor_inertia", 6.0, 24.0, "rotor of 550 kg, radius of gyration 0.10–0.21 m; "
                  "x½ … x2 around 12 kg m^2"),
    # b_M (docs/validation.md, "The motor slope"): the converter holds the healthy motor's torque
    # for slow motions — on the constant-power hyperbola M ω = P the slope is M/ω = 12 800 N m /
    # 212 rad/s ≈ 60 N m s/rad; faster than its torque control the motor shows its natural
    # characteristic, M/(s_n ω_s) ≈ 12 800 / (0.005 · 214) ≈ 12 000 N m s/rad at 0.5 % slip
    FreeParameter("motor_slope", 60.0, 12000.0, "asynchronous drive between its controlled "
                  "characteristic (constant power, M/ω ≈ 60) and its natural one at 0.5 % slip "
                  "(≈ 12 000 N m s/rad)"),
)
SEARCH_PARAMETERS = CREEP_SHAPE_PARAMETERS + STRUCTURAL_PARAMETERS
FREE_PARAMETERS = CREEP_PARAMETERS + SEARCH_PARAMETERS


# a rigid body's principal inertias obey I_z <= I_x + I_y (equality for a flat body); Polach's
# kS <= kA: the search keeps both as it moves the others
def with_constraints(parameters: Parameters) -> Parameters:
    """``parameters`` with the frame's yaw inertia limited to the sum of its roll and pitch
    inertias and Polach's kS limited to kA."""
    changes = {}
    limit = parameters["frame_inertia_x"] + parameters["frame_inertia_y"]
    if parameters["frame_inertia_z"] > limit:
        changes["frame_inertia_z"] = float(limit)
    if parameters["polach_kS"] > parameters["polach_kA"]:
        changes["polach_kS"] = float(parameters["polach_kA"])
    return parameters.replace(**changes) if changes else parameters


@dataclass(frozen=True)
class TargetRow:
    name: str
    target: float
    achieved: float
    unit: str

    @property
    def error(self) -> float:
        return (self.achieved - self.target) / abs(self.target)


CANDIDATES = 14  # lowest complex pairs whose character is computed (Table 1 has ten)


def _signature_assignment(model, result, candidates):
    """Table 2's characters assigned one-to-one to the ``candidates`` (indices of complex pairs
    in ``result``) by an optimal assignment on their signature scores: (rows: Table 2's
    characters, columns: positions in ``candidates``, the score matrix (characters x
    candidates), the characters computed)."""
    shapes = [result.mode_shape(i) for i in candidates]
    characters = [characterize(model, result.eigenvalues[i], q)
                  for i, q in zip(candidates, shapes, strict=True)]
    yaws = [wheelset_yaw_fraction(model, q) for q in shapes]
    score = np.array([[signature(c, yaw) for c, yaw in zip(characters, yaws, strict=True)]
                      for _, signature in MODE_SIGNATURES])
    rows, columns = linear_sum_assignment(-score)
    return rows, columns, score, characters


def match_table1_modes(model, result, max_modes: int = CANDIDATES):
    """Indices (into ``result.eigenvalues``) of the modes matching Table 2's characters, by an
    optimal one-to-one assignment on the signature scores over the ``max_modes`` lowest complex
    pairs; plus the characters computed."""
    candidates = result.complex_index[:max_modes]
    rows, columns, _, characters = _signature_assignment(model, result, candidates)
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


def frequency_rows(parameters: Parameters, model=None) -> list[TargetRow]:
    """The imaginary parts of the modes with Table 2's ten characters (matched by character,
    whatever their rank) and of the driving-shaft mode at s0 = 0.005 — the frequency targets of
    the linearized posterior (model/studies/posterior.py), whose sensitivities follow a mode, not a rank;
    ``model`` is the model built from ``parameters`` if the caller has it already."""
    model = build_model(parameters) if model is None else model
    stable = eigen_analysis(model, _operating_point(parameters, S0_STABLE))
    matched, _ = match_table1_modes(model, stable)
    rows = [TargetRow(f"Im λ{k} [{MODE_SIGNATURES[k - 1][0]}]", target,
                      stable.eigenvalues[index].imag / (2 * np.pi), "Hz")
            for k, (index, target) in enumerate(zip(matched, TABLE1_IM_HZ, strict=True), start=1)]
    ds = driving_shaft_mode(model, stable)
    rows.append(TargetRow("Im λ58 [ID1 driving shaft twisting]", DRIVING_SHAFT_HZ,
                          stable.eigenvalues[ds].imag / (2 * np.pi), "Hz"))
    return rows

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


def _operating_point(parameters: Parameters, s0: float) -> OperatingPoint:
    return OperatingPoint(s0, V_REF, parameters["wheel_force"], parameters["motor_slope"])


@dataclass(frozen=True)
class RankEvaluation:
    """What the calibration compares, for one parameter set (eigenvalues [1/s])."""

    stable: np.ndarray  # the ten lowest complex pairs at s0 = 0.005, by Im (upper half)
    character_ok: np.ndarray  # bool per rank: the k-th pair has Table 2's k-th character
    matched: np.ndarray  # the pair with Table 2's k-th character (by character), per k
    driving_shaft: complex  # ID1 driving-shaft mode at s0 = 0.005
    max_real_stable: float  # largest real part at s0 = 0.005
    unstable: np.ndarray | None = None  # the ten lowest complex pairs at s0 = 0.014
    unstable_real: np.ndarray | None = None  # real eigenvalues at s0 = 0.014, largest first
    max_real_below_limit: float | None = None  # largest real part at 0.98 · 0.0082


LIMIT_CHECK = 0.98 * STABILITY_LIMIT  # the bogie must still be stable here (no early flutter)


def evaluate_by_rank(parameters: Parameters, model=None, complete: Callable | None = None
                     ) -> RankEvaluation:
    """The eigen-analyses the calibration needs.  ``complete(partial)`` (optional) is asked after
    the analysis at s0 = 0.005 whether the others are worth computing (the search skips them
    when the partial cost is already too high)."""
    model = build_model(parameters) if model is None else model
    stable = eigen_analysis(model, _operating_point(parameters, S0_STABLE))
    matched, _ = match_table1_modes(model, stable)
    ranked = stable.complex_index[:len(TABLE1_IM_HZ)]
    ds = driving_shaft_mode(model, stable)
    result = RankEvaluation(stable.eigenvalues[ranked], matched == ranked[:len(matched)],
                            stable.eigenvalues[matched], complex(stable.eigenvalues[ds]),
                            stable.max_real_part)
    if complete is not None and not complete(result):
        return result
    unstable = eigen_analysis(model, _operating_point(parameters, S0_UNSTABLE), vectors=False)
    below = eigen_analysis(model, _operating_point(parameters, LIMIT_CHECK), vectors=False)
    return RankEvaluation(result.stable, result.character_ok, result.matched,
                          result.driving_shaft, result.max_real_stable,
                          unstable.complex_pairs[:len(TABLE1_IM_HZ)], unstable.real,
                          below.max_real_part)


# --- the cost ----------------------------------------------------------------------------------
FREQUENCY_SCALE = 0.03  # [-] the literature tests' aim for the imaginary parts (log error)
CHARACTER_PENALTY = 2.0  # a rank held by a mode of another character (≈ a 4.5 % miss)
RE_MODES = (1, 3, 4, 8, 9, 10)  # Table 1 rows whose real part at s0 = 0.005 is a target
RE_WEIGHT = 0.5
UNSTABLE_RE_MODES = (7, 8, 9, 10)  # the wheelset modes at s0 = 0.014
UNSTABLE_RE_WEIGHT = 0.25
DIVERGENCE_WEIGHT = 0.5
STABILITY_SCALE = 0.01  # [1/s] a positive real part where the bogie must be stable


def _soft(r: float) -> float:
    """Soft-L1: ≈ r² below 1, linear above."""
    return 2.0 * (math.sqrt(1.0 + r * r) - 1.0)


def real_part_residual(achieved: float, published: float) -> float:
    """Relative to the Re acceptance: 30 % on a log scale, or 0.05 1/s where |Re| < 0.2 1/s
    (a residual of 1 is the acceptance limit)."""
    if abs(published) >= 0.2 and achieved * published > 0:
        return math.log(achieved / published) / math.log(1.3)
    return (achieved - published) / max(0.3 * abs(published), 0.05)


def partial_cost(e: RankEvaluation) -> float:
    """Cost of the s0 = 0.005 part (frequencies by rank with characters, Re, driving shaft)."""
    cost = 0.0
    for k, target in enumerate(TABLE1_IM_HZ):
        cost += _soft(math.log(max(e.stable[k].imag, 1e-9) / (2 * np.pi) / target)
                      / FREQUENCY_SCALE)
        if not e.character_ok[k]:
            cost += CHARACTER_PENALTY + _soft(math.log(max(e.matched[k].imag, 1e-9)
                                                       / (2 * np.pi) / target) / FREQUENCY_SCALE)
    for k in RE_MODES:
        cost += RE_WEIGHT * _soft(real_part_residual(e.matched[k - 1].real, TABLE1_RE[k - 1]))
    cost += _soft(math.log(e.driving_shaft.imag / (2 * np.pi) / DRIVING_SHAFT_HZ)
                  / FREQUENCY_SCALE)
    if e.max_real_stable > 0:
        cost += 10 * _soft(e.max_real_stable / STABILITY_SCALE)
    return cost


def rank_cost(e: RankEvaluation) -> float:
    """The calibration's cost (see the module docstring)."""
    cost = partial_cost(e)
    if e.unstable is None:
        return math.inf
    for k in UNSTABLE_RE_MODES:
        if k <= len(e.unstable):
            cost += UNSTABLE_RE_WEIGHT * _soft(
                (e.unstable[k - 1].real - TABLE1_UNSTABLE[k - 1][0])
                / max(0.3 * abs(TABLE1_UNSTABLE[k - 1][0]), 0.1))
    positive = e.unstable_real[e.unstable_real > 0]
    if len(positive):
        cost += DIVERGENCE_WEIGHT * _soft(math.log(positive[0] / DIVERGENCE_RATES[0]) / 0.3)
    else:
        cost += 10.0
    if len(positive) < 2:  # the second divergence: only its sign is a target (see motor_slope)
        second = e.unstable_real[1] if len(e.unstable_real) > 1 else -1.0
        cost += 2.0 + _soft((0.05 - second) / 0.05)
    if e.max_real_below_limit > 0:
        cost += 10 * _soft(e.max_real_below_limit / STABILITY_SCALE)
    return cost


# --- stage A: the creep law and the gear ratio to the operating data ------------------------------
def fit_operating_data(parameters: Parameters) -> Parameters:
    """(μ0, A, B, p) solved for M(0.005) = M(0.014) = 12 800 N m, M_ad = 0.52·10⁵ N m and the
    creep maximum at 0.0082, for the set's creep shape (kA, kS, initial slope); least squares on
    the relative errors from the set's values."""
    free = CREEP_PARAMETERS
    names = [f.name for f in free]
    low, high = np.log([f.low for f in free]), np.log([f.high for f in free])
    x0 = np.clip(np.log([parameters[name] for name in names]), low + 1e-9, high - 1e-9)

    def fun(x: np.ndarray) -> np.ndarray:
        trial = parameters.replace(**dict(zip(names, np.exp(x).tolist(), strict=True)))
        try:
            return np.array([row.error for row in operating_rows(trial)])
        except ValueError:  # no creep maximum below s = 1
            return np.full(len(names), 10.0)

    solution = least_squares(fun, x0, bounds=(low, high), diff_step=1e-6, xtol=1e-12,
                             ftol=1e-12, gtol=1e-12, max_nfev=200)
    return parameters.replace(**dict(zip(names, np.exp(solution.x).tolist(), strict=True)))


# --- stage B: compass search ---------------------------------------------------------------------
PATTERN_STEPS = (0.3, 0.1, 0.03)  # [log units]: factors 1.35, 1.105, 1.03
MIN_IMPROVEMENT = 0.002  # relative cost decrease a step must bring (no creeping by tiny steps)
RESTART_GAIN = 0.01  # a cycle of the step schedule is repeated while it gains this much


def _pattern_search(start: Parameters, free: tuple[FreeParameter, ...], cost: Callable,
                    max_evaluations: int, progress: Callable, label: str,
                    steps: tuple[float, ...] = PATTERN_STEPS) -> Parameters:
    """Compass search in log space within the bounds: try each parameter up and down by the
    current step, accept the first improvement (by at least ``MIN_IMPROVEMENT``); shrink the
    step when none improves.  ``cost(parameters, best_cost)`` may stop early (and return inf)
    once it knows the trial is no better than ``best_cost``."""
    start = with_constraints(start)
    best, best_cost, count = start, cost(start, math.inf), 1
    began = time.perf_counter()
    progress(f"  {label}: start, cost {best_cost:.4g}")
    cycle_start = math.inf
    # the step schedule is repeated while a cycle still lowers the cost by RESTART_GAIN: a large
    # step after small ones can leave the basin a one-parameter move at small steps cannot
    while best_cost < (1 - RESTART_GAIN) * cycle_start and count < max_evaluations:
        cycle_start = best_cost
        for step in steps:
            improved = True
            while improved and count < max_evaluations:
                improved = False
                for f in free:
                    for direction in (1.0, -1.0):
                        value = best[f.name] * math.exp(direction * step)
                        if not f.low <= value <= f.high or count >= max_evaluations:
                            continue
                        trial = with_constraints(best.replace(**{f.name: value}))
                        threshold = (1 - MIN_IMPROVEMENT) * best_cost
                        trial_cost, count = cost(trial, threshold), count + 1
                        if trial_cost < threshold:
                            best, best_cost, improved = trial, trial_cost, True
                            progress(f"  {label}: {f.name} -> {value!r}, cost {best_cost:.4g} "
                                     f"({count} evaluations, {time.perf_counter() - began:.0f} s)")
                            break
            progress(f"  {label}: step {step:g} done, cost {best_cost:.4g}, {count} evaluations "
                     f"({time.perf_counter() - began:.0f} s)")
    return best


_CREEP_SHAPE = tuple(f.name for f in CREEP_SHAPE_PARAMETERS)


def search_cost(parameters: Parameters, threshold: float = math.inf) -> float:
    """Cost of a trial set of the search: stage A solved for its creep shape first; the
    eigen-analyses at 0.014 and below the limit are skipped when the s0 = 0.005 part alone
    reaches ``threshold``."""
    parameters = fit_operating_data(parameters)
    operating = sum(_soft(row.error / 0.01) for row in operating_rows(parameters))
    evaluation = evaluate_by_rank(
        parameters, complete=lambda e: operating + partial_cost(e) < threshold)
    return operating + rank_cost(evaluation)


def character_cost(parameters: Parameters, threshold: float = math.inf) -> float:
    """Stage B1's cost: the operating data and the frequencies of the modes matched to Table 2's
    characters (whatever their rank) and of the driving-shaft mode — one eigen-analysis, a
    smoother landscape that places the ten characters before stage B2 orders them."""
    parameters = fit_operating_data(parameters)
    operating = sum(_soft(row.error / 0.01) for row in operating_rows(parameters))
    e = evaluate_by_rank(parameters, complete=lambda e: False)
    return operating + sum(
        _soft(math.log(max(z.imag, 1e-9) / (2 * np.pi) / target) / FREQUENCY_SCALE)
        for z, target in zip(e.matched, TABLE1_IM_HZ, strict=True)) + _soft(
        math.log(e.driving_shaft.imag / (2 * np.pi) / DRIVING_SHAFT_HZ) / FREQUENCY_SCALE)


# --- stages C–F: the ranking (Table 1 by rank) --------------------------------------------------------
# Stage B2 leaves the ten characters near their frequencies but not at their ranks: modes of other
# characters (the frame's roll and yaw, the motors' pitch and opposite longitudinal motion) sit
# among them below 12.6 Hz.  Stages C–F move those out and put the ten in Table 1's order, each a
# deterministic compass search (fixed move order, fixed evaluation budget, no time limits):
#   C  restart the three parameters stage B drives to the edge of their bounds (frame roll
#      inertia, stator pitch inertia, silent-block x stiffness) from the values the review
#      of the first calibration proposed;
#   D  :func:`extra_mode_cost` without the by-rank terms (count the extra modes below the cut);
#   E  the same with the by-rank terms and a penalty per complex pair lost to overdamping;
#   F  :func:`ranked_search_cost`: :func:`search_cost` (damping, divergences, driving shaft) with
#      the ranking held by large penalties.
RESTART_VALUES = {"frame_inertia_x": 1800.0, "stator_inertia_y": 180.0,
                  "silent_block_stiffness_x": 8.8e6}
STAGE_BUDGETS = {"D": 1000, "E": 1500, "F": 3000}  # evaluations per stage
EXTRA_MODE_CUT = 12.6  # [Hz] just above Table 1's 10th pair (12.58 Hz): no other mode below it
EXTRA_MODE_CANDIDATES = 16.0  # [Hz] characters are computed for the pairs below this
RANK_BAND, RANK_BAND_WEIGHT = 0.045, 20.0  # stage F: free band of ln(f_k/Table1_k), its penalty
WRONG_CHARACTER_WEIGHT = 20.0  # stage F: per rank held by another character
EXTRA_DIVERGENCE_WEIGHT = 2.0  # stage F: per positive real at s0 = 0.014 beyond the published two


def _extra_mode_analysis(parameters: Parameters) -> dict:
    """The pairs below :data:`EXTRA_MODE_CANDIDATES` at s0 = 0.005 with Table 2's characters
    assigned (one-to-one, by signature score) and the count of complex pairs."""
    parameters = fit_operating_data(with_constraints(parameters))
    model = build_model(parameters)
    result = eigen_analysis(model, _operating_point(parameters, S0_STABLE))
    index = result.complex_index
    frequency = result.eigenvalues[index].imag / (2 * np.pi)
    candidates = index[:max(12, int(np.count_nonzero(frequency < EXTRA_MODE_CANDIDATES)))]
    rows, columns, score, _ = _signature_assignment(model, result, candidates)
    position = np.empty(len(MODE_SIGNATURES), dtype=int)  # rank position of Table 2's k-th
    position[rows] = columns
    return {"frequency": frequency[:len(candidates)], "position": position,
            "score": score[rows, columns], "operating": [r.error for r in operating_rows(parameters)],
            "max_real": result.max_real_part, "complex_pairs": len(index)}


def extra_mode_cost(a: dict, by_rank: bool, complex_pairs: int | None = None) -> float:
    """Stages D and E: each pair below :data:`EXTRA_MODE_CUT` without a Table-2 character costs
    0.3 plus more the lower it sits; each character's frequency is held within 10 % of Table 1
    (and pulled gently towards it) with a weak-match penalty; the operating data and stability
    at s0 = 0.005 as hard terms.  ``by_rank``: the k-th pair by Im within 4.5 % of Table 1's k-th
    and with the k-th character.  ``complex_pairs``: a penalty per pair fewer than this (a mode
    pushed out of the band by overdamping it does not count as moved)."""
    f, position = a["frequency"], a["position"]
    assigned = set(position.tolist())
    cost = sum(0.3 + 3.0 * (EXTRA_MODE_CUT - f[j]) / EXTRA_MODE_CUT
               for j in range(len(f)) if f[j] < EXTRA_MODE_CUT and j not in assigned)
    for k, target in enumerate(TABLE1_IM_HZ):
        miss = math.log(f[position[k]] / target)
        cost += (max(0.0, abs(miss) - 0.10) / 0.03) ** 2 + 0.2 * (miss / 0.10) ** 2
        cost += 3.0 * max(0.0, 0.15 - a["score"][k]) / 0.15
    cost += sum((e / 0.01) ** 2 for e in a["operating"])
    if a["max_real"] > 0:
        cost += 10 + 100 * a["max_real"]
    if complex_pairs is not None:
        cost += max(0, complex_pairs - a["complex_pairs"])
    if by_rank:
        for k, target in enumerate(TABLE1_IM_HZ):
            miss = math.log(f[k] / target)
            cost += 0.5 * (max(0.0, abs(miss) - 0.045) / 0.02) ** 2 + 0.5 * (position[k] != k)
    return cost


def ranked_search_cost(parameters: Parameters) -> tuple[float, Parameters]:
    """Stage F: :func:`search_cost` plus :data:`RANK_BAND_WEIGHT` per rank outside the band,
    :data:`WRONG_CHARACTER_WEIGHT` per rank with another character and
    :data:`EXTRA_DIVERGENCE_WEIGHT` per positive real at s0 = 0.014 beyond two; returns the cost
    and the set with stage A solved."""
    parameters = fit_operating_data(with_constraints(parameters))
    operating = sum(_soft(row.error / 0.01) for row in operating_rows(parameters))
    e = evaluate_by_rank(parameters)
    miss = np.log(e.stable.imag / (2 * np.pi) / np.array(TABLE1_IM_HZ))
    cost = operating + rank_cost(e)
    cost += sum(RANK_BAND_WEIGHT * (max(0.0, abs(x) - RANK_BAND) / 0.01) ** 2 for x in miss)
    cost += WRONG_CHARACTER_WEIGHT * int(np.count_nonzero(~e.character_ok))
    cost += EXTRA_DIVERGENCE_WEIGHT * max(0, int(np.count_nonzero(e.unstable_real > 0)) - 2)
    return cost, parameters


def _within_bounds(parameters: Parameters) -> Parameters:
    parameters = with_constraints(parameters)
    for f in SEARCH_PARAMETERS:
        parameters = parameters.replace(**{f.name: float(min(max(parameters[f.name], f.low), f.high))})
    return with_constraints(parameters)


def compass_search(start: Parameters, cost: Callable, budget: int, steps: tuple[float, ...],
                     progress: Callable, label: str) -> tuple[Parameters, float]:
    """Compass search in log space within :data:`SEARCH_PARAMETERS`' bounds, parameters tried
    cyclically in their order (+step before -step; after an accepted move the sweep goes on with
    the next parameter); a step ends after a whole sweep without improvement; the schedule is
    repeated while it gains 0.1 %.  ``cost(parameters)`` returns (cost, anything)."""
    free = SEARCH_PARAMETERS
    best = start
    best_cost = cost(best)[0]
    count = 1
    began = time.perf_counter()
    progress(f"  {label}: start, cost {best_cost:.6g}")
    for _cycle in range(20):
        cycle_start = best_cost
        for step in steps:
            i, since = 0, 0  # since: moves tried since the last improvement
            while count < budget and since < 2 * len(free):
                f = free[i % len(free)]
                i += 1
                for direction in (1, -1):
                    since += 1
                    x = math.log(best[f.name])
                    x_new = min(max(x + direction * step, math.log(f.low)), math.log(f.high))
                    if abs(x_new - x) < 1e-9 or count >= budget:
                        continue
                    trial = with_constraints(best.replace(**{f.name: float(math.exp(x_new))}))
                    trial_cost = cost(trial)[0]
                    count += 1
                    if trial_cost < best_cost - 1e-4 * max(1, best_cost):
                        best, best_cost, since = trial, trial_cost, 0
                        progress(f"  {label}: {f.name} -> {math.exp(x_new):.5g}, cost "
                                 f"{best_cost:.6g} ({count} evaluations, "
                                 f"{time.perf_counter() - began:.0f} s)")
                        break
            progress(f"  {label}: step {step:g} done, cost {best_cost:.6g}, {count} evaluations "
                     f"({time.perf_counter() - began:.0f} s)")
        if best_cost > cycle_start * (1 - 1e-3) or count >= budget:
            break
    return best, best_cost


def _guarded(cost: Callable) -> Callable:
    def guarded(parameters: Parameters):
        try:
            return cost(parameters)
        except (ValueError, np.linalg.LinAlgError):  # a trial the model cannot analyse
            return math.inf, None
    return guarded


def rank_stages(stage_b: Parameters, progress: Callable = print, scale: float = 1.0
                ) -> Parameters:
    """Stages C–F from stage B's set (see above); ``scale`` multiplies the budgets."""
    budget = {k: max(8, round(v * scale)) for k, v in STAGE_BUDGETS.items()}
    complex_pairs = _extra_mode_analysis(stage_b)["complex_pairs"]
    p = fit_operating_data(_within_bounds(stage_b.replace(**RESTART_VALUES)))
    progress(f"  stage C: restart values {RESTART_VALUES}")
    steps = (0.4, 0.15, 0.05, 0.015)
    p, _ = compass_search(
        _within_bounds(p), _guarded(lambda q: (extra_mode_cost(_extra_mode_analysis(q), False),)),
        budget["D"], steps, progress, "stage D (extra modes below 12.6 Hz)")
    p = fit_operating_data(p)
    p, _ = compass_search(
        _within_bounds(p),
        _guarded(lambda q: (extra_mode_cost(_extra_mode_analysis(q), True, complex_pairs),)),
        budget["E"], steps, progress, "stage E (extra modes, by rank)")
    p = fit_operating_data(p)
    p, _ = compass_search(_within_bounds(p), _guarded(ranked_search_cost), budget["F"],
                            (0.3, 0.1, 0.03, 0.01), progress,
                            "stage F (damping and divergences, ranking held)")
    return fit_operating_data(p)


def calibrate(start: Parameters, max_evaluations: int = 2400, progress: Callable = print,
              scale: float = 1.0) -> tuple[Parameters, list[TargetRow]]:
    """Stage A fits the creep law and the gear ratio to the operating data (least squares);
    stage B1 places the ten characters (:func:`character_cost`, a quarter of the budget),
    stage B2 searches the creep shape, the structure, the dampers and the motor slope against
    Table 1 by rank (:func:`search_cost`); both are pattern searches over
    :data:`SEARCH_PARAMETERS` with stage A re-solved for every trial set, at most
    ``max_evaluations`` trial sets in all; stages C–F (:func:`rank_stages`, budgets
    :data:`STAGE_BUDGETS` times ``scale``) put the ten pairs in Table 1's order.  Returns the
    calibrated set and all its targets.  Deterministic: no random numbers, no time limits (run it
    with one BLAS thread, as :func:`run` does: another thread count rounds differently and can
    send a compass search down another path)."""
    stage_a = fit_operating_data(with_constraints(start))
    first = max_evaluations // 4
    stage_b = _pattern_search(stage_a, SEARCH_PARAMETERS, character_cost, first, progress,
                              "stage B1 (Table 2 characters)", steps=PATTERN_STEPS[:2])
    stage_b = _pattern_search(stage_b, SEARCH_PARAMETERS, search_cost, max_evaluations - first,
                              progress, "stage B2 (Table 1 by rank)")
    stage_b = fit_operating_data(stage_b)
    stage_f = rank_stages(stage_b, progress, scale)
    notes = dict(start.notes)
    for f in FREE_PARAMETERS:
        notes[f.name] = (f"calibrated by `bogie calibrate` within [{f.low:g}, {f.high:g}] "
                         f"({f.reason}); estimate {start[f.name]:g}")
    calibrated = Parameters(dict(stage_f.values), notes, "calibrated")
    return calibrated, evaluate(calibrated)


def evaluate(parameters: Parameters) -> list[TargetRow]:
    """All calibration targets with the values the model achieves (Table 1 by rank)."""
    e = evaluate_by_rank(parameters)
    rows = []
    for k, target in enumerate(TABLE1_IM_HZ, start=1):
        mark = "" if e.character_ok[k - 1] else " (other character!)"
        rows.append(TargetRow(f"Im λ{k} by rank [{MODE_SIGNATURES[k - 1][0]}]{mark}", target,
                              e.stable[k - 1].imag / (2 * np.pi), "Hz"))
    for k in RE_MODES:
        rows.append(TargetRow(f"Re λ{k} at s0=0.005", TABLE1_RE[k - 1],
                              e.matched[k - 1].real, "1/s"))
    rows.append(TargetRow("Im λ58 [ID1 driving shaft twisting]", DRIVING_SHAFT_HZ,
                          e.driving_shaft.imag / (2 * np.pi), "Hz"))
    rows += operating_rows(parameters)
    for k in UNSTABLE_RE_MODES:
        rows.append(TargetRow(f"Re of pair {k} at s0=0.014 (Im {e.unstable[k - 1].imag / (2 * np.pi):.3f} Hz)",
                              TABLE1_UNSTABLE[k - 1][0], e.unstable[k - 1].real, "1/s"))
    for i, target in enumerate(DIVERGENCE_RATES):
        rows.append(TargetRow(f"real eigenvalue {i + 1} at s0=0.014", target,
                              float(e.unstable_real[i]), "1/s"))
    return rows


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


MAX_EVALUATIONS = 2400  # default budget of trial sets of stage B


def run(start_file=ESTIMATE_FILE, out_file=CALIBRATED_FILE, max_evaluations: int = MAX_EVALUATIONS,
        progress: Callable = print, scale: float = 1.0) -> list[TargetRow]:
    """The ``bogie calibrate`` command: fit (with one BLAS thread, for a reproducible path),
    write the calibrated set, print the table."""
    from threadpoolctl import threadpool_limits

    start = load_parameters(start_file)
    progress(f"calibrating {len(FREE_PARAMETERS)} parameters from {start_file} …")
    with threadpool_limits(1):
        calibrated, rows = calibrate(start, max_evaluations, progress, scale)
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
