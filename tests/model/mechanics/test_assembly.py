"""Invariants of the assembled bogie: properties every correct assembly has, whatever the
parameter values (so they hold for the estimate and for every calibration of it).

Each tolerance is relative to the norm of the matrix it concerns and says why it is what it is.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import scipy.linalg as sla

from model import (
    build_model,
    default_operating_point,
    eigen_analysis,
    load_parameters,
    motor_torque,
    output_matrices,
)
from model.analysis.eigen import state_space
from model.analysis.linear_system import massless_coordinates
from model.mechanics.assembly import DRIVES, YAW_DAMPERS, dof_names
from model.mechanics.dofs import AXES6, DofMap
from model.mechanics.operating_point import (
    OperatingPoint,
    creep_coefficients,
    creep_damping,
    damping_matrix,
)
from model.mechanics.outputs import static_load
from model.mechanics.parameters import CALIBRATED_FILE, ESTIMATE_FILE

EPS = np.finfo(float).eps
N_DOF = 197
N_RIGID = 4  # the two drivetrain spins, the vehicle's longitudinal translation and yaw

# sign of each coordinate under the central symmetry (180° about z): x, y → −x, −y; z → z; the
# rotations are axial vectors of a proper rotation and transform alike: rx, ry → −; rz → +.
SYMMETRY_SIGN = {"x": -1.0, "y": -1.0, "z": 1.0, "rx": -1.0, "ry": -1.0, "rz": 1.0}


@pytest.fixture(scope="module", params=["calibrated", "estimate"])
def model(request):
    path = {"calibrated": CALIBRATED_FILE, "estimate": ESTIMATE_FILE}[request.param]
    return build_model(load_parameters(path))


@pytest.fixture(scope="module")
def calibrated():
    return build_model(load_parameters())


def _scaled(matrix: np.ndarray) -> np.ndarray:
    """D^(−1/2) K D^(−1/2) with D = diag(K): unit diagonal, so metres and radians mix fairly."""
    d = 1 / np.sqrt(np.diag(matrix))
    return d[:, None] * matrix * d[None, :]


def _drive_indices(model, prefix):
    return [i for i, name in enumerate(model.dofs.names) if name.startswith(prefix + ".")]


def _symmetry_map(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indices of ID1, matching indices of ID2, diagonal sign matrix R)."""
    i1 = _drive_indices(model, "ID1")
    i2 = [model.dofs.index("ID2." + model.dofs.names[i].split(".", 1)[1]) for i in i1]
    R = np.diag([SYMMETRY_SIGN[model.dofs.names[i].rsplit(".", 1)[1]] for i in i1])
    return np.array(i1), np.array(i2), R


# ------------------------------------------------------------------------------------------------
# coordinates


def test_dof_count_and_names(calibrated):
    names = calibrated.dofs.names
    assert len(names) == N_DOF == calibrated.n == len(dof_names())
    assert len(set(names)) == len(names)
    axes = "|".join(AXES6)
    pattern = re.compile(rf"^((ID[12]\.[a-z]+[0-9]*|BF|CB)\.({axes})"
                         rf"|secondary\.yaw_damper_(left|right)\.stroke)$")
    bad = [name for name in names if not pattern.match(name)]
    assert not bad, f"names not <subsystem>.<part>.<axis> (BF/CB: <body>.<axis>): {bad}"
    # q = [q_ID1, q_BFCB, q_ID2] (eq. 1), the two drives with the same layout
    first = [name.split(".", 1)[0] for name in names]
    assert first == ["ID1"] * 93 + ["BF"] * 6 + ["CB"] * 3 + ["secondary"] * 2 + ["ID2"] * 93
    assert [n[4:] for n in names[:93]] == [n[4:] for n in names[104:]]
    assert [n for n in names if n.startswith("CB.")] == ["CB.x", "CB.z", "CB.rz"]
    for name in names:
        axis = name.rsplit(".", 1)[1]
        assert calibrated.dofs.unit(name) == ("m" if axis in ("x", "y", "z", "stroke") else "rad")


