"""Compiled step loop of :mod:`model.nonlinear` (numba, cached on disk; it releases the GIL, so
the dashboard's sessions step side by side).

Kept apart so that importing :mod:`model.nonlinear` does not import numba; see that module's
docstring for the scheme.  One loop step: propagate the modal state exactly, solve the channels
z = zp + D1 r(z) by Newton (the four contact velocities and ID2's slope torque: 5 x 5, partial
pivoting), add the remainder's end-of-step input, detect slip on ID2's wheelset.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, fastmath={"reassoc", "contract", "nsz", "arcp"}, nogil=True)
def law(s, v, mu0, A, B, kA, kS, slope):
    """Polach's μ(s, v) and ∂μ/∂s (as :class:`model.contact.PolachLaw`)."""
    w = abs(s) * v
    decay = math.exp(-B * w)
    mu_f = mu0 * ((1.0 - A) * decay + A)
    sgn = 1.0 if s > 0 else (-1.0 if s < 0 else 0.0)
    dmu_f = -mu0 * (1.0 - A) * decay * B * v * sgn
    eps = slope * s / mu_f
    deps = slope / mu_f - slope * s * dmu_f / (mu_f * mu_f)
    a = kA * eps
    k = kS * eps
    F = a / (1.0 + a * a) + math.atan(k)
    dF = kA * (1.0 - a * a) / ((1.0 + a * a) ** 2) + kS / (1.0 + k * k)
    return 2.0 / math.pi * mu_f * F, 2.0 / math.pi * (dmu_f * F + mu_f * dF * deps)

