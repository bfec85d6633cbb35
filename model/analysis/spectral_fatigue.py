"""Fatigue damage of a Gaussian stationary stress process from its one-sided power spectral
density (PSD), for an S–N curve with a knee: Dirlik's wide-band method and the narrow-band
(Rayleigh) method as a bound.

    curve = SNCurve(fatigue_limit=120e6, knee_cycles=1e6, slope=8.0,
                    slope_beyond_knee=haibach_slope(8.0))
    moments = spectral_moments(f_hz, psd)          # f [Hz], G(f) [Pa²/Hz], one-sided
    dirlik_damage_rate(moments, curve)             # Miner damage per second [1/s]
    narrow_band_damage_rate(moments, curve)        # the Rayleigh bound [1/s]

**S–N curve** (stress amplitudes σ_a, Pa): ``N(σ_a) = N_D (σ_D/σ_a)^k`` for ``σ_a ≥ σ_D`` (the
finite-life line through the knee (N_D, σ_D)); below the knee either no damage (``slope_beyond_knee
= None``: the fatigue limit holds for every cycle) or the line continued with the flatter slope
``k₂`` (``N = N_D (σ_D/σ_a)^k₂``, e.g. Haibach's ``k₂ = 2k − 1``), so that small cycles do damage
once the large ones have started a crack.  Miner's damage of ``nᵢ`` cycles of amplitude ``σ_aᵢ`` is
``Σ nᵢ / N(σ_aᵢ)``.

**Spectral moments** of a one-sided PSD G(f) over frequency f in Hz: ``m_n = ∫ fⁿ G(f) df``
(trapezoidal rule over the given grid); the process's variance is m0, its rate of zero
up-crossings ``ν₀ = √(m2/m0)``, its rate of peaks ``ν_p = √(m4/m2)`` [1/s], the irregularity factor
``γ = m2/√(m0 m4)`` (1 for a narrow band) and the mean frequency ``x_m = (m1/m0) √(m2/m4)``.

**Dirlik** (T. Dirlik, *Application of computers in fatigue analysis*, PhD thesis, University of
Warwick, 1985; in the form of N. W. M. Bishop and F. Sherratt, *Finite Element Based Fatigue
Calculations*, NAFEMS 2000): the density of the rainflow amplitudes ``σ_a`` with ``Z = σ_a/√m0`` is

    p(σ_a) = [D1/Q e^(−Z/Q) + D2 Z/R² e^(−Z²/(2R²)) + D3 Z e^(−Z²/2)] / √m0

with ``D1 = 2(x_m − γ²)/(1 + γ²)``, ``R = (γ − x_m − D1²)/(1 − γ − D1 + D1²)``,
``D2 = (1 − γ − D1 + D1²)/(1 − R)``, ``D3 = 1 − D1 − D2``, ``Q = 1.25 (γ − D3 − D2 R)/D1`` (Dirlik
wrote it for the range ``S = 2σ_a``; the same density in amplitudes; R enters squared, its sign
does not matter), and one rainflow cycle per
peak: the damage rate is ``ν_p ∫ p(σ_a)/N(σ_a) dσ_a``.  The integral is taken in closed form: each
term is a gamma (exponential term) or a Rayleigh (the other two) density, so each branch of the
S–N curve gives regularised incomplete gamma functions (``scipy.special.gammaincc`` above the
knee, ``gammainc`` below it).

**Narrow band** (S. O. Rice's Rayleigh peaks; J. W. Miles 1954): ``ν₀`` cycles per second of
Rayleigh-distributed amplitudes, ``p(σ_a) = σ_a/m0 e^(−σ_a²/(2 m0))``; exact for a narrow-band
process, conservative (larger) for a wide-band one (S. Wirsching and M. Light, 1980).  Where the
process is so narrow that Dirlik's coefficients degenerate (``1 − γ < 1e-6``) Dirlik's density is
Rayleigh's and the narrow-band rate is returned.

The process's mean does not enter: the amplitudes are about it.  A mean stress is the caller's,
e.g. by scaling the amplitudes (a PSD scales by the square) to the mean-corrected ones.

:func:`synthesize_history` draws a Gaussian time history with a given one-sided PSD (random phases
on an FFT grid), for checking a spectral estimate against a rainflow count.  SI units: stresses
in Pa, PSDs in Pa²/Hz, frequencies in Hz, times in s, damage rates in 1/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special

NARROW_BAND_LIMIT = 1e-6  # 1 − γ below which Dirlik's density is taken as Rayleigh's [-]


class SpectralFatigueError(ValueError):
    """Data a spectral fatigue estimate cannot use (one-line message naming the quantity)."""


def haibach_slope(slope: float) -> float:
    """Haibach's slope beyond the knee, ``2k − 1`` [-], for the finite-life slope ``slope`` = k."""
    return 2.0 * float(slope) - 1.0


