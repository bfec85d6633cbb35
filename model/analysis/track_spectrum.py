"""The track's vertical irregularity as a random input: a published spectrum, the four wheels'
input spectra at speed v, the outputs' power spectra and RMS.

**The spectrum.**  The vertical track profile (longitudinal level) of the German high-speed track
spectra, in the form used by ERRI/ORE B176 for its "low" level,

    S(Ω) = A_v Ω_c² / ((Ω² + Ω_r²) (Ω² + Ω_c²))        [m² / (rad/m)], one-sided, Ω [rad/m]

with ``A_v = 4.032·10⁻⁷ m²·rad/m``, ``Ω_c = 0.8246 rad/m``, ``Ω_r = 0.0206 rad/m`` (W. W. Guo, H. Xia,
G. De Roeck and K. Liu, "Integral model for train–track–bridge interaction on the Sesia viaduct",
Computers & Structures 112–113 (2012) 205–216; as coded with that reference in D. Cantero's TTB-2D,
SoftwareX 20 (2022) 101253), over wavelengths of 3 to 150 m (the band those sources give).  The
level ``A_v`` scales every PSD linearly and every RMS with its square root.

**In time at speed v.**  A wavenumber Ω passes a wheel at ``f = Ω v / (2π)`` [Hz]; the one-sided PSD
over frequency is ``G(f) = S(2π f / v) · 2π / v`` [m²/Hz] (the spec's ``S(ω/v)/v`` per rad/s, times
2π per Hz), so that the variance is the same in space and in time.

**The four wheels.**  Both rails carry the same profile (the spectrum is the track's vertical
level; its cross level, the difference of the rails, is not modelled), and the rear wheelset meets
it a wheelbase after the front one (:func:`model.analysis.wheel_excitation.wheel_phases`).  The
input spectral matrix is therefore ``G_jk(f) = G(f) e^(i(φ_j − φ_k))`` — fully coherent, rank one —
and each output's PSD with all cross terms is

    G_y(f) = Σ_j Σ_k H_j G_jk H_k* = G(f) |Σ_j H_j(2π f) e^(i φ_j)|²

with H_j from wheel j's deviation on the running system (:mod:`model.mechanics.irregularity`).
The spectral moments ``m_n = ∫ fⁿ G_y df`` (n = 0, 1, 2, 4; RMS = √m0) by adaptive quadrature
(``scipy.integrate.quad_vec``, all outputs and moments at once, relative error 1e-3, the running
system's resonances in the band as break points): a lightly damped mode's peak, a few mHz wide, and
its long tails are integrated to that accuracy (a trapezoidal rule on the frequency response's grid
of nine points per resonance overstates the RMS by several per cent there).  The PSD on that grid
is kept for plots.

Linear, about the operating point (creepage s0 fixed); the wheel follows the rail (no loss of
contact); wavelengths below 3 m (short-wave defects, corrugation) are outside the spectrum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad_vec

from model.analysis.eigen import non_neutral, running_system
from model.analysis.frequency_response import (
    MODEL_FREQUENCY_LIMIT_HZ,
    output_indices,
    resonance_grid,
)
from model.analysis.wheel_excitation import ModalWheels
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import OperatingPoint

MOMENT_RTOL = 1e-3  # relative error of the adaptive quadrature of the spectral moments


class TrackSpectrumError(ValueError):
    """Bad input for a track spectrum or its response (one-line message)."""


@dataclass(frozen=True)
class TrackSpectrum:
    """A vertical track profile spectrum ``S(Ω) = A_v Ω_c² / ((Ω² + Ω_r²)(Ω² + Ω_c²))``."""

    name: str
    A_v: float  # [m² rad/m]
    omega_c: float  # [rad/m]
    omega_r: float  # [rad/m]
    wavelength_min: float  # [m]
    wavelength_max: float  # [m]
    source: str

    def spatial(self, wavenumber) -> np.ndarray:
        """S(Ω) [m²/(rad/m)] at wavenumbers Ω [rad/m] (one-sided; 0 outside the wavelengths)."""
        omega = np.asarray(wavenumber, dtype=float)
        value = self.A_v * self.omega_c ** 2 / ((omega ** 2 + self.omega_r ** 2)
                                                * (omega ** 2 + self.omega_c ** 2))
        inside = (omega >= 2 * math.pi / self.wavelength_max) & (
            omega <= 2 * math.pi / self.wavelength_min)
        return np.where(inside, value, 0.0)

    def temporal(self, f_hz, v: float) -> np.ndarray:
        """G(f) = S(2π f / v) 2π / v [m²/Hz] at a wheel rolling at v [m/s]."""
        return self.spatial(2 * math.pi * np.asarray(f_hz, dtype=float) / v) * 2 * math.pi / v

    def band_hz(self, v: float) -> tuple[float, float]:
        """The frequencies [Hz] the wavelengths reach at v [m/s]: (v/λ_max, v/λ_min)."""
        return v / self.wavelength_max, v / self.wavelength_min

    def variance(self) -> float:
        """∫ S dΩ over the wavelengths [m²], in closed form (partial fractions and arctan)."""
        a, b = self.omega_r, self.omega_c
        low, high = 2 * math.pi / self.wavelength_max, 2 * math.pi / self.wavelength_min

        def primitive(x: float) -> float:
            return (math.atan(x / a) / a - math.atan(x / b) / b) / (b * b - a * a)

        return self.A_v * b * b * (primitive(high) - primitive(low))


SOURCE = ("German high-speed track spectrum (ERRI/ORE B176 form), low irregularity level: W. W. Guo, "
          "H. Xia, G. De Roeck, K. Liu, Computers & Structures 112-113 (2012) 205-216")
LOW = TrackSpectrum("low", 4.032e-7, 0.8246, 0.0206, 3.0, 150.0, SOURCE)
SPECTRA = {"low": LOW}


def track_spectrum(name: str) -> TrackSpectrum:
    try:
        return SPECTRA[name]
    except KeyError:
        raise TrackSpectrumError(f"unknown track spectrum '{name}'; known: "
                                 f"{', '.join(SPECTRA)}") from None


@dataclass(frozen=True)
class RandomResponse:
    """The outputs' PSD and RMS under the random track at one operating point."""

    operating_point: OperatingPoint
    spectrum: TrackSpectrum
    f_hz: np.ndarray  # (F,) [Hz]
    input_psd: np.ndarray  # (F,) G(f) at a wheel [m²/Hz]
    names: tuple[str, ...]
    units: tuple[str, ...]
    transfer: np.ndarray  # (outputs, F) Σ_j H_j e^(iφ_j) [output unit per m]
    psd: np.ndarray  # (outputs, F) [unit²/Hz] on the grid (for plots)
    moments: np.ndarray  # (outputs, 4): m0, m1, m2, m4 [unit², unit² Hz, unit² Hz², unit² Hz⁴]
    rms: np.ndarray  # (outputs,) √m0 [unit]
    stable: bool  # False: the running system has a growing mode (no stationary response)

    def output(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise TrackSpectrumError(f"unknown output '{name}'") from None


def random_response(model: BogieModel, op: OperatingPoint, spectrum: TrackSpectrum = LOW,
                    outputs: list[str] | None = None, points: int = 300) -> RandomResponse:
    """The outputs' PSD and RMS at ``op`` under ``spectrum`` (module docstring), on ``points``
    log-spaced frequencies over the spectrum's band at op.v (up to the model's 1 kHz) plus the
    running system's resonances there."""
    if not 10 <= points <= 100_000:
        raise TrackSpectrumError(f"the grid needs 10 to 100000 points, got {points}")
    f_lo, f_hi = spectrum.band_hz(op.v)
    f_hi = min(f_hi, MODEL_FREQUENCY_LIMIT_HZ)
    lam = running_system(model, op).eigen[0]
    grid = resonance_grid(lam, f_lo, f_hi, points)
    matrices, rows = output_indices(model, op, outputs)
    system = ModalWheels(model, op, rows)
    transfer = system.combined(grid)
    g = spectrum.temporal(grid, op.v)
    psd = g[None, :] * np.abs(transfer) ** 2

    def integrand(f: float) -> np.ndarray:
        value = spectrum.temporal(f, op.v) * np.abs(system.combined(f)[:, 0]) ** 2
        return np.concatenate([value, f * value, f * f * value, f ** 4 * value])

    upper = lam[lam.imag > 0].imag / (2 * math.pi)
    breaks = sorted(float(x) for x in upper if f_lo < x < f_hi)
    # the upper end a hair inside: the spectrum is cut off exactly at the shortest wavelength
    integral, _ = quad_vec(integrand, f_lo, f_hi * (1 - 1e-12), epsrel=MOMENT_RTOL,
                           points=breaks or None, limit=4000)
    moments = integral.reshape(4, len(rows)).T
    rms = np.sqrt(moments[:, 0])
    stable = bool(np.all(lam[non_neutral(lam)].real <= 0))
    return RandomResponse(op, spectrum, grid, g, tuple(matrices.names[i] for i in rows),
                          tuple(matrices.units[i] for i in rows), transfer, psd, moments, rms,
                          stable)


@dataclass(frozen=True)
class SpectralDamage:
    """An output's spectral fatigue estimate under the random track (in the output's unit)."""

    rms: float  # √m0 [unit]
    upcrossing_rate: float  # ν₀ [1/s]
    peak_rate: float  # ν_p [1/s]
    irregularity: float  # γ [-]
    dirlik_rate: float  # Miner damage per second, Dirlik [1/s]
    narrow_band_rate: float  # the Rayleigh bound [1/s]


def spectral_damage(response: RandomResponse, name: str, curve) -> SpectralDamage:
    """Dirlik's damage rate (and the narrow-band bound) of output ``name``'s PSD against the S–N
    curve ``curve`` (:class:`model.analysis.spectral_fatigue.SNCurve`, in the output's unit: a
    torque amplitude for a torque), :mod:`model.analysis.spectral_fatigue`."""
    from model.analysis.spectral_fatigue import (
        SpectralMoments,
        dirlik_damage_rate,
        narrow_band_damage_rate,
    )

    moments = SpectralMoments(*(float(x) for x in response.moments[response.output(name)]))
    return SpectralDamage(moments.rms, moments.upcrossing_rate, moments.peak_rate,
                          moments.irregularity, dirlik_damage_rate(moments, curve),
                          narrow_band_damage_rate(moments, curve))
