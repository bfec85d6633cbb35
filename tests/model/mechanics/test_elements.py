"""Unit tests of the building blocks: beam element, bodies, connections (contact: test_contact.py).

Expectations come from independent references (Euler–Bernoulli beam theory, Hertz theory,
rigid-body kinematics, finite differences, eq. 19 of the spec), never from the model's output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla

from model.mechanics.beam import TubeSection, beam_global_matrices, beam_local_matrices, local_frame
from model.mechanics.bodies import carried_body, free_body, point_map, rigid_mass_matrix, skew
from model.mechanics.connections import MaxwellDamper, Spring, SpringDamper, axis_springs
from model.mechanics.dofs import AXES6, DofMap

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


# --- the Maxwell element (a yaw damper in series with its end bushes) ----------------------------

def _maxwell(k=8.0e6, c=4.0e5, c_s=1.6e3):
    names = [f"{body}.{a}" for body in ("A", "B") for a in AXES6] + ["D.stroke"]
    dofs = DofMap(tuple(names))
    a = free_body("A", (0.1, -0.4, 0.3), dofs)
    b = free_body("B", (1.2, 0.5, -0.2), dofs)
    direction = np.array([0.6, 0.0, 0.8])
    damper = MaxwellDamper("D", "D", a, b, np.array([0.5, 1.3, 0.4]), direction, k, c,
                           dofs.index("D.stroke"), spring_damping=c_s)
    return dofs, a, b, damper


def test_maxwell_element_matrices_symmetric_psd_rigid_motion_free():
    """K = k h hᵀ, B = c_s h hᵀ + c e_d e_dᵀ (h: the series spring's elongation δ − d): both
    symmetric PSD; a rigid motion of both bodies with the stroke held stores no energy and
    dissipates nothing; rank 1 (K) and 2 (B)."""
    dofs, a, b, damper = _maxwell()
    K, B = damper.matrices()
    for matrix in (K, B):
        assert np.array_equal(matrix, matrix.T)
        assert np.linalg.eigvalsh(matrix).min() >= -1e-12 * np.abs(matrix).max()
    rng = np.random.default_rng(8)
    for _ in range(5):
        q = _rigid_motion(dofs, (a, b), rng.normal(size=3), rng.normal(size=3))
        assert np.linalg.norm(K @ q) <= 1e-12 * np.abs(K).max() * np.linalg.norm(q)
        assert np.linalg.norm(B @ q) <= 1e-12 * np.abs(B).max() * np.linalg.norm(q)
    assert np.linalg.matrix_rank(K) == 1
    assert np.linalg.matrix_rank(B) == 2


def test_maxwell_element_energy_dissipation_and_force():
    """Energy ½ k (δ − d)², dissipated power c ḋ² + c_s (δ̇ − ḋ)² ≥ 0, force k (δ − d) +
    c_s (δ̇ − ḋ), with δ computed by hand from u + θ × r."""
    k, c, c_s = 8.0e6, 4.0e5, 1.6e3
    dofs, a, b, damper = _maxwell(k, c, c_s)
    K, B = damper.matrices()
    rng = np.random.default_rng(9)
    q, qdot = rng.normal(size=(2, len(dofs)))

    def delta(x):
        point_b = x[6:9] + np.cross(x[9:12], damper.position - b.origin)
        point_a = x[0:3] + np.cross(x[3:6], damper.position - a.origin)
        return damper.direction @ (point_b - point_a)

    d, d_dot = q[-1], qdot[-1]
    assert 0.5 * q @ K @ q == pytest.approx(0.5 * k * (delta(q) - d) ** 2, rel=1e-12)
    power = c * d_dot**2 + c_s * (delta(qdot) - d_dot) ** 2
    assert qdot @ B @ qdot == pytest.approx(power, rel=1e-12)
    [(name, unit, row_q, row_v)] = damper.channels()
    assert (name, unit) == ("D.force", "N")
    force = row_q @ q + row_v @ qdot
    assert force == pytest.approx(k * (delta(q) - d) + c_s * (delta(qdot) - d_dot), rel=1e-12)


def test_maxwell_element_dynamic_stiffness():
    """A harmonic relative displacement δ of unit amplitude: the stroke's equation condensed
    gives F/δ = k iωc/(k + iωc) (c_s = 0) — a damper c at low frequency, the spring k at high."""
    k, c = 8.0e6, 4.0e5
    dofs, _a, _b, damper = _maxwell(k, c, 0.0)
    K, B = damper.matrices()
    i = dofs.index("D.stroke")
    g = damper.relative()
    for omega in (0.1, k / c, 1e4):
        # harmonic δ of unit amplitude: q = g-direction motion of B (least-norm), d from its row
        q = np.linalg.pinv(g[None, :]) @ np.array([1.0])
        q[i] = 0.0
        d = -(K[i] @ q) / (K[i, i] + 1j * omega * B[i, i])  # the stroke's row: (k + iωc) d = k δ
        q = q.astype(complex)
        q[i] = d
        force = damper.channels()[0][2] @ q
        assert force == pytest.approx(k * 1j * omega * c / (k + 1j * omega * c), rel=1e-10)
