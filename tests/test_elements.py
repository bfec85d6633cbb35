"""Unit tests of the building blocks: beam element, bodies, connections, wheel–rail contact.

Expectations come from independent references (Euler–Bernoulli beam theory, Hertz theory,
rigid-body kinematics, finite differences, eq. 19 of the spec), never from the model's output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla

from model.beam import TubeSection, beam_global_matrices, beam_local_matrices, local_frame
from model.bodies import carried_body, free_body, point_map, rigid_mass_matrix, skew
from model.connections import Spring, SpringDamper, axis_springs
from model.contact import (
    _KALKER_A_OVER_B_SMALL,
    _KALKER_B_OVER_A_SMALL,
    CREEP_PRESETS,
    PolachLaw,
    creep_block,
    hertz_contact,
    kalker_coefficients,
)
from model.dofs import AXES6, PAPER_RIM_ORDER, DofMap

# A steel tube of the size of the hollow shaft (independent of the parameter files).
STEEL = {"young": 2.1e11, "poisson": 0.3, "density": 7850.0}
TUBE = TubeSection(outer_radius=0.125, inner_radius=0.11)
LENGTH = 2.0  # [m]


def _shear(young=STEEL["young"], poisson=STEEL["poisson"]):
    return young / (2 * (1 + poisson))


def _rigid_modes(points: np.ndarray) -> np.ndarray:
    """(6·len(points)) x 6 rigid-body motions of nodes at ``points`` (DOF [x, y, z, rx, ry, rz]):
    translation t and small rotation θ about the origin give u_i = t + θ × p_i, θ_i = θ."""
    columns = []
    for k in range(6):
        t, theta = np.zeros(3), np.zeros(3)
        (t if k < 3 else theta)[k % 3] = 1.0
        columns.append(np.concatenate([np.concatenate([t + np.cross(theta, p), theta])
                                       for p in points]))
    return np.array(columns).T


def _assemble_line(n_elements: int, start=(0.0, 0.0, 0.0), end=(LENGTH, 0.0, 0.0)):
    """Global K, M of a straight tube from ``start`` to ``end`` meshed with equal elements."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    nodes = [start + (end - start) * k / n_elements for k in range(n_elements + 1)]
    n = 6 * len(nodes)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(n_elements):
        k, m = beam_global_matrices(nodes[e], nodes[e + 1], TUBE, **STEEL)
        block = slice(6 * e, 6 * e + 12)
        K[block, block] += k
        M[block, block] += m
    return K, M, np.array(nodes)


def _cantilever_frequencies(n_elements: int, local_dofs: tuple[int, ...]) -> np.ndarray:
    """Natural angular frequencies [rad/s] of a tube along x clamped at x = 0, restricted to the
    local DOFs ``local_dofs`` of every node (an uncoupled family: axial, torsion, one bending
    plane)."""
    K, M, _ = _assemble_line(n_elements)
    keep = [i for i in range(6, K.shape[0]) if i % 6 in local_dofs]
    w2 = sla.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], eigvals_only=True)
    return np.sqrt(w2)


# ------------------------------------------------------------------------------------------------
# beam element


@pytest.mark.parametrize("length", [0.05, 0.4, 3.0])
def test_beam_local_matrices_symmetric_definite_six_rigid_modes(length):
    K, M = beam_local_matrices(length, TUBE, **STEEL)
    assert np.array_equal(K, K.T)
    assert np.allclose(M, M.T, rtol=0, atol=1e-15 * np.abs(M).max())
    # consistent mass: positive definite (no rotary inertia, but every DOF has a shape function)
    assert np.linalg.eigvalsh(M).min() > 0
    # stiffness: exactly 6 zero eigenvalues (rigid-body modes), the other 6 clearly positive.
    # Scale by the diagonal so that N/m and N m/rad entries are comparable; numerical zeros of a
    # unit-diagonal 12 x 12 matrix are O(12 eps), so 1e-12 separates them from real stiffness.
    d = 1 / np.sqrt(np.diag(K))
    w = np.linalg.eigvalsh(d[:, None] * K * d[None, :])
    assert np.all(np.abs(w[:6]) < 1e-12)
    assert w[6] > 1e-6