def test_converter_filter_coordinate_is_named_and_has_a_unit():
    """With a torque control (``motor_bandwidth`` > 0) the one extra coordinate follows the naming
    scheme (``<subsystem>.<part>.<coordinate>``) and has its unit (rad) like every other one."""
    names = dof_names(converter=True)
    assert names[:-1] == dof_names()
    assert names[-1] == "ID2.converter.filtered_angle"
    dofs = DofMap(names)
    assert dofs.subsystem(names[-1]) == "ID2"
    assert dofs.part(names[-1]) == "ID2.converter"
    assert dofs.unit(names[-1]) == "rad"
    assert {dofs.unit(name) for name in names} == {"m", "rad"}


def test_rims_index_their_own_coordinates(calibrated):
    assert sorted(calibrated.rims) == ["ID1.rim12", "ID1.rim14", "ID2.rim12", "ID2.rim14"]
    for rim, index in calibrated.rims.items():
        assert [calibrated.dofs.names[i] for i in index] == [f"{rim}.{a}" for a in AXES6]


# ------------------------------------------------------------------------------------------------
# matrices


def test_mass_matrix_symmetric_positive_definite_but_on_the_yaw_dampers_strokes(model):
    """M is symmetric positive definite on every coordinate but the two yaw dampers' strokes,
    the massless inner nodes of the Maxwell elements, whose rows and columns are exactly zero."""
    M = model.M
    # W^T M6 W products round differently above and below the diagonal: allow a few ulps of ||M||
    assert np.allclose(M, M.T, rtol=0, atol=10 * EPS * np.abs(M).max())
    massless = massless_coordinates(M)
    assert [model.dofs.names[i] for i in massless] == [f"{d}.stroke" for d in YAW_DAMPERS]
    inertial = np.setdiff1d(np.arange(model.n), massless)
    sla.cholesky(0.5 * (M + M.T)[np.ix_(inertial, inertial)])  # LinAlgError unless PD
    assert np.all(np.diag(M)[inertial] > 0)
    assert not np.any(M[:, massless])


def test_stiffness_symmetric_psd_with_exactly_four_zero_eigenvalues(model):
    """Eigenvalues of the unit-diagonal scaled K: a backward-stable solver gives the true zeros
    as O(n eps ||K_s||) ≈ 1e-13; we call |λ| < 100 n eps ||K_s|| (≈ 1e-11) zero.  The softest
    real stiffness (soft secondary suspension) sits many decades above, so the count is not a
    tolerance artefact.  Four zeros: the drivetrain spins and the whole vehicle's longitudinal
    translation and yaw."""
    K = model.K
    assert np.array_equal(K, K.T)
    w = np.linalg.eigvalsh(_scaled(K))
    tol = 100 * model.n * EPS * np.abs(w).max()
    assert w.min() > -tol
    assert np.count_nonzero(np.abs(w) < tol) == N_RIGID
    assert w[N_RIGID] > 100 * tol


def test_damping_symmetric_psd(model):
    B = model.B
    assert np.array_equal(B, B.T)
    w = np.linalg.eigvalsh(B)
    assert w.min() > -100 * model.n * EPS * w.max()


def test_rigid_body_modes_are_the_null_space_of_k(model):
    R = model.rigid_body_modes
    assert R.shape == (model.n, N_RIGID)
    K = model.K
    residual = np.linalg.norm(K @ R, axis=0)
    assert np.all(residual <= 1e3 * EPS * np.linalg.norm(K, 2) * np.linalg.norm(R, axis=0))
    # one per drivetrain, each confined to its drive's spins
    for column, prefix in enumerate(DRIVES):
        touched = {model.dofs.names[i] for i in np.flatnonzero(R[:, column])}
        assert touched
        assert all(name.startswith(prefix) and name.endswith(".ry") for name in touched)
    names = model.dofs.names
    translation, yaw = R[:, 2], R[:, 3]
    # the translation: every x coordinate 1, nothing else (no spin: the wheels slide)
    assert all(translation[i] == (1.0 if n.endswith(".x") else 0.0) for i, n in enumerate(names))
    # the yaw about the vertical through the bogie centre: rz = 1 everywhere, x = −y0, y = x0
    assert all(yaw[i] == 1.0 for i, n in enumerate(names) if n.endswith(".rz"))
    ax11 = model.positions["ID1.ax11"]
    assert yaw[model.dofs.index("ID1.ax11.x")] == pytest.approx(-ax11[1])
    assert yaw[model.dofs.index("ID1.ax11.y")] == pytest.approx(ax11[0])
    for damper in YAW_DAMPERS:  # both ends of a yaw damper move alike: no stroke
        assert R[model.dofs.index(f"{damper}.stroke")].tolist() == [0.0] * N_RIGID


