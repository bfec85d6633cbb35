"""Unit tests of the wheel–rail contact: Hertz ellipse, Kalker's coefficients, Polach's creep law,
the linearized creep damping block (eq. 19 of the spec).

Expectations come from independent references (Hertz theory, finite differences, the spec's
eq. 19 typed in by hand, the contact-point kinematics), never from the model's output.
"""

from __future__ import annotations

import numpy as np
import pytest

from model.contact.creep import (
    _KALKER_A_OVER_B_SMALL,
    _KALKER_B_OVER_A_SMALL,
    CREEP_PRESETS,
    PolachLaw,
    creep_block,
    hertz_contact,
    kalker_coefficients,
    kalker_creep_coefficients,
)
from model.mechanics.bodies import point_map
from model.mechanics.dofs import AXES6, PAPER_RIM_ORDER


def test_hertz_equal_curvatures_is_the_circular_formula():
    """A wheel of rolling radius R (flat across) on a rail head of transverse radius R is the
    contact of crossed cylinders = a sphere of radius R on a plane: a = (3 N R / (4 E*))^(1/3),
    1/E* = 2 (1 − ν²)/E (Johnson, Contact Mechanics, eq. 4.22)."""
    N, R, E, nu = 1e5, 0.5, 2.1e11, 0.28
    contact = hertz_contact(N, R, R, E, nu)
    e_star = E / (2 * (1 - nu**2))
    radius = (3 * N * R / (4 * e_star)) ** (1 / 3)
    assert contact.a == pytest.approx(radius, rel=1e-12)
    assert contact.b == pytest.approx(radius, rel=1e-12)
    # the elliptic branch joins the circular one: curvatures differing by δ change the semi-axes
    # by O(δ) (first order: −δ/6 and +δ/2 for a and b, from the series of K(e²), E(e²))
    for delta in (1e-2, 1e-3, 1e-4):
        near = hertz_contact(N, R, R * (1 + delta), E, nu)
        assert abs(near.a / radius - 1) < delta
        assert abs(near.b / radius - 1) < delta
        assert near.b > near.a


def test_hertz_ellipse_properties():
    """Swapping the two radii swaps the semi-axes; the semi-axis across the flatter direction is
    longer; the area scales as N^(2/3) and the load equals (2/3) π a b p0 with the Hertz pressure
    p0 consistent between different loads."""
    E, nu = 2.1e11, 0.28
    c1 = hertz_contact(1e5, 0.625, 0.3, E, nu)
    c2 = hertz_contact(1e5, 0.3, 0.625, E, nu)
    assert c1.a == pytest.approx(c2.b, rel=1e-10)
    assert c1.b == pytest.approx(c2.a, rel=1e-10)
    assert c1.a > c1.b  # the wheel (larger radius along x) gives the longer axis along x
    c3 = hertz_contact(8e5, 0.625, 0.3, E, nu)
    assert c3.a / c1.a == pytest.approx(2.0, rel=1e-10)  # (8)^(1/3)
    assert c3.b / c1.b == pytest.approx(2.0, rel=1e-10)


def test_kalker_coefficients_at_table_points_and_between():
    for row in _KALKER_A_OVER_B_SMALL:
        assert kalker_coefficients(row[0]) == pytest.approx(tuple(row[1:]), rel=1e-12)
    for row in _KALKER_B_OVER_A_SMALL:
        assert kalker_coefficients(1 / row[0]) == pytest.approx(tuple(row[1:]), rel=1e-12)
    # linear interpolation between neighbours
    lo, hi = _KALKER_A_OVER_B_SMALL[3], _KALKER_A_OVER_B_SMALL[4]
    mid = kalker_coefficients(0.5 * (lo[0] + hi[0]))
    assert mid == pytest.approx(tuple(0.5 * (lo[1:] + hi[1:])), rel=1e-12)


