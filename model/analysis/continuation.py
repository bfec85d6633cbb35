"""Exact continuation of all eigenvalues along the creepage s0 (numpy/scipy only).

Along a line at fixed speed v, wheel force N0 and motor slope b_M, s0 enters the model only
through the longitudinal creep coefficient ``c = b11 = N0 μ'(s0)/v`` [N s/m], one scalar shared
by the four contacts: ``B_total = B_nl + c G Gᵀ`` (G: n x 4, :func:`model.mechanics.operating_point.
longitudinal_creep_pattern`; :mod:`model.analysis.export`'s identity with H = −Gᵀ).  The first-order state
matrix is therefore a **rank-4 update** of the one at a reference (*anchor*) point:

    A(c) = A_ref + (c − c_ref) U Vᵀ,   U = [0; −M⁻¹G],  V = [0; G]   (2n x 4).

The rigid-body zeros are exact for every c and deflated as in :mod:`model.analysis.linear_system`
(``Qᵀ U``, ``Qᵀ V`` vanish on the rigid block); with the anchor's balanced eigendecomposition
``A22 = X Λ X⁻¹`` every non-rigid eigenvalue μ of A(c) is an eigenvalue of

    Λ + Δc Ũ Ṽᵀ,   Ũ = X⁻¹ U2 (p x 4),  Ṽᵀ = V2ᵀ X (4 x p),  Δc = c − c_ref.

**Secular equation with the root's own poles removed.**  For each root, split the poles into a
group C (the anchor cluster of its nearest pole — the near-twin ID1/ID2 and left/right modes,
relative gap ≤ :data:`CLUSTER_GAP` —, the poles whose term in E_R exceeds :data:`GROUP_TERM`,
and, shared, those of roots close to it) and the rest R.  Eliminating the rest exactly gives the
m x m (m = |C|) nonlinear eigenproblem

    μ ∈ eig S(μ),   S(μ) = Λ_C + Δc Ũ_C E_R(μ)⁻¹ Ṽ_Cᵀ,   E_R(μ) = I₄ − Δc Σ_{j∈R} ṽ_j ũ_jᵀ/(μ − λ_j)

which is smooth near the group's poles (unlike det(I − Δc F(μ)), which has them as poles).  Any
grouping is exact; it only shapes Newton's basins.  Every tracked root solves
``h(μ) = eig_sel S(μ) − μ = 0`` by Newton's method (h' from the eigenvalue derivative of S), all
roots at once: the sum over R is one complex matrix product (roots x poles) @ (poles x 16);
roots sharing a group choose their eigenvalues of S jointly.  The roots are continued from point
to point (predictor: the degenerate first-order perturbation from the anchor, then the secant in
c; real roots get a small imaginary kick so that two that meet can leave the axis as a pair), so
every branch keeps its identity without any eigenvector matching.

**Checks at every point (else: shorter steps, then a full eigen-analysis there, which becomes
the new anchor):** each root's last Newton step ≤ :data:`STEP_RTOL`·max(|μ|, 1 1/s); a complex
pair tracked by one half keeps Im > 0 (a collision on the real axis changes the count); roots
closer to each other than :data:`CLUSTER_RTOL` must be, one to one, the eigenvalues of their
S(μ) there to :data:`DUPLICATE_RTOL` (S(μ) holds every root near μ: a root found twice, or one
of a near-multiple group found in place of another, fails); and two exact identities of the
update, ``Σ μ = tr A22(c) = Σ λ_j + Δc tr(ṼᵀŨ)`` and ``Σ 1/μ = tr A22(c)⁻¹``
(Sherman–Morrison–Woodbury; it weighs the small eigenvalues that decide stability), to
:data:`TRACE_RTOL` of the sums of magnitudes.  The fallbacks are counted.

Only one of each complex pair far from the real axis is tracked (its conjugate is implied: A is
real); real roots and pairs near the axis are tracked one by one.  Units: c [N s/m],
eigenvalues [1/s].  docs/continuation.md has the measured accuracy and cost.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from model.analysis.eigen import eigen_analysis, state_space
from model.analysis.linear_system import massless_coordinates
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import (
    OperatingPoint,
    creep_coefficients,
    damping_matrix,
    longitudinal_creep_pattern,
)

CLUSTER_GAP = 1e-5  # poles closer than this relative gap are eliminated together
STEP_RTOL = 1e-10  # a root is converged when its Newton step is below this relative size
CLUSTER_RTOL = 1e-6  # roots this close (relative) must match S(μ)'s eigenvalues there...
DUPLICATE_RTOL = 1e-9  # ...one to one, to this (relative; plus |dS/dμ| x their distance)
TRACE_RTOL = 1e-9  # tolerance of the trace identities, relative to Σ|μ| and Σ|1/μ|
MAX_ITERATIONS = 12
REAL_RTOL = 1e-9  # |Im μ| ≤ this·|μ|: real
GROUP_TERM = 0.1  # poles whose term in E_R is larger than this are eliminated with the root
GROUP_MAX = 8  # at most this many poles per root (more where more roots share a group)
ROOT_NEIGHBOURS = 0.1  # roots closer than this x their distance to the nearest pole share
PREDICTOR_GROUPING = 3.0  # poles closer than this x their summed first-order shifts interact
KICK = 1e-7  # relative imaginary start of real roots (see LineContinuation._predict)
UNMIRROR = 0.05  # pairs with Im ≤ this·|μ| are tracked half by half (they may turn real)


def creep_coefficient(model: BogieModel, op: OperatingPoint) -> float:
    """c = b11 = N0 μ'(s0)/v [N s/m] at an operating point."""
    return float(creep_coefficients(model.parameters, op).b11)


