"""Spectral fatigue damage (Dirlik, narrow band) against its closed forms, numerical quadrature
and a time-domain rainflow count of a synthesized Gaussian history of the same spectrum.

Tolerances:

* Closed forms against ``scipy.integrate.quad`` of the density over the S–N curve: 1e-7
  relative (quad's own error estimate is below 1e-10 here; the incomplete gamma functions are
  accurate to ≈ 1e-14).
* Dirlik against rainflow on a wide-band (two-mode) spectrum: the rainflow damage of a record is
  itself random, so the test measures its standard error from independent records and allows 3
  standard errors for it; on top of that Dirlik's density is an empirical fit to rainflow counts
  of simulated histories, not an exact result: the comparisons since Dirlik's thesis (N. W. M.
  Bishop and F. Sherratt, NAFEMS 2000; D. Benasciutti and R. Tovo, Int. J. Fatigue 27, 2005;
  M. Mršnik, J. Slavič and M. Boltežar, Int. J. Fatigue 47, 2013) find it within about 10 % of
  the count for unimodal spectra and further below it for bimodal spectra with well separated
  modes, the more so the steeper the S–N curve: an allowance of 20 %.  Measured here (two modes at
  8 and 45 Hz, γ ≈ 0.7): Dirlik 6 % below the count for k = 3, 13 % for k = 5, 18 % for k = 8
  (standard errors 0.2 %, 0.9 %, 2 %).
* Narrow band: a band 1 Hz wide at 10 Hz (γ ≈ 0.998) is Rice's narrow-band process; the Rayleigh
  amplitudes and ν₀ cycles per second are then exact up to the band's width: 2 % allowance plus 3
  standard errors.  For the wide-band spectrum the narrow-band estimate must exceed the rainflow
  damage (its known conservatism, Wirsching and Light 1980) by more than the scatter.
* Sampling: 2 kHz for content up to 100 Hz, 20 samples per period of the highest line, so a
  sampled peak misses the true one by at most 1 − cos(π/20) ≈ 1.2 % of that line's amplitude
  (the lines near 100 Hz carry < 1 % of the variance).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special

from model.analysis.load_spectrum import rainflow_cycles
from model.analysis.spectral_fatigue import (
    SNCurve,
    SpectralFatigueError,
    dirlik_amplitude_density,
    dirlik_coefficients,
    dirlik_damage_rate,
    dirlik_exceedance,
    haibach_slope,
    narrow_band_damage_rate,
    rayleigh_amplitude_density,
    spectral_moments,
    synthesize_history,
)

MPA = 1e6
RMS = 50 * MPA
F_HZ = np.linspace(0.0, 100.0, 4001)


def _mode(f, fn, zeta):
    r = f / fn
    return 1.0 / ((1 - r**2) ** 2 + (2 * zeta * r) ** 2)


def _scaled(psd):
    """The PSD scaled to an RMS of 50 MPa [Pa²/Hz]."""
    return psd * RMS**2 / np.trapezoid(psd, F_HZ)


TWO_MODES = _scaled(_mode(F_HZ, 8.0, 0.05) + 0.3 * _mode(F_HZ, 45.0, 0.05))
NARROW = _scaled(np.where((F_HZ >= 9.5) & (F_HZ <= 10.5), 1.0, 0.0))
CURVES = [SNCurve(1.2 * RMS, 1e6, 5.0), SNCurve(1.2 * RMS, 1e6, 5.0, haibach_slope(5.0)),
          SNCurve(0.2 * RMS, 2e6, 3.0)]
STEEP = SNCurve(1.5 * RMS, 1e6, 8.0, 15.0)  # scatters more: a slow test with more records


def _rainflow_damage_rates(psd, curves, records=10, duration=100.0, dt=5e-4, seed=11):
    """Per curve: the rainflow damage rate [1/s] of each of ``records`` independent histories."""
    rng = np.random.default_rng(seed)
    rates = np.zeros((len(curves), records))
    for j in range(records):
        cycles = rainflow_cycles(synthesize_history(F_HZ, psd, duration, dt, rng))
        for i, curve in enumerate(curves):
            rates[i, j] = curve.damage(cycles[:, 0] / 2, cycles[:, 2]) / duration
    return rates


# --- the S–N curve ---------------------------------------------------------------------------


def test_sn_curve_through_its_knee_and_both_slopes():
    curve = SNCurve(100 * MPA, 1e6, 5.0, 9.0)
    assert curve.cycles_to_failure(100 * MPA) == pytest.approx(1e6, rel=1e-12)
    assert curve.cycles_to_failure(200 * MPA) == pytest.approx(1e6 / 2**5, rel=1e-12)
    assert curve.cycles_to_failure(50 * MPA) == pytest.approx(1e6 * 2**9, rel=1e-12)
    assert SNCurve(100 * MPA, 1e6, 5.0).cycles_to_failure(99 * MPA) == math.inf
    assert haibach_slope(5.0) == 9.0


def test_miner_sum_of_a_two_level_spectrum_by_hand():
    # 1000 cycles at 200 MPa: N = 1e6 / 2^5 = 31 250; 1e5 cycles at 80 MPa: N = 1e6 (100/80)^9
    curve = SNCurve(100 * MPA, 1e6, 5.0, 9.0)
    hand = 1000 / 31250 + 1e5 / (1e6 * 1.25**9)
    assert curve.damage([200 * MPA, 80 * MPA], [1000, 1e5]) == pytest.approx(hand, rel=1e-12)
    assert SNCurve(100 * MPA, 1e6, 5.0).damage([200 * MPA, 80 * MPA], [1000, 1e5]) \
        == pytest.approx(1000 / 31250, rel=1e-12)


@pytest.mark.parametrize("kwargs", [
    {"fatigue_limit": 0.0, "knee_cycles": 1e6, "slope": 5.0},
    {"fatigue_limit": 1e8, "knee_cycles": -1.0, "slope": 5.0},
    {"fatigue_limit": 1e8, "knee_cycles": 1e6, "slope": math.nan},
    {"fatigue_limit": 1e8, "knee_cycles": 1e6, "slope": 5.0, "slope_beyond_knee": 3.0},
])
def test_bad_curves_refused(kwargs):
    with pytest.raises(SpectralFatigueError):
        SNCurve(**kwargs)


# --- moments, density, closed forms ----------------------------------------------------------


def test_moments_of_a_flat_band():
    f = np.linspace(2.0, 60.0, 20001)
    m = spectral_moments(f, np.full_like(f, 3.0))
    for n, value in ((0, m.m0), (1, m.m1), (2, m.m2), (4, m.m4)):
        assert value == pytest.approx(3.0 * (60.0 ** (n + 1) - 2.0 ** (n + 1)) / (n + 1),
                                      rel=1e-6)
    assert m.peak_rate == pytest.approx(math.sqrt(m.m4 / m.m2))
    assert m.irregularity == pytest.approx(m.upcrossing_rate / m.peak_rate)


@pytest.mark.parametrize(("f", "g"), [
    ([0.0], [1.0]), ([1.0, 0.5], [1.0, 1.0]), ([0.0, 1.0], [1.0, -1.0]), ([0.0, 1.0], [0, 0]),
    ([-1.0, 1.0], [1.0, 1.0]), ([0.0, 1.0], [1.0, math.inf]),
])
def test_bad_psd_refused(f, g):
    with pytest.raises(SpectralFatigueError):
        spectral_moments(f, g)


def test_dirlik_density_is_a_density():
    m = spectral_moments(F_HZ, TWO_MODES)
    c = dirlik_coefficients(m)
    assert c.D1 + c.D2 + c.D3 == pytest.approx(1.0, abs=1e-12)
    assert min(c.D1, c.D2, c.D3, c.Q) > 0
    total, _ = integrate.quad(lambda a: dirlik_amplitude_density(a, m), 0, 20 * RMS,
                              points=[RMS, 3 * RMS])
    assert total == pytest.approx(1.0, rel=1e-8)


@pytest.mark.parametrize("curve", [*CURVES, STEEP], ids=lambda c: f"k{c.slope:g}-{c.slope_beyond_knee}")
@pytest.mark.parametrize("method", ["dirlik", "narrow"])
def test_closed_form_equals_quadrature(curve, method):
    m = spectral_moments(F_HZ, TWO_MODES)
    if method == "dirlik":
        density, rate, closed = dirlik_amplitude_density, m.peak_rate, dirlik_damage_rate(m, curve)
    else:
        density, rate = rayleigh_amplitude_density, m.upcrossing_rate
        closed = narrow_band_damage_rate(m, curve)

    def integrand(a):
        return float(density(a, m)) / float(curve.cycles_to_failure(a))

    above, _ = integrate.quad(integrand, curve.fatigue_limit, 40 * RMS, epsabs=0, epsrel=1e-12,
                              limit=200)
    below = 0.0
    if curve.slope_beyond_knee is not None:
        below, _ = integrate.quad(integrand, 0.0, curve.fatigue_limit, epsabs=0, epsrel=1e-12,
                                  limit=200)
    assert closed == pytest.approx(rate * (above + below), rel=1e-7)


def test_single_line_equals_the_classic_closed_form():
    """A curve whose slope continues beyond the knee is Basquin's N = C σ_a^−k; Dirlik's damage
    rate is then ν_p m0^(k/2) [D1 Q^k Γ(1+k) + √2^k Γ(1+k/2)(|R|^k D2 + D3)] / C."""
    k = 4.0
    curve = SNCurve(100 * MPA, 1e6, k, k)
    C = 1e6 * (100 * MPA) ** k
    m = spectral_moments(F_HZ, TWO_MODES)
    c = dirlik_coefficients(m)
    classic = m.peak_rate * m.m0 ** (k / 2) / C * (
        c.D1 * c.Q**k * special.gamma(1 + k)
        + math.sqrt(2) ** k * special.gamma(1 + k / 2) * (abs(c.R) ** k * c.D2 + c.D3))
    assert dirlik_damage_rate(m, curve) == pytest.approx(classic, rel=1e-10)
    rayleigh = m.upcrossing_rate * m.m0 ** (k / 2) / C * math.sqrt(2) ** k * special.gamma(1 + k / 2)
    assert narrow_band_damage_rate(m, curve) == pytest.approx(rayleigh, rel=1e-10)


def test_synthesized_history_has_the_spectrum_variance():
    x = synthesize_history(F_HZ, TWO_MODES, 50.0, 5e-4, np.random.default_rng(1))
    assert len(x) == 100_000
    assert abs(x.mean()) < 1e-9 * RMS
    # random phases on fixed amplitudes: the variance is the sum of the lines' A²/2, which is
    # the trapezoidal m0 up to the grid's interpolation (Δf = 0.02 Hz against the 0.4 Hz
    # half-power width of the 8 Hz mode)
    assert x.std() == pytest.approx(RMS, rel=0.01)


# --- against rainflow --------------------------------------------------------------------------


def _check_dirlik_against_rainflow(curves, records):
    m = spectral_moments(F_HZ, TWO_MODES)
    assert 0.6 < m.irregularity < 0.85  # wide band: the test is about Dirlik, not Rice
    rates = _rainflow_damage_rates(TWO_MODES, curves, records=records)
    for curve, record_rates in zip(curves, rates, strict=True):
        counted = record_rates.mean()
        standard_error = record_rates.std(ddof=1) / math.sqrt(len(record_rates)) / counted
        assert standard_error < 0.03  # the records are long enough to test against
        dirlik = dirlik_damage_rate(m, curve)
        assert abs(dirlik / counted - 1) <= 0.20 + 3 * standard_error, (curve, dirlik, counted)
        assert narrow_band_damage_rate(m, curve) / counted > 1 + 3 * standard_error


def test_dirlik_against_rainflow_of_a_synthesized_wide_band_history():
    _check_dirlik_against_rainflow(CURVES, records=10)


@pytest.mark.slow
def test_dirlik_against_rainflow_with_a_steep_curve():
    _check_dirlik_against_rainflow([STEEP], records=40)


def test_narrow_band_against_rainflow_of_a_narrow_band_history():
    m = spectral_moments(F_HZ, NARROW)
    assert m.irregularity > 0.99
    curves = [SNCurve(0.2 * RMS, 2e6, 3.0), SNCurve(0.5 * RMS, 1e6, 5.0, haibach_slope(5.0))]
    rates = _rainflow_damage_rates(NARROW, curves, records=10, duration=200.0)
    for curve, record_rates in zip(curves, rates, strict=True):
        counted = record_rates.mean()
        standard_error = record_rates.std(ddof=1) / math.sqrt(len(record_rates)) / counted
        for estimate in (narrow_band_damage_rate(m, curve), dirlik_damage_rate(m, curve)):
            assert abs(estimate / counted - 1) <= 0.02 + 3 * standard_error, (curve, estimate,
                                                                             counted)


def test_dirlik_exceedance_is_the_density_s_tail():
    m = spectral_moments(F_HZ, TWO_MODES)
    for a in (0.0, 0.5 * RMS, 2 * RMS):
        tail, _ = integrate.quad(lambda x: dirlik_amplitude_density(x, m), a, 20 * RMS)
        assert dirlik_exceedance(a, m) == pytest.approx(tail, rel=1e-8)
    narrow = spectral_moments(F_HZ, NARROW)
    # a 1 Hz band at 10 Hz (γ ≈ 0.998): Dirlik's tail is Rayleigh's to a few parts in a thousand
    assert dirlik_exceedance(RMS, narrow) == pytest.approx(math.exp(-0.5), rel=5e-3)
