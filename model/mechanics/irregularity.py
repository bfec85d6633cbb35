"""Rail–wheel surface deviations Δ_j [m] (eq. 4's irregularities): what they do to the linear model.

A deviation Δ_j between rail and rim at wheel j (positive where the rail rises into the wheel or
the wheel's radius grows; a rail defect and a wheel defect act alike in the contact) compresses
the track's mass–spring–damper of eq. (11) as the rim's own vertical motion does with the
opposite sign.  The vertical wheel force becomes

    N_j = N0 − (m_R (z̈_j − Δ̈_j) + b_R (ż_j − Δ̇_j) + k_R (z_j − Δ_j))          (z_j: ``IDk.rimNN.z``)

so the rim's vertical coordinate gets the generalized force ``k_R Δ_j + b_R Δ̇_j + m_R Δ̈_j``
(upwards), and the longitudinal creep force T_j = μ(s, v) N_j (eq. 8) changes at the operating
creepage by ``μ(s0, v) ΔN_j`` with ``ΔN_j = N_j − N0``, in the sense of the steady traction
(+x at every contact point, the rim's pattern ``e_x − r0 e_ry``).

ΔN_j holds the rim's own vertical motion as well as Δ_j: at low frequency the wheel follows the
rail (z_j ≈ Δ_j) and the wheel force hardly changes.  Its state part
``−μ(s0) (m_R z̈_j + b_R ż_j + k_R z_j)`` on the contact's longitudinal pattern is the *wheel-force
coupling*: non-symmetric terms of M, B and K from each rim's ``z`` column into its ``x`` and ``ry``
rows.  The study's linearization (eq. 14) keeps N = N0 in the creep force; the short-circuit
analyses keep that form exactly, and the coupling belongs to the running system the
irregularities drive (:func:`model.analysis.eigen.running_system`).

The running system::

    (M + M_c) q̈ + (B_total + B_c) q̇ + (K + K_c) q = G_q Δ + G_v Δ̇ + G_a Δ̈

one column of ``G_q``, ``G_v``, ``G_a`` per wheel (:func:`irregularity_inputs`): ``k_R``, ``b_R``,
``m_R`` times ``e_z + μ(s0) (e_x − r0 e_ry)`` of the wheel's rim; ``M_c``, ``B_c``, ``K_c`` are
``m_R``, ``b_R``, ``k_R`` times ``μ(s0) (e_x − r0 e_ry) e_zᵀ`` summed over the rims (the state part
of μ ΔN_j moved to the left-hand side).  With Δ = 0 and without the coupling this is eq. (20).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import OperatingPoint, creep_coefficients, longitudinal_creep_pattern

SUFFIX = ".irregularity"
UNIT = "m"


def irregularity_inputs(model: BogieModel) -> tuple[str, ...]:
    """The four wheels' surface deviations as inputs, ``IDk.rimNN.irregularity`` [m], in the
    order of ``model.rims`` (ID1's rims 12 and 14, then ID2's)."""
    return tuple(f"{rim}{SUFFIX}" for rim in model.rims)


def is_irregularity(name: str) -> bool:
    return name.endswith(SUFFIX)


@dataclass(frozen=True)
class IrregularityForces:
    """The irregularities' generalized forces and the wheel-force coupling at an operating point.

    Generalized force (n) = ``G_q Δ + G_v Δ̇ + G_a Δ̈`` with Δ (4) [m, m/s, m/s²]; the running
    system adds ``M_c``, ``B_c``, ``K_c`` (n x n) to M, B_total, K (module docstring)."""

    names: tuple[str, ...]  # IDk.rimNN.irregularity, one per column
    G_q: np.ndarray  # (n, 4) [N/m, N]: k_R (e_z + μ0 (e_x − r0 e_ry))
    G_v: np.ndarray  # (n, 4) [N s/m, N s]: b_R (…)
    G_a: np.ndarray  # (n, 4) [kg, kg m]: m_R (…)
    M_c: np.ndarray  # (n, n) [kg, kg m]: μ0 m_R (e_x − r0 e_ry) e_zᵀ per rim
    B_c: np.ndarray  # (n, n) [N s/m, N s]
    K_c: np.ndarray  # (n, n) [N/m, N]
    mu: float  # μ(s0, v) [-]: the creep force per unit wheel force

    def column(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"unknown irregularity input '{name}'; known: "
                           f"{', '.join(self.names)}") from None

    def force(self, name: str, s: complex) -> np.ndarray:
        """Generalized force (n, complex) of ``Δ = Re(e^(st))`` at wheel ``name``: ``G_q + s G_v
        + s² G_a`` (s = iω [1/s])."""
        j = self.column(name)
        return self.G_q[:, j] + s * self.G_v[:, j] + s * s * self.G_a[:, j]


def irregularity_forces(model: BogieModel, op: OperatingPoint) -> IrregularityForces:
    """:class:`IrregularityForces` at ``op``: the track's ``k_R``, ``b_R``, ``m_R`` on each rim's
    ``z`` and, times μ(s0, v), on the contact's longitudinal pattern (module docstring)."""
    p = model.parameters
    track = np.array([p["track_stiffness"], p["track_damping"], p["track_mass"]])
    mu = creep_coefficients(p, op).mu
    pattern = longitudinal_creep_pattern(model)  # (n, 4): e_x − r0 e_ry, traction sense +x
    E = np.zeros((model.n, len(model.rims)))  # the rims' vertical coordinates
    for column, index in enumerate(model.rims.values()):
        E[index[2], column] = 1.0  # [x, y, z, rx, ry, rz]: z
    unit = E + mu * pattern  # generalized force of a unit rise of the wheel force, per wheel
    G_q, G_v, G_a = (value * unit for value in track)
    # the state part of ΔN_j on the longitudinal pattern only: the vertical part is already the
    # track's own spring, damper and mass in K, B, M
    coupling = mu * pattern @ E.T  # (n, n): rim z -> the contact's longitudinal force
    return IrregularityForces(irregularity_inputs(model), G_q, G_v, G_a, track[2] * coupling,
                              track[1] * coupling, track[0] * coupling, float(mu))
