"""Literature tests: the calibrated model against the published results of Zeman & Hlaváč
(CITATION.cff: Table 1, Table 2, stability limit, operating data).

Table 1 is compared **by rank**, as the study lists it ("the first ten pairs of complex conjugate
eigenvalues sequenced according to magnitude of imaginary parts"): the model's k-th complex pair
by imaginary part against the published k-th, and it must have Table 2's k-th character
(``calibration_targets.MODE_SIGNATURES``, optimal one-to-one assignment over the lowest pairs).

Tolerances (the acceptance limits, justified):

* imaginary parts by rank 5 %: Table 1 gives 4 significant digits, but the study's parameters
  were not published; ours are estimates calibrated to the table within physical bounds, and
  two published pairs lie 0.4 % (modes 3/4) and 0.9 % (modes 6/7) apart, so a calibrated model
  of an unknown structure can be asked for 5 % (the calibration aims at 3 %);
* real parts of modes 1, 3, 4, 8, 9, 10 at s0 = 0.005: 30 %, or 0.05 1/s where the published
  |Re| < 0.2 1/s — damping is the least certain part of any model (the study's dampers are
  unknown; a 30 % spread is what damper rates of one design vary by), and below 0.2 1/s a
  relative tolerance would ask for hundredths of a per cent of damping ratio;
* driving-shaft mode 3 %: one stiffness against one reduced inertia, both estimated;
* motor torque M(s0, v) 2 %: eq. 7 with one friction value, the published 12 800 N m is given
  to 3 digits; adhesion moment M_ad and stability limit 3 %: published to 2 digits.

Where the calibrated model misses a target, the test is marked ``xfail(strict=True)`` with the
achieved value in its reason: the miss is documented (docs/validation.md), and the test turns
red the day the model meets the target, so the record cannot go stale.  Regenerate the numbers
with ``bogie calibrate`` (prints the table) — nothing here is copied into the model.
"""

from __future__ import annotations

import numpy as np
import pytest

from model import OperatingPoint, build_model, eigen_analysis, load_parameters, mode_character
from model.analysis.modes import wheelset_yaw_fraction
from model.analysis.stability import stability_limit
from model.mechanics.operating_point import adhesion_moment, motor_torque
from model.studies.calibration_bounds import FREE_PARAMETERS, constraint_values
from model.studies.calibration_targets import (
    ADHESION_MOMENT,
    DIVERGENCE_RATES,
    DRIVING_SHAFT_HZ,
    MOTOR_TORQUE,
    RE_MODES,
    STABILITY_LIMIT,
    SUSPENSION_MODES,
    SUSPENSION_ZETA,
    TABLE1_IM_HZ,
    TABLE1_RE,
    TABLE1_UNSTABLE,
    V_REF,
    driving_shaft_mode,
    match_table1_modes,
)

IM_TOLERANCE = 0.05  # [-] relative, by rank
RE_TOLERANCE, RE_ABSOLUTE = 0.30, 0.05  # [-] relative; [1/s] where |Re_published| < 0.2 1/s

# documented misses of the calibrated set (see docs/validation.md); value achieved in the reason
MISSED_IM: dict[int, str] = {
    9: "rank 9, wheelset 2's longitudinal-yaw mode, at 10.741 Hz (-12.0 %): the bundled set "
       "weighs the divergence at s0 = 0.014 (+7.025 against +7.031 1/s) against the wheelsets' "
       "yaw frequencies (docs/validation.md, 'The bundled set'); the single-wheelset model with "
       "the divergence puts the in-phase yaw at best -5.05 % with the heaviest drive and wheels "
       "1.65 times the set's, -7.8 % with the set's wheels (docs/validation.md, 'Which published "
       "numbers a bogie can reach')",
    10: "rank 10, wheelset 1's longitudinal-yaw mode, at 11.490 Hz (-8.7 %), the same trade",
}
MISSED_CHARACTER: dict[int, str] = {
    3: "rank 3 (5.455 Hz) is the frame's bounce with both TMs, Table 2's 4th character; the "
       "frame's pitch (Table 2's 3rd) is at 5.466 Hz: the two published 0.4 % apart are 0.2 % "
       "apart and in the other order",
    4: "rank 4 (5.466 Hz) is the frame's pitch with both TMs, Table 2's 3rd character (3 and 4 "
       "swapped)",
}
MISSED_RE: dict[int, str] = {
    8: "Re of wheelset 1's longitudinal-pitch mode -7.16 1/s (published -3.282, -118 %)",
    9: "Re of wheelset 2's longitudinal-yaw mode -6.74 1/s (published -3.958, -70 %)",
    10: "Re of wheelset 1's longitudinal-yaw mode -5.33 1/s (published -4.010, -33 %)",
}
MISSED_TWO_DIVERGENCES = ("one positive real eigenvalue, +7.025 1/s, within 0.1 % of the "
                          "published +7.031 (wheelset 1's spin with rotor 1 on the calibrated "
                          "creep's falling slope); the published second, +0.062, has no "
                          "counterpart: ID2's spin is held by its motor slope b_M = 1.21e3 "
                          "N m s/rad and oscillates instead (+4.34 1/s at 1.78 Hz)")