def test_parts_add_up_to_the_matrices(model):
    """Energy bookkeeping: the per-component shares of M and per-group shares of K are complete."""
    for parts, total in ((model.mass_parts, model.M), (model.stiffness_parts, model.K)):
        summed = np.zeros_like(total)
        for part in parts.values():
            summed[np.ix_(part.index, part.index)] += part.matrix
        assert np.allclose(summed, total, rtol=0, atol=1e-12 * np.abs(total).max())


def test_rigid_translation_carries_the_total_mass(model):
    """Translating everything by 1 m gives the kinetic-energy mass 2T/v² = Σ masses, computed
    here from the parameters (beam masses ρ A L from the geometry)."""
    p = model.parameters
    rho = p["steel_density"]
    hollow = np.pi * (p["hollow_shaft_outer_radius"] ** 2 - p["hollow_shaft_inner_radius"] ** 2)
    hollow_length = abs(p["gear_lateral_position"] - p["claw_clutch_lateral_position"])
    axle = np.pi * p["axle_radius"] ** 2 * 2 * p["journal_half_distance"]
    per_drive = (p["stator_mass"] + p["rotor_mass"] + p["pinion_mass"] + p["gear_mass"]
                 + rho * hollow * hollow_length + rho * axle + 2 * p["wheel_disc_mass"]
                 + 2 * p["axle_box_mass"] + 2 * p["rim_mass"])
    horizontal = 2 * per_drive + p["frame_mass"]
    vertical = horizontal + p["car_body_mass"] + 4 * p["track_mass"]
    longitudinal = horizontal + p["car_body_mass"]  # the half car body moves in x, not in y
    for axis, expected in (("x", longitudinal), ("y", horizontal), ("z", vertical)):
        q = np.array([1.0 if name.endswith("." + axis) else 0.0 for name in model.dofs.names])
        assert q @ model.M @ q == pytest.approx(expected, rel=1e-12), axis


def test_drivetrain_rigid_spin_needs_rotor_at_minus_p(model):
    """Turning a whole drivetrain with the wheel at 1 rad and rotor and pinion at c rad stores the
    strain energy E(c) = a (c − c*)², a quadratic in c.  Its minimum must be c* = −p (one
    external gear mesh reverses the sense, p = gear ratio) with E(c*) = 0 to rounding, and the
    curvature a > 0 (any other ratio stores energy).  Turning the rotor alone against the pinion
    twists the driving shaft."""
    p = model.parameters["gear_ratio"]
    K = model.K
    scale = np.linalg.norm(K, 2)
    for prefix in DRIVES:
        wheel = np.zeros(model.n)  # wheel side: gear, hollow shaft, axle, rims
        fast = np.zeros(model.n)  # motor side: rotor and pinion
        for i, name in enumerate(model.dofs.names):
            if name.startswith(prefix) and name.endswith(".ry") and ".stator." not in name:
                (fast if (".rotor." in name or ".pinion." in name) else wheel)[i] = 1.0
        a = fast @ K @ fast
        c_star = -(wheel @ K @ fast) / a
        assert c_star == pytest.approx(-p, rel=1e-10)
        r = wheel - p * fast
        assert abs(r @ K @ r) <= 1e3 * EPS * scale * (r @ r)
        assert np.allclose(r, model.rigid_body_modes[:, DRIVES.index(prefix)])
        for c in (-0.9 * p, -1.1 * p, p, 0.0):
            r = wheel + c * fast
            assert r @ K @ r == pytest.approx(a * (c + p) ** 2, rel=1e-8)
            assert r @ K @ r > 1e6 * EPS * scale * (r @ r)
        rotor_only = wheel - p * fast
        rotor_only[model.dofs.index(f"{prefix}.rotor.ry")] += 0.1
        k_ds = model.parameters["driving_shaft_stiffness"]
        assert rotor_only @ K @ rotor_only == pytest.approx(k_ds * 0.1**2, rel=1e-9)


