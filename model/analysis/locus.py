"""Root locus over creepage s0 or speed v, with branches tracked by eigenvector similarity (MAC).

Method — a reduced model whose error is estimated at every point and bounded by dense checks:

1. Along a sweep only ``B_ad`` changes, a combination of four fixed patterns,
   ``B_ad = b11 P11 + b22 P22 + b23 P23 + b33 P33`` (:func:`creep_patterns`).
2. The displacement space is reduced to ``Φ`` = orthonormal basis of the rigid-body modes and the
   real and imaginary parts of the exact eigenvectors (displacement part) of all eigenvalues with
   |λ| < 2π f_max at the first, the middle and the last point of the sweep.  The second-order structure is
   kept: ``Φᵀ M Φ``, ``Φᵀ K Φ``, ``Φᵀ (B + b_M B_M) Φ`` and ``Φᵀ P_k Φ`` are formed once, so a point
   costs one small eigenproblem (Galerkin projection of eq. 20).
3. At every point each tracked Ritz pair's residual in the *full* model,
   ``r = (λ² M + λ B_total + K) Φ x``, gives a first-order error estimate
   ``|δλ| ≈ ‖r‖ / ‖(2λ M + B_total) Φ x‖`` (conservative here: the measured errors are 10–30 times
   smaller).  The tolerance is enforced for branches inside the disc |λ| < 1.5·2π f_max (a heavily
   damped branch that leaves it is still tracked and its estimate recorded).  Where the estimate
   exceeds ``rtol·|λ|`` for some branches, those are refined by Newton's method on the full
   model (quadratic convergence; the last step size is the recorded error; one solve per complex
   pair, a few LU factorizations, about a tenth of a dense solve); where that needs more solves
   than half the number of tracked branches, or the MAC tracking is ambiguous, the point is
   solved densely (exact there).
   ``lambda_floor`` [1/s] measures the errors relative to max(|λ|, lambda_floor) instead: a
   branch passing through λ = 0 (a drivetrain spin near the creep maximum) has no relative
   accuracy to reach, and without a floor every point near its zero is solved densely.
   The reduced eigenproblems of the inner points are independent of each other and are solved
   first, on ``workers`` threads; tracking and error control then run through them in order.
   The start of a sweep (the exact end points, the basis and the projected matrices) and the
   reduced solutions of a short sweep are kept (:class:`_SweepStart`, a few per process): a
   denser sweep over the same range — the dashboard's dense locus after its coarse one — reuses
   them and solves only its new points (same basis, so bitwise the same values where both have
   a point).
4. Branches are continued from point to point by an optimal assignment on ``1 − MAC`` plus the
   normalized eigenvalue distance, so branches do not swap at near-crossings.  An assignment is
   ambiguous where a branch continues into a value neither of similar shape (MAC > 0.5) nor
   close (5 % of |λ|), or where the two branches of a conjugate pair continue into values that
   are not a conjugate pair (nor both real).  An ambiguous reduced point is reached through
   reduced points in between (2, 4, then 8 steps; :func:`_reduced_steps`), else solved
   densely; an ambiguous dense point halves the step: the branches are carried through densely solved
   intermediate points (not recorded) until every assignment is unambiguous, at most
   :data:`BRIDGE_HALVINGS` times (:func:`_bridge`).  Without it, where branches move far
   within one step (near s0 = 0.0025 at 120 km/h two well damped ≈ 18 Hz pairs move by a
   quarter of their size per step of 0.0005 while two reals run out of the disc and merge), a
   coarse sweep took a branch into another mode's pair and split a conjugate pair.
5. ``select`` (optional) narrows step 2 and the tracking to some of the modes inside the disc
   (say, those a motor's torque excites: :mod:`model.analysis.campbell`): the basis holds only
   their vectors, so a sweep of a few modes spread over a wide band costs what a sweep of a
   narrow band does.  The error control is the same (the other modes are simply not tracked).

The naive reference (:func:`dense_generalized_eigenvalues`) solves the generalized eigenproblem
(21)–(22) densely at a point; ``scripts/bench_locus.py`` compares both.
"""

from __future__ import annotations

import math
import os
import threading
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg as sla
from scipy.optimize import linear_sum_assignment

from model.analysis.eigen import eigen_analysis
from model.analysis.linear_system import massless_coordinates
from model.analysis.reduced_model import Reduced, creep_patterns, pattern_coefficients
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import OperatingPoint, damping_matrix