MISSED_PATTERN = ("unstable among the first ten at s0 = 0.014: pairs 2, 3, 8 (published 3, 7, 8, "
                  "9, 10): wheelset 2's pitch with its disc clutch (+4.34 1/s at 1.78 Hz), "
                  "ID1's torsion with its disc clutch (+1.81 at 3.15 Hz) and the wheelsets' "
                  "longitudinal mode (+1.43 at 9.28 Hz); the wheelsets' yaw modes stay damped "
                  "(-3.22 at 9.75 Hz, -0.94 at 10.80 Hz)")
MISSED_ON_BOUNDS = ("four calibrated parameters on a bound: stator_inertia_y (its upper "
                    "400 kg m^2), yaw_damper_height (0.60 m), traction_link_stiffness (its lower "
                    "3 MN/m), traction_link_height (0.30 m); every value inside its bounds")


# published numbers that no bogie within the hardware bounds can reach (the proofs: the reduced
# models of model/studies/reachability.py, numbers in docs/validation.md, "Which published
# numbers a bogie can reach"; regenerate with scripts/reachability.py)
FORBIDDEN_SUSPENSION_RE = (
    "the published real parts of the car body bounce (-0.032 1/s) and the frame bounce (-0.056) "
    "need vertical dampers 16x and 80x below their hardware lower bounds (10 kN s/m), and the "
    "frame pitch (-0.199) is damped more than that even without vertical dampers (-2.09 1/s): "
    "with the dampers at the bounds the full model gives -0.52, -3.71 and -2.95 1/s "
    "(docs/validation.md, 'Which published numbers a bogie can reach')")
FORBIDDEN_MODE2 = (
    "mode 2's Re -0.041 at s0 = 0.005 and -0.060 at 0.014 with the +7.031 1/s spin divergence: "
    "in the torsional chain (rotor and gears against the disc clutch, creep damper on the "
    "wheelset) mode 2 is less damped at 0.014 than at 0.005 whenever the creep slope falls "
    "(published: 0.019 1/s more damped), and with the motor slope within its bounds no chain "
    "keeps mode 2 within 5 % of 2.689 Hz at 0.014 (docs/validation.md, 'Which published numbers "
    "a bogie can reach')")


@pytest.fixture(scope="module")
def calibrated():
    parameters = load_parameters()
    model = build_model(parameters)
    op = OperatingPoint(0.005, V_REF, parameters["wheel_force"], parameters["motor_slope"])
    result = eigen_analysis(model, op)
    matched, _ = match_table1_modes(model, result)
    return parameters, model, result, matched


@pytest.fixture(scope="module")
def unstable(calibrated):
    parameters, model, _, _ = calibrated
    return eigen_analysis(model, OperatingPoint(0.014, V_REF, parameters["wheel_force"],
                                                parameters["motor_slope"]), vectors=False)


def _marks(misses: dict[int, str], k: int):
    if k in misses:
        return pytest.mark.xfail(strict=True, reason="documented miss: " + misses[k])
    return ()


@pytest.mark.parametrize("k", [pytest.param(k, marks=_marks(MISSED_IM, k)) for k in range(1, 11)])
def test_table1_imaginary_part_by_rank_within_5_percent(calibrated, k):
    _, _, result, _ = calibrated
    achieved = result.complex_pairs[k - 1].imag / (2 * np.pi)
    assert achieved == pytest.approx(TABLE1_IM_HZ[k - 1], rel=IM_TOLERANCE)


@pytest.mark.parametrize("k", [pytest.param(k, marks=_marks(MISSED_CHARACTER, k))
                               for k in range(1, 11)])
def test_table1_pair_by_rank_has_table2_character(calibrated, k):
    """The k-th pair by Im is the mode the character assignment gives Table 2's k-th row."""
    _, _, result, matched = calibrated
    assert matched[k - 1] == result.complex_index[k - 1]


def _re_marks(k: int):
    if k in SUSPENSION_MODES:
        return pytest.mark.xfail(strict=True, reason="forbidden by the bounds: "
                                 + FORBIDDEN_SUSPENSION_RE)
    return _marks(MISSED_RE, k)


@pytest.mark.parametrize("k", [pytest.param(k, marks=_re_marks(k)) for k in RE_MODES])
def test_table1_real_part(calibrated, k):
    _, _, result, matched = calibrated
    published = TABLE1_RE[k - 1]
    achieved = result.eigenvalues[matched[k - 1]].real
    if abs(published) < 0.2:
        assert achieved == pytest.approx(published, abs=RE_ABSOLUTE)
    else:
        assert achieved == pytest.approx(published, rel=RE_TOLERANCE)


