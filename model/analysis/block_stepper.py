"""Step loop of :mod:`model.analysis.nonlinear` in numpy and scipy (see that module's docstring for the
scheme): the creep remainders of a whole block of steps are solved together.

Within a block of ``L`` steps (``L ≤ SUB_STEPS``), the channel values (the four contact
velocities and ID2's slope torque) are linear in the block's unknown remainders r:

    z = a + T r(z),        a_i = Re(W ζ⁻_i) without the block's remainders,
                           T = block lower-triangular Toeplitz:  D1 on the diagonal,
                               Re(W E^(l−1) Q) l steps below (Q = diag(E) P1 + P0),

because the modal state obeys ``ζ⁻_{i+1} = E ζ⁻_i + F_i + Q r_i`` (the end-of-step input of step
i folded into step i+1; ``ζ_i = ζ⁻_i + P1 r_i``).  The 5L equations are solved by Newton with the
Jacobian ``T diag(r') − I`` less the within-step coupling between channels (≈ 10⁻⁸ of the
diagonal, measured; the residual keeps it, so the solution is that of the coupled equations):
that Jacobian is lower triangular, one ``solve_triangular`` per iteration, and the creep law is
evaluated on all 4L contact values at once.  What stays per step in Python is one vectorised
O(modes) recurrence (the block's forced state).  The outputs y = Re(V ζ) are formed the same way
as the channels: ``y = Re(V ζ_forced) + T_V r`` with the Toeplitz ``T_V`` of V (``Re(V P1)`` on the
diagonal, ``Re(V E^(l−1) Q)`` below), and the state carried to the next block is the block's last
one only (``ζ_(L−1) = ζ_forced,(L−1) + Σ_j E^(L−2−j) Q r_j + P1 r_(L−1)``): the modal states of
the steps inside a block are never formed.

A block that does not converge is halved (down to one step, the plain one-step implicit
scheme); a block in which the anti-slip protection trips is cut where the torque reduction
starts (it depends on the detection time) and the next block starts there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import get_lapack_funcs

from model.contact.creep import polach_mu_and_slope

SUB_STEPS = 32  # steps solved together
TOLERANCE = 1e-12  # relative change of the channel values at which Newton stops
MAX_ITERATIONS = 40  # per block before it is halved


def hold_weights(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """φ1(x) = (eˣ − 1)/x and φ2(x) = (eˣ − 1 − x)/x² (complex x), with series near 0: the
    modal weights of a first-order hold over a step h are ``h(φ1 − φ2)`` (the start value) and
    ``h φ2`` (the end value) at x = λh."""
    x = np.asarray(x, dtype=complex)
    small = np.abs(x) < 1e-2
    xs = np.where(small, 1.0, x)
    phi1 = np.where(small, 1 + x / 2 + x**2 / 6 + x**3 / 24 + x**4 / 120 + x**5 / 720,
                    np.expm1(xs) / xs)
    phi2 = np.where(small, 0.5 + x / 6 + x**2 / 24 + x**3 / 120 + x**4 / 720 + x**5 / 5040,
                    (np.expm1(xs) - xs) / xs**2)
    return phi1, phi2


def _toeplitz(W: np.ndarray, E: np.ndarray, Q: np.ndarray, D1: np.ndarray, L: int) -> np.ndarray:
    """T (L·rows x L·nc): row block i, column block j holds D1 (i = j) or Re(W E^(i−j−1) Q)
    (W: rows x m, Q: m x nc, D1: rows x nc)."""
    rows, nc = W.shape[0], Q.shape[1]
    powers = E[None, :] ** np.arange(L - 1)[:, None]  # (L−1) x m
    lags = np.einsum("cm,lm,md->lcd", W, powers, Q).real  # (L−1) x rows x nc
    T = np.zeros((L, rows, L, nc))
    for i in range(L):
        T[i, :, i, :] = D1
        for j in range(i):
            T[i, :, j, :] = lags[i - j - 1]
    return T.reshape(L * rows, L * nc)


class _Blocks:
    """The matrices of one step loop, built once per run (≈ 4 ms): the channels' Toeplitz T and
    its triangular part for Newton, the outputs' Toeplitz T_V, the powers of E and the index
    patterns of a block."""

    def __init__(self, W, E, Q, D1, P1, V, creep, wheel=None):
        self.Q, self.P1 = Q, P1
        self.channels = nc = W.shape[0]
        self.creep = creep  # channels: creep (True) or ID2's slope torque
        self.rows_out = V.shape[0]
        # the wheel-force rows (irregularities only): ΔN = Re(W_n ζ) + D_n r + known inputs
        self.wheel_rows = 0 if wheel is None else wheel[0].shape[0]
        self.full = _toeplitz(W, E, Q, D1, SUB_STEPS)
        # the Newton matrix's part: T without the within-step coupling between channels
        self.triangular = np.tril(self.full)
        for i in range(SUB_STEPS):
            block = self.triangular[i * nc:(i + 1) * nc, i * nc:(i + 1) * nc]
            block[np.triu_indices(nc, 1)] = 0.0  # np.tril kept the lower part of D1 only
            block[np.tril_indices(nc, -1)] = 0.0
        self.outputs = _toeplitz(V, E, Q, (V @ P1).real, SUB_STEPS)
        self.wheel = None
        if wheel is None:
            self.projection = np.ascontiguousarray(np.vstack([W, V]).T)  # m x (nc + outputs)
        else:  # m x (nc + wheels + outputs); the wheel forces' Toeplitz has their direct feed
            W_n, D_n = wheel
            self.wheel = _toeplitz(W_n, E, Q, (W_n @ P1).real + D_n, SUB_STEPS)
            self.projection = np.ascontiguousarray(np.vstack([W, W_n, V]).T)
        self.powers = E[None, :] ** np.arange(SUB_STEPS)[:, None]  # E^k, k = 0 … L−1
        self.doubling = [E]  # E^(2^k) for the doubling scan
        while 2 ** len(self.doubling) < SUB_STEPS:
            self.doubling.append(self.doubling[-1] * self.doubling[-1])
        self.is_creep = np.tile(creep, SUB_STEPS)
        self.trtrs = get_lapack_funcs("trtrs", (self.triangular,))
        self._newton: dict[int, np.ndarray] = {}

    def newton_matrix(self, L: int, slopes: np.ndarray) -> np.ndarray:
        """Newton's Jacobian T_triangular diag(r') − I of the first L steps, in a buffer of the
        run (overwritten by the next call)."""
        n = L * self.channels
        J = self._newton.get(L)
        if J is None:
            J = self._newton[L] = np.empty((n, n))
        np.multiply(self.triangular[:n, :n], slopes[None, :], out=J)
        J.flat[::n + 1] -= 1.0
        return J


def step_matrices(W, E, P0, P1, D1, V, n_creep, wheel=None) -> _Blocks:
    """The matrices of a run's step loop (Q = diag(E) P1 + P0; V: outputs x m, y = Re(V ζ);
    the first ``n_creep`` of the channels are creep channels), built once per run and passed, in
    the run's :class:`StepInputs`, to every :func:`march` call of it (one per output block of
    2 048 steps).  ``wheel``: with irregularities, (W_n, D_n) of the contacts' wheel-force
    changes ``ΔN = Re(W_n ζ) + D_n r + …`` (n_creep x m, n_creep x channels) [N]."""
    return _Blocks(W, E, E[:, None] * P1 + P0, D1, P1, V, np.arange(W.shape[0]) < n_creep, wheel)


@dataclass(frozen=True)
class StepInputs:
    """What stays fixed over one run's step loop: built once per run by
    :func:`model.analysis.nonlinear.nonlinear_response` and passed to each of its :func:`march`
    calls (modal quantities per kept mode; "channels": the four contacts, then ID2's slope
    torque)."""

    h: float  # step [s]
    E: np.ndarray  # m: e^(λh) per kept mode
    inc_step: np.ndarray  # m: exact modal increment per step of M_C's step part
    cp: np.ndarray  # m: modal weights of M_C's damped oscillation e^(μt) over a step
    cm: np.ndarray  # m: the same for its conjugate e^(μ̄t)
    g_step: complex  # e^(μh): the oscillation's factor per step
    g0: complex  # the oscillation's factor at step 0
    P0: np.ndarray  # m x channels: first-order-hold weights (start of the step) of the channels
    p0_2: np.ndarray  # m: the same for ΔM_2 (ID2's motor torque) at the start of the step
    p1_2: np.ndarray  # m: … at the end of the step
    contact_scale: float  # velocity added to |z| in Newton's relative change [m/s]
    law_params: np.ndarray  # Polach's law: (mu0, A, B, kA, kS, slope) of ``creep_law``
    s0: float  # steady creepage [-]
    v: float  # speed [m/s]
    N0: float  # wheel force [N]
    mu_s0: float  # μ(s0, v) [-]
    dmu_s0: float  # ∂μ/∂s at s0 [-]
    tangent: bool  # μ replaced by its tangent at s0
    detect_rows: np.ndarray  # channels: weights of ID2's wheelset slip velocity (detection)
    threshold: float  # |Δ slip velocity| that trips the protection [m/s] (inf: none)
    M_step: float  # M(s0, v) before the fault [N m]
    delay: float  # reaction delay after detection [s]
    rate: float  # torque reduction rate [1/s]
    floor: float  # torque kept after the reduction [fraction of M(s0, v)]
    blocks: _Blocks  # the run's :func:`step_matrices`
    # the rail–wheel irregularities (None: none, N = N0): an object with ``forcing(k, L)``, the
    # exact or held modal increments of their generalized force over steps k … k+L−1 (L x m),
    # ``known(k, L)``, the wheel-force changes at the ends of those steps that do not come from
    # the modal state or the remainders (L x contacts) [N], and ``d_m2`` (contacts), the direct
    # feed of ID2's motor torque into them [N per N m]
    # (:class:`model.analysis.nonlinear_irregularity.IrregularityLoop`)
    irregularity: object | None = None


def march(k0, k1, inputs: StepInputs, zeta, phi, z, u2_now, det_state, Y_out, z_out, phi_out,
          u2_out, iterations, wheel_out=None):
    """Steps k0 → k1 (exclusive of k0's state, which is given).  Writes the outputs Re(V ζ)
    (``inputs.blocks``' V), contact velocities, remainder forces and ΔM_2 of steps k0+1 … k1 into
    rows 0 … of ``Y_out``, ``z_out``, ``phi_out``, ``u2_out`` (and, with irregularities, the
    contacts' wheel-force changes ΔN [N] into ``wheel_out``); updates zeta, phi, z, det_state and
    ``iterations`` in place (``u2_now``: ΔM_2 at step k0 [N m]).  Returns 0, or the step at which
    Newton failed (negative)."""
    i = inputs
    creep = i.blocks.creep
    nc = z.shape[0]
    fixed = _MarchConstants(basis=np.vstack([i.cp, i.cm, i.p0_2, i.p1_2]).astype(complex),
                            law=tuple(float(x) for x in i.law_params),
                            detect=np.asarray(i.detect_rows, dtype=float),
                            scale=float(i.contact_scale))
    slope = np.zeros(nc)  # r'(z) of the given step (Newton's start of the first block)
    if not i.tangent:
        slope[creep] = i.N0 / i.v * (polach_mu_and_slope(i.s0 + z[creep] / i.v, i.v, *fixed.law)[1]
                                     - i.dmu_s0)
    state = _LoopState(zeta.copy(), phi.copy(), z.copy(), float(u2_now), float(det_state[0]),
                       slope)
    out = _Buffers(Y_out, z_out, phi_out, u2_out, wheel_out)
    row, L = 0, SUB_STEPS
    while row < k1 - k0:
        L = min(L, k1 - k0 - row)
        done = _block(state, k0 + row, L, row, i, fixed, out, iterations)
        if done == 0:
            if L == 1:
                return -(k0 + row + 1)
            L = max(1, L // 2)  # not converged: a shorter block
            continue
        row += done
        L = SUB_STEPS
    zeta[:], phi[:], z[:] = state.zeta, state.phi, state.z
    det_state[0] = state.detection
    return 0


def _recurrence(doubling: list[np.ndarray], f: np.ndarray) -> np.ndarray:
    """x_i = E x_(i−1) + f_i (x_(−1) = 0) for all rows i of f at once, in place: a doubling scan
    (after the round with shift d, row i holds the sum over f_(i−2d+1 … i)), log2(rows)
    vectorised rounds instead of a Python step per row; ``doubling``: E, E², E⁴, …"""
    d = 1
    for power in doubling:
        if d >= len(f):
            break
        f[d:] += power * f[:-d]
        d *= 2
    return f


class _LoopState:
    """What carries over from one block to the next (the last accepted step)."""

    def __init__(self, zeta, phi, z, u2, detection, slope):
        self.zeta = zeta  # modal state ζ (after the step's end input)
        self.phi = phi  # remainders r of the step [N] / slope torque change [N m]
        self.z = z  # channel values of the step
        self.u2 = u2  # ΔM_2 at the step [N m]
        self.detection = detection  # detection time [s], < 0: not yet
        self.slope = slope  # r'(z) of the creep channels at the step [N s/m]


@dataclass(frozen=True)
class _MarchConstants:
    """What :func:`march` prepares once for its blocks from the run's :class:`StepInputs`."""

    basis: np.ndarray  # 4 x m: cp, cm, p0_2, p1_2 (the weights of the block's inputs)
    law: tuple  # Polach's law parameters as floats
    detect: np.ndarray  # channels: weights of ID2's wheelset slip velocity
    scale: float  # velocity added to |z| in Newton's relative change [m/s]


@dataclass(frozen=True)
class _Buffers:
    """The rows of one :func:`march` call: outputs, channel values, remainders, ΔM_2."""

    Y: np.ndarray
    z: np.ndarray
    phi: np.ndarray
    u2: np.ndarray
    wheel: np.ndarray | None = None  # the contacts' wheel-force changes ΔN [N] (irregularities)


def _block(state: _LoopState, kb: int, L: int, row0: int, inputs: StepInputs,
           fixed: _MarchConstants, out: _Buffers, iterations) -> int:
    """Solve steps kb+1 … kb+L from ``state``; returns the number of accepted steps (0: Newton
    did not converge) and advances ``state`` to the last of them, whose rows from ``row0`` on it
    writes into ``out``."""
    nc = state.z.shape[0]
    t1, reduction, u2, forced, projected = _forced_block(state, kb, L, inputs, fixed.basis)
    wheel = None
    if inputs.irregularity is not None:  # the wheel-force changes without the block's remainders
        nw = inputs.blocks.wheel_rows
        wheel = (projected[:, nc:nc + nw] + inputs.irregularity.known(kb, L)
                 + u2[:, None] * inputs.irregularity.d_m2[None, :]).reshape(-1)
    solved = _solve_remainders(state, L, inputs, fixed, projected[:, :nc].reshape(-1), reduction,
                               wheel)
    if solved is None:
        return 0
    zf, r, dr, count, n = solved
    zb, rb = zf.reshape(L, nc), r.reshape(L, nc)
    accepted = L
    if state.detection < 0.0:
        accepted = _cut_at_detection(state, zb, t1, inputs, fixed.detect)
    _accept(state, accepted, row0, inputs.blocks, forced, projected, zb, rb, dr, u2, out)
    if n is not None:
        out.wheel[row0:row0 + accepted] = n.reshape(L, -1)[:accepted]
    iterations[0] += count * accepted  # every accepted step took part in `count` iterations
    return accepted


def _forced_block(state: _LoopState, kb: int, L: int, i: StepInputs, basis: np.ndarray):
    """The block's steps without their remainders: the ends of the steps t1 [s], the torque
    reduction's fraction and ΔM_2 [N m] at each (from the detection known so far), the forced
    modal states and their projection on the channels and outputs (L x (channels, outputs))."""
    t1 = (kb + 1 + np.arange(L)) * i.h
    reduction = np.zeros(L)
    if state.detection >= 0.0:
        reduction = (1.0 - i.floor) * np.clip(i.rate * (t1 - state.detection - i.delay), 0.0, 1.0)
    u2 = -i.M_step * reduction
    u2_before = np.concatenate([[state.u2], u2[:-1]])
    # forced modal states without the block's remainders: b_0 = E ζ + F + P0 φ, b_(i+1) = E b_i + …
    inputs = np.empty((L, 4), dtype=complex)  # the weights of cp, cm, p0_2, p1_2 (``basis``)
    inputs[:, 0] = i.g0 * np.power(complex(i.g_step), np.arange(kb, kb + L))
    inputs[:, 1] = inputs[:, 0].conj()
    inputs[:, 2] = u2_before
    inputs[:, 3] = u2
    forcing = inputs @ basis
    forcing += i.inc_step
    if i.irregularity is not None:
        forcing += i.irregularity.forcing(kb, L)
    forcing[0] += i.E * state.zeta + i.P0 @ state.phi
    forced = _recurrence(i.blocks.doubling, forcing)
    projected = (forced @ i.blocks.projection).real
    return t1, reduction, u2, forced, projected


def _solve_remainders(state: _LoopState, L: int, i: StepInputs, fixed: _MarchConstants,
                      a: np.ndarray, reduction: np.ndarray, wheel: np.ndarray | None = None):
    """Newton on ``z = a + T r(z)`` for the block's L·nc channel values (``a``: the forced
    values); (z, r, r'(z), iterations, ΔN), or None when it does not converge.

    With irregularities (``wheel``: the contacts' wheel-force changes without the block's
    remainders, L·contacts [N]) the creep remainder is ``N0 (μ − μ0) − N0 μ0' z/v + ΔN (μ − μ0)``
    (:mod:`model.analysis.nonlinear`) with ``ΔN = wheel + T_n r`` (the wheel forces' Toeplitz):
    ΔN is formed from each iterate's remainders and held in the Jacobian (its only entries would
    be ``(μ − μ0) ∂ΔN/∂r``: the creep forces move the wheels' vertical motion through the
    structure's couplings only); the residual and the stopping rule keep it, so the solution is
    that of the coupled equations, ΔN included (ΔN's change counts relative to N0)."""
    blocks = i.blocks
    nc = state.z.shape[0]
    T = blocks.full[:L * nc, :L * nc]
    is_creep = blocks.is_creep[:L * nc]
    slope_scale = -np.repeat(reduction, nc)[~is_creep]
    dr = np.zeros(L * nc)
    dr[~is_creep] = slope_scale
    tangent_slope = i.N0 * i.dmu_s0 / i.v
    trtrs = blocks.trtrs
    # Newton's start: the block solved with the remainders linearized about the last step,
    # r ≈ r_last + r'_last (z − z_last) (one triangular solve, no evaluation of the law)
    dr[is_creep] = np.tile(state.slope[blocks.creep], L)
    offset = np.tile(state.phi - state.slope * state.z, L)
    offset[~is_creep] = 0.0
    zf, info = trtrs(blocks.newton_matrix(L, dr), -(a + T @ offset), lower=1)
    if info != 0:
        return None
    n = T_n = None
    if wheel is not None:  # ΔN from the start's remainders (linearized about the last step)
        T_n = blocks.wheel[:L * blocks.wheel_rows, :L * nc]
        n = wheel + T_n @ (offset + dr * zf)
    r = np.empty(L * nc)
    count = 0
    while True:
        zc = zf[is_creep]
        if i.tangent:
            r[is_creep] = i.N0 * ((i.mu_s0 + i.dmu_s0 * (zc / i.v)) - i.mu_s0) - tangent_slope * zc
            if n is not None:  # T = N (μ0 + μ0' z/v): the product ΔN μ0' z/v
                r[is_creep] += n * (i.dmu_s0 * (zc / i.v))
                dr[is_creep] = n * (i.dmu_s0 / i.v)
        else:
            mu_v, dmu_v = polach_mu_and_slope(i.s0 + zc / i.v, i.v, *fixed.law)
            r[is_creep] = i.N0 * (mu_v - i.mu_s0) - tangent_slope * zc
            dr[is_creep] = i.N0 / i.v * (dmu_v - i.dmu_s0)
            if n is not None:  # T = N μ: the product ΔN (μ − μ0)
                r[is_creep] += n * (mu_v - i.mu_s0)
                dr[is_creep] += n * (dmu_v / i.v)
        r[~is_creep] = slope_scale * zf[~is_creep]
        residual = a + T @ r - zf
        step, info = trtrs(blocks.newton_matrix(L, dr), residual, lower=1)
        if info != 0:
            return None
        zf = zf - step
        r = r - dr * step  # the remainders at the new values to first order (O(step²) ≈ 1e-24)
        count += 1
        change = float(np.max(np.abs(step) / (np.abs(zf) + fixed.scale)))
        if n is not None:
            n_new = wheel + T_n @ r
            change = max(change, float(np.max(np.abs(n_new - n))) / i.N0)
            n = n_new
        if not math.isfinite(change):
            return None
        if change <= TOLERANCE:
            return zf, r, dr, count, n
        if count >= MAX_ITERATIONS:
            return None


def _cut_at_detection(state: _LoopState, zb: np.ndarray, t1: np.ndarray, i: StepInputs,
                      detect: np.ndarray) -> int:
    """Detection on ID2's wheelset slip velocity (mean of its wheels) in a block solved without
    it: sets ``state.detection`` [s] where the slip first exceeds the threshold (interpolated
    within the step) and returns the steps to accept, up to where the torque reduction that
    follows from it starts (all L if the slip stays below)."""
    L = len(t1)
    slip = zb @ detect
    over = np.flatnonzero(np.abs(slip) > i.threshold)
    if not len(over):
        return L
    k = int(over[0])
    before = abs(float(state.z @ detect)) if k == 0 else abs(float(slip[k - 1]))
    fraction = (i.threshold - before) / (abs(slip[k]) - before) if before < i.threshold else 0.0
    state.detection = float(t1[k] - i.h + i.h * min(1.0, max(0.0, fraction)))
    late = np.flatnonzero(t1[k + 1:] > state.detection + i.delay)
    return k + 1 + int(late[0]) if len(late) else L


def _accept(state: _LoopState, accepted: int, row0: int, blocks: _Blocks, forced, projected, zb,
            rb, dr, u2, out: _Buffers) -> None:
    """Write the first ``accepted`` steps of the block into ``out`` from ``row0`` on and carry its
    last one in ``state``."""
    # outputs with the remainders: y_i = Re(V ζ_forced,i) + Σ_j Re(V E^(i−1−j) Q) r_j + Re(V P1) r_i;
    # the last state: ζ_(n−1) = ζ_forced,(n−1) + Σ_(j < n−1) E^(n−2−j) Q r_j + P1 r_(n−1)
    nc = zb.shape[1]
    n_out = blocks.rows_out
    r = rb.reshape(-1)
    out.Y[row0:row0 + accepted] = projected[:accepted, nc + blocks.wheel_rows:] + (
        blocks.outputs[:accepted * n_out, :accepted * nc] @ r[:accepted * nc]).reshape(accepted, n_out)
    last = forced[accepted - 1] + blocks.P1 @ rb[accepted - 1]
    if accepted > 1:
        weights = blocks.powers[accepted - 2::-1].T @ rb[:accepted - 1]  # m x nc
        last += (blocks.Q * weights).sum(axis=1)
    out.z[row0:row0 + accepted] = zb[:accepted]
    out.phi[row0:row0 + accepted] = rb[:accepted]
    out.u2[row0:row0 + accepted] = u2[:accepted]
    state.zeta = last
    state.phi = rb[accepted - 1].copy()
    state.slope = np.where(blocks.creep, dr.reshape(len(zb), nc)[accepted - 1], 0.0)
    state.z = zb[accepted - 1].copy()
    state.u2 = float(u2[accepted - 1])
