"""Which published numbers a bogie can reach together: reduced models of the study's suspected
contradictions, each against the plausible hardware (the calibration bounds,
:mod:`model.studies.calibration_bounds`).

**(a) The torsional chain of mode 2.**  Table 1's mode 2 (2.69 Hz, ID1's rotor and gears against
the disc clutch) has Re −0.041 1/s at s0 = 0.005 and −0.060 at 0.014, while at 0.014 the study's
largest divergence, +7.031 1/s, is the spin of a wheelset with its drive on the falling creep
slope.  The reduced model is the two-inertia chain: J1 = J_rotor p² + J_pinion p² + J_gear (rotor
and gears, on the wheelset's side of the gearing), J2 (the wheelset side beyond the disc clutch:
wheel discs, rims, hollow shaft), the disc clutch k with its own damping c_dc, the motor slope
b = b_M p² on J1 and the creep damper c on J2 (c = 2 r0² N0 ∂μ/∂s / v: positive on the rising
creep slope, negative on the falling one)::

    J1 θ1'' + c_dc (θ1' − θ2') + k (θ1 − θ2) + b θ1' = 0
    J2 θ2'' + c_dc (θ2' − θ1') + k (θ2 − θ1) + c θ2' = 0

For light damping its twisting mode's real part is −[c (J1/J2)² + b + c_dc (1 + J1/J2)²] / (2 m)
with the modal inertia m = J1 (J1 + J2) / J2, and the spin's −(b + c)/(J1 + J2): with b = c_dc = 0
the twisting mode carries Re_spin · J1 / (2 J2) of the spin's.  Since Re_twist falls with c and the
creep damper at 0.014 (a divergence) is below the one at 0.005 (c14 < 0 <= c5), mode 2 is always
*less* damped at 0.014 than at 0.005 — the published pair (−0.041 then −0.060) is the other way
round.  :func:`torsional_chain_proof` scans the plausible box (J_rotor, p, J2, the disc clutch's
damping ratio, b_M), sets c14 so that the chain's spin is the published divergence, and reports
the least difference Re_twist(0.014) − Re_twist(0.005) any of them can have (the study's is
−0.019 1/s).

**(b) The suspension modes' real parts.**  Table 1's car body bounce (−0.032 ± i 1.262),
frame pitch (−0.199 ± i 5.425) and frame bounce (−0.056 ± i 5.449) at s0 = 0.005 are damping
ratios of 0.4 %, 0.6 % and 0.16 %.  :func:`suspension_proof` computes them on the full model of a
set with the vertical dampers at their lower hardware bounds (the least damping the bounds allow
them) and the dampers each published real part needs (the real part is linear in a damper's rate
for light damping: a first-order modal-damping model, checked against the full solve).

**(c) The wheelsets' longitudinal and yaw modes against the divergence:**
:mod:`model.studies.wheelset_reachability`.

Plain dataclasses; numpy/scipy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from model.mechanics.parameters import Parameters
from model.studies.calibration_bounds import FREE_PARAMETERS
from model.studies.calibration_targets import (
    S0_STABLE,
    TABLE1_IM_HZ,
    TABLE1_RE,
    TABLE1_UNSTABLE,
)

_BOUNDS = {f.name: f for f in FREE_PARAMETERS}
MODE2_HZ = TABLE1_IM_HZ[1]  # [Hz] mode 2 at s0 = 0.005
MODE2_RE_STABLE, MODE2_RE_UNSTABLE = TABLE1_RE[1], TABLE1_UNSTABLE[1][0]  # [1/s]
# the wheelset side beyond the disc clutch: two wheel discs and two rims (40 and 80 kg m^2 each in
# the estimate), the hollow shaft and axle; x0.6 … x1.6 as the estimate's other inertias
J2_RANGE = (150.0, 400.0)  # [kg m^2]
# the disc clutch's own damping ratio in the twisting mode: rubber loss factors η 0 … 0.5 (ζ = η/2)
DISC_CLUTCH_ZETA_RANGE = (0.0, 0.25)
MODE2_FREQUENCY_TOLERANCE = 0.05  # [-] a chain has the study's mode 2 within Table 1's acceptance


# --- (a) the two-inertia torsional chain -------------------------------------------------------

@dataclass(frozen=True)
class Chain:
    """The reduced torsional chain (SI: kg m^2, N m/rad, N m s/rad)."""

    J1: float  # rotor and gears, reduced to the wheelset's side of the gearing
    J2: float  # the wheelset side beyond the disc clutch
    k: float  # the disc clutch's torsional stiffness
    c_dc: float = 0.0  # the disc clutch's own damping
    b: float = 0.0  # the motor slope on J1 (b_M p²)

    @classmethod
    def tuned(cls, J1: float, J2: float, frequency_hz: float = MODE2_HZ, zeta_dc: float = 0.0,
              b: float = 0.0) -> Chain:
        """The chain whose undamped twisting mode is at ``frequency_hz``, with the disc clutch's
        damping given as its damping ratio in that mode."""
        omega = 2 * math.pi * frequency_hz
        reduced = J1 * J2 / (J1 + J2)
        return cls(J1, J2, omega**2 * reduced, 2 * zeta_dc * omega * reduced, b)

    def eigenvalues(self, c: float) -> np.ndarray:
        """The chain's four eigenvalues [1/s] with the creep damper ``c`` on J2."""
        M = np.diag([self.J1, self.J2])
        K = self.k * np.array([[1.0, -1.0], [-1.0, 1.0]])
        B = self.c_dc * np.array([[1.0, -1.0], [-1.0, 1.0]]) + np.diag([self.b, c])
        Minv = np.linalg.inv(M)
        A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ B]])
        return np.linalg.eigvals(A)

    def twisting(self, c: float) -> complex:
        """The twisting mode (the eigenvalue with the largest positive imaginary part) [1/s]."""
        lam = self.eigenvalues(c)
        return complex(lam[np.argmax(lam.imag)])

    def spin(self, c: float) -> float:
        """The spin [1/s]: of the two non-oscillating eigenvalues the one away from zero (the
        other is the zero of the chain's free rotation angle)."""
        lam = self.eigenvalues(c)
        slow = lam[np.argsort(np.abs(lam.imag))[:2]].real
        return float(slow[np.argmax(np.abs(slow))])

    def creep_damper_for_spin(self, rate: float) -> float:
        """The creep damper c (< 0 for a divergence) that makes the spin ``rate`` [1/s]."""
        guess = -(rate * (self.J1 + self.J2) + self.b)  # the rigid chain's (k → ∞)
        low = 1.5 * guess - 1.0
        while self.spin(low) < rate:  # the elastic chain's spin is slower: widen the bracket
            low *= 2
        return brentq(lambda c: self.spin(c) - rate, low, 0.0, xtol=1e-9, rtol=1e-12)

    def first_order_twisting_real(self, c: float) -> float:
        """Re of the twisting mode to first order in the damping [1/s] (the closed form)."""
        r = self.J1 / self.J2
        modal = self.J1 * (self.J1 + self.J2) / self.J2
        return -(c * r**2 + self.b + self.c_dc * (1 + r) ** 2) / (2 * modal)