def test_beam_rigid_body_motions_store_no_energy_in_any_orientation():
    rng = np.random.default_rng(1)
    for _ in range(5):
        a, b = rng.normal(size=3), rng.normal(size=3)
        K, M = beam_global_matrices(a, b, TUBE, **STEEL)
        R = _rigid_modes(np.array([a, b]))
        assert np.linalg.norm(K @ R) <= 1e-12 * np.linalg.norm(K) * np.linalg.norm(R)
        # and the mass of a rigid translation is the element mass ρ A L
        mass = STEEL["density"] * TUBE.area * np.linalg.norm(b - a)
        for axis in range(3):
            assert R[:, axis] @ M @ R[:, axis] == pytest.approx(mass, rel=1e-12)


def test_local_frame_is_a_rotation_with_x_along_the_beam():
    for start, end in (((0, 0, 0), (1, 0, 0)), ((0, 0, 0), (0, 0, 2)), ((1, 2, 3), (-1, 0.5, 4))):
        T = local_frame(np.array(start, float), np.array(end, float))
        assert np.allclose(T @ T.T, np.eye(3), atol=1e-14)
        assert np.linalg.det(T) == pytest.approx(1.0)
        axis = np.subtract(end, start) / np.linalg.norm(np.subtract(end, start))
        assert np.allclose(T[0], axis, atol=1e-14)


def test_global_beam_frequencies_do_not_depend_on_orientation():
    """A free-free tube along x and the same tube along a skew direction: same spectrum."""
    K1, M1, _ = _assemble_line(6)
    K2, M2, _ = _assemble_line(6, start=(0.3, -0.2, 0.1),
                               end=np.array([0.3, -0.2, 0.1]) + LENGTH * np.array([1, 2, -2]) / 3)
    w1 = sla.eigh(K1, M1, eigvals_only=True)
    w2 = sla.eigh(K2, M2, eigvals_only=True)
    assert np.allclose(w1[6:], w2[6:], rtol=1e-9)


def test_cantilever_bending_frequencies_euler_bernoulli():
    """Clamped-free Euler–Bernoulli beam: ω_k = (β_k L)² √(EI / (ρ A L⁴)) with β_k L = 1.8751,
    4.6941, 7.8548, 10.9955 (roots of cos βL cosh βL = −1)."""
    roots = np.array([1.875104069, 4.694091133, 7.854757438, 10.99554073])
    for k, beta_L in enumerate(roots):
        residual = math.cos(beta_L) * math.cosh(beta_L) + 1.0
        assert abs(residual) < 1e-6 * math.cosh(beta_L)
        assert k == 0 or beta_L > roots[k - 1]
    EI = STEEL["young"] * TUBE.second_moment
    rho_A = STEEL["density"] * TUBE.area
    exact = roots**2 * math.sqrt(EI / (rho_A * LENGTH**4))
    for plane in ((1, 5), (2, 4)):  # v with θz, w with θy
        w = _cantilever_frequencies(20, plane)[:4]
        # 20 cubic elements: the 4th mode has ~2.5 elements per half wave; error well below 1e-4
        assert np.allclose(w, exact, rtol=1e-4)
        assert np.all(w >= exact * (1 - 1e-12))  # conforming Rayleigh–Ritz: upper bounds


@pytest.mark.parametrize(("dofs", "wave_speed"), [
    ((0,), math.sqrt(STEEL["young"] / STEEL["density"])),  # axial: c = √(E/ρ)
    ((3,), math.sqrt(_shear() / STEEL["density"])),  # torsion of a circular tube: c = √(G/ρ)
])
def test_cantilever_axial_and_torsion_frequencies(dofs, wave_speed):
    """Clamped-free rod: ω_k = (2k − 1) π c / (2 L).  Linear elements with consistent mass have
    eigenvalue error O(h²): with 40 elements the first three modes are within 0.2 %."""
    exact = (2 * np.arange(1, 4) - 1) * np.pi * wave_speed / (2 * LENGTH)
    w = _cantilever_frequencies(40, dofs)[:3]
    assert np.allclose(w, exact, rtol=2e-3)
    assert np.all(w >= exact)


