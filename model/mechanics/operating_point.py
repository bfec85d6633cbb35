"""Operating point: creepage, speed, wheel force, motor slope, and what they add to the model.

``B_total = B + b_M B_M + B_ad(s0, v, N0)`` (eq. 20); the constant ``B`` is never re-assembled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model.contact.creep import KalkerCoefficients, PolachLaw, creep_block, kalker_creep_coefficients
from model.mechanics.assembly import BogieModel
from model.mechanics.parameters import Parameters

KMH = 1 / 3.6  # m/s per km/h
V_MIN, V_MAX = 1 * KMH, 500 * KMH  # speed range of the linearized model [m/s]


class OperatingPointError(ValueError):
    """An operating point outside the model's domain."""


@dataclass(frozen=True)
class OperatingPoint:
    """Where the bogie runs before the fault (SI units)."""

    s0: float  # longitudinal creepage [-], 0 < s0 < 1
    v: float  # forward speed [m/s]
    N0: float  # static vertical wheel force [N]
    b_M: float  # falling slope of the healthy motor's characteristic [N m s/rad]

    def __post_init__(self) -> None:
        # the linearization (creep damping ∝ 1/v, Hertz contact ∝ N0) needs v and N0 well above 0
        checks = (("creepage s0", self.s0, 0.0, 1.0, False, "between 0 and 1 (exclusive)"),
                  ("speed v", self.v, V_MIN, V_MAX, True, "1 to 500 km/h"),
                  ("wheel force N0", self.N0, 1e3, 1e6, True, "1e3 to 1e6 N"),
                  ("motor slope b_M", self.b_M, 0.0, 1e9, True, "0 to 1e9 N m s/rad"))
        for label, value, low, high, closed, allowed in checks:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise OperatingPointError(f"{label} must be a number, got {value!r}")
            inside = low <= value <= high if closed else low < value < high
            if not math.isfinite(value) or not inside:
                raise OperatingPointError(f"{label} = {value:g} is not allowed: must be {allowed}")

    @property
    def v_kmh(self) -> float:
        return self.v / KMH

    @classmethod
    def from_kmh(cls, s0: float, v_kmh: float, N0: float, b_M: float) -> OperatingPoint:
        if not isinstance(v_kmh, int | float) or isinstance(v_kmh, bool):
            raise OperatingPointError(f"speed v must be a number, got {v_kmh!r}")
        return cls(s0, v_kmh * KMH, N0, b_M)

    def as_dict(self) -> dict[str, float]:
        return {"s0": self.s0, "v_kmh": self.v_kmh, "N0": self.N0, "b_M": self.b_M}


def default_operating_point(parameters: Parameters, s0: float = 0.005,
                            v_kmh: float = 120.0) -> OperatingPoint:
    """The operating point (s0 [-], v_kmh [km/h]) with the set's wheel force N0 and motor slope
    b_M.

    Example::

        >>> from model import default_operating_point, load_parameters
        >>> op = default_operating_point(load_parameters(), s0=0.005, v_kmh=120)
        >>> op.s0, round(op.v, 3)                       # v in m/s inside
        (0.005, 33.333)
    """
    return OperatingPoint.from_kmh(s0, v_kmh, parameters["wheel_force"], parameters["motor_slope"])


def creep_law(parameters: Parameters, N0: float | None = None) -> PolachLaw:
    """Polach's law with the parameters of the set; the initial slope scales as N^(−1/3) (Hertz)
    from the set's reference wheel force."""
    p = parameters
    N0 = p["wheel_force"] if N0 is None else N0
    slope = p["creep_slope"] * (N0 / p["wheel_force"]) ** (-1.0 / 3.0)
    return PolachLaw(p["polach_mu0"], p["polach_A"], p["polach_B"], p["polach_kA"], p["polach_kS"],
                     slope)