@dataclass(frozen=True)
class RootLocus:
    """Tracked eigenvalues along a parameter sweep."""

    parameter: str  # "s0" [-] or "v" [m/s]
    values: np.ndarray  # (n_points,) parameter values, SI
    eigenvalues: np.ndarray  # (n_points, n_branches) complex [1/s]; column = one tracked branch
    # (n_points, n_branches) estimated error relative to max(|λ|, lambda_floor) (0: exact)
    error_estimate: np.ndarray
    dense_points: np.ndarray  # (n_points,) bool: solved densely (exact) at that point
    operating_point: OperatingPoint  # the fixed quantities of the sweep
    basis_size: int  # columns of the reduction basis Φ
    newton_refinements: int  # branch-points refined by Newton's method on the full model
    lambda_floor: float = 0.0  # [1/s] errors relative to max(|λ|, this) (0: relative to |λ|)

    @property
    def max_real_part(self) -> np.ndarray:
        """Largest real part of the tracked branches at each point [1/s]."""
        return self.eigenvalues.real.max(axis=1)

    @property
    def stable(self) -> np.ndarray:
        """Tracked branches all in the closed left half-plane, per point."""
        return self.max_real_part <= 0.0

    @property
    def upper_branches(self) -> np.ndarray:
        """Indices of branches with Im ≥ 0 at the first point (one of each conjugate pair)."""
        return np.flatnonzero(self.eigenvalues[0].imag >= 0)


@dataclass
class _SweepStart:
    """What a sweep over a range starts from: the exact end points (eigenvalues, unit
    displacement vectors), the reduced model built on them, and reduced solutions by their
    creep coefficients (those of the last short sweep over the range)."""

    model: BogieModel
    first: tuple[np.ndarray, np.ndarray]
    last: tuple[np.ndarray, np.ndarray]
    reduced: Reduced
    solutions: dict[bytes, tuple[np.ndarray, np.ndarray]]
    tracked: np.ndarray  # indices of the first point's eigenvalues that are tracked


_SWEEP_STARTS: OrderedDict[tuple, _SweepStart] = OrderedDict()
_SWEEP_STARTS_KEPT = 8  # sweep starts kept per process (≈ 5 MB each with 32 kept solutions)
_SOLUTIONS_KEPT = 32  # a sweep with at most this many inner points keeps its solutions
_SWEEP_STARTS_LOCK = threading.Lock()


def _sweep_start_key(model: BogieModel, first: OperatingPoint, last: OperatingPoint,
                     radius: float, select) -> tuple:
    return (id(model), first, last, radius, select)


def clear_sweep_starts() -> None:
    """Forget the kept sweep starts (tests; the cache is bounded anyway)."""
    with _SWEEP_STARTS_LOCK:
        _SWEEP_STARTS.clear()


_POOLS: dict[tuple[int, int], ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()


def thread_niceness() -> int:
    """The scheduling niceness of the calling thread (Linux schedules threads one by one; 0
    where that is not available)."""
    try:
        return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())
    except (AttributeError, OSError):
        return 0


def set_thread_niceness(niceness: int) -> None:
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), niceness)
    except (AttributeError, OSError):
        pass  # another OS, or not allowed: the threads keep the process's priority


def _solver_pool(workers: int) -> ThreadPoolExecutor:
    """A persistent pool of ``workers`` threads per process and per caller's niceness, shared by
    all root loci (the dashboard computes many; no threads are created and torn down per call).
    The threads run at the niceness of the thread that asks (a root locus the dashboard computes
    in the background must not take the cores from the answer to the next change)."""
    niceness = thread_niceness()
    with _POOLS_LOCK:
        if (workers, niceness) not in _POOLS:
            _POOLS[workers, niceness] = ThreadPoolExecutor(
                max_workers=workers, thread_name_prefix=f"bogie-locus-n{niceness}",
                initializer=set_thread_niceness, initargs=(niceness,))
        return _POOLS[workers, niceness]