def test_free_free_tube_bending_frequency():
    """Free-free beam: β₁L = 4.7300 (cos βL cosh βL = 1); six rigid-body modes."""
    K, M, _ = _assemble_line(24)  # 24 cubic elements: error of mode 1 ~ 1e-6 (N⁻⁴ rate)
    w2 = sla.eigh(K, M, eigvals_only=True)
    omega_max = math.sqrt(w2[-1])
    assert np.all(np.abs(w2[:6]) < 1e-9 * omega_max**2)  # six rigid-body modes, relative to the top
    assert w2[6] > 1.0
    EI = STEEL["young"] * TUBE.second_moment
    rho_A = STEEL["density"] * TUBE.area
    exact = 4.730040745**2 * math.sqrt(EI / (rho_A * LENGTH**4))
    # the first flexible modes are the two bending planes (equal by symmetry of the tube)
    assert math.sqrt(w2[6]) == pytest.approx(exact, rel=1e-5)
    assert math.sqrt(w2[7]) == pytest.approx(exact, rel=1e-5)


def test_bending_frequency_converges_at_the_theoretical_rate():
    """Cubic Hermite elements with consistent mass: the eigenvalue error is O(h^(2(p+1−m))) with
    p = 3 (cubic) and m = 2 (bending energy order), i.e. O(h⁴); so the first frequency's
    relative error falls like N⁻⁴.  Measured on N = 4, 8, 16 (asymptotic range) the observed
    rate log2(e_N / e_2N) is ≈ 3.97–3.99; we ask for ≥ 3.8, which fails if an element term were
    wrong (a wrong mass term degrades the rate to 2 or stalls it)."""
    EI = STEEL["young"] * TUBE.second_moment
    rho_A = STEEL["density"] * TUBE.area
    exact = 1.875104069**2 * math.sqrt(EI / (rho_A * LENGTH**4))
    errors = [(_cantilever_frequencies(n, (1, 5))[0] - exact) / exact for n in (4, 8, 16)]
    assert all(e > 0 for e in errors)  # upper bounds
    rates = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert min(rates) >= 3.8, rates


def test_axial_frequency_converges_at_second_order():
    """Linear elements, consistent mass: eigenvalue error O(h²) → rate ≈ 2 (asked ≥ 1.9)."""
    exact = math.pi * math.sqrt(STEEL["young"] / STEEL["density"]) / (2 * LENGTH)
    errors = [(_cantilever_frequencies(n, (0,))[0] - exact) / exact for n in (4, 8, 16)]
    rates = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert min(rates) >= 1.9, rates


def test_tube_section_properties():
    section = TubeSection(0.1, 0.06)
    assert section.area == pytest.approx(np.pi * (0.01 - 0.0036))
    assert section.second_moment == pytest.approx(np.pi / 4 * (0.1**4 - 0.06**4))
    assert section.polar_moment == pytest.approx(2 * section.second_moment)


# ------------------------------------------------------------------------------------------------
# bodies and connections


def _two_free_bodies():
    names = [f"{body}.{a}" for body in ("A", "B") for a in AXES6] + ["C.ry"]
    dofs = DofMap(tuple(names))
    a = free_body("A", (0.1, -0.4, 0.3), dofs)
    b = free_body("B", (1.2, 0.5, -0.2), dofs)
    return dofs, a, b


def _random_connection(a, b, rng) -> SpringDamper:
    springs = []
    for rotational in (False, True):
        for _ in range(3):
            direction = rng.normal(size=3)
            springs.append(Spring(direction / np.linalg.norm(direction), rng.uniform(1e5, 1e7),
                                  rng.uniform(1e2, 1e4), rotational))
    return SpringDamper("AB", "AB", a, b, rng.normal(size=3), tuple(springs))


def _rigid_motion(dofs: DofMap, bodies, t, theta) -> np.ndarray:
    """q for which every 6-DOF body moves as one rigid body (translation t of the global origin,
    small rotation θ): u_body = t + θ × origin, θ_body = θ."""
    q = np.zeros(len(dofs))
    for body in bodies:
        u = t + np.cross(theta, body.origin)
        for k, axis in enumerate(AXES6):
            q[dofs.index(f"{body.name}.{axis}")] = np.concatenate([u, theta])[k]
    return q


def test_point_map_is_small_rotation_kinematics():
    rng = np.random.default_rng(2)
    r, u, theta = rng.normal(size=(3, 3))
    assert np.allclose(skew(r) @ theta, np.cross(r, theta))
    assert np.allclose(point_map(r) @ np.concatenate([u, theta]), u + np.cross(theta, r))