def kalker(parameters: Parameters, N0: float) -> KalkerCoefficients:
    p = parameters
    return kalker_creep_coefficients(N0, p["wheel_radius"], p["rail_head_radius"],
                                     p["young_modulus"], p["poisson_ratio"])


@dataclass(frozen=True)
class CreepCoefficients:
    """Linearized contact coefficients at an operating point."""

    mu: float  # μ(s0, v) [-]
    dmu_ds: float  # ∂μ/∂s at s0 [-]
    b11: float  # N0 μ'/v [N s/m] (negative on the falling branch)
    b22: float  # f22/v [N s/m]
    b23: float  # f23/v [N s]
    b33: float  # f33/v [N s m]


def creep_coefficients(parameters: Parameters, op: OperatingPoint) -> CreepCoefficients:
    law = creep_law(parameters, op.N0)
    coefficients = kalker(parameters, op.N0)
    mu = float(law.mu(op.s0, op.v))
    dmu = float(law.dmu_ds(op.s0, op.v))
    return CreepCoefficients(mu, dmu, op.N0 * dmu / op.v, coefficients.f22 / op.v,
                             coefficients.f23 / op.v, coefficients.f33 / op.v)


def line_creep_coefficients(parameters: Parameters, s0_values, v: float,
                            N0: float) -> np.ndarray:
    """:func:`creep_coefficients`' (b11, b22, b23, b33) [N s/m, N s/m, N s, N s m] at every
    creepage of ``s0_values`` [-] at speed v [m/s] and wheel force N0 [N], one row each, with
    the same values: the contact (Hertz, Kalker) depends on N0 only, so it is solved once, and
    μ'(s0) for all creepages at once."""
    law = creep_law(parameters, N0)
    coefficients = kalker(parameters, N0)
    s0_values = np.asarray(s0_values, dtype=float)
    rows = np.empty((len(s0_values), 4))
    rows[:, 0] = N0 * np.asarray(law.dmu_ds(s0_values, v)) / v
    rows[:, 1:] = (coefficients.f22 / v, coefficients.f23 / v, coefficients.f33 / v)
    return rows


def motor_torque(parameters: Parameters, op: OperatingPoint) -> float:
    """Steady motor torque before the fault, M(s0, v) = 2 μ N0 r0 / p [N m] (eq. 7)."""
    mu = float(creep_law(parameters, op.N0).mu(op.s0, op.v))
    return 2 * mu * op.N0 * parameters["wheel_radius"] / parameters["gear_ratio"]


def adhesion_moment(parameters: Parameters, v: float, N0: float) -> float:
    """Maximal adhesion moment of a wheelset M_ad = 2 N0 r0 μ_max(v) [N m]."""
    _, mu_max = creep_law(parameters, N0).maximum(v)
    return 2 * N0 * parameters["wheel_radius"] * mu_max


def longitudinal_creep_pattern(model: BogieModel) -> np.ndarray:
    """n x 4 matrix G with B_long = b11 G Gᵀ: one column per wheel, ``e_x − r0 e_ry``."""
    r0 = model.parameters["wheel_radius"]
    G = np.zeros((model.n, len(model.rims)))
    for column, index in enumerate(model.rims.values()):
        G[index[0], column] = 1.0
        G[index[4], column] = -r0
    return G


def creep_damping(model: BogieModel, coefficients: CreepCoefficients) -> np.ndarray:
    """B_ad: the non-symmetric creep blocks of all four rims (n x n)."""
    r0 = model.parameters["wheel_radius"]
    block = creep_block(coefficients.b11, coefficients.b22, coefficients.b23, coefficients.b33, r0)
    B_ad = np.zeros((model.n, model.n))
    for index in model.rims.values():
        B_ad[np.ix_(index, index)] += block
    return B_ad


def damping_matrix(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """B + b_M B_M + B_ad(s0, v, N0): all damping at the operating point (n x n)."""
    return model.B + op.b_M * model.motor_pattern + creep_damping(
        model, creep_coefficients(model.parameters, op))
