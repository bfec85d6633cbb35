"""Unit tests of the shared first-order form (model.analysis.linear_system): the Householder deflation
and the eigendecomposition shared by the eigen-analysis and the response."""

import threading

import numpy as np
import pytest

from model import build_model, default_operating_point, eigen_analysis, load_parameters
from model.analysis.eigen import bogie_system
from model.analysis.linear_system import Deflation, LinearSystem, SystemCache, balancing_scale


@pytest.mark.parametrize("rank", [0, 1, 2, 3])
def test_deflation_is_orthogonal_and_spans_the_basis(rank):
    rng = np.random.default_rng(rank)
    basis = rng.standard_normal((9, rank))
    deflation = Deflation(basis)
    Q = deflation.apply(np.eye(9))
    np.testing.assert_allclose(Q.T @ Q, np.eye(9), atol=1e-14)
    np.testing.assert_allclose(deflation.apply_transpose(np.eye(9)), Q.T, atol=1e-14)
    # the basis lies in span(Q1) and is orthogonal to Q2
    np.testing.assert_allclose(Q[:, rank:].T @ basis, 0.0, atol=1e-13)
    np.testing.assert_allclose(deflation.Q1, Q[:, :rank], atol=1e-14)
    A = rng.standard_normal((9, 9))
    np.testing.assert_allclose(deflation.project(A), Q.T @ A @ Q, atol=1e-13)


def test_balancing_equalizes_rows_and_columns_by_powers_of_two():
    """A balanced matrix spoilt by a diagonal similarity spanning 1e±9: the balancing returns
    powers of 2, and at its end every row/column 1-norm ratio is within (1/2, 2) — the stopping
    rule (no factor 2^round(½ log2(r/c)) left to apply); a zero row keeps its scale 1."""
    rng = np.random.default_rng(5)
    n = 60
    A = rng.standard_normal((n, n))
    spoil = 2.0 ** rng.integers(-30, 30, n)
    A = A * spoil[None, :] / spoil[:, None]
    A[7, :] = 0.0
    d = balancing_scale(A)
    np.testing.assert_array_equal(np.log2(d), np.round(np.log2(d)))
    B = np.abs(A * d[None, :] / d[:, None])
    np.fill_diagonal(B, 0.0)
    rows, columns = B.sum(axis=1), B.sum(axis=0)
    live = (rows > 0) & (columns > 0)
    assert np.all(rows[live] / columns[live] < 2.0)
    assert np.all(rows[live] / columns[live] > 0.5)
    assert d[7] == 1.0
    ratio = np.abs(A).max() / np.abs(A[np.abs(A) > 0]).min()
    assert B.max() / B[B > 0].min() < 1e-6 * ratio  # the spread of the entries is gone


def test_real_form_solve_matches_the_complex_solve():
    """The eigenvectors' LU is of their real form (Re y, Im y per pair); real and complex
    right-hand sides must give Yb⁻¹ rhs as a complex solve would."""
    system = _random_system(n=40, seed=11)
    lam, Y, _, cond, _ = system.modal
    assert np.any(lam.imag > 0)
    assert np.isfinite(cond)
    rng = np.random.default_rng(2)
    for rhs in (rng.standard_normal(Y.shape[0]),
                rng.standard_normal(Y.shape[0]) + 1j * rng.standard_normal(Y.shape[0])):
        np.testing.assert_allclose(system.solve_eigenvectors(rhs), np.linalg.solve(Y, rhs),
                                   rtol=1e-10, atol=1e-12 * np.abs(np.linalg.solve(Y, rhs)).max())


def test_cache_keeps_the_newest_points():
    cache = SystemCache(size=2)
    built = []
    for key in ("a", "b", "a", "c"):
        cache.get(key, lambda key=key: built.append(key) or key)
    assert built == ["a", "b", "c"]  # "a" was reused, not rebuilt
    assert cache.peek("b") is None
    assert cache.peek("a") == "a"
    assert cache.peek("c") == "c"


def test_eigen_analysis_and_response_share_one_decomposition():
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, 0.006, 110.0)
    result = eigen_analysis(model, op)
    system = bogie_system(model, op)
    assert "eigen" in system._cache
    assert result.eigenvalues is system.eigen[0]
    # eigenvectors of the full state matrix, rigid subspace handled exactly
    X = result.vectors
    residual = np.linalg.norm(system.A @ X - X * result.eigenvalues, axis=0)
    assert residual.max() < 1e-8 * np.abs(result.eigenvalues).max()
    # the no-vector path (a fresh, uncached system: eigenvalues without balancing first)
    fresh = bogie_system(model, op, cached=False).eigenvalues()
    distance = np.abs(fresh[:, None] - result.eigenvalues[None, :]).min(axis=1)
    assert len(fresh) == len(result.eigenvalues)
    # two backward-stable solvers agree to rounding × condition: the near-rigid drivetrain-spin
    # eigenvalue (≈ −0.02 1/s) of this stiff matrix (|λ| up to 3e5 1/s) moves by ~3e-9 1/s
    assert np.all(distance <= 1e-7 * np.maximum(np.abs(fresh), 1.0))