def test_spring_between_free_bodies_symmetric_psd_and_rigid_motion_free():
    rng = np.random.default_rng(3)
    dofs, a, b = _two_free_bodies()
    connection = _random_connection(a, b, rng)
    K, B = connection.matrices()
    for matrix in (K, B):
        assert np.allclose(matrix, matrix.T, rtol=0, atol=1e-14 * np.abs(matrix).max())
        assert np.linalg.eigvalsh(matrix).min() >= -1e-12 * np.abs(matrix).max()
    scale = np.abs(K).max()
    for _ in range(5):
        q = _rigid_motion(dofs, (a, b), rng.normal(size=3), rng.normal(size=3))
        assert abs(q @ K @ q) <= 1e-12 * scale * (q @ q)
        assert np.linalg.norm(K @ q) <= 1e-12 * scale * np.linalg.norm(q)
    # a relative motion does store energy: 6 independent springs, rank 6
    assert np.linalg.matrix_rank(K, tol=1e-9 * scale) == 6


def test_spring_energy_is_half_k_delta_squared():
    """One translational spring: energy ½ k δ² with δ the relative displacement of the joined
    material point along the spring (computed here by hand from u + θ × r)."""
    dofs, a, b = _two_free_bodies()
    position = np.array([0.5, 0.0, 0.0])
    direction = np.array([0.0, 0.6, 0.8])
    k = 3.0e6
    connection = SpringDamper("AB", "AB", a, b, position, (Spring(direction, k),))
    K, _ = connection.matrices()
    rng = np.random.default_rng(4)
    q = rng.normal(size=len(dofs))
    ua, ta = q[0:3], q[3:6]
    ub, tb = q[6:9], q[9:12]
    point_b = ub + np.cross(tb, position - b.origin)
    point_a = ua + np.cross(ta, position - a.origin)
    delta = direction @ (point_b - point_a)
    assert 0.5 * q @ K @ q == pytest.approx(0.5 * k * delta**2, rel=1e-12)