@dataclass(frozen=True)
class ChainCase:
    """One chain of the scan and its real parts."""

    J_rotor: float
    gear_ratio: float
    J1: float
    J2: float
    zeta_dc: float
    motor_slope: float
    spin_rate: float  # [1/s] the published divergence the chain's spin is set to
    c_unstable: float  # creep damper at 0.014 that gives that spin [N m s/rad]
    re_unstable: float  # Re of the twisting mode at 0.014 [1/s]
    re_stable_least: float  # Re of the twisting mode at 0.005, least damped (c5 = 0) [1/s]
    frequency_unstable_hz: float  # its Im at 0.014 [Hz]
    frequency_stable_hz: float  # its Im at 0.005 (c5 = 0) [Hz]

    @property
    def difference(self) -> float:
        """Re(0.014) − Re(0.005) at least (c5 >= 0 only damps more at 0.005) [1/s]."""
        return self.re_unstable - self.re_stable_least


@dataclass(frozen=True)
class ChainProof:
    """The scan of the plausible chains for one published divergence."""

    spin_rate: float  # [1/s] the chains' spin at 0.014
    published_difference: float  # Re(0.014) − Re(0.005) of mode 2 in Table 1: −0.019 [1/s]
    cases: list[ChainCase]  # the scanned chains whose twisting mode oscillates at both creepages
    scanned: int  # chains scanned

    def within_bounds(self) -> list[ChainCase]:
        """The chains with the motor slope within its calibration bounds (the scan adds
        b_M = 0, a drive controlled at constant torque)."""
        return [c for c in self.cases if c.motor_slope >= _BOUNDS["motor_slope"].low]

    def least(self, cases: list[ChainCase] | None = None) -> ChainCase:
        """The chain with the least Re(0.014) − Re(0.005)."""
        return min(self.within_bounds() if cases is None else cases, key=lambda c: c.difference)

    def with_mode2_frequency(self, cases: list[ChainCase] | None = None) -> list[ChainCase]:
        """The chains whose twisting mode lies within 5 % of the study's mode 2 at both
        creepages (2.694 Hz at 0.005, 2.689 Hz at 0.014)."""
        return [c for c in (self.within_bounds() if cases is None else cases)
                if abs(c.frequency_stable_hz / MODE2_HZ - 1) <= MODE2_FREQUENCY_TOLERANCE
                and abs(c.frequency_unstable_hz / TABLE1_UNSTABLE[1][1] - 1)
                <= MODE2_FREQUENCY_TOLERANCE]

    @property
    def reachable(self) -> bool:
        """Whether a chain within the bounds has the study's mode 2 at both creepages: its
        frequencies within 5 % and Re(0.014) − Re(0.005) as published or lower (the creep
        damper at 0.005 only damps more, so the least-damped Re(0.005) is the bound)."""
        return any(c.difference <= self.published_difference
                   and c.re_stable_least >= MODE2_RE_STABLE
                   for c in self.with_mode2_frequency())