def test_drive_2_mirrors_drive_1(model):
    """Drive 2 is built from drive 1's description through the geometry transform
    diag(−1, −1, 1) of positions and directions.  In coordinates that means M₂₂ = R M₁₁ R (same
    for K, B) with R the sign map of the central symmetry, and the couplings to the frame
    K₂,BF = R K₁,BF R_BF; the frame/car-body block itself is invariant (R_BF K R_BF = K).  On
    the frame and car body R_BF is the sign map; the yaw dampers swap sides, and a damper's
    stroke (its elongation along +x) changes sign with the direction: d_left ↔ −d_right."""
    i1, i2, R = _symmetry_map(model)
    frame = ([model.dofs.index(f"BF.{a}") for a in AXES6]
             + [model.dofs.index(f"CB.{a}") for a in ("x", "z", "rz")]
             + [model.dofs.index(f"{d}.stroke") for d in YAW_DAMPERS])
    R_frame = np.diag([SYMMETRY_SIGN[a] for a in AXES6]
                      + [SYMMETRY_SIGN[a] for a in ("x", "z", "rz")] + [0.0, 0.0])
    R_frame[-2:, -2:] = [[0.0, -1.0], [-1.0, 0.0]]
    for label, matrix in (("M", model.M), ("K", model.K), ("B", model.B)):
        scale = np.abs(matrix).max()
        d1, d2 = matrix[np.ix_(i1, i1)], matrix[np.ix_(i2, i2)]
        assert np.allclose(d2, R @ d1 @ R, rtol=0, atol=1e-12 * scale), label
        c1, c2 = matrix[np.ix_(i1, frame)], matrix[np.ix_(i2, frame)]
        assert np.allclose(c2, R @ c1 @ R_frame, rtol=0, atol=1e-12 * scale), label
        f = matrix[np.ix_(frame, frame)]
        assert np.allclose(f, R_frame @ f @ R_frame, rtol=0, atol=1e-12 * scale), label
        # the drives do not couple directly
        assert not np.any(matrix[np.ix_(i1, i2)]), label
    # the rigid spins map onto each other (up to the sign of a spin, which R flips)
    r1, r2 = model.rigid_body_modes[i1, 0], model.rigid_body_modes[i2, 1]
    assert np.allclose(np.abs(R @ r1), np.abs(r2))


# ------------------------------------------------------------------------------------------------
# operating-point terms


def test_creep_damping_nonsymmetric_on_rim_coordinates_only(model):
    op = default_operating_point(model.parameters, s0=0.005, v_kmh=120.0)
    B_ad = creep_damping(model, creep_coefficients(model.parameters, op))
    rim_dofs = np.concatenate(list(model.rims.values()))
    others = np.setdiff1d(np.arange(model.n), rim_dofs)
    assert not np.any(B_ad[others, :])
    assert not np.any(B_ad[:, others])
    assert not np.allclose(B_ad, B_ad.T)
    # blocks only within a rim, never between rims
    for a, ia in model.rims.items():
        for b, ib in model.rims.items():
            if a != b:
                assert not np.any(B_ad[np.ix_(ia, ib)])
    # the four rims see the same block (same contact, vehicle axes)
    blocks = [B_ad[np.ix_(i, i)] for i in model.rims.values()]
    assert all(np.array_equal(blocks[0], blk) for blk in blocks[1:])


def test_creep_damping_changes_sign_of_b11_across_the_creep_maximum(calibrated):
    p = calibrated.parameters
    low = creep_coefficients(p, default_operating_point(p, s0=0.005))
    high = creep_coefficients(p, default_operating_point(p, s0=0.014))
    assert low.b11 > 0 > high.b11  # positive slope, then negative damping on the falling branch