@dataclass(frozen=True)
class SNCurve:
    """An S–N curve in stress amplitudes with a knee (module docstring)."""

    fatigue_limit: float  # σ_D: the amplitude at the knee [Pa]
    knee_cycles: float  # N_D: the cycles at the knee [-]
    slope: float  # k of the finite-life line above the knee [-]
    slope_beyond_knee: float | None = None  # k₂ below the knee [-]; None: no damage below

    def __post_init__(self):
        for label, value in (("fatigue limit", self.fatigue_limit),
                             ("knee cycles", self.knee_cycles), ("slope", self.slope)):
            if not (math.isfinite(value) and value > 0):
                raise SpectralFatigueError(f"S-N curve: the {label} must be > 0, got {value!r}")
        k2 = self.slope_beyond_knee
        if k2 is not None and not (math.isfinite(k2) and k2 >= self.slope):
            raise SpectralFatigueError(f"S-N curve: the slope beyond the knee must be >= the "
                                       f"slope {self.slope:g} (or none), got {k2!r}")

    def cycles_to_failure(self, amplitude) -> np.ndarray:
        """N(σ_a) [-] for stress amplitudes ``amplitude`` [Pa] (inf where no damage is done)."""
        a = np.abs(np.asarray(amplitude, dtype=float))
        with np.errstate(divide="ignore"):
            ratio = self.fatigue_limit / a
            above = self.knee_cycles * ratio**self.slope
            if self.slope_beyond_knee is None:
                below = np.full(a.shape, np.inf)
            else:
                below = self.knee_cycles * ratio**self.slope_beyond_knee
        return np.where(a >= self.fatigue_limit, above, below)

    def amplitude_at(self, cycles: float) -> float:
        """The amplitude σ_a [Pa] at which the curve gives ``cycles`` to failure (the inverse of
        :meth:`cycles_to_failure`; on the line beyond the knee for more cycles than N_D, where
        there is one; ``ValueError`` where there is none)."""
        if not (math.isfinite(cycles) and cycles > 0):
            raise SpectralFatigueError(f"S-N curve: cycles to failure must be > 0, got {cycles!r}")
        if cycles <= self.knee_cycles:
            return self.fatigue_limit * (self.knee_cycles / cycles) ** (1.0 / self.slope)
        if self.slope_beyond_knee is None:
            raise SpectralFatigueError(f"S-N curve: no amplitude lasts {cycles:g} cycles and "
                                       "fails: beyond the knee nothing does damage")
        return self.fatigue_limit * (self.knee_cycles / cycles) ** (1.0 / self.slope_beyond_knee)

    def damage(self, amplitudes, counts) -> float:
        """Miner's sum Σ nᵢ / N(σ_aᵢ) [-] of ``counts`` nᵢ cycles at ``amplitudes`` σ_aᵢ [Pa]."""
        n = np.asarray(counts, dtype=float)
        return float(np.sum(n / self.cycles_to_failure(amplitudes)))

    def as_dict(self) -> dict:
        return {"fatigue_limit": self.fatigue_limit, "knee_cycles": self.knee_cycles,
                "slope": self.slope, "slope_beyond_knee": self.slope_beyond_knee}


@dataclass(frozen=True)
class SpectralMoments:
    """The moments of a one-sided PSD over frequency in Hz (module docstring)."""

    m0: float  # variance [unit²]
    m1: float  # [unit² Hz]
    m2: float  # [unit² Hz²]
    m4: float  # [unit² Hz⁴]

    @property
    def rms(self) -> float:
        """√m0 [unit]."""
        return math.sqrt(self.m0)

    @property
    def upcrossing_rate(self) -> float:
        """ν₀ = √(m2/m0): zero (mean) up-crossings per second [1/s]."""
        return math.sqrt(self.m2 / self.m0)

    @property
    def peak_rate(self) -> float:
        """ν_p = √(m4/m2): peaks (maxima) per second [1/s]."""
        return math.sqrt(self.m4 / self.m2)

    @property
    def irregularity(self) -> float:
        """γ = m2/√(m0 m4) = ν₀/ν_p [-] (1: narrow band)."""
        return self.m2 / math.sqrt(self.m0 * self.m4)

    @property
    def mean_frequency(self) -> float:
        """x_m = (m1/m0) √(m2/m4) [-]."""
        return self.m1 / self.m0 * math.sqrt(self.m2 / self.m4)