def test_driving_shaft_mode_within_3_percent(calibrated):
    _, model, result, _ = calibrated
    index = driving_shaft_mode(model, result)
    assert result.eigenvalues[index].imag / (2 * np.pi) == pytest.approx(DRIVING_SHAFT_HZ, rel=0.03)
    description = mode_character(model, result, index).description
    assert "twisting of driving shaft 1" in description  # Table 2, ν = 58


@pytest.mark.parametrize(("k", "words"), [
    (1, ("vertical", "car body")),  # vertical of car body (in phase with BF and TMs)
    (2, ("torsion of rotor 1", "twisting of disc clutch 1")),  # ID1 rotor with gears, DC twisting
    (5, ("lateral of", "in phase")),  # lateral (and roll) of BF with TMs in phase
    # lateral of both TMs in opposite phase; the TM with the larger amplitude is named first, and
    # which one that is depends on the small asymmetry of the drives, so the order is not asserted
    (6, ("lateral of TM", "opposite phase", "silent blocks")),
])
def test_generated_description_agrees_with_table2(calibrated, k, words):
    _, model, result, matched = calibrated
    description = mode_character(model, result, matched[k - 1]).description
    for word in words:
        assert word in description, description


def test_wheelset_modes_told_apart_by_journal_phase(calibrated):
    """Table 2's longitudinal–pitch modes (7, 8) move both journals of a wheelset in phase, its
    longitudinal–yaw modes (9, 10) in opposite phase: the matched modes must do the same."""
    _, model, result, matched = calibrated
    for k in (7, 8, 9, 10):
        yaw = wheelset_yaw_fraction(model, result.mode_shape(matched[k - 1]))
        drive = "ID2" if k in (7, 9) else "ID1"
        assert (yaw[drive] > 0.5) == (k in (9, 10)), (k, yaw)


def test_calibrated_inertias_are_physical(calibrated):
    """A rigid body's principal inertias obey |I_x − I_y| <= I_z <= I_x + I_y
    (calibration_bounds.constraint_values); the frame's roll inertia cannot exceed all its mass
    at the frame's outer edges (m · 1.1² m²), its pitch inertia all its mass at the ends
    (m · 1.75² m²); Polach's kS <= kA."""
    parameters = calibrated[0]
    assert np.all(constraint_values(parameters) <= 1e-12)
    assert parameters["frame_inertia_x"] <= parameters["frame_mass"] * 1.1**2
    assert parameters["frame_inertia_y"] <= parameters["frame_mass"] * 1.75**2
    assert parameters["polach_kS"] <= parameters["polach_kA"]


@pytest.mark.xfail(bool(MISSED_ON_BOUNDS), strict=True, reason="documented miss: " + MISSED_ON_BOUNDS)
def test_calibrated_values_inside_their_bounds_at_most_two_on_one(calibrated):
    """Every calibrated parameter within the range its source allows (its calibration bounds,
    calibration_bounds.FREE_PARAMETERS, each with its reason), and at most two on a bound (within
    0.1 %, calibration_bounds.on_bound): the acceptance limit; a set that fits by bending its data
    sits on many."""
    parameters = calibrated[0]
    for f in FREE_PARAMETERS:
        assert f.low - 1e-12 * abs(f.low) <= parameters[f.name] <= f.high + 1e-12 * abs(f.high)
    on = [f.name for f in FREE_PARAMETERS if f.on_bound(parameters[f.name])]
    assert len(on) <= 2, on


@pytest.mark.xfail(strict=True, reason="forbidden by the bounds: three of the six are the "
                   "suspension modes' (" + FORBIDDEN_SUSPENSION_RE + "); of the wheelset modes' "
                   "8, 9, 10 none is met (MISSED_RE)")
def test_at_least_five_of_six_real_parts(calibrated):
    """The earlier target on the real parts of modes 1, 3, 4, 8, 9, 10 (each with the
    tolerance of test_table1_real_part): at least five; out of reach of hardware dampers."""
    _, _, result, matched = calibrated
    met = 0
    for k in RE_MODES:
        published, achieved = TABLE1_RE[k - 1], result.eigenvalues[matched[k - 1]].real
        tolerance = RE_ABSOLUTE if abs(published) < 0.2 else RE_TOLERANCE * abs(published)
        met += abs(achieved - published) <= tolerance
    assert met >= 5


def test_stable_at_small_creepage(calibrated):
    _, _, result, _ = calibrated
    assert result.stable
    # the two drivetrain spins (the study's two ~0 eigenvalues) and, since the car body moves
    # longitudinally and in yaw, the whole vehicle's translation and yaw; and the velocity of
    # the vehicle rolling without slip, which nothing damps (no running resistance)
    assert result.n_rigid == 5