def test_axis_springs_skip_zero_entries():
    springs = axis_springs((1.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    assert [s.stiffness for s in springs] == [1.0, 3.0]
    assert np.allclose(springs[1].direction, (0, 0, 1))


def test_carried_body_follows_its_carrier():
    """With its own spin equal to the carrier's rotation about the spin axis, a carried body
    moves as a rigid part of the carrier: every material point has the carrier's displacement."""
    dofs, carrier, _ = _two_free_bodies()
    carried = carried_body("C", (0.7, 0.2, -0.1), carrier, dofs, spin_axis="ry")
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = rng.normal(size=len(dofs))
        q[dofs.index("C.ry")] = q[dofs.index("A.ry")]
        for point in rng.normal(size=(3, 3)):
            assert np.allclose(carried.point(point) @ q, carrier.point(point) @ q)
        # its own spin moves only its rotation about y
        dq = np.zeros(len(dofs))
        dq[dofs.index("C.ry")] = 1.0
        assert np.allclose(carried.W @ dq, [0, 0, 0, 0, 1, 0])
        assert np.allclose(carrier.W @ dq, 0)


def test_rigid_mass_matrix():
    M = rigid_mass_matrix(10.0, (1.0, 2.0, 3.0))
    assert np.array_equal(np.diag(M), [10, 10, 10, 1, 2, 3])
    assert np.count_nonzero(M - np.diag(np.diag(M))) == 0


# ------------------------------------------------------------------------------------------------
# wheel–rail contact


def test_hertz_equal_curvatures_is_the_circular_formula():
    """A wheel of rolling radius R (flat across) on a rail head of transverse radius R is the
    contact of crossed cylinders = a sphere of radius R on a plane: a = (3 N R / (4 E*))^(1/3),
    1/E* = 2 (1 − ν²)/E (Johnson, Contact Mechanics, eq. 4.22)."""
    N, R, E, nu = 1e5, 0.5, 2.1e11, 0.28
    contact = hertz_contact(N, R, R, E, nu)
    e_star = E / (2 * (1 - nu**2))
    radius = (3 * N * R / (4 * e_star)) ** (1 / 3)
    assert contact.a == pytest.approx(radius, rel=1e-12)
    assert contact.b == pytest.approx(radius, rel=1e-12)
    # the elliptic branch joins the circular one: curvatures differing by δ change the semi-axes
    # by O(δ) (first order: −δ/6 and +δ/2 for a and b, from the series of K(e²), E(e²))
    for delta in (1e-2, 1e-3, 1e-4):
        near = hertz_contact(N, R, R * (1 + delta), E, nu)
        assert abs(near.a / radius - 1) < delta
        assert abs(near.b / radius - 1) < delta
        assert near.b > near.a


def test_hertz_ellipse_properties():
    """Swapping the two radii swaps the semi-axes; the semi-axis across the flatter direction is
    longer; the area scales as N^(2/3) and the load equals (2/3) π a b p0 with the Hertz pressure
    p0 consistent between different loads."""
    E, nu = 2.1e11, 0.28
    c1 = hertz_contact(1e5, 0.625, 0.3, E, nu)
    c2 = hertz_contact(1e5, 0.3, 0.625, E, nu)
    assert c1.a == pytest.approx(c2.b, rel=1e-10)
    assert c1.b == pytest.approx(c2.a, rel=1e-10)
    assert c1.a > c1.b  # the wheel (larger radius along x) gives the longer axis along x
    c3 = hertz_contact(8e5, 0.625, 0.3, E, nu)
    assert c3.a / c1.a == pytest.approx(2.0, rel=1e-10)  # (8)^(1/3)
    assert c3.b / c1.b == pytest.approx(2.0, rel=1e-10)


def test_kalker_coefficients_at_table_points_and_between():
    for row in _KALKER_A_OVER_B_SMALL:
        assert kalker_coefficients(row[0]) == pytest.approx(tuple(row[1:]), rel=1e-12)
    for row in _KALKER_B_OVER_A_SMALL:
        assert kalker_coefficients(1 / row[0]) == pytest.approx(tuple(row[1:]), rel=1e-12)
    # linear interpolation between neighbours
    lo, hi = _KALKER_A_OVER_B_SMALL[3], _KALKER_A_OVER_B_SMALL[4]
    mid = kalker_coefficients(0.5 * (lo[0] + hi[0]))
    assert mid == pytest.approx(tuple(0.5 * (lo[1:] + hi[1:])), rel=1e-12)


def test_kalker_coefficients_bounds_and_trends():
    """Bounds a/b ∈ [0.1, 10] (table g = 0.1 for both a/b and b/a); outside: ValueError.
    C11, C22, C23 grow with a/b and C33 falls (Kalker's table): a guard against a row
    stored against the wrong ratio (b/a instead of a/b)."""
    assert kalker_coefficients(0.1)[0] == pytest.approx(2.51)
    assert kalker_coefficients(10.0)[0] == pytest.approx(10.7)
    for bad in (0.0999, 10.01, 0.0, -1.0):
        with pytest.raises(ValueError, match="outside"):
            kalker_coefficients(bad)
    ratios = np.geomspace(0.1, 10.0, 61)
    table = np.array([kalker_coefficients(r) for r in ratios])
    assert np.all(np.diff(table[:, 0]) > 0)
    assert np.all(np.diff(table[:, 1]) > 0)
    assert np.all(np.diff(table[:, 2]) > 0)
    assert np.all(np.diff(table[:, 3]) < 0)
    # continuity across a/b = 1 where the two halves of the table meet
    assert np.allclose(kalker_coefficients(1 - 1e-9), kalker_coefficients(1 + 1e-9), rtol=1e-6)


@pytest.mark.parametrize("preset", sorted(CREEP_PRESETS))
def test_polach_derivative_matches_central_differences(preset):
    c = CREEP_PRESETS[preset]
    law = PolachLaw(c["polach_mu0"], c["polach_A"], c["polach_B"], c["polach_kA"], c["polach_kS"],
                    slope=600.0)
    for v in (5.0, 33.3, 55.0):
        for s in np.geomspace(1e-4, 0.3, 25):
            h = 1e-6 * s
            fd = (law.mu(s + h, v) - law.mu(s - h, v)) / (2 * h)
            assert float(law.dmu_ds(s, v)) == pytest.approx(float(fd), rel=1e-6, abs=1e-8)


def test_polach_law_shape():
    """μ(0) = 0, initial slope (2/π)(kA + kS)·slope, a maximum with dμ/ds = 0 and a falling
    branch beyond it; the maximum is the largest value on a fine grid and stays below μ0."""
    c = CREEP_PRESETS["dry"]
    slope = 600.0
    law = PolachLaw(c["polach_mu0"], c["polach_A"], c["polach_B"], c["polach_kA"], c["polach_kS"],
                    slope)
    v = 120 / 3.6
    assert float(law.mu(0.0, v)) == 0.0
    assert float(law.dmu_ds(0.0, v)) == pytest.approx(
        2 / np.pi * (c["polach_kA"] + c["polach_kS"]) * slope, rel=1e-12)
    s_max, mu_max = law.maximum(v)
    assert abs(float(law.dmu_ds(s_max, v))) < 1e-8
    assert float(law.dmu_ds(0.5 * s_max, v)) > 0
    assert float(law.dmu_ds(2.0 * s_max, v)) < 0
    s = np.geomspace(1e-5, 0.5, 400)
    assert mu_max >= float(np.max(law.mu(s, v)))
    assert mu_max == pytest.approx(float(np.max(law.mu(s, v))), rel=1e-4)
    assert mu_max < c["polach_mu0"]


def test_creep_block_longitudinal_part_symmetric_and_psd_for_positive_b11():
    b = creep_block(b11=2.0e5, b22=1.0e6, b23=3.0e3, b33=40.0, r0=0.6)
    X, RY = 0, 4
    longi = b[np.ix_([X, RY], [X, RY])]
    assert np.array_equal(longi, longi.T)
    assert np.linalg.eigvalsh(longi).min() >= -1e-9 * np.abs(longi).max()
    # the pure rolling motion ẋ = r0 ṙy is free of longitudinal creep
    assert np.allclose(longi @ [0.6, 1.0], 0.0)
    # the spin coupling b23 is the antisymmetric (gyroscopic-like) part
    assert not np.allclose(b, b.T)
    antisym = 0.5 * (b - b.T)
    assert np.count_nonzero(np.abs(antisym) > 0) == 4  # (y, rz), (rx, rz) and their transposes


def test_creep_block_matches_equation_19_of_the_spec():
    """Eq. 19 of docs/spec model.md, in the study's order [u, v, w, φ, ϑ, ψ] = [y, z, x, ry, rz, rx]
    (model.dofs.PAPER_RIM_ORDER), typed in here by hand."""
    b11, b22, b23, b33, r0 = -3.1e5, 1.7e6, 4.2e3, 55.0, 0.625
    eq19 = np.array([
        [b22, 0, 0, 0, b23, r0 * b22],
        [0, 0, 0, 0, 0, 0],
        [0, 0, b11, -r0 * b11, 0, 0],
        [0, 0, -r0 * b11, r0**2 * b11, 0, 0],
        [-b23, 0, 0, 0, b33, -r0 * b23],
        [r0 * b22, 0, 0, 0, r0 * b23, r0**2 * b22],
    ])
    assert PAPER_RIM_ORDER == ("y", "z", "x", "ry", "rz", "rx")
    order = [AXES6.index(axis) for axis in PAPER_RIM_ORDER]
    block = creep_block(b11, b22, b23, b33, r0)
    assert np.allclose(block[np.ix_(order, order)], eq19, rtol=1e-14, atol=0)


def test_creep_block_from_contact_point_kinematics():
    """Independent derivation: the contact point (0, 0, −r0) below the rim centre has the velocity
    P q̇ with P = [I, −S(r)]; longitudinal creep force ΔT = −b11 ẋ_c, lateral
    F_y = −b22 ẏ_c − b23 ṙz, spin moment M_z = b23 ẏ_c − b33 ṙz (Kalker's sign convention).
    The generalized force is Pᵀ F + e_rz M_z, and B_ad is minus its derivative w.r.t. q̇."""
    b11, b22, b23, b33, r0 = 2.3e5, 1.1e6, 5.0e3, 70.0, 0.6
    P = point_map(np.array([0.0, 0.0, -r0]))
    e_rz = np.eye(6)[5]
    force = -(b11 * np.outer(np.eye(3)[0], P[0]) + b22 * np.outer(np.eye(3)[1], P[1])
              + b23 * np.outer(np.eye(3)[1], e_rz))  # 3 x 6: F = force @ q̇
    moment = b23 * P[1] - b33 * e_rz  # M_z = moment @ q̇
    generalized = P.T @ force + np.outer(e_rz, moment)
    assert np.allclose(creep_block(b11, b22, b23, b33, r0), -generalized, rtol=1e-14, atol=1e-9)
