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

Massless coordinates (exact, no artificial mass).  A coordinate whose row and column of M are
zero — the internal coordinate of a Maxwell element, a damper in series with a spring, whose
inner node has no mass — is first order: its row of ``M q̈ + B q̇ + K q = f u`` reads
``B_mm q̇_m + B_mi q̇_i + K_m q = f_m u`` (``B_mm`` invertible: the damper).  The state then holds
every coordinate but only the velocities of the inertial ones, ``x = [q; v]``, ``v = q̇_i``
(N = n + n_i states), and

    q̇_i = v,     q̇_m = −B_mm⁻¹ (K_m q + B_mi v − f_m u),
    M_ii v̇ = −K_i q − B_ii v − B_im q̇_m + f_i u.

Without massless coordinates this is the form above.

Free rigid motions.  A rigid-body mode that no damping meets either (``K r = 0`` and ``B r = 0``:
the vehicle rolling without slip, with no running resistance in the model) gives a second exact
zero: its velocity state ``[0; r_i]`` is mapped by A onto the rigid subspace,
``A [0; r_i] = [r; 0]`` (a Jordan chain).  Such modes are given as ``free`` (n x k, in the span of
R) and deflated with the others: Q1 spans ``[[R, 0], [0, F_i]]`` and

    Qᵀ A Q = [[N, A12], [0, A22]],   N nilpotent (N² = 0),