def torsional_chain_proof(gear_inertia: float, pinion_inertia: float, spin_rate: float,
                          points: int = 5) -> ChainProof:
    """Scan the plausible chains (rotor inertia and gear ratio within their calibration bounds,
    J2 within :data:`J2_RANGE`, the disc clutch's damping ratio within
    :data:`DISC_CLUTCH_ZETA_RANGE`, b_M within its bounds and 0; ``points`` values each,
    log-spaced for the scale parameters), each with its spin set to ``spin_rate`` at 0.014 by
    its creep damper, the twisting mode at 2.694 Hz undamped (``gear_inertia``,
    ``pinion_inertia`` [kg m^2] the set's)."""
    rotor, ratio, slope = (_BOUNDS[n] for n in ("rotor_inertia", "gear_ratio", "motor_slope"))
    slopes = [0.0, *np.geomspace(slope.low, slope.high, points - 1)]
    cases, scanned = [], 0
    for J_rotor in np.geomspace(rotor.low, rotor.high, points):
        for p in np.linspace(ratio.low, ratio.high, points):
            J1 = (J_rotor + pinion_inertia) * p**2 + gear_inertia
            for J2 in np.geomspace(*J2_RANGE, points):
                for zeta in np.linspace(*DISC_CLUTCH_ZETA_RANGE, points):
                    for b_M in slopes:
                        scanned += 1
                        chain = Chain.tuned(J1, J2, zeta_dc=zeta, b=b_M * p**2)
                        c14 = chain.creep_damper_for_spin(spin_rate)
                        unstable, stable = chain.twisting(c14), chain.twisting(0.0)
                        if min(unstable.imag, stable.imag) <= 0:  # no twisting oscillation
                            continue
                        cases.append(ChainCase(
                            float(J_rotor), float(p), float(J1), float(J2), float(zeta),
                            float(b_M), spin_rate, float(c14), unstable.real, stable.real,
                            unstable.imag / (2 * math.pi), stable.imag / (2 * math.pi)))
    return ChainProof(spin_rate, MODE2_RE_UNSTABLE - MODE2_RE_STABLE, cases, scanned)


# --- (b) the suspension modes' real parts ------------------------------------------------------

SUSPENSION_MODES = {1: "car body bounce", 3: "frame pitch", 4: "frame bounce"}  # Table 1 row
DAMPERS = ("primary_damping_z", "secondary_damping_z")