def test_unstable_at_large_creepage(unstable):
    assert not unstable.stable
    assert unstable.divergence >= 1  # a drivetrain spins up on the falling creep branch
    assert unstable.flutter >= 1


@pytest.mark.xfail(bool(MISSED_TWO_DIVERGENCES), strict=True,
                   reason="documented miss: " + MISSED_TWO_DIVERGENCES)
def test_two_divergent_reals_at_large_creepage(unstable):
    """Published: +7.031 and +0.062 1/s.  Asserted: exactly two positive real eigenvalues, the
    larger within 30 % of +7.031 (it is set by the falling creep slope and the drivetrain's
    inertia, both calibrated only through other targets).  The smaller one is reported, not
    asserted: +0.062 is 1 % of the larger, a near-cancellation of ID2's creep and motor slope
    that no independently derived b_M can be asked to reproduce (docs/validation.md)."""
    assert unstable.divergence == 2
    assert unstable.real_eigenvalues[0] == pytest.approx(DIVERGENCE_RATES[0], rel=0.3)


def test_largest_divergence_within_10_percent(unstable):
    """The study's larger divergence, +7.031 1/s at s0 = 0.014: a wheelset's spin with its drive
    on the falling creep slope.  10 %: the rate is the falling slope of a creep law published
    only through its operating data (M(s0) at two creepages, M_ad, s0*) over the drivetrain's
    inertia, both calibrated; the calibration weighs it against Table 1's frequencies
    (docs/validation.md, 'The bundled set')."""
    assert unstable.real_eigenvalues[0] == pytest.approx(DIVERGENCE_RATES[0], rel=0.10)


@pytest.mark.xfail(bool(MISSED_PATTERN), strict=True, reason="documented miss: " + MISSED_PATTERN)
def test_unstable_pattern_as_published(unstable):
    """Published at s0 = 0.014: pairs 3, 7, 8, 9, 10 of the first ten flutter, the others not."""
    published = [re > 0 for re, _ in TABLE1_UNSTABLE]
    assert list(unstable.complex_pairs[:10].real > 0) == published


def test_stability_limit_within_3_percent(calibrated):
    parameters, model, _, _ = calibrated
    limit = stability_limit(model, V_REF, parameters["wheel_force"], parameters["motor_slope"])
    assert limit.s0_limit == pytest.approx(STABILITY_LIMIT, rel=0.03)


@pytest.mark.parametrize("s0", [0.005, 0.014])
def test_motor_torque_within_2_percent(calibrated, s0):
    parameters = calibrated[0]
    op = OperatingPoint(s0, V_REF, parameters["wheel_force"], parameters["motor_slope"])
    assert motor_torque(parameters, op) == pytest.approx(MOTOR_TORQUE, rel=0.02)


def test_adhesion_moment_within_3_percent(calibrated):
    parameters = calibrated[0]
    assert adhesion_moment(parameters, V_REF, parameters["wheel_force"]) == pytest.approx(
        ADHESION_MOMENT, rel=0.03)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="forbidden by the bounds: " + FORBIDDEN_SUSPENSION_RE)
def test_suspension_real_parts_reachable_within_hardware_bounds(calibrated):
    """The published real parts of the car body bounce, the frame pitch and the frame bounce
    with the vertical dampers within their hardware bounds (reachability.suspension_proof:
    the least damping the bounds allow is at the lower bounds)."""
    from model.studies.reachability import suspension_proof

    proof = suspension_proof(calibrated[0])
    assert all(mode.reachable for mode in proof.modes)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="forbidden by the bounds: " + FORBIDDEN_MODE2)
def test_mode2_real_parts_reachable_with_the_published_divergence(calibrated):
    """Mode 2 at both creepages with the +7.031 1/s spin, in the torsional chain over the
    plausible inertias, disc clutch damping and motor slope (reachability.torsional_chain_proof,
    3 values each here; 5 in docs/validation.md)."""
    from model.studies.reachability import torsional_chain_proof

    parameters = calibrated[0]
    proof = torsional_chain_proof(parameters["gear_inertia"], parameters["pinion_inertia"],
                                  DIVERGENCE_RATES[0], points=3)
    assert proof.reachable


def test_suspension_modes_damped_as_real_hardware(calibrated):
    """The car body's and the frame's bounce and pitch (Table 2's rows 1, 3, 4, matched by
    character) with a damping ratio of at least 0.05."""
    _, _, result, matched = calibrated
    for k in SUSPENSION_MODES:
        lam = result.eigenvalues[matched[k - 1]]
        assert -lam.real / abs(lam) >= SUSPENSION_ZETA, k