def test_motor_pattern_only_on_id2_rotor_and_stator(model):
    """B_M (b_M = 1): the slope torque acts on ID2's rotor and, as reaction, on its stator (rows);
    it measures the rotor's speed relative to the stator less the rolling that the vehicle's
    speed CB.x implies through the gear ratio and the wheel radius (columns, eq. 6)."""
    Bm = model.motor_pattern
    names = model.dofs.names
    rows = sorted({names[i] for i in np.flatnonzero(np.any(Bm != 0, axis=1))})
    columns = sorted({names[i] for i in np.flatnonzero(np.any(Bm != 0, axis=0))})
    assert rows == ["ID2.rotor.ry", "ID2.stator.ry"]
    assert columns == ["CB.x", "ID2.rotor.ry", "ID2.stator.ry"]
    rotor, stator, car_body = (model.dofs.index(n) for n in ("ID2.rotor.ry", "ID2.stator.ry", "CB.x"))
    p = model.parameters
    assert Bm[rotor, rotor] == 1.0
    assert Bm[rotor, stator] == -1.0
    assert Bm[rotor, car_body] == pytest.approx(p["gear_ratio"] / p["wheel_radius"], rel=1e-15)
    assert np.array_equal(Bm[stator], -Bm[rotor])  # the reaction: no net torque on the bogie
    # relative form: a rotation of rotor and stator together does not change the motor torque
    together = np.zeros(model.n)
    together[[rotor, stator]] = 1.0
    assert not np.any(Bm @ together)


def test_rolling_mode_is_the_vehicle_rolling_without_slip(model):
    """Every .x coordinate of a body 1, every rolling part's .ry 1/r0, rotors and pinions −p/r0,
    nothing else (the stators, frame and car body do not pitch): K r = 0."""
    r = model.rolling_mode
    p = model.parameters
    r0, ratio = p["wheel_radius"], p["gear_ratio"]
    for i, name in enumerate(model.dofs.names):
        part, axis = name.rsplit(".", 1)
        if axis == "x":
            assert r[i] == pytest.approx(1.0, rel=1e-15), name
        elif axis == "ry" and part.split(".")[-1] in ("rotor", "pinion"):
            assert r[i] == pytest.approx(-ratio / r0, rel=1e-15), name
        elif axis == "ry" and part.startswith(("ID1.", "ID2.")) and ".stator" not in part:
            assert r[i] == pytest.approx(1.0 / r0, rel=1e-15), name
        else:
            assert r[i] == 0.0, name
    K = model.K
    assert np.linalg.norm(K @ r) <= 1e3 * EPS * np.linalg.norm(K, 2) * np.linalg.norm(r)


@pytest.mark.parametrize("bandwidth", [0.0, 2.0, 40.0])
@pytest.mark.parametrize(("s0", "v_kmh", "b_M"), [(0.005, 120.0, None), (0.014, 120.0, 3000.0),
                                                  (0.002, 40.0, 20_000.0), (0.03, 250.0, 0.0)])
def test_a_vehicle_rolling_faster_without_slip_meets_no_damping(model, bandwidth, s0, v_kmh, b_M):
    """The check of eq. 6 against the vehicle's speed: the velocity of the vehicle rolling 1 m/s
    faster without slip meets no damping force — no creep (no slip), no motor slope (the rotor
    turns exactly as the vehicle's speed implies), no damper (nothing moves relative to anything)
    — at every operating point, with and without the converter's torque control: ‖B r‖ at the
    rounding of B's entries (B's largest entry ≈ 1e6 N s/m, the rolling's entries ≤ p/r0)."""
    parameters = model.parameters.replace(motor_bandwidth=bandwidth)
    bogie = build_model(parameters)
    b_M = parameters["motor_slope"] if b_M is None else b_M
    B = damping_matrix(bogie, OperatingPoint.from_kmh(s0, v_kmh, parameters["wheel_force"], b_M))
    r = bogie.rolling_mode
    force = B @ r
    assert np.abs(force).max() <= 100 * EPS * np.abs(B).max() * np.abs(r).max()
    # against the constant reference of the initial speed the slope would brake ID2's rotor:
    # b_M p/r0 [N m per m/s] on its rotor (and the reaction on its stator)
    rotor = bogie.dofs.index("ID2.rotor.ry")
    constant_reference = b_M * (r[rotor] - r[bogie.dofs.index("ID2.stator.ry")])
    assert abs(constant_reference) == pytest.approx(
        b_M * parameters["gear_ratio"] / parameters["wheel_radius"], rel=1e-14)