def root_locus(model: BogieModel, op: OperatingPoint, parameter: str, values,
               max_frequency_hz: float = 20.0, rtol: float = 1e-6, workers: int = 2,
               lambda_floor: float = 0.0, select=None) -> RootLocus:
    """Track the non-rigid eigenvalues with |λ| < 2π·max_frequency_hz (at the first value) while
    ``parameter`` ("s0" [-] or "v" [m/s]) runs through ``values``; the other quantities of the
    operating point ``op`` stay fixed.  ``workers`` threads solve the reduced eigenproblems
    (default 2, the cores of the target machine).  A real eigenvalue inside the disc that meets a
    real one outside it continues as one half of the new complex pair (the other half is not
    tracked); pairs that start complex stay conjugate pairs.  ``rtol``: the tolerance of every
    tracked eigenvalue inside the controlled disc, relative to max(|λ|, ``lambda_floor`` [1/s])
    (default 0: relative to |λ|; the module docstring says when a floor is wanted).
    ``select``: None (every mode inside the disc) or a hashable callable ``select(model, point,
    eigenvalues) -> bool mask`` over the eigenvalues of :func:`eigen_analysis` at ``point``: the
    modes (inside the disc) whose vectors form the basis at each of the three exact points and,
    at the first, the branches tracked (module docstring, step 5).

    Example::

        >>> import numpy as np
        >>> from model import build_model, default_operating_point, load_parameters, root_locus
        >>> parameters = load_parameters()
        >>> model = build_model(parameters)
        >>> locus = root_locus(model, default_operating_point(parameters), "s0",
        ...                    np.linspace(0.002, 0.016, 8))
        >>> locus.eigenvalues.shape[0]                  # one row per swept value
        8
    """
    if not (math.isfinite(lambda_floor) and lambda_floor >= 0):
        raise ValueError(f"lambda_floor must be a finite value >= 0 [1/s], got {lambda_floor!r}")
    values, points, coefficients = _sweep_points(model, op, parameter, values)
    radius = 2 * np.pi * max_frequency_hz
    key = _sweep_start_key(model, points[0], points[-1], radius, select)
    start = _sweep_start(model, op, parameter, points, radius, workers, key, select)
    inner = _InnerSolutions(start, coefficients[1:-1], workers)
    tracks = _track(model, parameter, points, coefficients, start, inner, radius, rtol,
                    max(lambda_floor, 1e-300))
    _keep_sweep_start(key, model, start, inner)
    return RootLocus(parameter, values, tracks.eigenvalues, tracks.errors, tracks.dense, op,
                     start.reduced.size, tracks.refined, float(lambda_floor))


@dataclass(frozen=True)
class RitzEstimate:
    """The eigenvalues at one operating point from the reduced model of a kept sweep
    (:func:`kept_sweep_estimate`): no dense solve, each with its first-order error estimate."""

    operating_point: OperatingPoint
    eigenvalues: np.ndarray  # non-rigid Ritz values inside the sweep's controlled disc [1/s]
    error_estimate: np.ndarray  # estimated error of each, relative to max(|λ|, lambda_floor)
    lambda_floor: float  # [1/s]
    basis_size: int  # columns of the sweep's basis Φ

    @property
    def absolute_error(self) -> np.ndarray:
        """The estimated absolute error of each eigenvalue [1/s] (first order: the sweep's
        measured errors are 10–30 times smaller; not a rigorous bound)."""
        return self.error_estimate * np.maximum(np.abs(self.eigenvalues), self.lambda_floor)

    @property
    def leading(self) -> int:
        """Index of the eigenvalue with the largest real part."""
        return int(np.argmax(self.eigenvalues.real))

    @property
    def stable(self) -> bool | None:
        """The verdict where the error estimates decide it: False if a real part exceeds its
        estimated error, True if every real part stays ≤ 0 with its error added, None otherwise
        (the estimate cannot tell; only the eigenvalues inside the disc are judged, as
        :attr:`RootLocus.stable` does)."""
        re, bound = self.eigenvalues.real, self.absolute_error
        if np.any(re - bound > 0):
            return False
        if np.all(re + bound <= 0):
            return True
        return None