@dataclass(frozen=True)
class SuspensionMode:
    row: int  # Table 1's row (its character)
    name: str
    published_re: float  # [1/s]
    published_zeta: float
    re_at_set: float  # [1/s] the set's
    re_at_lower_bounds: float  # [1/s] both vertical dampers at their lower bounds
    zeta_at_lower_bounds: float
    slopes: dict  # dRe/dc [1/(N s)] per damper between half its lower bound and the bound (the
    # other at its lower bound), from the full solves
    re_without_dampers: float  # [1/s] the first-order model with both vertical dampers at zero
    scale_needed: float  # both dampers at this share of their lower bounds give the published Re
    re_at_half_bounds: float  # [1/s] the full solve with both dampers at half their lower bounds
    re_first_order: float  # the first-order model there (check of linearity)

    @property
    def factor_below_bounds(self) -> float:
        """How many times below their lower bounds the dampers must be (inf: no positive rate
        gives the published Re)."""
        return 1.0 / self.scale_needed if self.scale_needed > 0 else math.inf

    @property
    def reachable(self) -> bool:
        """Whether both dampers within their bounds can give the published real part (the
        least damping within the bounds is at the lower bounds)."""
        return self.re_at_lower_bounds >= self.published_re


@dataclass(frozen=True)
class SuspensionProof:
    modes: list[SuspensionMode]
    lower_bounds: dict  # damper -> its lower bound [N s/m]
    set_values: dict  # damper -> the set's rate [N s/m]


def _by_character(parameters: Parameters) -> dict[int, complex]:
    from model.analysis.eigen import eigen_analysis
    from model.mechanics.assembly import build_model
    from model.studies.calibration_targets import match_table1_modes, reference_point

    model = build_model(parameters)
    result = eigen_analysis(model, reference_point(parameters, S0_STABLE))
    matched, _ = match_table1_modes(model, result)
    return {row: complex(result.eigenvalues[matched[row - 1]]) for row in SUSPENSION_MODES}


def _zeta(lam: complex) -> float:
    return -lam.real / abs(lam)


def suspension_proof(parameters: Parameters) -> SuspensionProof:
    """The suspension modes of ``parameters`` (matched by Table 2's characters) with its
    vertical dampers, with both at their lower bounds, each at half its bound (the other at its
    bound) and both at half; the rate each published real part needs (first order about the
    lower bounds: Re linear in each damper's rate below them, checked at half the bounds)."""
    lower = {name: _BOUNDS[name].low for name in DAMPERS}
    base = {name: float(parameters[name]) for name in DAMPERS}
    at_set = _by_character(parameters)
    both = _by_character(parameters.replace(**lower))
    half = {name: _by_character(parameters.replace(**{**lower, name: 0.5 * lower[name]}))
            for name in DAMPERS}
    both_half = _by_character(parameters.replace(**{d: 0.5 * lower[d] for d in DAMPERS}))
    modes = []
    for row, name in SUSPENSION_MODES.items():
        published = TABLE1_RE[row - 1]
        slopes = {d: (both[row].real - half[d][row].real) / (0.5 * lower[d]) for d in DAMPERS}
        share = sum(slopes[d] * lower[d] for d in DAMPERS)  # the dampers at their bounds [1/s]
        without = both[row].real - share
        first = both[row].real - 0.5 * share
        scale = (published - without) / share if share < 0 else math.inf
        published_lam = complex(published, 2 * math.pi * TABLE1_IM_HZ[row - 1])
        modes.append(SuspensionMode(row, name, published, _zeta(published_lam), at_set[row].real,
                                    both[row].real, _zeta(both[row]), slopes, without, scale,
                                    both_half[row].real, first))
    return SuspensionProof(modes, lower, base)



def bounce_two_mass(parameters: Parameters, sprung_bogie_mass: float) -> np.ndarray:
    """The vertical bounce of the half car body on the four secondary springs over the bogie's
    sprung mass (``sprung_bogie_mass`` [kg]: the frame with the motors) on the four primary
    springs and dampers: the closed-form reduced model of the car body's and the frame's
    bounce; its two eigenvalues with positive imaginary part [1/s], the car body's first."""
    M = np.diag([parameters["car_body_mass"], sprung_bogie_mass])
    ks, kp = 4 * parameters["secondary_stiffness_z"], 4 * parameters["primary_stiffness_z"]
    cs, cp = 4 * parameters["secondary_damping_z"], 4 * parameters["primary_damping_z"]
    K = np.array([[ks, -ks], [-ks, ks + kp]])
    B = np.array([[cs, -cs], [-cs, cs + cp]])
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ B]])
    lam = np.linalg.eigvals(A)
    upper = lam[lam.imag > 0]
    return upper[np.argsort(upper.imag)]
