"""One s0-line (numpy/scipy only): the stability quantities at every creepage of a list and the
stability limit s0* along it, at one (v, N0, b_M) — the unit of work of a stability map
(:mod:`model.studies.maps`).

A **line** is all creepages s0 of a map at one (v, N0, b_M).  Along a line
only the longitudinal creep coefficient b11 = N0 μ'(s0)/v changes (b22, b23, b33 depend on v and
N0 only), so the state matrix is a rank-4 update of the one at an anchor creepage.

:func:`s0_line` with method "continuation" continues **every** non-rigid eigenvalue
along the line from one eigendecomposition (:mod:`model.analysis.continuation`): exact to its
convergence tolerance at every point, checked there (convergence, local multiplicity, trace and
inverse-trace identities); a point failing the checks is solved by a full eigen-analysis and
becomes the new anchor (counted in ``LineResult.fallbacks``).  s0* is found by Brent's method on
the same continuation.  Against a full eigen-analysis at every point of 100-point lines at 40,
120 and 250 km/h: all eigenvalues within 6.5·10⁻⁹ relative, the counts identical
(``scripts/bench_study.py --check-lines``, tests/model/analysis/test_continuation.py).

The reduced method, :func:`reduced_s0_line` (method "reduced", the default: it is
cheaper, see BENCHMARKS.md), reuses one Galerkin-reduced model (:class:`model.analysis.locus.Reduced`)
per line and costs one dense eigen-analysis with vectors (the *anchor*: the last creepage), two
without (the first creepage and the grid creepage of the most negative b11, the steepest falling
creep slope, the most destabilizing point) and one small eigenproblem per point (2r − 2
unknowns: the rigid-body zeros of the reduced model are deflated once per line).

**The basis**: the anchor's exact eigenvectors of the selection below and the
*creep responses* ``T_a(σ)⁻¹ G`` (T_a(λ) = λ²M + λC_a + K at the anchor, G the four
longitudinal creep patterns, :func:`model.mechanics.operating_point.longitudinal_creep_pattern`).  Along a
line only b11 changes, by a rank-4 term: an eigenpair (μ, x) at b11 = c solves
T_a(μ) x = −(c − c_a) μ G Gᵀ x, so **x lies in the range of T_a(μ)⁻¹ G**, whose modal expansion
is the anchor's modes near μ (in the basis) plus the far ones', which change slowly with μ.  The
shifts σ are −1 1/s (the low-frequency part), the top eigenvalue of each densely solved point
(there the top eigenvector is in the span exactly) and iω at each near-twin pair among the
anchor's selected modes (relative gap ≤ ``TWIN_GAP``: the ID1/ID2 twins, which the creep splits;
without these shifts one twin of the ≈ 37 Hz pair had no Ritz value between the checked points
and three test lines came out with 2 flutter pairs too few).  Measured: 59–66 columns instead
of 69–71 for the exact eigenvectors at both ends (BENCHMARKS.md, "Parameter studies on Dask").
The dense eigenvalues at the first creepage and at the b11 minimum check the basis: every
eigenvalue there that the selection would take must have a Ritz value within
10⁻⁴·max(|λ|, 1 1/s); if one has none, the basis falls back to the exact eigenvectors at both
ends, and at that creepage as a third anchor if its check still fails.
Its properties:

What a point reports is a property of **all** eigenvalues, not only of tracked branches:

* The basis holds, at every anchor, the exact eigenvectors of every eigenvalue inside the disc
  |λ| < 2π·``max_frequency_hz`` and of every eigenvalue less damped than Re λ > −5 1/s
  (``SELECTION_MARGIN``) whatever its frequency (e.g. the ≈ 50 Hz longitudinal rim modes that
  the falling creep branch destabilizes), and at the checked creepages a Ritz value within
  10⁻⁴ of each of those eigenvalues.  All Ritz values of the reduced model are summarized,
  except the rigid-body zeros and, outside the controlled disc (1.5 × the basis disc), Ritz
  values whose error estimate exceeds 10⁻³·|λ| (they approximate no eigenvalue).
* Every Ritz value that can decide the result (the largest real part; any whose estimated error
  could change the sign of its real part or lift it to the top) is error-controlled: its
  first-order error from the full-model residual (as in the root locus) must be below
  ``rtol``·max(|λ|, 1 1/s), else it is refined by Newton's method on the full model; if more than
  a few need it, the point is solved densely (exact).
* The eigenvalues outside the basis are damped by more than 5 1/s at every anchor and at the
  checked creepages (by the selection and the check); each line records their largest real part
  there (``outside_max_real_part``).
  That they stay below the top in between is an **assumption**, not a theorem: a real part is
  not monotone in b11 (modes interact).  With a margin of 2 1/s instead of 5 it failed (at
  40 km/h modes damped by 2–5 1/s at the anchors turn unstable between s0 = 0.0137 and 0.0144,
  and the flutter count came out 2 low); with 5 it holds on every line checked against the
  dense reference point by point (the tests; ``scripts/bench_study.py --check-lines``).

The reference is :func:`dense_line` (a full eigen-analysis at every point); the tests compare
both on a grid, point by point.  Units: SI (s0 [-], v [m/s], N0 [N], b_M [N m s/rad],
real parts [1/s]).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
import scipy.linalg as sla
from scipy.optimize import brentq

from model.analysis.continuation import LineContinuation
from model.analysis.eigen import eigen_analysis, non_neutral
from model.analysis.locus import newton, nonlinear_inverse_iteration
from model.analysis.reduced_model import Reduced, creep_patterns, pattern_coefficients
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import (
    OperatingPoint,
    damping_matrix,
    line_creep_coefficients,
    longitudinal_creep_pattern,
)

SELECTION_MARGIN = 5.0  # modes with Re λ > −this [1/s] at an end join the basis, at any |λ|
BAND = 1.0  # Ritz values with Re λ ≥ min(top, 0) − BAND [1/s] are checked (the others cannot
# decide the largest real part or a sign)
BASIS_CUTOFF = 1e-12  # singular values of the basis vectors below this (relative) are dropped;
# 1e-8 halves the basis but loses one of the near-twin ID1/ID2 pairs near 50 Hz (flutter counts
# off by 2 against the dense reference: measured), so the root locus's cut-off is kept
SPURIOUS = 1e-3  # relative error estimate above which a Ritz value outside the disc is dropped
MAX_NEWTON = 4  # more Ritz values failing the tolerance at a point: solve the point densely
MATCH = 1e-4  # a Ritz value this close (relative) to an eigenvalue represents it in the basis check
IMAG_TOL = 1e-9  # |Im λ| ≤ IMAG_TOL·|λ|: a real eigenvalue
TWIN_GAP = 1e-3  # anchor eigenvalues closer than this (relative) are a near-twin pair (a shift)
CREEP_RESPONSE_SHIFT = -1.0  # σ [1/s] of the basis's low-frequency creep-response vectors


# --- spectral summary -----------------------------------------------------------------------------

def spectrum_summary(eigenvalues: np.ndarray) -> tuple[float, int, int]:
    """(largest real part [1/s], unstable complex pairs, positive real eigenvalues) of a set of
    eigenvalues closed under conjugation (a pair counted once).  A real eigenvalue zero to
    rounding (:func:`model.analysis.eigen.non_neutral`) is neutral: neither growth nor a divergence."""
    lam = np.asarray(eigenvalues)
    lam = lam[non_neutral(lam)]
    is_real = np.abs(lam.imag) <= IMAG_TOL * np.abs(lam)
    unstable = lam.real > 0
    return (float(lam.real.max()), int(np.count_nonzero(unstable & ~is_real & (lam.imag > 0))),
            int(np.count_nonzero(unstable & is_real)))


def basis_modes(eigenvalues: np.ndarray, radius: float) -> np.ndarray:
    """Which eigenvalues' vectors (at an end of a line) enter the reduction basis (bool): those
    inside the disc |λ| < ``radius`` [1/s] and those less damped than ``SELECTION_MARGIN``."""
    return (np.abs(eigenvalues) < radius) | (eigenvalues.real > -SELECTION_MARGIN)


# --- one s0-line --------------------------------------------------------------------------------

@dataclass(frozen=True)
class LineResult:
    """The stability quantities along s0 at one (v, N0, b_M)."""

    s0: np.ndarray  # (n,) creepages [-]
    v: float  # speed [m/s]
    N0: float  # wheel force [N]
    b_M: float  # motor slope [N m s/rad]
    largest_real_part: np.ndarray  # (n,) largest real part of all non-rigid eigenvalues [1/s]
    flutter_pairs: np.ndarray  # (n,) int: complex pairs with Re > 0
    divergent_real: np.ndarray  # (n,) int: real eigenvalues > 0
    s0_limit: float  # smallest s0* in [s0[0], s0[-1]] where the bogie turns unstable [-]; nan: none
    dense_points: np.ndarray  # (n,) bool: solved by a full eigen-analysis
    newton_refinements: int  # Ritz values refined by Newton's method on the full model
    outside_max_real_part: float  # largest Re outside the basis at the anchors and the
    # checked creepage [1/s]
    basis_size: int  # columns of the reduction basis (0: dense or continuation)
    fallbacks: int = 0  # continuation: points where its checks failed (solved densely there)
    method: str = "dense"  # "continuation", "reduced" or "dense"

    @property
    def stable(self) -> np.ndarray:
        """(n,) bool: all non-rigid eigenvalues in the closed left half-plane."""
        return self.largest_real_part <= 0.0


def _top(eigenvalues: np.ndarray) -> complex | float:
    """The eigenvalue with the largest real part [1/s] (of a pair, the one with Im > 0; a real
    one as a float)."""
    top = eigenvalues[np.argmax(eigenvalues.real)]
    if abs(top.imag) <= IMAG_TOL * abs(top):
        return float(top.real)
    return complex(top.real, abs(top.imag))


def _dense_point(model: BogieModel, op: OperatingPoint, vectors: bool = False):
    return eigen_analysis(model, op, vectors=vectors)


def dense_line(model: BogieModel, s0_values, v: float, N0: float, b_M: float,
               s0_limit_xtol: float = 1e-6) -> LineResult:
    """The reference: a full eigen-analysis at every creepage (and the dense stability limit)."""
    s0_values = check_s0(s0_values)
    rows = [spectrum_summary(_dense_point(model, OperatingPoint(float(s), v, N0, b_M)).eigenvalues)
            for s in s0_values]
    growth = np.array([r[0] for r in rows])
    limit = _limit_on_grid(s0_values, growth, lambda s: _dense_point(
        model, OperatingPoint(s, v, N0, b_M)).max_real_part, s0_limit_xtol)
    n = len(s0_values)
    return LineResult(s0_values, v, N0, b_M, growth, np.array([r[1] for r in rows]),
                      np.array([r[2] for r in rows]), limit, np.ones(n, dtype=bool), 0, np.nan, 0)


def check_s0(s0_values) -> np.ndarray:
    """``s0_values`` as a float array; ValueError unless a non-empty, finite, increasing list."""
    s0_values = np.asarray(s0_values, dtype=float)
    if s0_values.ndim != 1 or len(s0_values) < 1 or not np.all(np.isfinite(s0_values)):
        raise ValueError("s0 values must be a non-empty list of finite creepages")
    if len(s0_values) > 1 and np.any(np.diff(s0_values) <= 0):
        raise ValueError("s0 values must increase")
    return s0_values


def _limit_on_grid(s0_values, growth, function, xtol: float) -> float:
    """s0* by Brent between the first two grid points where ``growth`` turns from ≤ 0 to > 0."""
    unstable = np.flatnonzero(growth > 0)
    if len(unstable) == 0 or unstable[0] == 0:
        return float("nan")
    i = unstable[0]
    return float(brentq(function, s0_values[i - 1], s0_values[i], xtol=xtol, rtol=1e-12))


def _reduced_limit(line_model, s0_values, growth, xtol: float, evaluations: int = 8) -> float:
    """s0* on the reduced evaluation g(s) (its largest real part) between the first two grid
    points where ``growth`` turns from ≤ 0 to > 0, to the same tolerance as Brent's method: a
    bracket [lo, hi] with g(lo) ≤ 0 < g(hi) no wider than ``xtol``, and the secant root inside.

    g is the maximum over branches: below s0* its top is often another, nearly flat branch, so
    Brent's method from the grid bracket took 9–12 evaluations.  Here the secant steps follow
    the real part of the crossing branch: the top eigenvalue at the grid point above the
    crossing, extrapolated linearly (slope from the next grid point, then from the last two
    evaluations), and at each evaluation the eigenvalue nearest to the extrapolation among those
    that moved since the grid point below the crossing (the slow creeping modes sit near 0 and do
    not move; the extrapolation is ≈ 0 at a secant root, so without that they were taken for the
    branch and the steps crawled by xtol/4: 21 evaluations at 250 km/h).  Each step
    stays inside the bracket (regula falsi on g where the branch's secant leaves it) and is at
    least xtol/4 long, so that the bracket closes once the iterate has converged: 3–8
    evaluations measured.  Brent's method on the remaining bracket after ``evaluations``."""
    unstable = np.flatnonzero(growth > 0)
    if len(unstable) == 0 or unstable[0] == 0:
        return float("nan")
    i = unstable[0]
    lo, g_lo, hi, g_hi = s0_values[i - 1], growth[i - 1], s0_values[i], growth[i]
    top = line_model.top_values
    known = (s0_values[i], top[i])  # a point of the crossing branch: (s0, eigenvalue)
    slope = 0.0  # d(eigenvalue)/ds0 of the branch, from the top at the next grid point if any
    if i + 1 < len(s0_values):
        slope = (top[i + 1] - top[i]) / (s0_values[i + 1] - s0_values[i])
    x = known[0] - known[1].real / slope.real if slope.real > 0 else np.nan
    if not lo < x < hi:
        x = lo - g_lo * (hi - lo) / (g_hi - g_lo)  # regula falsi on the grid bracket
    steady = line_model.grid_values[i - 1] if len(line_model.grid_values) == len(s0_values) \
        else np.zeros(0, dtype=complex)
    for _ in range(evaluations):
        gx = line_model.point(x)[0][0]
        values = line_model.values
        # the branch moves by about |slope| (x - s_below) since the grid point below; a value
        # within 1 % of that from one there did not move: a slow mode, not the branch
        moved = values
        if len(steady):
            shift = np.min(np.abs(values[:, None] - steady[None, :]), axis=1)
            moved = values[shift > 0.01 * abs(slope) * (x - s0_values[i - 1])]
        candidates = moved if len(moved) else values
        branch = candidates[np.argmin(np.abs(candidates - (known[1] + slope * (x - known[0]))))]
        if x != known[0]:
            slope, known = (branch - known[1]) / (x - known[0]), (x, branch)
        if gx > 0:
            hi, g_hi = x, gx
        else:
            lo, g_lo = x, gx
        if hi - lo <= xtol:
            return float(lo - g_lo * (hi - lo) / (g_hi - g_lo))
        following = x - branch.real / slope.real if slope.real != 0 else np.nan
        if not lo < following < hi:
            following = lo - g_lo * (hi - lo) / (g_hi - g_lo)  # regula falsi: inside
        if abs(following - x) < 0.25 * xtol:  # toward the crossing: x is an end of the bracket
            following = x + 0.25 * xtol if gx <= 0 else x - 0.25 * xtol
        x = float(np.clip(following, lo + 0.1 * xtol, hi - 0.1 * xtol))
    return float(brentq(lambda s: line_model.point(s)[0][0], lo, hi, xtol=xtol, rtol=1e-12))


def _line_limit(model, line_model, s0_values, growth, v, N0, b_M, xtol) -> float:
    """s0* on the reduced evaluation (:func:`_reduced_limit`); the dense one if the reduced
    evaluation does not change sign where the grid did."""
    try:
        return _reduced_limit(line_model, s0_values, growth, xtol)
    except ValueError:
        return _limit_on_grid(s0_values, growth, lambda s: _dense_point(
            model, OperatingPoint(s, v, N0, b_M)).max_real_part, xtol)


def _newton_without_rigid(M, C, K, R, lam: complex, x: np.ndarray, rtol: float,
                          iterations: int = 6):
    """Newton's method (nonlinear inverse iteration, as :func:`model.analysis.locus.newton`) for a
    non-rigid eigenpair of ``(λ² M + λ C + K) x = 0`` near 0: with ``K R = 0`` (R: the rigid-body
    modes, orthonormal or not) the rows Rᵀ of the equation are λ Rᵀ(λ M + C) x, so they are
    divided by λ: S(λ) = [Rᵀ(λ M + C); Zᵀ(λ² M + λ C + K)] (Z: the orthogonal complement of R)
    has the non-rigid eigenpairs of the problem and no rigid zeros, which spoil the iteration for
    the real eigenvalue crossing 0 at s0*.  Returns (λ, unit x, last step relative to
    max(|λ|, 1 1/s))."""
    n_rigid = R.shape[1]
    Q = np.linalg.qr(R, mode="complete")[0]
    Rt, Zt = Q[:, :n_rigid].T, Q[:, n_rigid:].T
    RM, RC, ZM, ZC, ZK = Rt @ M, Rt @ C, Zt @ M, Zt @ C, Zt @ K
    return nonlinear_inverse_iteration(
        lambda lam: np.vstack([lam * RM + RC, lam * lam * ZM + lam * ZC + ZK]),
        lambda lam: np.vstack([RM, 2 * lam * ZM + ZC]), lam, x, rtol, iterations, floor=1.0)


def _outside_max_real_part(spectra, radius: float) -> float:
    """Largest real part [1/s] of the eigenvalues outside the basis selection
    (:func:`basis_modes`, ``radius`` [1/s]) over the densely solved ``spectra``."""
    return max(float(lam.real[~basis_modes(lam, radius)].max(initial=-np.inf)) for lam in spectra)


def _missing_modes(eigenvalues: np.ndarray, ritz: np.ndarray, radius: float) -> bool:
    """Whether an eigenvalue that the selection takes (:func:`basis_modes`, ``radius`` [1/s]) has
    no Ritz value within ``MATCH``·max(|λ|, 1 1/s): the basis misses that mode."""
    wanted = eigenvalues[basis_modes(eigenvalues, radius)]
    if len(wanted) == 0:
        return False
    distance = np.abs(wanted[:, None] - ritz[None, :]).min(axis=1, initial=np.inf)
    return bool(np.any(distance > MATCH * np.maximum(np.abs(wanted), 1.0)))


class _LineModel:
    """The reduced model of one line and its error-controlled point evaluation."""

    def __init__(self, model: BogieModel, v: float, N0: float, b_M: float, anchors,
                 max_frequency_hz: float, rtol: float, creep_shifts=()):
        self.model, self.v, self.N0, self.b_M, self.rtol = model, v, N0, b_M, rtol
        self.radius = 2 * np.pi * max_frequency_hz
        n = model.n
        in_basis = partial(basis_modes, radius=self.radius)

        def modes(result):
            lam = result.eigenvalues
            q = result.vectors[:n, in_basis(lam)]
            return [q.real, q.imag]

        patterns = creep_patterns(model)
        vectors = [model.rigid_body_modes] + [part for r in anchors for part in modes(r)]
        if len(creep_shifts):
            # T_a(σ)⁻¹ G (module docstring): the far modes' share of every eigenvector on the line
            C_anchor = damping_matrix(model, anchors[0].operating_point)
            G = longitudinal_creep_pattern(model)
            for shift in creep_shifts:
                try:
                    Y = np.linalg.solve(shift * shift * model.M + shift * C_anchor + model.K, G)
                except np.linalg.LinAlgError:  # a shift on an anchor eigenvalue: its mode is in
                    continue  # the basis already
                vectors += [Y.real, Y.imag] if np.iscomplexobj(Y) else [Y]
            # columns of very different scales (displacement parts of unit state vectors fall as
            # 1/|λ|, the responses are ≈ 10⁻⁷ m per N): each scaled to unit length before the SVD
            stacked = np.hstack(vectors)
            norms = np.linalg.norm(stacked, axis=0)
            vectors = [stacked[:, norms > 0] / norms[norms > 0]]
        U, sigma, _ = np.linalg.svd(np.hstack(vectors), full_matrices=False)
        basis = U[:, sigma > BASIS_CUTOFF * sigma[0]]
        self.reduced = Reduced(model, anchors[0].operating_point, patterns, [basis])
        self.newton = 0
        red, r = self.reduced, self.reduced.size
        # The first-order reduced matrix [[0, I], [−K_r, −C]] is affine in the creep
        # coefficients c: C = C0_r + Σ c_k P_k,r.  The basis holds the rigid-body modes, whose
        # reduced coordinates y_R = Lᵀ Φᵀ R give the exact eigenpairs (0, [y_R; 0]) of the reduced
        # model (K_r y_R = 0) whatever C, and the free rolling velocity's [0; y_roll] maps onto
        # them: that invariant subspace (Reduced.deflation, as in the full model) is deflated
        # once per line, and each point solves the eigenvalues of the rest,
        # A22(c) = base + Σ c_k D_k (2r − n_rigid unknowns), only.
        r_i = len(red.inertial)  # the reduced state: r coordinates, r_i velocities
        deflation, n_rigid = red.deflation, red.zero_count

        def first_order(K, C):
            if K is None:  # a creep pattern (inertial coordinates only): its part of A
                A = np.zeros((r + r_i, r + r_i))
                A[r:, r:] = -C[np.ix_(red.inertial, red.inertial)]
            else:
                A = red.first_order(K, C)
            return deflation.project(A)[n_rigid:, n_rigid:]

        self._base = first_order(red.K_r, red.C0_r)
        self._parts = [first_order(None, P) for P in red.P_r]
        self._start = np.random.default_rng(0).standard_normal(r)  # inverse iteration start
        self._line_key: tuple | None = None  # (b22, b23, b33) of self._line_parts
        self._line_parts: tuple = ()
        self.values = np.zeros(0, dtype=complex)  # the last point's eigenvalues [1/s]
        self.top_values = np.zeros(0, dtype=complex)  # the top eigenvalue at each grid point
        self.grid_values: list[np.ndarray] = []  # all eigenvalues at each grid point [1/s]
        # [1/s] (set by reduced_s0_line; the s0* search follows the crossing branch from it)

    def _ritz_vectors(self, lam: np.ndarray, C: np.ndarray) -> np.ndarray:
        """Unit displacement vectors (Φ coordinates) of Ritz values ``lam`` of the reduced
        quadratic problem ``(λ² diag(I, 0) + λ C + K_r) y = 0`` (the massless reduced
        coordinates last) by one step of inverse iteration each."""
        red, r = self.reduced, self.reduced.size
        X = np.zeros((r, len(lam)), dtype=complex)
        real = lam.imag == 0  # real Ritz values: real arithmetic (a quarter of the work)
        for group, values in ((real, lam.real[real]), (~real, lam[~real])):
            if len(values) == 0:
                continue
            shift = values * (1 + 1e-13)  # never an exactly singular matrix
            T = np.multiply.outer(shift, C)
            T += red.K_r
            T.reshape(len(shift), -1)[:, ::r + 1] += np.multiply.outer(shift * shift,
                                                                       red.mass_diagonal)
            start = np.broadcast_to(self._start, (len(shift), r))[..., None]
            X[:, group] = np.linalg.solve(T, start)[..., 0].T
        X = red.Linv.T @ X
        return X / np.linalg.norm(X, axis=0)

    def _matrices(self, c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A22, reduced C, full C Φ) at creep coefficients c = (b11, b22, b23, b33).  Along a
        line only b11 changes: the terms of b22, b23 and b33 are summed once and kept (for the
        last (b22, b23, b33) seen), and each point adds the b11 term."""
        key = tuple(float(ck) for ck in c[1:])
        if key != self._line_key:
            red = self.reduced
            A22, C, C_Phi = self._base.copy(), red.C0_r.copy(), red.C0_Phi.copy()
            for ck, D, P, P_Phi in zip(key, self._parts[1:], red.P_r[1:], red.P_Phi[1:],
                                       strict=True):
                A22 += ck * D
                C += ck * P
                C_Phi += ck * P_Phi
            self._line_key, self._line_parts = key, (A22, C, C_Phi)
        A22, C, C_Phi = self._line_parts
        b11 = float(c[0])
        return (A22 + b11 * self._parts[0], C + b11 * self.reduced.P_r[0],
                C_Phi + b11 * self.reduced.P_Phi[0])

    def ritz_values(self, c: np.ndarray) -> np.ndarray:
        """All non-rigid Ritz values [1/s] at creep coefficients ``c`` (eigenvalues only; the
        rigid zeros are deflated)."""
        return self._eigvals(self._matrices(c)[0])

    @staticmethod
    def _eigvals(A22: np.ndarray) -> np.ndarray:
        return sla.eigvals(A22, overwrite_a=True, check_finite=False)

    def _result(self, values: np.ndarray, dense: bool) -> tuple[tuple[float, int, int], bool]:
        self.values = values  # the last point's eigenvalues (refined Ritz values or dense)
        return spectrum_summary(values), dense

    def point(self, s0: float, c: np.ndarray | None = None) -> tuple[tuple[float, int, int], bool]:
        """(summary, solved densely) at creepage s0; ``c``: its creep coefficients (b11, b22,
        b23, b33) if already known."""
        op = OperatingPoint(float(s0), self.v, self.N0, self.b_M)
        if c is None:
            c = pattern_coefficients(self.model, op)
        red = self.reduced
        A22, C, C_Phi = self._matrices(c)
        lam = self._eigvals(A22)
        lam = lam[lam.imag >= -IMAG_TOL * np.abs(lam)]  # one of each pair, and the reals
        # Only Ritz values with Re λ ≥ min(top, 0) − BAND can decide the summary; their vectors
        # and first-order errors (from the full residual) are computed.  Beyond the controlled
        # disc a Ritz value whose estimate exceeds SPURIOUS·|λ| approximates no eigenvalue (its
        # vector is not in the basis): dropped; the eigenvalues there are the ones checked at the
        # anchors (outside_max_real_part).
        checked = np.zeros(len(lam), dtype=bool)
        error = np.full(len(lam), np.inf)
        vectors = np.zeros((red.size, len(lam)), dtype=complex)  # of the checked Ritz values
        while True:
            candidates = np.flatnonzero(~checked & (lam.real >= min(lam.real.max(), 0.0) - BAND))
            if len(candidates) == 0:
                break
            try:
                X = self._ritz_vectors(lam[candidates], C)
            except np.linalg.LinAlgError:  # a Ritz value exact to the last bit: no inverse step
                return self._result(_dense_point(self.model, op).eigenvalues, True)
            relative = red.error_estimate(c, lam[candidates], X, C_Phi)
            checked[candidates] = True
            error[candidates] = relative * np.abs(lam[candidates])
            vectors[:, candidates] = X
            spurious = candidates[(np.abs(lam[candidates]) >= 1.5 * self.radius)
                                  & (relative >= SPURIOUS)]
            if len(spurious) == 0:
                break
            keep = np.setdiff1d(np.arange(len(lam)), spurious)
            lam, checked, error, vectors = lam[keep], checked[keep], error[keep], vectors[:, keep]
        top = int(np.argmax(lam.real))
        # refined: the largest real part unless within rtol·max(|λ|, 1 1/s), and any Ritz value
        # whose estimate could change the sign of its real part or lift it to the top
        needs = ((lam.real + error > 0) & (lam.real - error <= 0)) | (
            lam.real + error >= lam.real[top] - error[top])
        needs[top] = error[top] > self.rtol * max(abs(lam[top]), 1.0)
        needs &= checked & (error > self.rtol * np.maximum(np.abs(lam), 1.0))
        failing = np.flatnonzero(needs)
        if len(failing) > MAX_NEWTON:
            return self._result(_dense_point(self.model, op).eigenvalues, True)
        if len(failing):
            C_full = damping_matrix(self.model, op)
            lam = lam.copy()
            for b in failing:
                # converged to rtol·max(|λ|, 1 1/s), the accuracy asked of every decisive
                # value (relative to |λ| alone, a real eigenvalue crossing 0 near s0* never
                # converges and sent the point to a full eigen-analysis)
                if abs(lam[b]) < 1.0:  # near the rigid zeros: their rows divided by λ
                    value, _, step = _newton_without_rigid(
                        self.model.M, C_full, self.model.K, self.model.rigid_body_modes, lam[b],
                        red.Phi @ vectors[:, b], self.rtol)
                else:
                    value, _, step = newton(self.model.M, C_full, self.model.K, lam[b],
                                            red.Phi @ vectors[:, b], self.rtol, floor=1.0)
                if not step <= self.rtol:
                    return self._result(_dense_point(self.model, op).eigenvalues, True)
                lam[b] = value
            self.newton += len(failing)
        return self._result(np.concatenate([lam, lam[lam.imag > 0].conj()]), False)


def s0_line(model: BogieModel, s0_values, v: float, N0: float, b_M: float,
            max_frequency_hz: float = 10.0, rtol: float = 1e-6,
            s0_limit_xtol: float = 1e-6, method: str = "reduced") -> LineResult:
    """Largest real part, flutter pairs and divergent reals at every creepage of ``s0_values``
    (increasing) at speed ``v`` [m/s], wheel force ``N0`` [N], motor slope ``b_M``
    [N m s/rad]; and s0* inside the line's range by Brent's method on the same evaluation.

    ``method``: "continuation" (:mod:`model.analysis.continuation`: every non-rigid eigenvalue at every
    point, exact to the convergence tolerance, checked at every point; a point that fails the
    checks is solved by a full eigen-analysis and counted in ``fallbacks``), "reduced" (the
    default: :func:`reduced_s0_line`, ``max_frequency_hz`` and ``rtol`` apply) or "dense"
    (:func:`dense_line`).  The default is "reduced" because it is cheaper: a map point costs
    about 0.2 of an eigenvalues-only analysis with "reduced" and about 1 with "continuation"
    (BENCHMARKS.md, "Parameter studies")."""
    if method == "reduced":
        return reduced_s0_line(model, s0_values, v, N0, b_M, max_frequency_hz, rtol,
                               s0_limit_xtol)
    if method == "dense":
        return dense_line(model, s0_values, v, N0, b_M, s0_limit_xtol)
    if method != "continuation":
        raise ValueError(f"method must be 'continuation', 'reduced' or 'dense', got '{method}'")
    s0_values = check_s0(s0_values)
    n = len(s0_values)
    line = LineContinuation(model, v, N0, b_M)
    rows, dense, states = [], np.zeros(n, dtype=bool), []
    for i, s in enumerate(s0_values):
        spectrum, dense[i] = line.evaluate(float(s))
        rows.append(spectrum_summary(spectrum))
        states.append(line.state())
    growth = np.array([r[0] for r in rows])

    def growth_at(s: float, start: int) -> float:
        line.restore(states[start])  # continue from the grid point below s
        return spectrum_summary(line.evaluate(s, reanchor=False)[0])[0]

    unstable = np.flatnonzero(growth > 0)
    limit = float("nan")
    if len(unstable) and unstable[0] > 0:
        i = unstable[0]
        limit = float(brentq(growth_at, s0_values[i - 1], s0_values[i], args=(i - 1,),
                             xtol=s0_limit_xtol, rtol=1e-12))
    return LineResult(s0_values, v, N0, b_M, growth, np.array([r[1] for r in rows]),
                      np.array([r[2] for r in rows]), limit, dense, 0, float("nan"), 0,
                      line.fallbacks, "continuation")


def reduced_s0_line(model: BogieModel, s0_values, v: float, N0: float, b_M: float,
                    max_frequency_hz: float = 10.0, rtol: float = 1e-6,
                    s0_limit_xtol: float = 1e-6) -> LineResult:
    """The Galerkin-reduced line (``s0_line``'s default method): largest
    real part, flutter pairs and divergent reals at every creepage of ``s0_values``
    (increasing) at speed ``v`` [m/s], wheel force ``N0`` [N], motor slope ``b_M``
    [N m s/rad]; and s0* inside the line's range on the same evaluation (secant steps in a
    closing bracket, :func:`_reduced_limit`; Brent's method if they do not close it).

    ``max_frequency_hz``: the reduction basis holds the exact eigenvectors with |λ| < 2π·f (and
    those with Re λ > −5 1/s) at the anchor and the creep responses there (see the module
    docstring for the basis, its checks and what is assumed of the eigenvalues outside it).
    """
    s0_values = check_s0(s0_values)
    n = len(s0_values)
    points = [OperatingPoint(float(s), v, N0, b_M) for s in s0_values]
    coefficients = line_creep_coefficients(model.parameters, s0_values, v, N0)
    middle = int(np.argmin(coefficients[:, 0]))
    radius = 2 * np.pi * max_frequency_hz
    if n < 3:
        line = dense_line(model, s0_values, v, N0, b_M, s0_limit_xtol)
        spectra = [_dense_point(model, points[i]).eigenvalues for i in sorted({0, n - 1})]
        return LineResult(**{**line.__dict__, "method": "reduced",
                             "outside_max_real_part": _outside_max_real_part(spectra, radius)})
    # The basis: the exact eigenvectors at the last creepage and the creep-response vectors there
    # (module docstring).  The first creepage and the grid creepage of the most negative b11 are
    # solved densely (eigenvalues only) and check it: every eigenvalue there that the selection
    # would take (basis_modes) must have a Ritz value next to it.  If one has none, the basis is
    # the exact eigenvectors at both ends, and at that grid creepage if its check still fails.
    anchors = {n - 1: _dense_point(model, points[n - 1], vectors=True)}
    checked = sorted({0, middle} - {n - 1})  # grid points that check the basis
    solved = {n - 1: anchors[n - 1].eigenvalues}  # grid points solved densely
    for i in checked:
        solved[i] = _dense_point(model, points[i]).eigenvalues
    shifts = [CREEP_RESPONSE_SHIFT] + [_top(solved[i]) for i in checked]
    lam = anchors[n - 1].eigenvalues
    lam = lam[basis_modes(lam, radius) & (lam.imag > 0)]
    twins, _ = np.nonzero(np.triu(np.abs(lam[:, None] - lam[None, :])
                                  <= TWIN_GAP * np.abs(lam)[:, None], k=1))
    shifts += [1j * lam[k].imag for k in np.unique(twins)]
    line_model = _LineModel(model, v, N0, b_M, [anchors[n - 1]], max_frequency_hz, rtol,
                            creep_shifts=shifts)
    if any(_missing_modes(solved[i], line_model.ritz_values(coefficients[i]), radius)
           for i in checked):
        anchors[0] = _dense_point(model, points[0], vectors=True)
        line_model = _LineModel(model, v, N0, b_M, [anchors[0], anchors[n - 1]],
                                max_frequency_hz, rtol)
        if middle not in anchors and _missing_modes(
                solved[middle], line_model.ritz_values(coefficients[middle]), radius):
            anchors[middle] = _dense_point(model, points[middle], vectors=True)
            line_model = _LineModel(model, v, N0, b_M, [anchors[i] for i in sorted(anchors)],
                                    max_frequency_hz, rtol)
    rows = []
    dense = np.zeros(n, dtype=bool)
    line_model.top_values = np.zeros(n, dtype=complex)  # the top eigenvalue at each point
    line_model.grid_values = []
    for i in range(n):
        if i in solved:
            values = solved[i]
            rows.append(spectrum_summary(values))
            dense[i] = True
        else:
            summary, dense[i] = line_model.point(s0_values[i], coefficients[i])
            rows.append(summary)
            values = line_model.values
        line_model.top_values[i] = values[np.argmax(values.real)]
        line_model.grid_values.append(values)
    growth = np.array([r[0] for r in rows])
    limit = _line_limit(model, line_model, s0_values, growth, v, N0, b_M, s0_limit_xtol)
    return LineResult(s0_values, v, N0, b_M, growth, np.array([r[1] for r in rows]),
                      np.array([r[2] for r in rows]), limit, dense, line_model.newton,
                      _outside_max_real_part(solved.values(), radius),
                      line_model.reduced.size, 0, "reduced")
