"""Wheel–rail contact: Hertz ellipse, Kalker's linear creep coefficients, Polach's creep law and
the linearized creep damping blocks ``B_ad`` (eq. 19 of the study).

Sign conventions (vehicle axes, see :mod:`model.mechanics.dofs`): the wheels roll forward (+x) with a
positive spin ``ry``; traction creepage ``s = (r ω_y − v)/v > 0``.  The longitudinal creep force
on the wheel is ``T = μ(s, v) N`` in +x, acting at the contact point ``(0, 0, −r0)`` below the rim
centre.  Linearized, the rim feels ``f = −B_ad q̇`` with the 6 x 6 block of :func:`creep_block`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

# Kalker's creepage and spin coefficients for Poisson's ratio 0.25: J. J. Kalker, "On the
# rolling contact of two elastic bodies in the presence of dry friction", thesis, Delft 1967,
# as tabulated in V. K. Garg, R. V. Dukkipati, "Dynamics of Railway Vehicle Systems", Academic
# Press 1984, Table 5.1.  Columns C11, C22, C23 are the ν = 0.25 values.  The C33 column holds the
# ν = 0 values of the same table (C33 depends only weakly on ν, a few per cent); its ν = 0.25
# column could not be checked against the primary source from this workplace.
# Rows: (g, C11, C22, C23, C33); g = a/b for a <= b (first block), b/a for a >= b (second).
_KALKER_A_OVER_B_SMALL = np.array([  # a/b = g <= 1
    (0.1, 3.31, 2.52, 0.473, 6.42), (0.2, 3.37, 2.63, 0.603, 3.46), (0.3, 3.44, 2.75, 0.715, 2.49),
    (0.4, 3.53, 2.88, 0.823, 2.02), (0.5, 3.62, 3.01, 0.929, 1.74), (0.6, 3.72, 3.14, 1.03, 1.56),
    (0.7, 3.81, 3.28, 1.14, 1.43), (0.8, 3.91, 3.41, 1.25, 1.34), (0.9, 4.01, 3.54, 1.36, 1.27),
    (1.0, 4.12, 3.67, 1.47, 1.21)])
_KALKER_B_OVER_A_SMALL = np.array([  # b/a = g <= 1 (a/b = 1/g >= 1)
    (0.9, 4.22, 3.81, 1.59, 1.16), (0.8, 4.36, 3.99, 1.75, 1.10), (0.7, 4.54, 4.21, 1.95, 1.05),
    (0.6, 4.78, 4.50, 2.23, 1.01), (0.5, 5.10, 4.90, 2.62, 0.958), (0.4, 5.57, 5.48, 3.24, 0.912),
    (0.3, 6.34, 6.40, 4.32, 0.868), (0.2, 7.78, 8.14, 6.63, 0.828), (0.1, 11.7, 12.8, 14.6, 0.795)])


def kalker_coefficients(a_over_b: float) -> tuple[float, float, float, float]:
    """(C11, C22, C23, C33) [-] for the contact ellipse ratio a/b, linear interpolation in the
    table (0.1 <= a/b <= 10)."""
    ratio = np.concatenate([_KALKER_A_OVER_B_SMALL[:, 0], 1.0 / _KALKER_B_OVER_A_SMALL[:, 0]])
    table = np.vstack([_KALKER_A_OVER_B_SMALL[:, 1:], _KALKER_B_OVER_A_SMALL[:, 1:]])
    if not 0.1 <= a_over_b <= 10.0:
        raise ValueError(f"contact ellipse ratio a/b = {a_over_b:.3g} outside Kalker's table 0.1…10")
    return tuple(float(np.interp(a_over_b, ratio, table[:, j])) for j in range(4))


@dataclass(frozen=True)
class HertzContact:
    """Semi-axes of the Hertz contact ellipse."""

    a: float  # longitudinal semi-axis [m]
    b: float  # lateral semi-axis [m]


def hertz_contact(normal_force: float, wheel_radius: float, rail_head_radius: float,
                  young: float, poisson: float) -> HertzContact:
    """Hertz ellipse of a conical wheel (radius ``wheel_radius`` in the rolling direction, flat
    across) on a rail head of transverse radius ``rail_head_radius`` (Johnson, Contact Mechanics,
    §4.2, eqs. 4.37–4.39)."""
    curvature_x = 0.5 / wheel_radius  # A, rolling direction
    curvature_y = 0.5 / rail_head_radius  # B, lateral
    e_star = young / (2 * (1 - poisson**2))
    small, large = sorted((curvature_x, curvature_y))  # semi-axis 'major' goes with small curvature

    def ratio_error(e2: float) -> float:
        K, E = ellipk(e2), ellipe(e2)
        return ((E / (1 - e2) - K) / (K - E)) - large / small

    ratio = large / small
    # nearly equal curvatures: circular contact (the ellipse equation has a spurious root at e² → 0)
    e2 = 0.0 if ratio - 1 < 1e-6 else brentq(ratio_error, 0.1 * min(ratio - 1, 1), 1 - 1e-12)
    if e2 == 0.0:
        major = (3 * normal_force / (4 * e_star * 2 * small)) ** (1 / 3)
        minor = major
    else:
        K, E = ellipk(e2), ellipe(e2)
        major = (3 * normal_force * (K - E) / (2 * math.pi * e_star * e2 * small)) ** (1 / 3)
        minor = major * math.sqrt(1 - e2)
    if curvature_x <= curvature_y:
        return HertzContact(a=major, b=minor)
    return HertzContact(a=minor, b=major)


@dataclass(frozen=True)
class KalkerCoefficients:
    """Linear creep coefficients f_ij (Kalker): f11, f22 [N], f23 [N m], f33 [N m^2]."""

    f11: float
    f22: float
    f23: float
    f33: float
    contact: HertzContact


def kalker_creep_coefficients(normal_force: float, wheel_radius: float, rail_head_radius: float,
                              young: float, poisson: float) -> KalkerCoefficients:
    contact = hertz_contact(normal_force, wheel_radius, rail_head_radius, young, poisson)
    c = math.sqrt(contact.a * contact.b)
    shear = young / (2 * (1 + poisson))
    C11, C22, C23, C33 = kalker_coefficients(contact.a / contact.b)
    return KalkerCoefficients(shear * c**2 * C11, shear * c**2 * C22, shear * c**3 * C23,
                              shear * c**4 * C33, contact)


@dataclass(frozen=True)
class PolachLaw:
    """Polach's creep law (Wear 258 (2005) 992–1000) for the longitudinal direction.

    ``μ_f(w) = μ0 [(1 − A) e^(−B w) + A]`` with slip velocity ``w = s v``,
    ``ε = slope · s / μ_f`` where ``slope = G π a b C11 / (4 N)`` is kept as its own parameter,
    ``μ = (2 μ_f / π) [kA ε / (1 + (kA ε)²) + arctan(kS ε)]``.

    Defined for every creepage: the friction falls with the slip *speed* ``|w| = |s| v`` (a
    speed, whatever the direction of slip), so μ is odd in s (braking creepage gives the
    mirrored force) and bounded by μ_f ≤ μ0 at any slip (slip velocities of metres per second:
    μ_f → μ0 A).  At s = 0 the kink of |s| enters μ only at order s⁴ (ε ∝ s/μ_f and F is odd), so
    μ and ∂μ/∂s are continuous there.
    """

    mu0: float  # [-]
    A: float  # [-]
    B: float  # [s/m]
    kA: float  # [-]
    kS: float  # [-]
    slope: float  # [-] initial creep slope (dμ/ds at s = 0 is (2/π)(kA + kS) slope μ_f/μ_f)

    def coefficients(self) -> tuple[float, float, float, float, float, float]:
        """(mu0, A, B, kA, kS, slope): the arguments of :func:`polach_mu_and_slope`."""
        return self.mu0, self.A, self.B, self.kA, self.kS, self.slope

    def mu(self, s, v):
        """Adhesion coefficient μ(s, v) [-] at creepage s [-] and speed v [m/s]."""
        return polach_mu_and_slope(s, v, *self.coefficients())[0]

    def dmu_ds(self, s, v):
        """∂μ/∂s at (s, v) [-]."""
        return polach_mu_and_slope(s, v, *self.coefficients())[1]

    def maximum(self, v: float) -> tuple[float, float]:
        """(s at the creep maximum, μ_max) at speed v [m/s]."""
        f = lambda s: float(self.dmu_ds(s, v))  # noqa: E731
        lo, hi = 1e-7, 1e-3
        while f(hi) > 0:
            lo, hi = hi, hi * 2
            if hi > 1.0:
                raise ValueError("creep law has no maximum below s = 1")
        s_max = brentq(f, lo, hi, xtol=1e-14, rtol=1e-12)
        return s_max, float(self.mu(s_max, v))


def polach_mu_and_slope(s, v: float, mu0: float, A: float, B: float, kA: float, kS: float,
                        slope: float):
    """Polach's μ(s, v) [-] and ∂μ/∂s [-] (:class:`PolachLaw`), for a creepage s [-] (scalar or
    array; real, or complex for a complex-step derivative: |s| is then continued analytically as
    sign(Re s)·s) at the speed v [m/s].  The one implementation of the law: the nonlinear step
    loop calls it every Newton iteration on a few wheels, so it is written with few array
    operations."""
    s = np.asarray(s)
    if np.iscomplexobj(s):
        sign = np.sign(s.real)
        decay = np.exp(-(B * v) * (sign * s))
        signed_decay = sign * decay
    else:  # (a parameter may still be complex: a complex step in B, v …)
        s = s.astype(float, copy=False)
        decay = np.exp(-(B * v) * np.abs(s))
        signed_decay = np.sign(s) * decay  # at s = 0 its factor F is 0 anyway
    c1 = mu0 * (1.0 - A)
    mu_f = c1 * decay + mu0 * A  # friction falling with the slip speed |s| v
    dmu_f = signed_decay * (-c1 * B * v)
    inverse = 1.0 / mu_f
    eps = (slope * s) * inverse
    deps = (slope - eps * dmu_f) * inverse
    a = kA * eps
    k = kS * eps
    a2 = a * a
    aa = 1.0 + a2
    F = a / aa + np.arctan(k)
    dF = kA * (1.0 - a2) / (aa * aa) + kS / (1.0 + k * k)
    c = 2.0 / math.pi
    return c * mu_f * F, c * (dmu_f * F + mu_f * dF * deps)


CREEP_PRESETS = {
    # Polach 2005, Table 1 (dry and wet rail); mu0 as in the spec; the slope is the calibrated one.
    "dry": {"polach_kA": 1.00, "polach_kS": 0.40, "polach_A": 0.40, "polach_B": 0.60, "polach_mu0": 0.55},
    "wet": {"polach_kA": 0.30, "polach_kS": 0.10, "polach_A": 0.40, "polach_B": 0.20, "polach_mu0": 0.30},
}


def creep_block(b11: float, b22: float, b23: float, b33: float, r0: float) -> np.ndarray:
    """6 x 6 creep damping block on a rim's coordinates ``[x, y, z, rx, ry, rz]`` (eq. 19 of the
    study, which writes it in the order ``[u, v, w, φ, ϑ, ψ] = [y, z, x, ry, rz, rx]``).

    b11 [N s/m] = N0 μ'(s0)/v, b22 [N s/m] = f22/v, b23 [N s] = f23/v, b33 [N s m] = f33/v.
    """
    X, Y, _, RX, RY, RZ = range(6)  # the vertical z has no creep term
    B = np.zeros((6, 6), dtype=np.result_type(b11, b22, b23, b33, r0, float))  # complex step too
    # longitudinal: slip velocity r0 ω_y − ẋ,  F_x = b11 (r0 ṙy − ẋ), M_y = −r0 F_x
    B[X, X], B[X, RY], B[RY, X], B[RY, RY] = b11, -r0 * b11, -r0 * b11, r0 * r0 * b11
    # lateral: slip velocity ẏ + r0 ṙx; spin ṙz.  F_y = −b22 (ẏ + r0 ṙx) − b23 ṙz, M_x = r0 F_y,
    # M_z = b23 (ẏ + r0 ṙx) − b33 ṙz
    B[Y, Y], B[Y, RX], B[Y, RZ] = b22, r0 * b22, b23
    B[RX, Y], B[RX, RX], B[RX, RZ] = r0 * b22, r0 * r0 * b22, r0 * b23
    B[RZ, Y], B[RZ, RX], B[RZ, RZ] = -b23, -r0 * b23, b33
    return B
