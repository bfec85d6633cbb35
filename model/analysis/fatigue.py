"""Torsional fatigue of a shaft section after DIN 743 (shaft strength: fatigue limit in torsion
with the mean stress's influence), simplified to what the model knows of a section: its outer
diameter D, its bore d_i, the steel's tensile strength, a notch factor and a roughness.

    data = torsional_fatigue(sigma_B=1000e6, strength_diameter=0.016, D=0.12, d_i=0.0,
                             beta_tau=1.8, R_z=6.3e-6, tau_yield=375e6)
    data.tau_WK                                   # fatigue limit of the section [Pa]
    permissible_amplitude(data, tau_mean=40e6)    # τ_ADK at that mean stress [Pa]

The chain (DIN 743-1, -2 and -3; equation by equation in the functions below):

* **Size of the raw part** (technological size factor K1, DIN 743-2, quenched and tempered
  steels): ``K1(d) = 1`` for ``d ≤ d_B``, ``1 − 0.26 lg(d/d_B)`` for ``d_B < d < 300 mm`` and
  0.67 beyond (``d_B = 16 mm``, the reference diameter of DIN 743-3's material table).  The
  tensile strength at the section is ``σ_B(d) = σ_B(d_ref) K1(d)/K1(d_ref)``: a strength given
  for the table's reference diameter (``d_ref = d_B``) is scaled down with the section's size; one
  given for the part itself (an axle's strength under EN 13261, ``d_ref`` = its diameter) is
  taken as it is.
* **Material fatigue limit** in torsion (DIN 743-3): ``τ_W(d) = 0.3 σ_B(d)``.
* **Geometric size factor** (DIN 743-2, bending and torsion): ``K2(d) = 1 − 0.2 lg(d/7.5 mm) /
  lg 20`` for 7.5 mm ≤ d < 150 mm, 0.8 from 150 mm, 1 below 7.5 mm.
* **Surface roughness** (DIN 743-2): ``K_Fσ = 1 − 0.22 lg(R_z/1 µm) (lg(σ_B(d)/20 MPa) − 1)``
  and in torsion ``K_Fτ = 0.575 K_Fσ + 0.425`` (1 for R_z ≤ 1 µm, a polished surface).
* **Total influence factor** ``K_τ = (β_τ / K2(d) + 1/K_Fτ − 1) / K_V`` (K_V = 1: no surface
  hardening) and the section's fatigue limit ``τ_WK = τ_W(d) / K_τ``.
* **Mean stress** (DIN 743-1, case 1: the mean stress stays while the amplitude grows, as the
  traction torque stays while a resonance raises the ripple): the sensitivity
  ``ψ_τK = τ_WK / (2 σ_B(d) − τ_WK)`` and the permissible amplitude ``τ_ADK = τ_WK − ψ_τK τ_mv``
  with ``τ_mv = |τ_m|`` in pure torsion, up to the mean at which the largest stress reaches the
  yield limit: beyond ``τ_mv = (τ_FK − τ_WK)/(1 − ψ_τK)`` it is ``τ_FK − τ_mv``.
* **Safety** ``S = τ_ADK / τ_a`` against the required ``S_min`` (DIN 743-1: 1.2).

**Simplifications** (the model has no drawing of the sections): the notch is one factor β_τ per
section, an input (DIN 743-2 derives it from the radius and the diameters of a shoulder, a groove
or a fit); the effective diameter of the raw part for K1 is the section's outer diameter (DIN
743-2 takes a tube's wall or the forging's size: the outer diameter is the larger, conservative);
only torsion (the bending of an axle under the wheel forces is EN 13103-1's, not checked here);
the yield limit of the section ``τ_FK`` is the section's permissible shear stress of the parameter
set (R_e/√3), without DIN 743's static support factor K2F γ_F ≥ 1 (conservative); no surface
hardening (K_V = 1); the fatigue limit (infinite life; the damage sum over a route is
:mod:`model.studies.life`'s, with an S–N curve through this limit).
Stresses in Pa, lengths in m.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

REFERENCE_DIAMETER = 0.016  # d_B [m] of DIN 743-3's table for quenched and tempered steels
K1_LIMIT_DIAMETER = 0.300  # [m]: K1 is constant from here on
K1_LIMIT = 0.67  # K1 beyond 300 mm [-]
K2_SMALL = 0.0075  # [m]: K2 = 1 below
K2_LARGE = 0.150  # [m]: K2 = 0.8 from here on
TORSION_TO_TENSILE = 0.3  # τ_W = 0.3 σ_B (DIN 743-3)
ROUGHNESS_REFERENCE = 1e-6  # [m]: R_z is taken in µm; at or below 1 µm the surface is polished
STRENGTH_REFERENCE = 20e6  # [Pa]: σ_B is taken over 20 N/mm² in K_Fσ


class FatigueError(ValueError):
    """Data a fatigue check cannot use (one-line message naming the quantity)."""


def technological_size_factor(d: float, d_B: float = REFERENCE_DIAMETER) -> float:
    """K1(d) [-] of the tensile strength of a quenched and tempered steel, raw part of diameter
    ``d`` [m], reference diameter ``d_B`` [m] (module docstring)."""
    if d <= d_B:
        return 1.0
    if d >= K1_LIMIT_DIAMETER:
        return K1_LIMIT
    return 1.0 - 0.26 * math.log10(d / d_B)


def geometric_size_factor(d: float) -> float:
    """K2(d) [-] in bending and torsion for a section of outer diameter ``d`` [m]."""
    if d < K2_SMALL:
        return 1.0
    if d >= K2_LARGE:
        return 0.8
    return 1.0 - 0.2 * math.log10(d / K2_SMALL) / math.log10(20.0)


def roughness_factor_torsion(R_z: float, sigma_B: float) -> float:
    """K_Fτ [-] of a surface of mean roughness depth ``R_z`` [m] on a steel of tensile strength
    ``sigma_B`` [Pa] at the section's size."""
    if R_z <= ROUGHNESS_REFERENCE:
        return 1.0
    bending = 1.0 - 0.22 * math.log10(R_z / ROUGHNESS_REFERENCE) * (
        math.log10(sigma_B / STRENGTH_REFERENCE) - 1.0)
    return 0.575 * bending + 0.425