so that a constant input gives the deflated coordinates a ramp and the free motion a uniform
acceleration (:meth:`LinearSystem.step_particular`).  The full velocity is ``q̇ = V x + …`` with
``V`` = the first n rows of A (:attr:`LinearSystem.velocity_map`; plus ``B_mm⁻¹ f_m u`` if an
input acts on a massless coordinate, which the bogie's inputs never do); a generalized force
enters as :meth:`LinearSystem.input_map`.  A rigid-body mode ``r`` (its massless part included:
``K r = 0``) gives the exact eigenpair ``(0, [r; 0])`` as before.
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
_DENSE_COUNT = [0]  # dense eigendecompositions of a full state matrix in this process
_DENSE_COUNT_LOCK = threading.Lock()


def dense_decompositions() -> int:
    """How many dense eigendecompositions of a full (deflated) state matrix this process has
    computed, with or without vectors (:attr:`LinearSystem.eigen`,
    :meth:`LinearSystem.eigenvalues`): every eigen-analysis, stability-limit evaluation and
    dense root-locus point costs one.  What a cheaper path (a preview from a reduced model)
    promises not to spend is checked against it."""
    with _DENSE_COUNT_LOCK:
        return _DENSE_COUNT[0]


def _count_dense() -> None:
    with _DENSE_COUNT_LOCK:
        _DENSE_COUNT[0] += 1


def balancing_scale(A: np.ndarray, sweeps: int = 32) -> np.ndarray:
    """Diagonal balancing of A by powers of 2: ``d`` such that ``D⁻¹ A D`` (D = diag(d)) has
    equal 1-norms of row i and column i without the diagonal, for every i (as far as powers of 2
    allow).  All rows are updated at once, ``d_i ← d_i·2^round(½ log2(r_i/c_i))``, two
    matrix-vector products per sweep, until no factor changes (a fraction of the time
    of LAPACK's sequential dgebal on the bogie's state matrix; on the bogie the eigenvector matrix of the result is 5x
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


class RigidDeflation:
    """The deflation of a system's exact zero eigenvalues: ``W = T Q P`` with Q = [Q1 Q2] the
    orthogonal :class:`Deflation` of the rigid positions [R; 0] and, for each free velocity
    state x_v = [0; F_i] (module docstring), an elementary (Gauss) transform
    ``T = I + (x_v − e_c) e_cᵀ`` that makes the state coordinate c (the free motion's heaviest
    velocity, where x_v is scaled to 1) that velocity; P orders the coordinates [rigid, free,
    rest].  An orthogonal reflector of x_v would mix the velocity rows of every body, stiff and
    soft (their scales span ten orders of magnitude), and cost the slow eigenvalues six digits;
    T only adds multiples of the heaviest body's row.  ``W⁻¹ A W = [[N, A12], [0, A22]]``."""

    def __init__(self, R_state: np.ndarray, free_velocities: np.ndarray,
                 weights: np.ndarray):
        # R_state: N x r rigid positions [R; 0]; free_velocities: N x k (zero where R_state is
        # not: velocity rows); weights: N, the pivot's choice (kinetic energy per unit entry²)
        self.size = R_state.shape[0]
        self.rigid = Deflation(R_state)
        k = free_velocities.shape[1]
        pivots = []
        X = free_velocities.astype(float).copy()
        for j in range(k):
            c = int(np.argmax(weights * X[:, j] ** 2))
            X[:, j] /= X[c, j]
            pivots.append(c)
        if k > 1 and np.any(np.abs(X[pivots] - np.eye(k)) > 0):
            raise ValueError("free modes must not share a pivot coordinate")
        self.pivots = np.array(pivots, dtype=int)
        self.shift = X  # x_v (N x k), 1 at its own pivot
        self.shift[self.pivots, np.arange(k)] -= 1.0  # x_v − e_c
        r = R_state.shape[1]
        rest = np.setdiff1d(np.arange(r, self.size), self.pivots)
        self.order = np.concatenate([np.arange(r), self.pivots, rest]).astype(int)
        self.rank = r + k

    def _T(self, X: np.ndarray) -> np.ndarray:
        return X + self.shift @ X[self.pivots] if len(self.pivots) else X

    def _T_inverse(self, X: np.ndarray) -> np.ndarray:
        return X - self.shift @ X[self.pivots] if len(self.pivots) else X

    def apply(self, Z: np.ndarray) -> np.ndarray:
        """W Z (Z: N or N x m, rows in the deflated order)."""
        X = np.empty_like(Z)
        X[self.order] = Z
        return self._T(self.rigid.apply(X))

    def to_deflated(self, X: np.ndarray) -> np.ndarray:
        """W⁻¹ X: a state (or input) in the deflated coordinates."""
        return self.rigid.apply_transpose(self._T_inverse(X))[self.order]

    def rows(self, C: np.ndarray) -> np.ndarray:
        """C W: output rows (p x N) on the deflated coordinates."""
        CT = C.copy()
        if len(self.pivots):
            CT[:, self.pivots] += C @ self.shift
        return self.rigid.apply_transpose(CT.T).T[:, self.order]

    def project(self, A: np.ndarray) -> np.ndarray:
        """W⁻¹ A W (N x N)."""
        if len(self.pivots):
            A = A.copy()
            A[:, self.pivots] += A @ self.shift  # A T
            A -= self.shift @ A[self.pivots]  # T⁻¹ (A T)
        return self.rigid.project(A)[np.ix_(self.order, self.order)]


@dataclass
class LinearSystem:
    """``M q̈ + B q̇ + K q = f u(t)``, rigid modes ``K R = 0`` (R: n x r, r may be 0).

    Coordinates whose row of M is zero are massless (first order, see the module docstring);
    M restricted to the others is symmetric positive definite.  The pieces that depend only on
    the system (not on the input) are computed on first use and kept.  ``inverse_mass`` may be
    given: the inverse of M restricted to the inertial coordinates (it does not depend on the
    operating point).
    """

    M: np.ndarray  # n x n, symmetric positive semi-definite (zero rows: massless coordinates)
    B: np.ndarray  # n x n (any; invertible on the massless coordinates)
    K: np.ndarray  # n x n, symmetric, null space spanned exactly by R
    f: np.ndarray  # n, generalized force per unit input
    R: np.ndarray  # n x r rigid-body modes
    inverse_mass: np.ndarray | None = None  # M_ii⁻¹ (inertial coordinates) if known
    free: np.ndarray | None = None  # n x k rigid modes no damping meets (B F = 0), in span R
    _cache: dict = field(default_factory=dict, repr=False)
    _lock: threading.RLock = field(default_factory=threading.RLock, repr=False)

    @property
    def n(self) -> int:
        """Number of coordinates (inertial and massless)."""
        return self.M.shape[0]

    @property
    def massless(self) -> np.ndarray:
        """Indices of the massless coordinates (rows of M that are exactly zero)."""
        return self._get("massless", lambda: massless_coordinates(self.M))

    @property
    def inertial(self) -> np.ndarray:
        """Indices of the coordinates with mass (their velocities are states)."""
        return self._get("inertial", lambda: np.setdiff1d(np.arange(self.n), self.massless))

    @property
    def N(self) -> int:
        """Number of states: every coordinate and the velocities of the inertial ones."""
        return self.n + len(self.inertial)

    @property
    def free_modes(self) -> np.ndarray:
        """F (n x k): the rigid modes whose velocity meets no damping (module docstring)."""
        return self.free if self.free is not None else np.zeros((self.n, 0))

    @property
    def rigid_count(self) -> int:
        """Exact zero eigenvalues deflated: the rigid modes and the free ones' velocities."""
        return self.R.shape[1] + self.free_modes.shape[1]

    def _get(self, key, build):
        with self._lock:  # sessions of the dashboard share systems: build each piece once
            if key not in self._cache:
                self._cache[key] = build()
            return self._cache[key]

    def kept(self, key, build):
        """``build()`` once per system and ``key`` (pieces that depend on the system and a few
        settings, such as the rows of a list of outputs)."""
        return self._get(("kept", key), build)

    def last(self, name: str, key, build):
        """``build()``, unless the last value kept under ``name`` was built for an equal ``key``:
        then that value.  One value per name (pieces that depend on more than the system, such
        as an excitation's, asked for several times in a row)."""
        kept = self._cache.get(("last", name))  # (key, value): one read, safe across threads
        if kept is not None and kept[0] == key:
            return kept[1]
        value = build()
        self._cache[("last", name)] = (key, value)
        return value

    @property
    def Minv(self) -> np.ndarray:
        """M_ii⁻¹: inverse of the mass matrix on the inertial coordinates (n_i x n_i)."""
        def build():
            if self.inverse_mass is not None:
                return self.inverse_mass
            return inertial_inverse_mass(self.M, self.inertial)
        return self._get("Minv", build)

    @property
    def _massless_damping(self) -> tuple[np.ndarray, np.ndarray]:
        """(B_mm⁻¹, B_im): the damping on the massless coordinates and its coupling."""
        def build():
            m, i = self.massless, self.inertial
            B_mm = self.B[np.ix_(m, m)]
            try:
                inverse = np.linalg.inv(B_mm) if len(m) else np.zeros((0, 0))
            except np.linalg.LinAlgError:
                raise np.linalg.LinAlgError("a massless coordinate has no damping: its "
                                            "first-order equation is singular") from None
            return inverse, self.B[np.ix_(i, m)]
        return self._get("massless_damping", build)

    @property
    def A(self) -> np.ndarray:
        """State matrix (N x N) [1/s, 1/s²] of the state ``[q; v]`` (module docstring)."""
        def build():
            inverse = self._massless_damping[0] if len(self.massless) else None
            return first_order_matrix(self.Minv, self.B, self.K, self.inertial, self.massless,
                                      inverse)
        return self._get("A", build)

    @property
    def velocity_map(self) -> np.ndarray:
        """V (n x N): the velocities of all coordinates ``q̇ = V x`` without input (the inputs of
        the bogie never act on a massless coordinate) [1, 1/s]."""
        return self._get("velocity_map", lambda: self.A[:self.n])

    def input_map(self, F: np.ndarray) -> np.ndarray:
        """State input ``b`` (N, or N x k) of generalized forces ``F`` (n, or n x k): ``ẋ = A x +
        b u`` for the force ``F u``."""
        F = np.asarray(F)
        i, m, n = self.inertial, self.massless, self.n
        out = np.zeros((self.N, *F.shape[1:]), dtype=np.result_type(F, float))
        F_i = F[i]
        if len(m):
            inverse, B_im = self._massless_damping
            out[m] = inverse @ F[m]
            F_i = F_i - B_im @ out[m]
        out[n:] = self.Minv @ F_i
        return out

    def state_output(self, C_q: np.ndarray, C_v: np.ndarray) -> np.ndarray:
        """Output rows on the state (p x N) of ``y = C_q q + C_v q̇`` (C_q, C_v: p x n)."""
        C_q, C_v = np.atleast_2d(C_q), np.atleast_2d(C_v)
        out = C_v @ self.velocity_map
        out[:, :self.n] += C_q
        return out

    @property
    def b(self) -> np.ndarray:
        """Input vector of ``f`` (N)."""
        return self._get("b", lambda: self.input_map(self.f))

    @property
    def deflation(self) -> RigidDeflation:
        """W with the first columns spanning the rigid subspace [R; 0] and the free modes'
        velocities [0; F_i] (:class:`RigidDeflation`)."""
        def build():
            R, F, i, n = self.R, self.free_modes, self.inertial, self.n
            R_state = np.vstack([R, np.zeros((len(i), R.shape[1]))])
            free = np.vstack([np.zeros((n, F.shape[1])), F[i]])
            weights = np.concatenate([np.zeros(n), np.diag(self.M)[i]])
            return RigidDeflation(R_state, free, weights)
        return self._get("deflation", build)

    @property
    def reduced(self) -> tuple[np.ndarray, np.ndarray]:
        """(A12, A22) of Qᵀ A Q = [[N, A12], [0, A22]] (N: :attr:`rigid_block`)."""
        return self._projected[1:]

    @property
    def rigid_block(self) -> np.ndarray:
        """N (rigid_count x rigid_count) of Qᵀ A Q: zero but for the free modes' velocities,
        which move their positions (N² = 0)."""
        return self._projected[0]

    @property
    def _projected(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        def build():
            r = self.rigid_count
            P = self.deflation.project(self.A)
            N = P[:r, :r].copy()
            if not self.free_modes.shape[1]:
                N[:] = 0.0  # exactly: the rigid subspace is A's null space
            return N, P[:r, r:], np.ascontiguousarray(P[r:, r:])
        return self._get("projected", build)

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
            _count_dense()
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

    def step_particular(self, u0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(α, β, γ) with x_p = α + β t + γ t² solving ẋ = A x + b u0 [state units].

        ``q_p = q0 + v t + a t²/2``: the free modes take a uniform acceleration a = F g, the
        damped rigid directions a constant velocity v = R_d c, both from the rigid projection
        ``Rᵀ (M a + B v) = Rᵀ f u0`` (R_d: the part of span R that is not free), and q0 from
        ``K q0 = f u0 − B v − M a``, ``Rᵀ q0 = 0``."""
        n, R, F, i = self.n, self.R, self.free_modes, self.inertial
        r, k = R.shape[1], F.shape[1]
        fu = self.f * u0
        zero = np.zeros(self.N)
        if r == 0:
            q = np.linalg.solve(self.K, fu)
            return np.concatenate([q, np.zeros(len(i))]), zero, zero
        if k:
            S = np.linalg.lstsq(R, F, rcond=None)[0]  # F = R S
            R_d = R @ sla.null_space(S.T)
            g = np.linalg.solve(np.hstack([R.T @ (self.M @ F), R.T @ (self.B @ R_d)]), R.T @ fu)
            acceleration, v = F @ g[:k], R_d @ g[k:]
        else:
            acceleration, v = np.zeros(n), R @ np.linalg.solve(R.T @ self.B @ R, R.T @ fu)
        bordered = np.block([[self.K, R], [R.T, np.zeros((r, r))]])
        rhs = fu - self.B @ v - self.M @ acceleration
        q = np.linalg.solve(bordered, np.concatenate([rhs, np.zeros(r)]))[:n]
        return (np.concatenate([q, v[i]]), np.concatenate([v, acceleration[i]]),
                np.concatenate([acceleration / 2, np.zeros(len(i))]))

    def exponential_particular(self, a: complex, mu: complex) -> np.ndarray:
        """x_μ with x_p = Re(x_μ e^(μt)) solving ẋ = A x + b Re(a e^(μt))."""
        q = np.linalg.solve(mu * mu * self.M + mu * self.B + self.K, self.f * a)
        return np.concatenate([q, mu * q[self.inertial]])

    def eigenvalues(self) -> np.ndarray:
        """The non-rigid eigenvalues only [1/s] (no vectors; uses them if already computed)."""
        if "eigen" in self._cache:
            return self._cache["eigen"][0]
        _count_dense()
        return sla.eigvals(self.reduced[1], overwrite_a=False, check_finite=False)

    def state_vectors(self, columns: np.ndarray | None = None) -> np.ndarray:
        """Unit eigenvectors x = Q1 (λ − N)⁻¹ A12 y + Q2 y of A for the eigenvalues of
        :attr:`eigen` (N x N − r; ``columns``: only those, N x len(columns)); (λ − N)⁻¹ =
        (I + N/λ)/λ since N² = 0."""
        lam, Yb, scale = self.eigen
        if columns is not None:
            columns = np.asarray(columns, dtype=int)
            lam, Yb = lam[columns], Yb[:, columns]
        Y = Yb * scale[:, None]
        rigid = (self.reduced[0] @ Y) / lam
        rigid = rigid + (self.rigid_block @ rigid) / lam
        X = self.deflation.apply(np.vstack([rigid, Y]))
        return X / np.linalg.norm(X, axis=0)


def first_order_matrix(Minv: np.ndarray, B: np.ndarray, K: np.ndarray, inertial: np.ndarray,
                       massless: np.ndarray, massless_damping_inverse: np.ndarray | None = None
                       ) -> np.ndarray:
    """State matrix A (N x N, N = n + n_i) of ``M q̈ + B q̇ + K q = 0`` on the state
    ``[q; q̇_inertial]`` (module docstring); ``Minv`` = M⁻¹ on the inertial coordinates,
    ``massless_damping_inverse`` = B_mm⁻¹ if known."""
    n, m, i = K.shape[0], massless, inertial
    A = np.zeros((n + len(i), n + len(i)))
    A[i, n + np.arange(len(i))] = 1.0
    K_i, B_ii = K[i], B[np.ix_(i, i)]
    if len(m):
        inverse = (np.linalg.inv(B[np.ix_(m, m)]) if massless_damping_inverse is None
                   else massless_damping_inverse)
        A[m, :n] = -inverse @ K[m]
        A[m, n:] = -inverse @ B[np.ix_(m, i)]
        B_im = B[np.ix_(i, m)]
        K_i = K_i + B_im @ A[m, :n]
        B_ii = B_ii + B_im @ A[m, n:]
    A[n:, :n] = -Minv @ K_i
    A[n:, n:] = -Minv @ B_ii
    return A


def massless_coordinates(M: np.ndarray) -> np.ndarray:
    """Indices of the coordinates whose row of M is exactly zero (no mass, first order)."""
    return np.flatnonzero(~np.any(M != 0, axis=1))


def inertial_inverse_mass(M: np.ndarray, inertial: np.ndarray | None = None) -> np.ndarray:
    """Inverse of M restricted to the inertial coordinates (Cholesky; n_i x n_i)."""
    if inertial is None:
        inertial = np.setdiff1d(np.arange(M.shape[0]), massless_coordinates(M))
    M_ii = M[np.ix_(inertial, inertial)]
    return sla.cho_solve(sla.cho_factor(M_ii), np.eye(len(inertial)))


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