def kept_sweep_estimate(model: BogieModel, op: OperatingPoint, first: OperatingPoint,
                        last: OperatingPoint, max_frequency_hz: float = 20.0,
                        lambda_floor: float = 0.0, select=None) -> RitzEstimate | None:
    """The eigenvalues at ``op`` (any s0, v, N0, b_M) from the reduced model of the kept start of
    a :func:`root_locus` sweep from ``first`` to ``last`` with the same ``max_frequency_hz`` and
    ``select``, or None if no such sweep start is kept: one small eigenproblem and the residuals of its Ritz
    pairs in the full model, never a dense solve (a preview while a slider is dragged).  The
    basis holds the modes at the sweep's ends and middle; away from the sweep the error
    estimates grow and :attr:`RitzEstimate.stable` says when they no longer decide the verdict.
    ``lambda_floor`` [1/s]: errors relative to max(|λ|, floor)."""
    radius = 2 * np.pi * max_frequency_hz
    with _SWEEP_STARTS_LOCK:
        start = _SWEEP_STARTS.get(_sweep_start_key(model, first, last, radius, select))
    if start is None or start.model is not model:
        return None
    reduced = start.reduced
    c = pattern_coefficients(model, op)
    lam, X = reduced.solve(c, op.b_M)  # non-rigid only (the zeros are deflated)
    keep = np.flatnonzero(np.abs(lam) < 1.5 * radius)  # where the sweep controls the error
    floor = max(float(lambda_floor), 1e-300)
    estimate = reduced.error_estimate(c, lam[keep], X[:, keep],
                                      C_Phi=reduced.damping_Phi(c, op.b_M), floor=floor)
    return RitzEstimate(op, lam[keep], estimate, floor, reduced.size)


def _sweep_points(model: BogieModel, op: OperatingPoint, parameter: str,
                  values) -> tuple[np.ndarray, list[OperatingPoint], np.ndarray]:
    """The sweep checked (ValueError otherwise): (values [SI], the operating points, their creep
    pattern coefficients b11, b22, b23, b33, points x 4)."""
    if parameter not in ("s0", "v"):
        raise ValueError(f"parameter must be 's0' or 'v', got '{parameter}'")
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or len(values) < 2 or not np.all(np.isfinite(values)):
        raise ValueError("need at least two finite parameter values")
    points = [replace(op, **{parameter: float(x)}) for x in values]  # validates each point
    coefficients = np.array([pattern_coefficients(model, p) for p in points])
    return values, points, coefficients


def _exact(model: BogieModel, point: OperatingPoint) -> tuple[np.ndarray, np.ndarray]:
    """All eigenvalues [1/s] at ``point`` (dense) and their displacement vectors, unit norm."""
    result = eigen_analysis(model, point)
    q = result.vectors[:model.n]
    return result.eigenvalues, q / np.linalg.norm(q, axis=0)


def _chosen(model: BogieModel, point: OperatingPoint, lam: np.ndarray, radius: float,
            select) -> np.ndarray:
    """Mask of the eigenvalues with |λ| < ``radius`` [1/s] that ``select`` keeps (all without)."""
    inside = np.abs(lam) < radius
    if select is None:
        return inside
    return inside & np.asarray(select(model, point, lam), dtype=bool)


def _modes(Q: np.ndarray, chosen: np.ndarray) -> list[np.ndarray]:
    """Real and imaginary parts of the vectors Q of the ``chosen`` eigenvalues."""
    return [Q[:, chosen].real, Q[:, chosen].imag]


def _sweep_start(model: BogieModel, op: OperatingPoint, parameter: str,
                 points: list[OperatingPoint], radius: float, workers: int,
                 key: tuple, select=None) -> _SweepStart:
    """The kept start of a sweep over this range, or a new one: the exact end points and the
    reduced model on their modes and those of the range's middle (``parameter`` halfway) with
    |λ| < ``radius`` [1/s] that ``select`` keeps (and the rigid-body modes)."""
    with _SWEEP_STARTS_LOCK:
        start = _SWEEP_STARTS.get(key)
        if start is not None and start.model is model:
            _SWEEP_STARTS.move_to_end(key)
        else:
            start = None
    if start is not None:
        return start
    # the exact end points and the middle of the range at once (they decide the basis; numpy
    # releases the GIL).  The middle's modes keep the basis good where the branches have moved
    # furthest from both ends: without them the 200-point sweep of scripts/bench_locus.py over
    # s0 = 0.002…0.016 solved 45 points densely (2.7 s), with them 5 (0.8 s)
    # (the middle of the range, not of the grid: a denser sweep over the same range has the
    # same basis)
    halfway = 0.5 * (getattr(points[0], parameter) + getattr(points[-1], parameter))
    others = [points[-1], replace(points[0], **{parameter: halfway})]
    if workers > 1:
        futures = [_solver_pool(workers).submit(_exact, model, point) for point in others]
        first = _exact(model, points[0])
        last, middle = (future.result() for future in futures)
    else:
        first, (last, middle) = _exact(model, points[0]), [_exact(model, p) for p in others]
    vectors = [model.rigid_body_modes]
    anchors = (points[0], others[0], others[1])
    masks = [_chosen(model, point, solution[0], radius, select)
             for point, solution in zip(anchors, (first, last, middle), strict=True)]
    for (_, Q), chosen in zip((first, last, middle), masks, strict=True):
        vectors += _modes(Q, chosen)
    reduced = Reduced(model, op, creep_patterns(model), vectors)
    return _SweepStart(model, first, last, reduced, {}, np.flatnonzero(masks[0]))