def test_kalker_coefficients_bounds_and_trends():
    """Bounds a/b ∈ [0.1, 10] (table g = 0.1 for both a/b and b/a); outside: ValueError.
    C11, C22, C23 grow with a/b and C33 falls (Kalker's table): a guard against a row
    stored against the wrong ratio (b/a instead of a/b)."""
    assert kalker_coefficients(0.1)[0] == pytest.approx(3.31)  # Kalker, ν = 0.25
    assert kalker_coefficients(10.0)[0] == pytest.approx(11.7)
    for bad in (0.0999, 10.01, 0.0, -1.0):
        with pytest.raises(ValueError, match="outside"):
            kalker_coefficients(bad)
    ratios = np.geomspace(0.1, 10.0, 61)
    table = np.array([kalker_coefficients(r) for r in ratios])
    assert np.all(np.diff(table[:, 0]) > 0)
    assert np.all(np.diff(table[:, 1]) > 0)
    assert np.all(np.diff(table[:, 2]) > 0)
    assert np.all(np.diff(table[:, 3]) < 0)
    # continuity across a/b = 1 where the two halves of the table meet
    assert np.allclose(kalker_coefficients(1 - 1e-9), kalker_coefficients(1 + 1e-9), rtol=1e-6)


@pytest.mark.parametrize("preset", sorted(CREEP_PRESETS))
def test_polach_derivative_matches_central_differences(preset):
    c = CREEP_PRESETS[preset]
    law = PolachLaw(c["polach_mu0"], c["polach_A"], c["polach_B"], c["polach_kA"], c["polach_kS"],
                    slope=600.0)
    for v in (5.0, 33.3, 55.0):
        for s in np.geomspace(1e-4, 0.3, 25):
            h = 1e-6 * s
            fd = (law.mu(s + h, v) - law.mu(s - h, v)) / (2 * h)
            assert float(law.dmu_ds(s, v)) == pytest.approx(float(fd), rel=1e-6, abs=1e-8)


def test_polach_law_shape():
    """μ(0) = 0, initial slope (2/π)(kA + kS)·slope, a maximum with dμ/ds = 0 and a falling
    branch beyond it; the maximum is the largest value on a fine grid and stays below μ0."""
    c = CREEP_PRESETS["dry"]
    slope = 600.0
    law = PolachLaw(c["polach_mu0"], c["polach_A"], c["polach_B"], c["polach_kA"], c["polach_kS"],
                    slope)
    v = 120 / 3.6
    assert float(law.mu(0.0, v)) == 0.0
    assert float(law.dmu_ds(0.0, v)) == pytest.approx(
        2 / np.pi * (c["polach_kA"] + c["polach_kS"]) * slope, rel=1e-12)
    s_max, mu_max = law.maximum(v)
    assert abs(float(law.dmu_ds(s_max, v))) < 1e-8
    assert float(law.dmu_ds(0.5 * s_max, v)) > 0
    assert float(law.dmu_ds(2.0 * s_max, v)) < 0
    s = np.geomspace(1e-5, 0.5, 400)
    assert mu_max >= float(np.max(law.mu(s, v)))
    assert mu_max == pytest.approx(float(np.max(law.mu(s, v))), rel=1e-4)
    assert mu_max < c["polach_mu0"]


def test_creep_block_longitudinal_part_symmetric_and_psd_for_positive_b11():
    b = creep_block(b11=2.0e5, b22=1.0e6, b23=3.0e3, b33=40.0, r0=0.6)
    X, RY = 0, 4
    longi = b[np.ix_([X, RY], [X, RY])]
    assert np.array_equal(longi, longi.T)
    assert np.linalg.eigvalsh(longi).min() >= -1e-9 * np.abs(longi).max()
    # the pure rolling motion ẋ = r0 ṙy is free of longitudinal creep
    assert np.allclose(longi @ [0.6, 1.0], 0.0)
    # the spin coupling b23 is the antisymmetric (gyroscopic-like) part
    assert not np.allclose(b, b.T)
    antisym = 0.5 * (b - b.T)
    assert np.count_nonzero(np.abs(antisym) > 0) == 4  # (y, rz), (rx, rz) and their transposes


def test_creep_block_matches_equation_19_of_the_spec():
    """Eq. 19 of docs/spec model.md, in the study's order [u, v, w, φ, ϑ, ψ] = [y, z, x, ry, rz, rx]
    (model.dofs.PAPER_RIM_ORDER), typed in here by hand."""
    b11, b22, b23, b33, r0 = -3.1e5, 1.7e6, 4.2e3, 55.0, 0.625
    eq19 = np.array([
        [b22, 0, 0, 0, b23, r0 * b22],
        [0, 0, 0, 0, 0, 0],
        [0, 0, b11, -r0 * b11, 0, 0],
        [0, 0, -r0 * b11, r0**2 * b11, 0, 0],
        [-b23, 0, 0, 0, b33, -r0 * b23],
        [r0 * b22, 0, 0, 0, r0 * b23, r0**2 * b22],
    ])
    assert PAPER_RIM_ORDER == ("y", "z", "x", "ry", "rz", "rx")
    order = [AXES6.index(axis) for axis in PAPER_RIM_ORDER]
    block = creep_block(b11, b22, b23, b33, r0)
    assert np.allclose(block[np.ix_(order, order)], eq19, rtol=1e-14, atol=0)


