"""Literature tests: the calibrated model against the published results of Zeman & Hlaváč
(shared/spec/reference-results.md: Table 1, Table 2, stability limit, operating data).

Tolerances (the issue's acceptance limits, justified):

* eigenfrequencies 3 %: Table 1 gives 4 significant digits, but the study's parameters are not
  published; ours are estimates calibrated to the table, so 3 % is what a calibrated model of an
  unknown structure can be asked to reproduce (the spread of the published WS1/WS2 pairs alone is
  3–7 %);
* motor torque M(s0, v) 2 %: eq. 7 with one friction value, the published 12 800 N m is given to
  3 digits;
* adhesion moment M_ad and stability limit 3 %: published to 2 digits (0.52·10⁵ N m, 0.0082).

Where the calibrated model misses a target, the test is marked ``xfail(strict=True)`` with the
achieved value in the reason: the miss is documented (docs/validation.md), and the test turns red
the day the model meets the target, so the record cannot go stale.  Regenerate the numbers with
``bogie calibrate`` (prints the table) — nothing here is copied into the model.
"""

from __future__ import annotations

import numpy as np
import pytest

from model import OperatingPoint, build_model, eigen_analysis, load_parameters, mode_character
from model.calibration import (
    ADHESION_MOMENT,
    DRIVING_SHAFT_HZ,
    MOTOR_TORQUE,
    STABILITY_LIMIT,
    TABLE1_IM_HZ,
    TABLE1_RE,
    V_REF,
    driving_shaft_mode,
    match_table1_modes,
    wheelset_yaw_fraction,
)
from model.operating_point import adhesion_moment, motor_torque
from model.stability import stability_limit

# documented misses of the calibrated set (see docs/validation.md); value achieved in the reason
MISSED_MODES: dict[int, str] = {}  # none since the yaw dampers joined the calibration


@pytest.fixture(scope="module")
def calibrated():
    parameters = load_parameters()
    model = build_model(parameters)
    op = OperatingPoint(0.005, V_REF, parameters["wheel_force"], parameters["motor_slope"])
    result = eigen_analysis(model, op)
    matched, _ = match_table1_modes(model, result)
    return parameters, model, result, matched


def _mark(k: int):
    if k in MISSED_MODES:
        return pytest.mark.xfail(strict=True, reason="documented miss: " + MISSED_MODES[k])
    return ()


@pytest.mark.parametrize("k", [pytest.param(k, marks=_mark(k)) for k in range(1, 11)])
def test_table1_imaginary_part_within_3_percent(calibrated, k):
    _, _, result, matched = calibrated
    achieved = result.eigenvalues[matched[k - 1]].imag / (2 * np.pi)
    assert achieved == pytest.approx(TABLE1_IM_HZ[k - 1], rel=0.03)


# --- Table 1 row by row (issue 11) ---------------------------------------------------------------
# The k-th complex pair *by rank* (ascending Im, as Table 1 lists them) must lie within 5 % of the
# published k-th (the acceptance limit; its aim is 3 %) and be the mode that carries
# Table 2's k-th character (a pair that matches in frequency but moves other parts is no match).
# The current set was calibrated by character, not by rank: it has 16 complex pairs below
# 12.6 Hz against the study's ten, so from row 6 on the rows belong to other modes.  Misses are
# strict xfails with the values achieved (v = 120 km/h, N0 and b_M of the set).
MISSED_BY_RANK: dict[int, str] = {
    6: "6th pair −2.080 ± i 7.429 Hz (−12.6 %), the frame's roll, not Table 2's 6th character",
    7: "7th pair −0.346 ± i 7.523 Hz (−12.4 %), the motors' longitudinal motion in opposite "
       "phase, not Table 2's 7th character",
    8: "8th pair −3.212 ± i 8.477 Hz (−7.7 %), Table 2's 6th character",
    9: "9th pair −1.796 ± i 8.632 Hz (−29.3 %), Table 2's 7th character",
    10: "10th pair −3.385 ± i 9.055 Hz (−28.0 %), Table 2's 8th character",
}
# Re of the modes the issue names, each taken as the mode with Table 2's character: within 30 %,
# or within 0.05 1/s where the published |Re| < 0.2 1/s (two or three digits published; damping
# was not a calibration target of the current set)
MISSED_REAL_PARTS: dict[int, str] = {
    1: "Re −0.100 1/s against −0.032 (car body bounce: primary and secondary vertical dampers)",
    3: "Re −2.367 1/s against −0.199 (frame pitch with the gears: yaw dampers against a fixed car "
       "body)",
    4: "Re −0.646 1/s against −0.056 (frame bounce with both motors)",
    9: "Re −21.9 1/s against −3.958 (wheelset 2's longitudinal–yaw mode)",
    10: "Re −8.74 1/s against −4.010 (wheelset 1's longitudinal–yaw mode)",
}