@dataclass(frozen=True)
class TorsionalFatigue:
    """A section's fatigue data (module docstring); every factor kept, so that a check can be recomputed by hand."""

    D: float  # outer diameter [m]
    d_i: float  # bore [m] (0: solid)
    sigma_B: float  # tensile strength at the section's size σ_B(d) [Pa]
    K1: float  # technological size factor relative to the strength's own diameter [-]
    K2: float  # geometric size factor [-]
    K_F: float  # roughness factor in torsion K_Fτ [-]
    beta_tau: float  # notch factor β_τ [-]
    K_tau: float  # total influence factor K_τ [-]
    tau_W: float  # material fatigue limit in torsion at the size τ_W(d) [Pa]
    tau_WK: float  # the section's fatigue limit [Pa]
    psi: float  # mean stress sensitivity ψ_τK [-]
    tau_FK: float  # the section's yield limit in shear [Pa]

    @property
    def section_modulus(self) -> float:
        """Polar section modulus W_t = π (D⁴ − d_i⁴) / (16 D) [m³]: τ = T / W_t."""
        return math.pi * (self.D**4 - self.d_i**4) / (16 * self.D)

    def as_dict(self) -> dict:
        return {**asdict(self), "W_t": self.section_modulus}


def torsional_fatigue(sigma_B: float, strength_diameter: float, D: float, d_i: float,
                      beta_tau: float, R_z: float, tau_yield: float) -> TorsionalFatigue:
    """The fatigue data of a circular section (outer diameter ``D``, bore ``d_i`` [m]) of a steel
    whose tensile strength is ``sigma_B`` [Pa] at the diameter ``strength_diameter`` [m], with the
    notch factor ``beta_tau`` [-], the roughness ``R_z`` [m] and the shear yield limit
    ``tau_yield`` [Pa] (module docstring)."""
    for label, value in (("tensile strength", sigma_B), ("strength diameter", strength_diameter),
                         ("outer diameter", D), ("shear yield limit", tau_yield)):
        if not (math.isfinite(value) and value > 0):
            raise FatigueError(f"fatigue: the {label} must be > 0, got {value:g}")
    if not 0.0 <= d_i < D:
        raise FatigueError(f"fatigue: need 0 <= bore < outer diameter, got d_i = {d_i:g} m, "
                           f"D = {D:g} m")
    if not (math.isfinite(beta_tau) and beta_tau >= 1.0):
        raise FatigueError(f"fatigue: the notch factor beta_tau must be >= 1, got {beta_tau:g}")
    K1 = technological_size_factor(D) / technological_size_factor(strength_diameter)
    sigma_at_size = sigma_B * K1
    K2 = geometric_size_factor(D)
    K_F = roughness_factor_torsion(R_z, sigma_at_size)
    K_tau = beta_tau / K2 + 1.0 / K_F - 1.0
    tau_W = TORSION_TO_TENSILE * sigma_at_size
    tau_WK = tau_W / K_tau
    if not tau_WK > 0:
        raise FatigueError(f"fatigue: the section's fatigue limit is {tau_WK:g} Pa, not > 0 "
                           "(roughness factor out of its range)")
    psi = tau_WK / (2.0 * sigma_at_size - tau_WK)
    return TorsionalFatigue(D, d_i, sigma_at_size, K1, K2, K_F, beta_tau, K_tau, tau_W, tau_WK,
                            psi, tau_yield)


def permissible_amplitude(data: TorsionalFatigue, tau_mean: float) -> float:
    """τ_ADK [Pa]: the shear stress amplitude the section bears indefinitely about the mean
    shear stress ``tau_mean`` [Pa] (case 1 of DIN 743-1: the mean stays; module docstring);
    0 where the mean alone reaches the yield limit."""
    tau_mv = abs(tau_mean)
    knee = (data.tau_FK - data.tau_WK) / (1.0 - data.psi)
    if tau_mv <= knee:
        amplitude = data.tau_WK - data.psi * tau_mv
    else:
        amplitude = data.tau_FK - tau_mv
    return max(amplitude, 0.0)


def fatigue_safety(data: TorsionalFatigue, tau_mean: float, tau_amplitude: float) -> float:
    """S = τ_ADK / τ_a [-] (inf without an amplitude)."""
    amplitude = abs(tau_amplitude)
    return permissible_amplitude(data, tau_mean) / amplitude if amplitude > 0 else math.inf