def spectral_moments(frequencies_hz, psd) -> SpectralMoments:
    """m0, m1, m2, m4 of the one-sided PSD ``psd`` [unit²/Hz] at ``frequencies_hz`` [Hz]
    (ascending, ≥ 0; trapezoidal rule)."""
    f = np.asarray(frequencies_hz, dtype=float)
    g = np.asarray(psd, dtype=float)
    if f.ndim != 1 or g.shape != f.shape or len(f) < 2:
        raise SpectralFatigueError("PSD: give frequencies and values of the same length >= 2")
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(g))):
        raise SpectralFatigueError("PSD: frequencies and values must be finite")
    if f[0] < 0 or np.any(np.diff(f) <= 0):
        raise SpectralFatigueError("PSD: frequencies must be >= 0 and strictly ascending")
    if np.any(g < 0):
        raise SpectralFatigueError("PSD: a one-sided PSD is >= 0")
    m0, m1, m2, m4 = (float(np.trapezoid(f**n * g, f)) for n in (0, 1, 2, 4))
    if not (m0 > 0 and m2 > 0 and m4 > 0):
        raise SpectralFatigueError("PSD: zero variance or no content above 0 Hz")
    return SpectralMoments(m0, m1, m2, m4)


@dataclass(frozen=True)
class DirlikCoefficients:
    """Dirlik's weights and shape parameters of the amplitude density (module docstring)."""

    D1: float  # weight of the exponential term [-]
    D2: float  # weight of the Rayleigh term of scale R [-]
    D3: float  # weight of the Rayleigh term of scale 1 [-]
    Q: float  # scale of the exponential term [-]
    R: float  # scale of the second Rayleigh term [-]


def dirlik_coefficients(moments: SpectralMoments) -> DirlikCoefficients:
    """D1, D2, D3, Q, R of Dirlik's density for a process with ``moments`` (module docstring)."""
    gamma, x_m = moments.irregularity, moments.mean_frequency
    D1 = 2.0 * (x_m - gamma**2) / (1.0 + gamma**2)
    R = (gamma - x_m - D1**2) / (1.0 - gamma - D1 + D1**2)
    D2 = (1.0 - gamma - D1 + D1**2) / (1.0 - R)
    D3 = 1.0 - D1 - D2
    Q = 1.25 * (gamma - D3 - D2 * R) / D1
    return DirlikCoefficients(D1, D2, D3, Q, R)


def _narrow(moments: SpectralMoments) -> bool:
    return 1.0 - moments.irregularity < NARROW_BAND_LIMIT


def dirlik_amplitude_density(amplitude, moments: SpectralMoments) -> np.ndarray:
    """Dirlik's density of rainflow stress amplitudes p(σ_a) [1/Pa] at ``amplitude`` [Pa]."""
    if _narrow(moments):
        return rayleigh_amplitude_density(amplitude, moments)
    c = dirlik_coefficients(moments)
    z = np.asarray(amplitude, dtype=float) / moments.rms
    density = (c.D1 / c.Q * np.exp(-z / c.Q) + c.D2 * z / c.R**2 * np.exp(-z**2 / (2 * c.R**2))
               + c.D3 * z * np.exp(-z**2 / 2))
    return density / moments.rms


def dirlik_exceedance(amplitude: float, moments: SpectralMoments) -> float:
    """The probability [-] that a rainflow amplitude of Dirlik's density reaches ``amplitude``
    [Pa]: D1 e^(−Z/Q) + D2 e^(−Z²/(2R²)) + D3 e^(−Z²/2) with Z = σ_a/√m0 (Rayleigh's e^(−Z²/2)
    for a narrow band)."""
    z = float(amplitude) / moments.rms
    if _narrow(moments):
        return math.exp(-z * z / 2)
    c = dirlik_coefficients(moments)
    return (c.D1 * math.exp(-z / c.Q) + c.D2 * math.exp(-z * z / (2 * c.R**2))
            + c.D3 * math.exp(-z * z / 2))


def rayleigh_amplitude_density(amplitude, moments: SpectralMoments) -> np.ndarray:
    """The narrow-band density of stress amplitudes σ_a/m0 e^(−σ_a²/(2 m0)) [1/Pa]."""
    a = np.asarray(amplitude, dtype=float)
    return a / moments.m0 * np.exp(-a**2 / (2 * moments.m0))