def test_short_circuit_force_is_internal_and_drives_drivetrain_1(model):
    """M_C acts on ID1's rotor and, as reaction, on ID1's stator: the net torque on the bogie is
    zero (rotating rotor and stator together, i.e. the whole motor as one body, absorbs no work),
    while on the drivetrain's rigid spin — rotor at −p, stator at rest — it does the work p per
    radian of the wheel: a positive driving torque M_C spins the wheels forward (+ry).  Drive 2's
    spin is untouched."""
    f = model.short_circuit_force
    p = model.parameters["gear_ratio"]
    touched = sorted(model.dofs.names[i] for i in np.flatnonzero(f))
    assert touched == ["ID1.rotor.ry", "ID1.stator.ry"]
    motor_as_one_body = np.zeros(model.n)
    for name in touched:
        motor_as_one_body[model.dofs.index(name)] = 1.0
    assert f @ motor_as_one_body == 0.0
    r1, r2, translation, yaw = model.rigid_body_modes.T
    assert f @ r1 == pytest.approx(p, rel=1e-14)
    assert f @ r2 == 0.0
    assert f @ translation == 0.0
    assert f @ yaw == 0.0


def test_static_traction_load_is_self_equilibrated(model):
    """Eq. 7: the motor torque M = 2 μ N0 r0 / p balances the creep moment 2 μ N0 r0 on each
    drivetrain's rigid spin, the drawbar pull the creep forces along the vehicle's translation,
    and the creep forces have no moment about the bogie centre, so K q0 = f0 is solvable
    (f0 ⟂ null space of K)."""
    for s0 in (0.005, 0.014):
        op = default_operating_point(model.parameters, s0=s0, v_kmh=120.0)
        f0 = static_load(model, op)
        for r in model.rigid_body_modes.T:
            assert abs(f0 @ r) <= 1e-12 * np.linalg.norm(f0) * np.linalg.norm(r)


def test_eigen_analysis_identifies_the_rigid_body_zeros(calibrated):
    """Four rigid-body modes (K r = 0) and the velocity of the vehicle rolling without slip, which
    no damping meets: five exact zeros, deflated, none of them left among the eigenvalues."""
    op = default_operating_point(calibrated.parameters)
    result = eigen_analysis(calibrated, op, vectors=False)
    assert result.n_rigid == N_RIGID + 1
    # states: every coordinate and the velocities of the inertial ones (not of the 2 strokes)
    assert result.eigenvalues.size == 2 * calibrated.n - 2 - N_RIGID - 1
    assert np.abs(result.eigenvalues).min() > 1e-3  # the slowest mode: the frame's drift, 0.06 1/s


# ------------------------------------------------------------------------------------------------
# energy


def _energy_matrix(model) -> np.ndarray:
    """P with E = ½ xᵀ P x = ½ vᵀ M_ii v + ½ qᵀ K q on the state x = [q; v] (v: velocities of the
    inertial coordinates)."""
    inertial = np.setdiff1d(np.arange(model.n), massless_coordinates(model.M))
    return sla.block_diag(model.K, model.M[np.ix_(inertial, inertial)])


def _trajectory(model, B, dt=1e-3, steps=20, seed=0):
    """Exact free response x(k dt) = expm(A dt)^k x0 of M q̈ + B q̇ + K q = 0 from a random state;
    the energies ½ xᵀ P x along it."""
    system = state_space(model).system(B)
    step = sla.expm(system.A * dt)
    P = _energy_matrix(model)
    x = np.random.default_rng(seed).normal(size=system.N)
    energies = [0.5 * x @ P @ x]
    for _ in range(steps):
        x = step @ x
        energies.append(0.5 * x @ P @ x)
    return np.array(energies)


def _maxwell_only(model) -> np.ndarray:
    """The damping of the yaw dampers alone (c on their strokes): without it a stroke has no
    equation of motion (its inner node is massless)."""
    B = np.zeros_like(model.M)
    for damper in YAW_DAMPERS:
        i = model.dofs.index(f"{damper}.stroke")
        B[i, i] = model.parameters["yaw_damping"]
    return B