def test_creep_block_from_contact_point_kinematics():
    """Independent derivation: the contact point (0, 0, −r0) below the rim centre has the velocity
    P q̇ with P = [I, −S(r)]; longitudinal creep force ΔT = −b11 ẋ_c, lateral
    F_y = −b22 ẏ_c − b23 ṙz, spin moment M_z = b23 ẏ_c − b33 ṙz (Kalker's sign convention).
    The generalized force is Pᵀ F + e_rz M_z, and B_ad is minus its derivative w.r.t. q̇."""
    b11, b22, b23, b33, r0 = 2.3e5, 1.1e6, 5.0e3, 70.0, 0.6
    P = point_map(np.array([0.0, 0.0, -r0]))
    e_rz = np.eye(6)[5]
    force = -(b11 * np.outer(np.eye(3)[0], P[0]) + b22 * np.outer(np.eye(3)[1], P[1])
              + b23 * np.outer(np.eye(3)[1], e_rz))  # 3 x 6: F = force @ q̇
    moment = b23 * P[1] - b33 * e_rz  # M_z = moment @ q̇
    generalized = P.T @ force + np.outer(e_rz, moment)
    assert np.allclose(creep_block(b11, b22, b23, b33, r0), -generalized, rtol=1e-14, atol=1e-9)


def test_kalker_creep_coefficients_scale_with_the_contact_size():
    """f11 = G c² C11, f22 = G c² C22, f23 = G c³ C23, f33 = G c⁴ C33 with c = √(ab) (spec §2.2)."""
    N, r_wheel, r_rail, E, nu = 1e5, 0.625, 0.3, 2.1e11, 0.28
    k = kalker_creep_coefficients(N, r_wheel, r_rail, E, nu)
    contact = hertz_contact(N, r_wheel, r_rail, E, nu)
    c = np.sqrt(contact.a * contact.b)
    G = E / (2 * (1 + nu))
    C11, C22, C23, C33 = kalker_coefficients(contact.a / contact.b)
    assert k.f11 == pytest.approx(G * c**2 * C11, rel=1e-12)
    assert k.f22 == pytest.approx(G * c**2 * C22, rel=1e-12)
    assert k.f23 == pytest.approx(G * c**3 * C23, rel=1e-12)
    assert k.f33 == pytest.approx(G * c**4 * C33, rel=1e-12)
    # c ∝ N^(1/3): f22 ∝ N^(2/3) at a fixed ellipse shape
    k8 = kalker_creep_coefficients(8 * N, r_wheel, r_rail, E, nu)
    assert k8.f22 / k.f22 == pytest.approx(4.0, rel=1e-10)


def test_polach_one_law_real_and_complex_branches_agree():
    """The one implementation of Polach's law (used by PolachLaw and by the nonlinear step loop):
    its ∂μ/∂s equals the complex-step derivative of its own μ (the complex branch continues |s|
    as sign(Re s)·s), and it is odd in s.  Complex step h = 1e-30: no subtraction, so agreement
    to rounding (1e-12 relative) is expected."""
    from model.contact.creep import polach_mu_and_slope

    law = (0.45, 0.4, 0.6, 0.9, 0.3, 250.0)  # mu0, A, B [s/m], kA, kS, slope
    v = 120 / 3.6
    s = np.concatenate([-np.logspace(-6, 0, 40), np.logspace(-6, 0, 40)])
    mu, dmu = polach_mu_and_slope(s, v, *law)
    h = 1e-30
    mu_c, _ = polach_mu_and_slope(s + 1j * h, v, *law)
    np.testing.assert_allclose(mu_c.real, mu, rtol=1e-14)
    np.testing.assert_allclose(mu_c.imag / h, dmu, rtol=1e-12)
    mu_neg, dmu_neg = polach_mu_and_slope(-s, v, *law)
    np.testing.assert_allclose(mu_neg, -mu, rtol=1e-14)
    np.testing.assert_allclose(dmu_neg, dmu, rtol=1e-14)
    assert polach_mu_and_slope(0.0, v, *law)[0] == 0.0