def _term_damage(weights_scales, lam: float, k: float, upper: bool) -> float:
    """Σ over the density's terms of ∫ (Z/λ)^k f(Z) dZ over Z ≥ λ (``upper``) or Z < λ.
    ``weights_scales``: (kind, weight, scale) with kind "exp" (f = e^(−Z/s)/s) or "rayleigh"
    (f = Z/s² e^(−Z²/(2s²))).  Closed forms: ∫ Z^k e^(−Z/s)/s dZ = s^k Γ(k+1) Q(k+1, λ/s) and
    ∫ Z^k Z/s² e^(−Z²/2s²) dZ = (√2 s)^k Γ(k/2+1) Q(k/2+1, λ²/2s²) over Z ≥ λ (P for Z < λ;
    P, Q the regularised incomplete gamma functions); summed in logarithms, which cannot
    overflow for steep slopes."""
    total = 0.0
    for kind, weight, scale in weights_scales:
        if weight == 0.0:
            continue
        if kind == "exp":
            shape, x, base = k + 1.0, lam / scale, scale / lam
        else:
            shape, x, base = k / 2 + 1.0, lam**2 / (2 * scale**2), math.sqrt(2.0) * scale / lam
        tail = special.gammaincc(shape, x) if upper else special.gammainc(shape, x)
        if tail > 0:
            total += weight * math.exp(k * math.log(base) + special.gammaln(shape)
                                       + math.log(tail))
    return total


def _damage_rate(terms, rate: float, moments: SpectralMoments, curve: SNCurve) -> float:
    """``rate`` cycles per second of amplitudes with the density ``terms`` (in Z = σ_a/√m0)
    against ``curve``: rate · ∫ p(σ_a)/N(σ_a) dσ_a [1/s]."""
    lam = curve.fatigue_limit / moments.rms
    # above the knee 1/N = (σ_a/σ_D)^k / N_D = (Z/λ)^k / N_D
    damage = _term_damage(terms, lam, curve.slope, upper=True)
    if curve.slope_beyond_knee is not None:
        damage += _term_damage(terms, lam, curve.slope_beyond_knee, upper=False)
    return rate * damage / curve.knee_cycles


def dirlik_damage_rate(moments: SpectralMoments, curve: SNCurve) -> float:
    """Miner's damage per second [1/s] of the process with ``moments`` against ``curve`` by
    Dirlik's amplitude density and one cycle per peak (module docstring)."""
    if _narrow(moments):
        return narrow_band_damage_rate(moments, curve)
    c = dirlik_coefficients(moments)
    terms = (("exp", c.D1, c.Q), ("rayleigh", c.D2, abs(c.R)), ("rayleigh", c.D3, 1.0))
    return _damage_rate(terms, moments.peak_rate, moments, curve)


def narrow_band_damage_rate(moments: SpectralMoments, curve: SNCurve) -> float:
    """Miner's damage per second [1/s] by the narrow-band method: ν₀ Rayleigh cycles per second."""
    return _damage_rate((("rayleigh", 1.0, 1.0),), moments.upcrossing_rate, moments, curve)


def synthesize_history(frequencies_hz, psd, duration: float, dt: float,
                       rng: np.random.Generator) -> np.ndarray:
    """A zero-mean Gaussian history sampled every ``dt`` [s] over ``duration`` [s] whose one-sided
    PSD is ``psd`` [unit²/Hz] at ``frequencies_hz`` [Hz] (linear interpolation, 0 outside): on the
    FFT grid Δf = 1/duration each line gets the amplitude √(2 G(f) Δf) and a random phase drawn
    from ``rng`` (a sum of many such lines is Gaussian by the central limit theorem)."""
    n = round(duration / dt)
    if n < 4:
        raise SpectralFatigueError("synthesis: the duration must hold at least 4 steps")
    f_grid = np.fft.rfftfreq(n, dt)
    g = np.interp(f_grid, np.asarray(frequencies_hz, dtype=float), np.asarray(psd, dtype=float),
                  left=0.0, right=0.0)
    df = 1.0 / (n * dt)
    amplitude = np.sqrt(2.0 * g * df)
    amplitude[0] = 0.0  # zero mean
    phase = rng.uniform(0.0, 2.0 * np.pi, len(f_grid))
    spectrum = amplitude * np.exp(1j * phase) * n / 2.0
    return np.fft.irfft(spectrum, n)