@dataclass
class Anchor:
    """The anchor's eigendecomposition in the form the continuation needs."""

    operating_point: OperatingPoint
    c_ref: float  # b11 at the anchor [N s/m]
    poles: np.ndarray  # (p,) non-rigid eigenvalues of A at the anchor [1/s]
    Ut: np.ndarray  # (p, 4) X⁻¹ U2
    Vt: np.ndarray  # (4, p) V2ᵀ X
    W: np.ndarray  # (p, 16) row j: ṽ_j ũ_jᵀ (4 x 4, row-major)
    cluster: np.ndarray  # (p,) cluster id of each pole
    members: np.ndarray  # (clusters, m_max) pole indices of each cluster, −1 padded
    sizes: np.ndarray  # (clusters,) members per cluster
    trace_update: complex  # tr(ṼᵀŨ) [1/s per N s/m]
    weight: np.ndarray  # (p,) ‖ũ_j‖‖ṽ_j‖: how strongly pole j moves with c [1/s per N s/m]


def update_vectors(model: BogieModel) -> tuple[np.ndarray, np.ndarray]:
    """(U, V), N x 4 each: A(c) = A_ref + (c − c_ref) U Vᵀ [U: 1/kg …, V: 1].  The creep acts on
    the rims only (inertial coordinates): U = −[0; M_ii⁻¹ G_i], V = [0; G_i] on the state
    [Δq; Δq̇_inertial] (:mod:`model.analysis.linear_system`)."""
    n = model.n
    G = longitudinal_creep_pattern(model)
    inertial = np.setdiff1d(np.arange(n), massless_coordinates(model.M))
    if np.any(G[np.setdiff1d(np.arange(n), inertial)]):
        raise ValueError("the creep acts on a massless coordinate")
    Minv = state_space(model).inverse_mass
    G_i = G[inertial]
    return (np.vstack([np.zeros((n, 4)), -Minv @ G_i]), np.vstack([np.zeros((n, 4)), G_i]))


def _clusters(poles: np.ndarray, extra: np.ndarray | float = 0.0):
    """Connected groups of poles with relative gaps ≤ CLUSTER_GAP (or absolute gaps ≤
    ``extra``, p x p [1/s]): (group of each pole, members of each group −1 padded, sizes)."""
    p = len(poles)
    scale = np.maximum(np.maximum(np.abs(poles)[:, None], np.abs(poles)[None, :]), 1.0)
    gap = np.abs(poles[:, None] - poles[None, :])
    close = (gap <= CLUSTER_GAP * scale) | (gap <= extra)
    cluster = np.full(p, -1)
    next_id = 0
    for start in range(p):
        if cluster[start] >= 0:
            continue
        stack = [start]
        cluster[start] = next_id
        while stack:
            j = stack.pop()
            for k in np.flatnonzero(close[j] & (cluster < 0)):
                cluster[k] = next_id
                stack.append(k)
        next_id += 1
    sizes = np.bincount(cluster, minlength=next_id)
    members = np.full((next_id, sizes.max()), -1)
    fill = np.zeros(next_id, dtype=int)
    for j, k in enumerate(cluster):
        members[k, fill[k]] = j
        fill[k] += 1
    return cluster, members, sizes


