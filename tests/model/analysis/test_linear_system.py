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