def _random_system(n: int = 190, seed: int = 3) -> LinearSystem:
    rng = np.random.default_rng(seed)
    L = rng.standard_normal((n, n))
    M = L @ L.T + n * np.eye(n)
    S = rng.standard_normal((n, n))
    K = S @ S.T + np.eye(n)
    B = 0.1 * rng.standard_normal((n, n)) + 0.5 * np.eye(n)
    return LinearSystem(M, B, K, rng.standard_normal(n), np.zeros((n, 0)))


def test_on_demand_vectors_are_the_full_vectors_columns():
    """``eigen_analysis(..., vectors="on_demand")``: the same eigenvalues (the same cached
    decomposition), no vector matrix, and each asked mode's shape equal to the full vectors'
    (rounding: the columns' products are formed alone, 1e-12 of the shape's largest entry);
    a mode asked twice is formed once."""
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, 0.007, 140.0)
    full = eigen_analysis(model, op)
    lazy = eigen_analysis(model, op, vectors="on_demand")
    assert lazy.vectors is None
    assert lazy.eigenvalues is full.eigenvalues
    indices = [int(i) for i in full.complex_index[:10]] + [int(full.real_index[0])]
    for index in indices:
        assert np.abs(lazy.mode_shape(index) - full.mode_shape(index)).max() <= 1e-12
    assert sorted(lazy._shapes) == sorted(indices)
    shape = lazy._shapes[indices[0]]
    lazy.mode_shape(indices[0])
    assert lazy._shapes[indices[0]] is shape
    with pytest.raises(ValueError, match="not computed"):
        eigen_analysis(model, op, vectors=False).mode_shape(indices[0])