def make_anchor(model: BogieModel, op: OperatingPoint) -> Anchor:
    """One eigendecomposition with vectors at ``op`` (not cached: a line's anchors are its own)."""
    system = state_space(model).system(damping_matrix(model, op))
    U, V = update_vectors(model)
    r = system.rigid_count
    U2 = system.deflation.to_deflated(U)[r:]
    V2 = system.deflation.rows(V.T).T[r:]
    lam, Yb, scale = system.eigen
    Ut = system.solve_eigenvectors(U2 / scale[:, None])
    Vt = (V2 * scale[:, None]).T @ Yb
    W = (Vt.T[:, :, None] * Ut[:, None, :]).reshape(len(lam), 16)
    cluster, members, sizes = _clusters(lam)
    return Anchor(op, creep_coefficient(model, op), lam, Ut, Vt, W, cluster, members, sizes,
                  complex(np.sum(Vt.T * Ut)),
                  np.linalg.norm(Ut, axis=1) * np.linalg.norm(Vt, axis=0))


def _eig2(S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues and (unnormalized) right eigenvectors of a batch of 2 x 2 matrices."""
    a, b, c, d = S[:, 0, 0], S[:, 0, 1], S[:, 1, 0], S[:, 1, 1]
    half = 0.5 * (a - d)
    root = np.sqrt(half * half + b * c)
    mean = 0.5 * (a + d)
    values = np.stack([mean + root, mean - root], axis=1)
    vectors = np.empty(S.shape, dtype=complex)
    for k, sign in ((0, 1.0), (1, -1.0)):
        # (S − λ) r = 0: r = (b, λ − a) or (λ − d, c), whichever is larger
        first = np.stack([b, half * -1 + sign * root], axis=1)  # λ − a = −half ± root
        second = np.stack([half + sign * root, c], axis=1)  # λ − d = half ± root
        use_first = np.linalg.norm(first, axis=1) >= np.linalg.norm(second, axis=1)
        chosen = np.where(use_first[:, None], first, second)
        chosen[np.linalg.norm(chosen, axis=1) == 0.0, k] = 1.0  # S = λ I: any vector
        vectors[:, :, k] = chosen
    return values, vectors


def _permutations(m: int) -> np.ndarray:
    return np.array(list(itertools.permutations(range(m))))


def _select(values: np.ndarray, mu: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """Which eigenvalue of its S(μ) each root continues (index into ``values``, b x m): the
    nearest to its current μ; roots that share their group of poles (nearly the same S) choose
    jointly (an optimal assignment), so that two roots whose estimates are farther from the
    roots than the roots are apart (numerically close twins) do not choose one value twice.
    Each root's eigenvalues are first put in the order of the first root's (a bijection by
    squared distance: robust to the common drift of S(μ) between the roots' μ)."""
    pick = np.argmin(np.abs(values - mu[:, None]), axis=1)
    b, m = values.shape
    if b < 2:
        return pick
    _, inverse, counts = np.unique(np.sort(groups, axis=1), axis=0, return_inverse=True,
                                   return_counts=True)
    inverse = inverse.ravel()
    full = np.flatnonzero(counts == m) if m <= 4 else np.zeros(0, dtype=int)
    if len(full):  # as many roots as poles in the group: all permutations, vectorized
        rows = np.argsort(inverse, kind="stable").reshape(-1)
        rows = rows[np.isin(inverse[rows], full)].reshape(len(full), m)
        perms = _permutations(m)
        V = values[rows]  # (K, roots, eigenvalues)
        reference = V[:, 0, :]
        mapped = V[:, :, perms]  # (K, roots, P, m)
        cost = (np.abs(mapped - reference[:, None, None, :]) ** 2).sum(axis=3)
        order = perms[np.argmin(cost, axis=2)]  # (K, roots, m): own index of reference e
        own = np.take_along_axis(V, order, axis=2)
        c2 = np.abs(own - mu[rows][:, :, None]) ** 2  # (K, roots, e)
        total = c2[:, np.arange(m)[None, :], perms].sum(axis=2)  # (K, P)
        assign = perms[np.argmin(total, axis=1)]  # (K, roots): reference e of each root
        pick[rows] = np.take_along_axis(order, assign[:, :, None], axis=2)[:, :, 0]
    for k in np.flatnonzero((counts > 1) & ~np.isin(np.arange(len(counts)), full)):
        rows = np.flatnonzero(inverse == k)
        reference = values[rows[0]]
        order = np.empty((len(rows), m), dtype=int)
        for n, r in enumerate(rows):
            ref_idx, own_idx = linear_sum_assignment(
                np.abs(reference[:, None] - values[r][None, :]) ** 2)
            order[n, ref_idx] = own_idx
        own = np.take_along_axis(values[rows], order, axis=1)
        r_idx, e_idx = linear_sum_assignment(np.abs(own - mu[rows, None]) ** 2)
        pick[rows[r_idx]] = order[r_idx, e_idx]
    return pick


def all_eigenvalues(roots: np.ndarray, mirrored: np.ndarray) -> np.ndarray:
    """The whole non-rigid spectrum from the tracked roots (conjugates of the mirrored added)."""
    return np.concatenate([roots, roots[mirrored].conj()])


@dataclass
class Tracked:
    """The tracked roots at one point: the spectrum is ``roots`` plus the conjugates of the
    ``mirrored`` ones (one of each complex pair far from the real axis); real roots and both
    halves of pairs close to the real axis are tracked one by one."""

    roots: np.ndarray  # (k,) complex [1/s]
    mirrored: np.ndarray  # (k,) bool
    origin: np.ndarray  # (k,) pole cluster of the anchor each root started from

    def spectrum(self) -> np.ndarray:
        return all_eigenvalues(self.roots, self.mirrored)


class Continuation:
    """Newton's method on the pole-removed secular equation of one anchor (see the module)."""

    def __init__(self, anchor: Anchor):
        self.anchor = anchor

    def start(self) -> Tracked:
        """The anchor's own eigenvalues as the tracked roots (mirrored: Im > 0 and not near
        the real axis, see :data:`UNMIRROR`)."""
        a = self.anchor
        lam = a.poles
        upper = lam.imag > UNMIRROR * np.abs(lam)
        own = np.flatnonzero(upper | (np.abs(lam.imag) <= UNMIRROR * np.abs(lam)))
        return Tracked(lam[own].astype(complex), upper[own], a.cluster[own])

    def predictor(self, dc: float, tracked: Tracked) -> np.ndarray:
        """Degenerate first-order perturbation from the anchor: the eigenvalues of the blocks of
        Λ + Δc ŨṼᵀ over groups of poles whose gaps are not large against their first-order
        shifts |Δc|·‖ũ_j‖‖ṽ_j‖ (they interact), matched to the anchor's roots ``tracked``."""
        a = self.anchor
        shift = abs(dc) * np.linalg.norm(a.Ut, axis=1) * np.linalg.norm(a.Vt, axis=0)
        groups, members, sizes = _clusters(a.poles, PREDICTOR_GROUPING * (
            shift[:, None] + shift[None, :]))
        result = tracked.roots.copy()
        pole_of = np.array([int(np.argmin(np.abs(a.poles - r))) for r in tracked.roots])
        for k in np.unique(groups[pole_of]):
            poles = members[k, :sizes[k]]
            block = np.diag(a.poles[poles]) + dc * (a.Ut[poles] @ a.Vt[:, poles])
            values = np.linalg.eigvals(block)
            # the block's values to the group's roots by an optimal assignment on distance (a
            # greedy nearest choice in index order cascaded when two real poles of the group
            # merged into a pair: each took its neighbour's value, the last one a far one)
            roots = np.flatnonzero(groups[pole_of] == k)
            rows, columns = linear_sum_assignment(
                np.abs(tracked.roots[roots][:, None] - values[None, :]))
            result[roots[rows]] = values[columns]
        return result

    def _groups(self, dc: float, mu: np.ndarray) -> np.ndarray:
        """The poles eliminated with each root μ: the anchor cluster of its nearest pole, and
        the poles whose term |Δc|·‖ũ_j‖‖ṽ_j‖/|μ − λ_j| in E_R exceeds :data:`GROUP_TERM` (they
        interact with the root strongly), at most :data:`GROUP_MAX` by that size.  Roots
        closer to each other than :data:`ROOT_NEIGHBOURS` x their distance to the nearest pole
        (e.g. two real roots about to meet) share one group of at least as many poles as they
        are (the union of theirs, topped up by the largest terms), so that they choose jointly
        among as many eigenvalues of S.  Any choice is exact; it only shapes Newton's basins.
        Returns (b, width) pole indices, −1 padded."""
        a = self.anchor
        distance = np.abs(mu[:, None] - a.poles[None, :])
        score = abs(dc) * a.weight[None, :] / np.maximum(distance, 1e-300)
        nearest = np.argmin(distance, axis=1)
        own = a.members[a.cluster[nearest]]
        b = np.repeat(np.arange(len(mu)), own.shape[1])
        ok = own.ravel() >= 0
        score[b[ok], own.ravel()[ok]] = np.inf
        top = np.argpartition(-score, GROUP_MAX - 1, axis=1)[:, :GROUP_MAX]
        chosen = np.take_along_axis(score, top, axis=1) > GROUP_TERM
        order = np.argsort(~chosen, axis=1, kind="stable")  # chosen first
        top = np.take_along_axis(np.where(chosen, top, -1), order, axis=1)
        # roots that are neighbours share a group
        gap = distance[np.arange(len(mu)), nearest]
        close = np.abs(mu[:, None] - mu[None, :]) <= ROOT_NEIGHBOURS * np.minimum(
            gap[:, None], gap[None, :])
        count, label = connected_components(csr_matrix(close), directed=False)
        sizes = np.bincount(label, minlength=count)
        # components whose roots already share one group with enough poles need nothing
        rows = np.sort(top, axis=1)
        _, first = np.unique(label, return_index=True)
        differs = np.any(rows != rows[first[label]], axis=1)
        enough = np.count_nonzero(rows >= 0, axis=1) >= sizes[label]
        needs = np.zeros(count, dtype=bool)
        np.logical_or.at(needs, label, differs | ~enough)
        shared = {}
        for k in np.flatnonzero((sizes > 1) & needs):
            roots = np.flatnonzero(label == k)
            poles = np.unique(top[roots])
            poles = list(poles[poles >= 0])
            if len(poles) < len(roots):  # top up by the largest terms over the roots
                ranking = np.argsort(-score[roots].max(axis=0))
                poles += [j for j in ranking if j not in poles][:len(roots) - len(poles)]
            shared[k] = (roots, poles)
        if not shared:
            return top
        width = max(top.shape[1], max(len(p) for _, p in shared.values()))
        groups = np.full((len(mu), width), -1)
        groups[:, :top.shape[1]] = top
        for roots, poles in shared.values():
            groups[roots] = -1
            groups[np.ix_(roots, np.arange(len(poles)))] = poles
        return groups

    def _newton_step(self, dc: float, mu: np.ndarray, members: np.ndarray):
        """One Newton step for the roots ``mu`` at Δc with their groups of poles ``members``
        (b x width, −1 padded): (selected eigenvalue of each root's S(μ), h'(μ) + 1, all
        eigenvalues of each root's S(μ), nan padded)."""
        a = self.anchor
        dr = mu.real[:, None] - a.poles.real[None, :]
        di = mu.imag[:, None] - a.poles.imag[None, :]
        denominator = dr * dr + di * di
        R = np.empty(dr.shape, dtype=complex)  # 1/(μ − λ_j) by real arithmetic (faster)
        with np.errstate(divide="ignore", invalid="ignore"):  # μ on its own pole: removed below
            R.real = dr / denominator
            R.imag = -di / denominator
        rows = np.repeat(np.arange(len(mu)), members.shape[1])
        cols = members.ravel()
        keep = cols >= 0
        R[rows[keep], cols[keep]] = 0.0  # the group's own poles are removed
        F = (R @ a.W).reshape(-1, 4, 4)
        Fp = -((R * R) @ a.W).reshape(-1, 4, 4)
        Einv = np.linalg.inv(np.eye(4) - dc * F)
        new = np.empty(len(mu), dtype=complex)
        derivative = np.empty(len(mu), dtype=complex)
        local = np.full((len(mu), members.shape[1]), np.nan, dtype=complex)  # eig S(μ)
        sizes = np.count_nonzero(members >= 0, axis=1)
        for m in np.unique(sizes):
            sel = np.flatnonzero(sizes == m)
            idx = members[sel, :m]
            Uc = a.Ut[idx]  # (b, m, 4)
            Vc = np.swapaxes(a.Vt[:, idx], 0, 1)  # (b, 4, m)
            left = Uc @ Einv[sel]
            S = dc * (left @ Vc)
            S[:, np.arange(m), np.arange(m)] += a.poles[idx]
            dS = dc * dc * (left @ Fp[sel] @ Einv[sel] @ Vc)
            b = np.arange(len(sel))
            if m == 1:
                new[sel] = S[:, 0, 0]
                derivative[sel] = dS[:, 0, 0]
                local[sel, 0] = S[:, 0, 0]
                continue
            if m == 2:
                values, vectors = _eig2(S)
            else:
                values, vectors = np.linalg.eig(S)
            pick = _select(values, mu[sel], idx)
            r_vec = vectors[b, :, pick]  # (b, m)
            l_vec = np.linalg.inv(vectors)[b, pick, :]  # (b, m)
            new[sel] = values[b, pick]
            derivative[sel] = np.einsum("bi,bij,bj->b", l_vec, dS, r_vec)
            local[sel, :m] = values
        return new, derivative, local

    def solve(self, c: float, start: np.ndarray):
        """Roots at creep coefficient ``c`` [N s/m] from ``start``: (roots, last relative step
        of each, (eigenvalues of each root's S(μ) at its last iterate, nan padded; |dS/dμ|
        of the selected one), iterations).  The groups of poles are chosen once, at the start; a root stops
        iterating when it and every root sharing its group (they choose jointly, see
        :func:`_select`) have converged."""
        dc = c - self.anchor.c_ref
        mu = np.array(start, dtype=complex)
        members = self._groups(dc, mu)
        _, key = np.unique(np.sort(members, axis=1), axis=0, return_inverse=True)
        key = key.ravel()
        step = np.full(len(mu), np.inf)
        local = np.full((len(mu), members.shape[1]), np.nan, dtype=complex)
        slope = np.zeros(len(mu))
        active = np.arange(len(mu))
        iterations = 0
        while iterations < MAX_ITERATIONS:
            iterations += 1
            new, derivative, values = self._newton_step(dc, mu[active], members[active])
            delta = (new - mu[active]) / (1.0 - derivative)
            mu[active] += delta
            local[active] = values
            slope[active] = np.abs(derivative)
            step[active] = np.abs(delta) / np.maximum(np.abs(mu[active]), 1.0)
            if not np.all(np.isfinite(mu)):
                break
            open_keys = key[step > STEP_RTOL]
            if len(open_keys) == 0:
                break
            active = np.flatnonzero(np.isin(key, open_keys))
        return mu, step, (local, slope), iterations

    def check(self, c: float, mu: np.ndarray, step: np.ndarray, local: tuple,
              tracked: Tracked) -> str | None:
        """Why the roots ``mu`` at ``c`` (continuing ``tracked``) cannot be certified (None:
        certified).  ``local``: the eigenvalues of each root's S(μ) and |dS/dμ| (from
        :meth:`solve`)."""
        a = self.anchor
        dc = c - a.c_ref
        if not np.all(np.isfinite(mu)):
            return "a root diverged"
        if np.any(step > STEP_RTOL):
            return f"{int(np.count_nonzero(step > STEP_RTOL))} roots did not converge"
        mirrored = tracked.mirrored
        if np.any(mu[mirrored].imag <= REAL_RTOL * np.abs(mu[mirrored])):
            return "a complex pair reached the real axis"
        full = all_eigenvalues(mu, mirrored)
        values, slope = local
        values = np.concatenate([values, values[mirrored].conj()])
        slope = np.concatenate([slope, slope[mirrored]])
        # Roots with neighbours (within CLUSTER_RTOL): they must be, one to one, the eigenvalues
        # of S(μ) within that radius (S(μ) holds every root near μ up to |dS/dμ|·distance): a
        # root found twice, or one of a near-multiple group found instead of another, fails
        scale = np.maximum(np.abs(full), 1.0)
        radius = CLUSTER_RTOL * scale
        close = np.abs(full[:, None] - full[None, :]) <= radius[:, None]
        for i in np.flatnonzero(close.sum(axis=1) > 1):
            ours = full[close[i]]
            theirs = values[i][np.abs(values[i] - full[i]) <= radius[i]]
            if len(theirs) != len(ours):
                return "two roots converged to one value"
            cost = np.abs(ours[:, None] - theirs[None, :])
            rows, cols = linear_sum_assignment(cost)
            allowed = DUPLICATE_RTOL * scale[i] + 2.0 * slope[i] * np.abs(ours[rows] - full[i])
            if np.any(cost[rows, cols] > allowed):
                return "two roots converged to one value"
        trace = a.poles.sum() + dc * a.trace_update
        mismatch = abs(full.sum() - trace) / np.abs(full).sum()
        if mismatch > TRACE_RTOL:
            return f"trace identity violated (a root is lost): {mismatch:.1e}"
        # tr (Λ + Δc Ũ Ṽᵀ)⁻¹ by Sherman–Morrison–Woodbury
        inv_poles = 1.0 / a.poles
        correction = 0.0
        if dc != 0.0:
            small = np.eye(4) / dc + (a.Vt * inv_poles) @ a.Ut
            correction = np.trace(np.linalg.solve(small, (a.Vt * inv_poles**2) @ a.Ut))
        inverse_trace = inv_poles.sum() - correction
        mismatch = abs((1.0 / full).sum() - inverse_trace) / np.abs(1.0 / full).sum()
        if mismatch > TRACE_RTOL:
            return f"inverse-trace identity violated (a small root is lost): {mismatch:.1e}"
        return None

    @staticmethod
    def unmirror(tracked: Tracked, history: list) -> tuple[Tracked, list]:
        """Track both halves of mirrored pairs that came close to the real axis (they may split
        into two real roots); ``history`` entries (c, roots) are extended alike."""
        near = tracked.mirrored & (tracked.roots.imag <= UNMIRROR * np.abs(tracked.roots))
        if not np.any(near):
            return tracked, history
        mirrored = tracked.mirrored.copy()
        mirrored[near] = False
        new = Tracked(np.concatenate([tracked.roots, tracked.roots[near].conj()]),
                      np.concatenate([mirrored, np.zeros(int(near.sum()), dtype=bool)]),
                      np.concatenate([tracked.origin, tracked.origin[near]]))
        return new, [(c, np.concatenate([r, r[near].conj()])) for c, r in history]


@dataclass(frozen=True)
class SpectrumLine:
    """All non-rigid eigenvalues along s0 at one (v, N0, b_M), by exact continuation."""

    s0: np.ndarray  # (n,) creepages [-]
    c: np.ndarray  # (n,) creep coefficient b11 [N s/m]
    spectra: list  # per point: all non-rigid eigenvalues [1/s]
    dense_points: np.ndarray  # (n,) bool: solved by a full eigen-analysis (anchor or fallback)
    fallbacks: int  # points where the continuation failed its checks (solved densely)
    substeps: int  # extra intermediate creep coefficients (step halving)
    iterations: int  # Newton iterations over all solves
    reasons: tuple  # why each fallback happened


class LineContinuation:
    """Continuation along one line at (v, N0, b_M) [m/s, N, N m s/rad]; points in any order
    (each continues from the last certified one)."""

    MAX_HALVINGS = 6  # a failing step is halved down to 1/64 of the way before a fallback

    def __init__(self, model: BogieModel, v: float, N0: float, b_M: float):
        self.model, self.v, self.N0, self.b_M = model, v, N0, b_M
        self.current: Continuation | None = None
        self.tracked: Tracked | None = None
        self.c = np.nan
        self.anchors = 0
        self.fallbacks = 0
        self.substeps = 0
        self.iterations = 0
        self.reasons: list[str] = []
        self._history: list[tuple[float, np.ndarray]] = []  # (c, roots) since the anchor

    def op(self, s0: float) -> OperatingPoint:
        return OperatingPoint(float(s0), self.v, self.N0, self.b_M)

    def _anchor_at(self, op: OperatingPoint) -> np.ndarray:
        self.current = Continuation(make_anchor(self.model, op))
        self.anchors += 1
        self.tracked = self.current.start()
        self.c = self.current.anchor.c_ref
        self._history = [(self.c, self.tracked.roots)]
        return self.tracked.spectrum()

    def _predict(self, c: float) -> np.ndarray:
        """Start of Newton's method at c: the anchor's first-order blocks, then the secant
        through the last two points.  Real roots (tracked one by one) get an imaginary kick of
        ±KICK·|μ|, alternating in the order of their real parts, so that two real roots that
        meet can leave the real axis as a conjugate pair (from a real start Newton's method on
        a real problem stays real)."""
        if len(self._history) == 1:
            mu = self.current.predictor(c - self.current.anchor.c_ref, self.tracked)
        else:
            (c1, m1), (c2, m2) = self._history[-2:]
            mu = m2 + (m2 - m1) * (c - c2) / (c2 - c1) if c2 != c1 else m2.copy()
        real = np.flatnonzero(~self.tracked.mirrored
                              & (np.abs(mu.imag) <= REAL_RTOL * np.abs(mu)))
        order = real[np.argsort(mu[real].real, kind="stable")]
        sign = np.where(np.arange(len(order)) % 2 == 0, 1.0, -1.0)
        mu[order] = mu[order].real + 1j * sign * KICK * np.maximum(np.abs(mu[order]), 1.0)
        return mu

    def _step(self, c: float) -> str | None:
        """Continue to c; None when certified (state advanced), else the reason."""
        self.tracked, self._history = Continuation.unmirror(self.tracked, self._history)
        mu, step, local, iterations = self.current.solve(c, self._predict(c))
        self.iterations += iterations
        reason = self.current.check(c, mu, step, local, self.tracked)
        if reason is None:
            self.tracked = Tracked(mu, self.tracked.mirrored, self.tracked.origin)
            self.c = c
            self._history = [*self._history, (c, mu)][-2:]
        return reason

    def state(self) -> tuple:
        """The continuation's state (to come back to with :meth:`restore`)."""
        return self.current, self.tracked, self.c, list(self._history)

    def restore(self, state: tuple) -> None:
        self.current, self.tracked, self.c, history = state
        self._history = list(history)

    def evaluate(self, s0: float, reanchor: bool = True) -> tuple[np.ndarray, bool]:
        """(all non-rigid eigenvalues [1/s], solved densely) at s0; the first call anchors
        there.  A step that fails the checks is retried as shorter steps (halved, down to
        1/2^MAX_HALVINGS of the way; a successful piece is kept and the next one doubled)
        before the point is solved densely: with ``reanchor`` it becomes the new anchor (an
        eigendecomposition with vectors), without (off-grid evaluations, e.g. for s0*) only its
        eigenvalues are computed and the state stays at the last certified point."""
        op = self.op(s0)
        if self.current is None:
            return self._anchor_at(op), True
        target = creep_coefficient(self.model, op)
        shortest = abs(target - self.c) / 2**self.MAX_HALVINGS
        piece = target - self.c
        while True:
            remaining = target - self.c
            if abs(piece) >= abs(remaining):
                piece = remaining
            reason = self._step(target if piece == remaining else self.c + piece)
            if reason is None:
                if self.c == target:
                    return self.tracked.spectrum(), False
                self.substeps += 1
                piece *= 2.0
                continue
            piece *= 0.5
            if abs(piece) < shortest * (1 - 1e-12):
                break
        self.fallbacks += 1
        self.reasons.append(f"s0 = {s0:.6g}: {reason}")
        if not reanchor:
            return eigen_analysis(self.model, op, vectors=False).eigenvalues, True
        return self._anchor_at(op), True


def continue_line(model: BogieModel, s0_values, v: float, N0: float, b_M: float) -> SpectrumLine:
    """All non-rigid eigenvalues at every creepage of ``s0_values`` (in order) at speed ``v``
    [m/s], wheel force ``N0`` [N], motor slope ``b_M`` [N m s/rad]: one eigendecomposition at the
    first creepage, then the continuation (module docstring); a point failing the checks even
    with halved steps is solved densely and becomes the new anchor."""
    s0_values = np.asarray(s0_values, dtype=float)
    line = LineContinuation(model, v, N0, b_M)
    spectra, dense = [], np.zeros(len(s0_values), dtype=bool)
    for i, s in enumerate(s0_values):
        spectrum, dense[i] = line.evaluate(s)
        spectra.append(spectrum)
    c = np.array([creep_coefficient(model, line.op(s)) for s in s0_values])
    return SpectrumLine(s0_values, c, spectra, dense, line.fallbacks, line.substeps,
                        line.iterations, tuple(line.reasons))