def _by_rank_mark(k: int, missed: dict[int, str]):
    if k in missed:
        return pytest.mark.xfail(strict=True, reason="documented miss (issue 11): " + missed[k])
    return ()


@pytest.mark.parametrize("k", [pytest.param(k, marks=_by_rank_mark(k, MISSED_BY_RANK))
                               for k in range(1, 11)])
def test_table1_by_rank_within_5_percent_with_its_character(calibrated, k):
    _, _, result, matched = calibrated
    index = result.complex_index[k - 1]
    assert result.eigenvalues[index].imag / (2 * np.pi) == pytest.approx(TABLE1_IM_HZ[k - 1],
                                                                          rel=0.05)
    assert index == matched[k - 1], "the k-th pair by rank has another mode's character"


@pytest.mark.parametrize("k", [pytest.param(k, marks=_by_rank_mark(k, MISSED_REAL_PARTS))
                               for k in (1, 3, 4, 8, 9, 10)])
def test_table1_real_part(calibrated, k):
    _, _, result, matched = calibrated
    published = TABLE1_RE[k - 1]
    tolerance = 0.05 if abs(published) < 0.2 else 0.3 * abs(published)
    assert result.eigenvalues[matched[k - 1]].real == pytest.approx(published, abs=tolerance)


def test_driving_shaft_mode_within_3_percent(calibrated):
    _, model, result, _ = calibrated
    index = driving_shaft_mode(model, result)
    assert result.eigenvalues[index].imag / (2 * np.pi) == pytest.approx(DRIVING_SHAFT_HZ, rel=0.03)
    description = mode_character(model, result, index).description
    assert "twisting of driving shaft 1" in description  # Table 2, ν = 58


@pytest.mark.parametrize(("k", "words"), [
    (1, ("vertical", "car body")),  # vertical of car body (in phase with BF and TMs)
    (2, ("torsion of rotor 1", "twisting of disc clutch 1")),  # ID1 rotor with gears, DC twisting
    (5, ("lateral of TM", "in phase", "bogie frame in phase")),  # lateral (and roll) of BF with TMs
    # lateral of both TMs in opposite phase; the TM with the larger amplitude is named first, and
    # which one that is depends on the small asymmetry of the drives, so the order is not asserted
    (6, ("lateral of TM", "opposite phase", "silent blocks")),
    (8, ("longitudinal of wheelset 1",)),  # combined longitudinal–pitch of wheelset 1
    (10, ("yaw of wheelset 1",)),  # combined longitudinal–yaw of wheelset 1
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


def test_mode10_is_wheelset_yaw(calibrated):
    """The axle is a chain of beam nodes: its yaw shows in the nodes' x translations, and the
    description splits them by the journals' phase (modes.wheelset_yaw_fraction)."""
    _, model, result, matched = calibrated
    assert "yaw of wheelset 1" in mode_character(model, result, matched[9]).description


def test_calibrated_frame_inertias_are_physical(calibrated):
    """A rigid body's principal inertias obey I_z <= I_x + I_y; the calibration keeps the frame's
    yaw inertia within it (calibration.with_constraints)."""
    parameters = calibrated[0]
    assert parameters["frame_inertia_z"] <= (parameters["frame_inertia_x"]
                                             + parameters["frame_inertia_y"]) * (1 + 1e-12)


def test_stable_at_small_creepage(calibrated):
    _, _, result, _ = calibrated
    assert result.stable
    assert result.n_rigid == 2  # the two drivetrain spins, as the study's two ~0 eigenvalues


def test_unstable_at_large_creepage(calibrated):
    parameters, model, _, _ = calibrated
    result = eigen_analysis(model, OperatingPoint(0.014, V_REF, parameters["wheel_force"],
                                                  parameters["motor_slope"]), vectors=False)
    assert not result.stable
    assert result.divergence >= 1  # a drivetrain spins up on the falling creep branch
    assert result.flutter >= 1


@pytest.mark.xfail(strict=True, reason="documented miss: the calibrated model has 3 unstable "
                   "pairs among the first ten (7 in all) and 1 positive real eigenvalue "
                   "(+13.75 1/s); the study has 5 and 2 (+7.03, +0.06)")
def test_unstable_pattern_as_published(calibrated):
    parameters, model, _, _ = calibrated
    result = eigen_analysis(model, OperatingPoint(0.014, V_REF, parameters["wheel_force"],
                                                  parameters["motor_slope"]), vectors=False)
    assert int(np.count_nonzero(result.complex_pairs[:10].real > 0)) == 5
    assert result.divergence == 2


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