@numba.njit(cache=True, fastmath={"reassoc", "contract", "nsz", "arcp"}, nogil=True)
def march(k0, k1, h, zeta, phi, z, u2_now, E, inc_step, cp, cm, g_step, g0, P0, P1, p0_2,
          p1_2, W, D1, contact_scale, law_params, s0, v, N0, mu_s0, dmu_s0, tangent,
          detect_rows, threshold, det_state, M_step, delay, rate, floor, Z_out, z_out,
          phi_out, u2_out, iterations, n_creep):
    """Steps k0 → k1 (exclusive of k0's state, which is given).  Writes the modal states,
    contact velocities, remainder forces and ΔM_2 of steps k0+1 … k1 into rows 0 … of the
    outputs; updates zeta, phi, z, u2_now, det_state in place.  Returns 0, or the step at
    which Newton failed (negative)."""
    m = zeta.shape[0]
    nc = z.shape[0]
    mu0, A, B, kA, kS, slope = law_params[0], law_params[1], law_params[2], \
        law_params[3], law_params[4], law_params[5]
    g = g0 * (g_step ** k0)
    zp = np.empty(nc)
    znew = np.empty(nc)
    rhs = np.empty(nc)
    J = np.empty((nc, nc))
    r = np.empty(nc)
    dr = np.empty(nc)
    for k in range(k0, k1):
        t1 = (k + 1) * h
        # ΔM_2 at the end of the step (the detection is known up to step k)
        reduction = 0.0  # 1 − ρ: the share of ID2's motor torque taken away at the end of the step
        if det_state[0] >= 0.0:
            t_act = det_state[0] + delay
            if t1 > t_act:
                reduction = (1.0 - floor) * min(1.0, rate * (t1 - t_act))
        u2_next = -M_step * reduction
        gc = g.conjugate()
        for j in range(m):
            acc = E[j] * zeta[j] + inc_step[j] + cp[j] * g + cm[j] * gc \
                + p0_2[j] * u2_now + p1_2[j] * u2_next
            for i in range(nc):
                acc += P0[j, i] * phi[i]
            zeta[j] = acc
        g = g * g_step
        for i in range(nc):
            s = 0.0
            for j in range(m):
                w = W[i, j]
                zj = zeta[j]
                s += w.real * zj.real - w.imag * zj.imag
            zp[i] = s
            znew[i] = z[i]
        # Newton on z = zp + D1 r(z)
        it = 0
        while True:
            for i in range(nc):
                if i >= n_creep:  # ID2's motor slope torque, scaled by ρ with the rest
                    r[i] = -reduction * znew[i]
                    dr[i] = -reduction
                elif tangent:
                    mu_t = mu_s0 + dmu_s0 * (znew[i] / v)
                    r[i] = N0 * (mu_t - mu_s0) - N0 * dmu_s0 * znew[i] / v
                    dr[i] = 0.0
                else:
                    mu_v, dmu_v = law(s0 + znew[i] / v, v, mu0, A, B, kA, kS, slope)
                    r[i] = N0 * (mu_v - mu_s0) - N0 * dmu_s0 * znew[i] / v
                    dr[i] = N0 * (dmu_v - dmu_s0) / v
            for i in range(nc):
                s = zp[i] - znew[i]
                for ll in range(nc):
                    s += D1[i, ll] * r[ll]
                    J[i, ll] = D1[i, ll] * dr[ll]
                J[i, i] -= 1.0
                rhs[i] = s
            # J dz = rhs with J = D1 diag(r') − I  (Gaussian elimination, partial pivoting)
            for c in range(nc):
                p = c
                for ll in range(c + 1, nc):
                    if abs(J[ll, c]) > abs(J[p, c]):
                        p = ll
                if p != c:
                    for ll in range(nc):
                        J[c, ll], J[p, ll] = J[p, ll], J[c, ll]
                    rhs[c], rhs[p] = rhs[p], rhs[c]
                for ll in range(c + 1, nc):
                    f = J[ll, c] / J[c, c]
                    for q in range(c, nc):
                        J[ll, q] -= f * J[c, q]
                    rhs[ll] -= f * rhs[c]
            change = 0.0
            for c in range(nc - 1, -1, -1):
                s = rhs[c]
                for q in range(c + 1, nc):
                    s -= J[c, q] * rhs[q]
                rhs[c] = s / J[c, c]
            # J dz = R with the residual R = zp + D1 r(z) − z  →  z_new = z − dz
            for i in range(nc):
                znew[i] -= rhs[i]
                change = max(change, abs(rhs[i]) / (abs(znew[i]) + contact_scale))
            it += 1
            if change <= 1e-12 or it >= 60:
                break
        if not change <= 1e-12 or not math.isfinite(change):
            return -(k + 1)
        iterations[0] += it
        # final remainder at the converged z
        for i in range(nc):
            if i >= n_creep:
                r[i] = -reduction * znew[i]
            elif tangent:
                mu_t = mu_s0 + dmu_s0 * (znew[i] / v)
                r[i] = N0 * (mu_t - mu_s0) - N0 * dmu_s0 * znew[i] / v
            else:
                mu_v, dmu_v = law(s0 + znew[i] / v, v, mu0, A, B, kA, kS, slope)
                r[i] = N0 * (mu_v - mu_s0) - N0 * dmu_s0 * znew[i] / v
        for j in range(m):
            acc = zeta[j]
            for i in range(nc):
                acc += P1[j, i] * r[i]
            zeta[j] = acc
        row = k - k0
        for j in range(m):
            Z_out[row, j] = zeta[j]
        slip_before = 0.0
        for i in range(nc):
            slip_before += detect_rows[i] * z[i]
        for i in range(nc):
            phi[i] = r[i]
            z[i] = znew[i]
            z_out[row, i] = znew[i]
            phi_out[row, i] = r[i]
        u2_now = u2_next
        u2_out[row] = u2_next
        # detection on ID2's wheelset slip velocity (mean of its wheels)
        if det_state[0] < 0.0:
            slip = 0.0
            for i in range(nc):
                slip += detect_rows[i] * znew[i]
            if abs(slip) > threshold:
                # the crossing time interpolated within the step (a detection time on the grid
                # would make the result only first-order accurate in h)
                before = abs(slip_before)
                fraction = (threshold - before) / (abs(slip) - before) if before < threshold else 0.0
                det_state[0] = t1 - h + h * min(1.0, max(0.0, fraction))
    return 0