class _InnerSolutions:
    """The reduced solutions of a sweep's inner points, asked for in order.

    They do not depend on each other: they are solved on ``workers`` threads (numpy's LAPACK calls
    release the GIL) while the caller tracks and checks the points in order as their solutions
    come in (tracking after all the solves left a core idle for ≈ 0.8 s of a 200-point sweep); a
    point the kept start has solved already is not solved again."""

    def __init__(self, start: _SweepStart, inner: np.ndarray, workers: int):
        self.start = start
        self.keys = [c.tobytes() for c in inner]  # the inner points' creep coefficients
        missing = [i for i, k in enumerate(self.keys) if k not in start.solutions]
        reduced = start.reduced
        if workers > 1:
            self._found = _solver_pool(workers).map(reduced.solve, inner[missing])  # in order
        else:
            self._found = (reduced.solve(c) for c in inner[missing])
        self._unsolved = set(missing)
        self.solutions: list[tuple[np.ndarray, np.ndarray]] = []  # those handed out, in order

    def __call__(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """The reduced solution (Ritz values [1/s], Φ-coordinate vectors) of inner point i."""
        self.solutions.append(next(self._found) if i in self._unsolved
                              else self.start.solutions[self.keys[i]])
        return self.solutions[i]


@dataclass
class _Tracks:
    """The tracked branches along the sweep (the arrays of :class:`RootLocus`)."""

    eigenvalues: np.ndarray  # (n_points, n_branches) complex [1/s]
    errors: np.ndarray  # (n_points, n_branches) estimated relative error (0: exact)
    dense: np.ndarray  # (n_points,) bool: solved densely
    refined: int  # branch-points refined by Newton's method on the full model


def _track(model: BogieModel, parameter: str, points: list[OperatingPoint],
           coefficients: np.ndarray, start: _SweepStart, solution: _InnerSolutions,
           radius: float, rtol: float, floor: float) -> _Tracks:
    """Continue the tracked branches (those with |λ| < ``radius`` [1/s] at the first point that
    the sweep's selection keeps) from point to point: the reduced solution where it is accurate to
    ``rtol`` (after Newton on a few branches) and unambiguously assigned, the dense one otherwise
    and at the last point (assigned through intermediate dense points where the step is too
    long to assign: :func:`_bridge`; ``parameter``: the swept quantity, "s0" or "v")."""
    first, last, reduced = start.first, start.last, start.reduced
    controlled = 1.5 * radius  # accuracy is enforced for branches inside this disc
    n_points = len(points)
    tracked = start.tracked
    eigenvalues = np.zeros((n_points, len(tracked)), dtype=complex)
    errors = np.zeros((n_points, len(tracked)))
    dense = np.zeros(n_points, dtype=bool)
    eigenvalues[0], dense[0] = first[0][tracked], True
    previous_values, previous_vectors = first[0][tracked], first[1][:, tracked]
    refined = 0
    for i in range(1, n_points):
        if i != n_points - 1:
            solved = solution(i - 1)
            point = _reduced_point(model, points[i], coefficients[i], reduced, solved,
                                   previous_values, previous_vectors, rtol, controlled, floor)
            if point is AMBIGUOUS:  # carried through reduced points in between, else dense
                point = _reduced_steps(model, parameter, points[i - 1], points[i], solved,
                                       reduced, previous_values, previous_vectors, rtol,
                                       controlled, floor)
            if point is not None:
                values_i, vectors_i, estimate, newton_branches = point
                refined += newton_branches
                eigenvalues[i], errors[i] = values_i, estimate
                previous_values, previous_vectors = values_i, vectors_i
                continue
        lam, Q = last if i == n_points - 1 else _exact(model, points[i])  # dense: exact here
        chosen = _bridge(model, parameter, points[i - 1], points[i], previous_values,
                         previous_vectors, lam, Q)
        eigenvalues[i], dense[i] = lam[chosen], True
        previous_values, previous_vectors = lam[chosen], Q[:, chosen]
    return _Tracks(eigenvalues, errors, dense, refined)


AMBIGUOUS = "ambiguous"  # _reduced_point's answer where the assignment is ambiguous
REDUCED_BRIDGE_HALVINGS = 3  # an ambiguous reduced step is split into 2, 4, 8 reduced steps


def _reduced_steps(model: BogieModel, parameter: str, start: OperatingPoint,
                   end: OperatingPoint, solved: tuple[np.ndarray, np.ndarray], reduced: Reduced,
                   previous_values: np.ndarray, previous_vectors: np.ndarray, rtol: float,
                   controlled: float, floor: float):
    """The branches at ``end`` (its reduced solution ``solved``) carried from ``start`` through
    evenly spaced reduced points in between (2, 4, then 8 steps of ``parameter``), as
    :func:`_reduced_point` gives them at ``end``; None if no split is unambiguous and accurate
    (the point is then solved densely).
    A step that is ambiguous only because branches move far within it (near s0 = 0.002 the
    coarse sweep's 25 points step by 0.0008) costs a few small eigenproblems instead of dense
    solves and their bridge."""
    a, b = getattr(start, parameter), getattr(end, parameter)
    for halvings in range(1, REDUCED_BRIDGE_HALVINGS + 1):
        values, vectors, refined = previous_values, previous_vectors, 0
        for x in np.linspace(a, b, 2**halvings + 1)[1:]:
            point = end if x == b else replace(end, **{parameter: float(x)})
            c = pattern_coefficients(model, point)
            step = _reduced_point(model, point, c, reduced,
                                  solved if point is end else reduced.solve(c), values, vectors,
                                  rtol, controlled, floor)
            if step is None:
                return None  # inaccurate: more steps do not help
            if step is AMBIGUOUS:
                break
            values, vectors, estimate, newton_branches = step
            refined += newton_branches
        else:
            return values, vectors, estimate, refined
    return None


def _reduced_point(model: BogieModel, point: OperatingPoint, c: np.ndarray, reduced: Reduced,
                   solved: tuple[np.ndarray, np.ndarray], previous_values: np.ndarray,
                   previous_vectors: np.ndarray, rtol: float, controlled: float, floor: float):
    """The branches at an inner point from its reduced solution ``solved`` (creep coefficients c),
    assigned to the previous point's: (eigenvalues [1/s], full displacement vectors, estimated
    errors relative to max(|λ|, ``floor`` [1/s]), branches refined by Newton); :data:`AMBIGUOUS`
    where the assignment is ambiguous; None where too many or unrefinable branches inside
    |λ| < controlled are inaccurate (the point must be solved densely)."""
    lam, X = solved  # non-rigid only: the reduced model deflates its zeros as the dense one
    # Φ has orthonormal columns, so a vector p in its span (a reduced point's) has the same MAC
    # with Φ x as Φᵀ p with x; a dense point's vector is compared by its projection onto the
    # basis (the part the reduced model can follow).  The assignment runs in the reduced
    # coordinates and only the chosen vectors are expanded
    chosen, ok = _assign(reduced.Phi.T @ previous_vectors, previous_values, X, lam)
    if not ok:
        return AMBIGUOUS
    estimate = reduced.error_estimate(c, lam[chosen], X[:, chosen], floor=floor)
    values_i, vectors_i = lam[chosen], reduced.Phi @ X[:, chosen]
    failing = np.flatnonzero((estimate > rtol) & (np.abs(values_i) < controlled))
    # one full-model Newton solve per inaccurate pair (its branches are conjugates): up to half
    # of the tracked branches' count before the point is solved densely instead (module
    # docstring, step 3)
    solves = len({complex(v.real, abs(v.imag)) for v in values_i[failing]})
    if solves > max(2, len(chosen) // 2):
        return None
    # refine the few inaccurate branches by Newton's method in the full model; the reduced
    # matrices are real, so a complex pair's two branches are exact conjugates: the second is
    # the conjugate of the first's refinement (one full-model solve per pair, not two)
    C = damping_matrix(model, point) if len(failing) else None
    partner_of: dict[int, int] = {}  # conjugate branch -> the refined one it copies
    for b in failing:
        if b in partner_of:
            a = partner_of[b]
            values_i[b], vectors_i[:, b] = values_i[a].conjugate(), vectors_i[:, a].conj()
            estimate[b] = estimate[a]
            continue
        conjugates = [other for other in failing if other != b and values_i[b].imag != 0
                      and values_i[other] == values_i[b].conjugate()]
        if conjugates:
            partner_of[conjugates[0]] = b
        values_i[b], vectors_i[:, b], estimate[b] = newton(
            model.M, C, model.K, values_i[b], vectors_i[:, b], rtol, floor=floor)
    if not np.all((estimate <= rtol) | (np.abs(values_i) >= controlled)):
        return None
    return values_i, vectors_i, estimate, len(failing) - len(partner_of)


def _keep_sweep_start(key: tuple, model: BogieModel, start: _SweepStart,
                      inner: _InnerSolutions) -> None:
    """Keep the sweep's start for the next sweep over the range (with its reduced solutions if
    it has at most ``_SOLUTIONS_KEPT`` inner points); at most ``_SWEEP_STARTS_KEPT`` are kept."""
    with _SWEEP_STARTS_LOCK:
        if len(inner.keys) <= _SOLUTIONS_KEPT:
            start = _SweepStart(model, start.first, start.last, start.reduced,
                                dict(zip(inner.keys, inner.solutions, strict=True)), start.tracked)
        _SWEEP_STARTS[key] = start
        _SWEEP_STARTS.move_to_end(key)
        while len(_SWEEP_STARTS) > _SWEEP_STARTS_KEPT:
            _SWEEP_STARTS.popitem(last=False)


def newton(M, C, K, lam: complex, x: np.ndarray, rtol: float, iterations: int = 6,
           floor: float = 1e-300):
    """Newton's method (nonlinear inverse iteration) for ``(λ² M + λ C + K) x = 0`` from a close
    start; returns (λ, unit x, size of the last step relative to max(|λ|, ``floor``) [floor in
    1/s]; the default measures it relative to |λ|)."""
    return nonlinear_inverse_iteration(lambda lam: lam * lam * M + lam * C + K,
                                       lambda lam: 2 * lam * M + C, lam, x, rtol, iterations,
                                       floor)


def nonlinear_inverse_iteration(matrix, derivative, lam: complex, x: np.ndarray, rtol: float,
                                iterations: int = 6, floor: float = 1e-300):
    """Newton's method for ``matrix(λ) x = 0`` (``derivative(λ)`` = d matrix / dλ, both square)
    from a close start (λ [1/s], x); stops when a step is below 0.01·rtol relative to
    max(|λ|, ``floor``).  Returns (λ, unit x, last step relative to max(|λ|, floor))."""
    v = x.conj()
    x = x / (v @ x)
    step = np.inf
    for _ in range(iterations):
        u = sla.lu_solve(sla.lu_factor(matrix(lam), check_finite=False), derivative(lam) @ x,
                         check_finite=False)
        correction = (v @ x) / (v @ u)
        lam = lam - correction
        x = u / (v @ u)
        step = abs(correction) / max(abs(lam), floor)
        if step < 0.01 * rtol:
            break
    return lam, x / np.linalg.norm(x), step


BRIDGE_HALVINGS = 4  # an ambiguous dense step is halved at most this often (≤ 15 dense points)
CONJUGATE_RTOL = 1e-12  # two values are a conjugate pair within this relative distance


def _bridge(model: BogieModel, parameter: str, start: OperatingPoint, end: OperatingPoint,
            values: np.ndarray, vectors: np.ndarray, end_values: np.ndarray,
            end_vectors: np.ndarray, halvings: int = BRIDGE_HALVINGS) -> np.ndarray:
    """Columns of the dense solution at ``end`` (``end_values`` [1/s], unit displacement
    ``end_vectors``) continuing the branches (``values``, ``vectors``) at ``start``.  Where the
    assignment is ambiguous (:func:`_assign`) the step in ``parameter`` is halved: the branches
    are assigned to a dense solution at the middle first, and from there to ``end`` (each half
    again, at most ``halvings`` times in all; the last assignment is taken as it is)."""
    chosen, ok = _assign(vectors, values, end_vectors, end_values)
    if ok or halvings == 0:
        return chosen
    halfway = 0.5 * (getattr(start, parameter) + getattr(end, parameter))
    middle = replace(start, **{parameter: halfway})
    middle_values, middle_vectors = _exact(model, middle)
    kept = _bridge(model, parameter, start, middle, values, vectors, middle_values,
                   middle_vectors, halvings - 1)
    return _bridge(model, parameter, middle, end, middle_values[kept], middle_vectors[:, kept],
                   end_values, end_vectors, halvings - 1)


def _conjugate_pairs(values: np.ndarray) -> list[tuple[int, int]]:
    """(b, p): the branches whose complex values are a conjugate pair (Im > 0 at b; each branch
    in one pair at most; a complex branch whose conjugate is not tracked is in none)."""
    lower = list(np.flatnonzero(values.imag < 0))
    pairs = []
    for b in np.flatnonzero(values.imag > 0):
        if not lower:
            break
        gaps = np.abs(values[lower] - values[b].conjugate())
        k = int(np.argmin(gaps))
        if gaps[k] <= CONJUGATE_RTOL * abs(values[b]):
            pairs.append((int(b), int(lower.pop(k))))
    return pairs


def _assign(previous_vectors, previous_values, vectors, values):
    """Columns of ``vectors`` continuing each previous branch (MAC + eigenvalue distance), and
    whether that assignment is unambiguous (module docstring, step 4)."""
    mac = np.abs(previous_vectors.conj().T @ vectors) ** 2  # unit vectors: MAC in [0, 1]
    scale = np.maximum(np.abs(previous_values), 1.0)[:, None]
    distance = np.abs(previous_values[:, None] - values[None, :]) / scale
    rows, columns = linear_sum_assignment((1 - mac) + distance)
    chosen = np.empty(len(previous_values), dtype=int)
    chosen[rows] = columns
    # unambiguous: similar mode shape, or (for near-repeated twins of ID1/ID2, whose eigenvectors
    # mix freely) an eigenvalue that moved by less than 5 % of its size
    ok = bool(np.all((mac[rows, columns] > 0.5) | (distance[rows, columns] < 0.05)))
    # and a conjugate pair stays a pair (or splits into two reals): the cost is the same for an
    # assignment and its conjugate, so a pair torn apart means no step-continuous choice exists
    for b, p in _conjugate_pairs(previous_values):
        w_b, w_p = values[chosen[b]], values[chosen[p]]
        if not ((w_b.imag == 0 and w_p.imag == 0)
                or abs(w_p - w_b.conjugate()) <= CONJUGATE_RTOL * abs(w_b)):
            ok = False
    return chosen, ok


def dense_generalized_eigenvalues(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """All finite eigenvalues of ``[λ N + P] u = 0`` (eqs. 21–22), dense QZ — the naive reference.

    A massless coordinate (zero row of M, :mod:`model.analysis.linear_system`) would make the first block
    row of eq. 22 vanish; there ``M̂`` (M with a unit entry on the massless diagonal) takes M's
    place in N's first row and P, which keeps ``w = λ q`` for every coordinate and adds one
    infinite eigenvalue per massless coordinate, dropped.  Without massless coordinates this is
    eqs. 21–22 as published (2n eigenvalues)."""
    n = model.n
    Z = np.zeros((n, n))
    M_hat = model.M.copy()
    massless = massless_coordinates(model.M)
    M_hat[massless, massless] = np.abs(np.diag(model.M)).max()
    N = np.block([[Z, M_hat], [model.M, damping_matrix(model, op)]])
    P = np.block([[-M_hat, Z], [Z, model.K]])
    alpha, beta = sla.eig(-P, N, right=False, check_finite=False, homogeneous_eigvals=True)
    if not len(massless):
        with np.errstate(divide="ignore", invalid="ignore"):
            return alpha / beta
    order = np.argsort(np.abs(beta) / np.maximum(np.abs(alpha), 1e-300))
    finite = np.sort(order[len(massless):])  # the n_m eigenvalues nearest to infinity dropped
    return alpha[finite] / beta[finite]