@pytest.mark.parametrize("damping", ["yaw dampers only", "structural"])
def test_energy_balance_is_exact(calibrated, damping):
    """dE/dt = −q̇ᵀ B q̇ with q̇ = V x the velocities of all coordinates (the strokes' from their
    first-order equations): as a matrix identity, sym(P A) = −Vᵀ B V.  With only the yaw
    dampers' c, everything else conserves energy and the loss is c ḋ² of each damper; with the
    structural damping (incl. the end bushes' rubber loss) it is the whole q̇ᵀ B q̇.  Tolerance
    relative to ‖P A‖: rounding of the 392-state products."""
    B = _maxwell_only(calibrated) if damping == "yaw dampers only" else calibrated.B
    system = state_space(calibrated).system(B)
    PA = _energy_matrix(calibrated) @ system.A
    V = system.velocity_map
    lhs = 0.5 * (PA + PA.T)
    rhs = -V.T @ B @ V
    assert np.abs(lhs - rhs).max() <= 1e-9 * np.abs(PA).max()
    if damping == "yaw dampers only":  # only the strokes' velocities dissipate
        strokes = [calibrated.dofs.index(f"{d}.stroke") for d in YAW_DAMPERS]
        expected = -sum(calibrated.parameters["yaw_damping"] * np.outer(V[i], V[i])
                        for i in strokes)
        assert np.abs(rhs - expected).max() <= 1e-12 * np.abs(expected).max()


def test_maxwell_dampers_alone_dissipate_monotonically(calibrated):
    """With the yaw dampers as the only damping the energy never grows, and falls."""
    energies = _trajectory(calibrated, _maxwell_only(calibrated))
    assert np.all(np.diff(energies) <= 1e-12 * energies[0])
    assert energies[-1] < energies[0]


def test_structural_damping_dissipates_monotonically(calibrated):
    """dE/dt = −q̇ᵀBq̇ ≤ 0 for B symmetric PSD: energy never grows and here falls a lot."""
    energies = _trajectory(calibrated, calibrated.B)
    assert np.all(np.diff(energies) <= 1e-12 * energies[0])
    assert energies[-1] < 0.5 * energies[0]


def test_static_traction_torque_chain(calibrated):
    """Steady traction (eq. 7) through the drivetrain: the driving shaft carries the motor torque
    M, the disc and claw clutches p·M = the wheelset's adhesion moment 2 μ N0 r0, and the gear mesh
    the tooth force M / (r_pinion cos α) along the line of action.  (The sign of ID2's gear mesh
    force is opposite to ID1's: its line of action is drive 1's turned by 180°.)"""
    p = calibrated.parameters
    ratio, alpha = p["gear_ratio"], p["pressure_angle"]
    r_pinion = p["gear_radius"] / ratio
    for s0 in (0.005, 0.014):
        op = default_operating_point(p, s0=s0, v_kmh=120.0)
        torque = motor_torque(p, op)
        outputs = output_matrices(calibrated, op)
        steady = dict(zip(outputs.names, outputs.steady, strict=True))
        for drive in DRIVES:
            assert steady[f"{drive}.driving_shaft.torque"] == pytest.approx(torque, rel=1e-9)
            for name in ("disc_clutch.torque", "claw_clutch.torque", "wheelset.adhesion_moment"):
                assert steady[f"{drive}.{name}"] == pytest.approx(ratio * torque, rel=1e-9), name
            assert abs(steady[f"{drive}.gear_mesh.force"]) == pytest.approx(
                torque / (r_pinion * np.cos(alpha)), rel=1e-9)


def test_dof_map_lookup_errors():
    with pytest.raises(ValueError, match="duplicate"):
        DofMap(("a.x", "a.x"))
    dofs = DofMap(("BF.x", "ID1.rim12.ry"))
    with pytest.raises(KeyError, match=r"unknown DOF 'BF\.q'"):
        dofs.index("BF.q")
    assert dofs.unit("ID1.rim12.ry") == "rad"
    assert dofs.part("ID1.rim12.ry") == "ID1.rim12"
    assert dofs.subsystem("ID1.rim12.ry") == "ID1"