def test_concurrent_solves_with_the_cached_factors_are_exact():
    """Sessions of the dashboard solve with one cached LU of the eigenvectors at once.  SciPy's
    getrs wrapper shifts the pivot array in place; with a shared pivot array this test aborted
    the interpreter ("double free or corruption") or gave wrong solutions within a second
    (reproduced with scipy 1.17.1, 3 threads); each solve now uses its own pivot copy."""
    system = _random_system()
    _, Y, _, _, _ = system.modal
    rng = np.random.default_rng(7)
    rhs = rng.standard_normal((8, Y.shape[0])) + 1j * rng.standard_normal((8, Y.shape[0]))
    expected = [np.linalg.solve(Y, b) for b in rhs]
    wrong = []

    def solve(thread: int) -> None:
        for k in range(3000):
            i = (k + thread) % len(rhs)
            x = system.solve_eigenvectors(rhs[i])
            if not np.allclose(x, expected[i], rtol=1e-9, atol=1e-12):
                wrong.append((thread, k))

    threads = [threading.Thread(target=solve, args=(t,)) for t in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not wrong, f"{len(wrong)} wrong solutions, first {wrong[:3]}"


# --- massless coordinates (the Maxwell elements' internal coordinates) ---------------------------

def _maxwell_sdof(m=3.0, k1=4.0e3, k2=9.0e3, c=150.0) -> LinearSystem:
    """A mass on a spring k1 to ground and a Maxwell element (damper c in series with a spring
    k2) to ground; coordinates [x, d], d the damper's elongation (massless):
    M = diag(m, 0), K = [[k1 + k2, −k2], [−k2, k2]], B = diag(0, c)."""
    M = np.diag([m, 0.0])
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    B = np.diag([0.0, c])
    return LinearSystem(M, B, K, np.array([1.0, 0.0]), np.zeros((2, 0)))


def test_massless_coordinate_state_matrix_has_the_characteristic_polynomial_roots():
    """det(λ²M + λB + K) = (mλ² + k1 + k2)(cλ + k2) − k2² is a cubic: three eigenvalues, the
    state [x, d, ẋ] (no velocity of the massless d)."""
    m, k1, k2, c = 3.0, 4.0e3, 9.0e3, 150.0
    system = _maxwell_sdof(m, k1, k2, c)
    assert system.N == 3
    np.testing.assert_array_equal(system.massless, [1])
    lam = np.linalg.eigvals(system.A)
    roots = np.roots([m * c, m * k2, c * (k1 + k2), k1 * k2])
    np.testing.assert_allclose(np.sort_complex(lam), np.sort_complex(roots), rtol=1e-12)
    assert np.all(lam.real < 0)  # the damper dissipates


def test_massless_velocity_and_input_maps():
    """q̇ = V x: ḋ = (k2/c)(x − d) for the Maxwell element; a force on x enters v̇ as f/m."""
    m, k1, k2, c = 3.0, 4.0e3, 9.0e3, 150.0
    system = _maxwell_sdof(m, k1, k2, c)
    x, d, v = 0.3, -0.1, 2.0
    np.testing.assert_allclose(system.velocity_map @ [x, d, v], [v, k2 / c * (x - d)])
    np.testing.assert_allclose(system.input_map(np.array([5.0, 0.0])), [0.0, 0.0, 5.0 / m])
    C = system.state_output(np.array([[0.0, 0.0]]), np.array([[0.0, c]]))  # damper force c ḋ
    np.testing.assert_allclose(C @ [x, d, v], [k2 * (x - d)])  # = the series spring's force


def test_massless_response_matches_a_direct_integration():
    """Response of the Maxwell single-DOF system to a step and a damped sinusoid: the modal
    closed form and the exact discretization against an independent integration of the
    hand-written first-order equations (scipy's DOP853 at rtol 1e-11)."""
    from scipy.integrate import solve_ivp

    from model.analysis.response import solve_linear

    m, k1, k2, c = 3.0, 4.0e3, 9.0e3, 150.0
    system = _maxwell_sdof(m, k1, k2, c)
    u0, a, mu = -2.0, 3.0 * np.exp(0.3j), complex(-6.0, 2 * np.pi * 7.0)
    t = np.arange(801) * 1e-3

    def rhs(time, s):
        x, d, v = s
        u = u0 + (a * np.exp(mu * time)).real
        return [v, k2 / c * (x - d), (u - (k1 + k2) * x + k2 * d) / m]

    exact = solve_ivp(rhs, (0, t[-1]), [0.0, 0.0, 0.0], method="DOP853", t_eval=t, rtol=1e-11,
                      atol=1e-14).y.T
    for method in ("modal", "expm"):
        y, used, _ = solve_linear(system, np.eye(3), u0, a, mu, len(t), 1e-3, method)
        assert used == method
        assert np.abs(y - exact).max() < 1e-7 * np.abs(exact).max()


def test_massless_coordinate_with_a_rigid_body_mode():
    """Two masses joined by a spring k1 and a Maxwell element (k, c): the common translation
    (d unchanged) is the rigid-body mode, deflated exactly; the relative motion has the cubic of
    the single-DOF test with the reduced mass, the translation's velocity a zero eigenvalue (no
    damping acts on it).  A force on one mass makes the centre of mass accelerate as F/(m1+m2)."""
    from model.analysis.response import solve_linear

    m1, m2, k1, k, c = 2.0, 5.0, 3.0e3, 8.0e3, 90.0
    h = np.array([-1.0, 1.0, -1.0])  # the Maxwell spring's elongation x2 − x1 − d
    g = np.array([-1.0, 1.0, 0.0])
    M, B = np.diag([m1, m2, 0.0]), np.diag([0.0, 0.0, c])
    R = np.array([[1.0], [1.0], [0.0]])
    system = LinearSystem(M, B, k * np.outer(h, h) + k1 * np.outer(g, g),
                          np.array([1.0, 0.0, 0.0]), R)
    np.testing.assert_allclose(system.A @ np.concatenate([R[:, 0], [0.0, 0.0]]), 0.0, atol=1e-12)
    lam = system.eigen[0]
    assert len(lam) == system.N - 1  # the rigid zero deflated
    mu = m1 * m2 / (m1 + m2)
    roots = np.roots([mu * c, mu * k, c * (k1 + k), k1 * k])
    np.testing.assert_allclose(np.sort_complex(lam), np.sort_complex(np.append(roots, 0.0)),
                               atol=1e-9 * np.abs(roots).max())
    t = np.arange(601) * 1e-3
    y, _, _ = solve_linear(system, np.eye(system.N), 1.0, 0.0j, complex(-1.0, 1.0), len(t),
                           1e-3, "expm")
    centre = (m1 * y[:, 0] + m2 * y[:, 1]) / (m1 + m2)
    np.testing.assert_allclose(centre, t**2 / (2 * (m1 + m2)), rtol=1e-9, atol=1e-15)
