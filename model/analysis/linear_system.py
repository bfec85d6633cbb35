"""The exact first-order form of ``M q̈ + B q̇ + K q = f u(t)`` and its eigendecomposition.

One :class:`LinearSystem` per operating point serves both the eigen-analysis
(:mod:`model.analysis.eigen`) and the short-circuit response (:mod:`model.analysis.response`): an operating point
costs one eigendecomposition, whichever is asked first (:func:`bogie_system` caches the last few
per model).

State ``x = [q; q̇]``, ``ẋ = A x + b u`` with ``A = [[0, I], [−M⁻¹K, −M⁻¹B]]``.  Every rigid-body
mode ``r`` (``K r = 0``) gives the exact eigenpair ``(0, [r; 0])`` of A whatever the damping; the
invariant subspace they span is deflated with an orthogonal ``Q = [Q1 Q2]`` (Householder
reflectors, applied in O(N²) instead of formed):

    Qᵀ A Q = [[0, A12], [0, A22]],   Q1 spans [R; 0].
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
from scipy.linalg.lapack import dgecon

CACHED_POINTS = 8  # operating points whose decomposition is kept per model


def balancing_scale(A: np.ndarray, sweeps: int = 32) -> np.ndarray:
    """Diagonal balancing of A by powers of 2: ``d`` such that ``D⁻¹ A D`` (D = diag(d)) has
    equal 1-norms of row i and column i without the diagonal, for every i (as far as powers of 2
    allow).  All rows are updated at once, ``d_i ← d_i·2^round(½ log2(r_i/c_i))``, two
    matrix-vector products per sweep, until no factor changes (≈ 1 ms for N = 384 against ≈ 6 ms
    for LAPACK's sequential dgebal; on the bogie the eigenvector matrix of the result is 5x
    better conditioned).  Any diagonal similarity is exact: the balancing only affects rounding.
    Zero rows or columns keep d_i = 1."""
    magnitude = np.abs(A)
    np.fill_diagonal(magnitude, 0.0)
    d = np.ones(A.shape[0])
    for _ in range(sweeps):
        rows = (magnitude @ d) / d
        columns = (magnitude.T @ (1.0 / d)) * d
        with np.errstate(divide="ignore"):
            factor = np.exp2(np.round(0.5 * np.log2(rows / columns)))
        factor[(rows == 0.0) | (columns == 0.0)] = 1.0
        if np.all(factor == 1.0):
            break
        d *= factor
    return d


class Deflation:
    """Orthogonal ``Q = [Q1 Q2] = I − V T Vᵀ`` (compact WY form of the Householder reflectors of
    the QR factorization of ``basis``, N x r): Q1 spans the columns of ``basis``."""

    def __init__(self, basis: np.ndarray):
        self.size, self.rank = basis.shape
        r = self.rank
        if r == 0:
            self.V, self.T = np.zeros((self.size, 0)), np.zeros((0, 0))
            return
        (packed, tau), _ = sla.qr(basis, mode="raw")
        V = np.tril(packed[:, :r], -1)
        V[np.arange(r), np.arange(r)] = 1.0
        T = np.zeros((r, r))
        for i in range(r):  # LAPACK dlarft (forward, columnwise)
            T[i, i] = tau[i]
            T[:i, i] = -tau[i] * (T[:i, :i] @ (V[:, :i].T @ V[:, i]))
        self.V, self.T = V, T

    def apply(self, X: np.ndarray) -> np.ndarray:
        """Q X (X: N or N x k)."""
        return X - self.V @ (self.T @ (self.V.T @ X))

    def apply_transpose(self, X: np.ndarray) -> np.ndarray:
        """Qᵀ X (X: N or N x k)."""
        return X - self.V @ (self.T.T @ (self.V.T @ X))

    def project(self, A: np.ndarray) -> np.ndarray:
        """Qᵀ A Q (N x N) by rank-r updates."""
        V, T = self.V, self.T
        if self.rank == 0:
            return A.copy()
        AV = A @ V
        VtA = V.T @ A
        VtAV = V.T @ AV
        return (A - V @ (T.T @ VtA) - (AV @ T) @ V.T
                + V @ (T.T @ VtAV @ T) @ V.T)

    @property
    def Q1(self) -> np.ndarray:
        """The first r columns of Q (N x r)."""
        return self.apply(np.eye(self.size, self.rank))


@dataclass
class LinearSystem:
    """``M q̈ + B q̇ + K q = f u(t)``, rigid modes ``K R = 0`` (R: n x r, r may be 0).

    The pieces that depend only on the system (not on the input) are computed on first use and
    kept.  ``inverse_mass`` may be given (it does not depend on the operating point).
    """

    M: np.ndarray  # n x n, symmetric positive definite
    B: np.ndarray  # n x n (any)
    K: np.ndarray  # n x n, symmetric, null space spanned exactly by R
    f: np.ndarray  # n, generalized force per unit input
    R: np.ndarray  # n x r rigid-body modes
    inverse_mass: np.ndarray | None = None  # M⁻¹ if known
    _cache: dict = field(default_factory=dict, repr=False)
    _lock: threading.RLock = field(default_factory=threading.RLock, repr=False)

    @property
    def n(self) -> int:
        return self.M.shape[0]

    def _get(self, key, build):
        with self._lock:  # sessions of the dashboard share systems: build each piece once
            if key not in self._cache:
                self._cache[key] = build()
            return self._cache[key]

    @property
    def Minv(self) -> np.ndarray:
        def build():
            if self.inverse_mass is not None:
                return self.inverse_mass
            return sla.cho_solve(sla.cho_factor(self.M), np.eye(self.n))
        return self._get("Minv", build)

    @property
    def A(self) -> np.ndarray:
        """State matrix (2n x 2n) [1/s, 1/s²]."""
        def build():
            n, Minv = self.n, self.Minv
            A = np.zeros((2 * n, 2 * n))
            A[:n, n:] = np.eye(n)
            A[n:, :n] = -Minv @ self.K
            A[n:, n:] = -Minv @ self.B
            return A
        return self._get("A", build)

    @property
    def b(self) -> np.ndarray:
        """Input vector [0; M⁻¹ f] (2n)."""
        return self._get("b", lambda: np.concatenate([np.zeros(self.n), self.Minv @ self.f]))

    @property
    def deflation(self) -> Deflation:
        """Q = [Q1 Q2] with Q1 spanning the rigid subspace [R; 0]."""
        return self._get("deflation",
                         lambda: Deflation(np.vstack([self.R, np.zeros_like(self.R)])))

    @property
    def reduced(self) -> tuple[np.ndarray, np.ndarray]:
        """(A12, A22) of Qᵀ A Q = [[0, A12], [0, A22]]."""
        def build():
            r = self.R.shape[1]
            P = self.deflation.project(self.A)
            return P[:r, r:], np.ascontiguousarray(P[r:, r:])
        return self._get("reduced", build)

    @property
    def eigen(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Eigen-decomposition of A22 = T Yb Λ Yb⁻¹ T⁻¹ with the diagonal balancing
        T = diag(scale) of :func:`balancing_scale` (powers of 2, exact): (λ [1/s], unit
        eigenvectors Yb of the balanced matrix, scale).  Balancing puts displacements and
        velocities on one footing (|λ| spans 0.3…3·10⁵ 1/s) and lowers cond(Yb) by three orders
        of magnitude against the unbalanced eigenvectors.  λ in LAPACK's order: a complex pair
        is adjacent, positive imaginary part first, exactly conjugate, as are its vectors."""
        def build():
            A22 = self.reduced[1]
            scale = balancing_scale(A22)
            lam, Y = np.linalg.eig(A22 * scale[None, :] / scale[:, None])
            return lam, Y / np.linalg.norm(Y, axis=0), scale
        return self._get("eigen", build)

    @property
    def modal(self) -> tuple[np.ndarray, np.ndarray, tuple, float, np.ndarray]:
        """:attr:`eigen` with the LU factors of the *real* form of Yb and its condition number
        (1-norm, LAPACK estimate): (λ, Yb, lu, cond, scale).  The real form Yr has, for a pair
        (y, ȳ), the columns (Re y, Im y), for a real λ its real vector: same span, half the
        arithmetic of a complex LU."""
        def build():
            lam, Y, scale = self.eigen
            first = np.flatnonzero(lam.imag > 0)  # first of each pair; the second is next
            if len(first) and (first[-1] + 1 >= len(lam)
                               or np.any(lam[first + 1] != lam[first].conj())):
                raise np.linalg.LinAlgError("eigenvalues are not in conjugate pairs")
            Yr = Y.real.copy()
            Yr[:, first + 1] = Y[:, first].imag
            lu = sla.lu_factor(Yr, check_finite=False)
            rcond, _ = dgecon(lu[0], np.abs(Yr).sum(axis=0).max(), norm="1")
            return lam, Y, lu, (1.0 / rcond if rcond > 0 else math.inf), scale
        return self._get("modal", build)

    def solve_eigenvectors(self, rhs: np.ndarray) -> np.ndarray:
        """Yb⁻¹ rhs (complex, rhs: real or complex, N or N x k) with the cached LU factors of
        the real form of :attr:`modal` (thread-safe): for a pair, ``Yr e = rhs`` gives the
        coefficients (e₁ ∓ i e₂)/2 of y and ȳ.

        SciPy's LAPACK wrappers (1.17 and earlier) shift the pivot array *in place* to LAPACK's
        1-based indices and back around each ``getrs``; two threads solving with one shared
        pivot array shift it twice, swap rows out of range and corrupt the heap (the dashboard's
        server aborted with "malloc(): invalid size" when sessions computed the same point).
        Each call therefore passes its own copy of the pivots (n integers)."""
        lam, _, (lu, pivots), _, _ = self.modal
        first = np.flatnonzero(lam.imag > 0)
        rhs = np.asarray(rhs)

        def solve(real: np.ndarray) -> np.ndarray:
            e = sla.lu_solve((lu, pivots.copy()), real, check_finite=False).astype(complex)
            half = 0.5 * (e[first] - 1j * e[first + 1])
            e[first], e[first + 1] = half, half.conj()
            return e

        if np.iscomplexobj(rhs):
            return solve(rhs.real) + 1j * solve(rhs.imag)
        return solve(rhs)

    def step_particular(self, u0: float) -> tuple[np.ndarray, np.ndarray]:
        """(α, β) with x_p = α + β t solving ẋ = A x + b u0 [state units]."""
        n, R = self.n, self.R
        r = R.shape[1]
        fu = self.f * u0
        if r == 0:
            q = np.linalg.solve(self.K, fu)
            return np.concatenate([q, np.zeros(n)]), np.zeros(2 * n)
        c = np.linalg.solve(R.T @ self.B @ R, R.T @ fu)  # spin velocities of the drift
        v = R @ c
        bordered = np.block([[self.K, R], [R.T, np.zeros((r, r))]])
        q = np.linalg.solve(bordered, np.concatenate([fu - self.B @ v, np.zeros(r)]))[:n]
        return np.concatenate([q, v]), np.concatenate([v, np.zeros(n)])

    def exponential_particular(self, a: complex, mu: complex) -> np.ndarray:
        """x_μ with x_p = Re(x_μ e^(μt)) solving ẋ = A x + b Re(a e^(μt))."""
        q = np.linalg.solve(mu * mu * self.M + mu * self.B + self.K, self.f * a)
        return np.concatenate([q, mu * q])

    def eigenvalues(self) -> np.ndarray:
        """The non-rigid eigenvalues only [1/s] (no vectors; uses them if already computed)."""
        if "eigen" in self._cache:
            return self._cache["eigen"][0]
        return sla.eigvals(self.reduced[1], overwrite_a=False, check_finite=False)

    def state_vectors(self) -> np.ndarray:
        """Unit eigenvectors x = Q1 A12 y/λ + Q2 y of A for the eigenvalues of :attr:`eigen`
        (2n x 2n − r)."""
        lam, Yb, scale = self.eigen
        Y = Yb * scale[:, None]
        A12 = self.reduced[0]
        X = self.deflation.apply(np.vstack([(A12 @ Y) / lam, Y]))
        return X / np.linalg.norm(X, axis=0)


class SystemCache:
    """The last :data:`CACHED_POINTS` systems of one model by operating point (thread-safe)."""

    def __init__(self, size: int = CACHED_POINTS):
        self.size = size
        self._systems: OrderedDict = OrderedDict()
        self._lock = threading.Lock()

    def peek(self, key) -> LinearSystem | None:
        """The system for ``key`` if it is kept (without changing the order)."""
        with self._lock:
            return self._systems.get(key)

    def get(self, key, build) -> LinearSystem:
        with self._lock:
            if key in self._systems:
                self._systems.move_to_end(key)
                return self._systems[key]
        system = build()
        with self._lock:
            system = self._systems.setdefault(key, system)
            self._systems.move_to_end(key)
            while len(self._systems) > self.size:
                self._systems.popitem(last=False)
        return system
