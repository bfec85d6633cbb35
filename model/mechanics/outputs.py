"""Named output quantities ``y = C_q Δq + C_v Δq̇`` and the steady pre-fault loads.

Names follow the DOF scheme: ``<drive>.<element>.<quantity>``, e.g.

* ``ID1.driving_shaft.torque`` — M_DS = k_DS (φ_rotor − φ_pinion) + damping part [N m]
* ``ID1.disc_clutch.torque`` — M_xDC, torque about the shaft axis [N m]; ``…force_x|y|z`` [N]
* ``ID1.claw_clutch.torque`` [N m], ``ID1.gear_mesh.force`` (along the line of action) [N]
* ``ID1.rim12.creep_force`` — longitudinal creep force on the wheel [N]
* ``ID1.wheelset.adhesion_moment`` — r0 × (sum of the two creep forces) [N m]

Torques are about the global +y axis, forces along global axes (see :mod:`model.mechanics.dofs`), for
both drives, so that ID1 and ID2 compare directly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.mechanics.assembly import DRIVES, RIM_NODES, BogieModel
from model.mechanics.operating_point import (
    OperatingPoint,
    creep_coefficients,
    longitudinal_creep_pattern,
    motor_torque,
)


@dataclass(frozen=True)
class OutputMatrices:
    """Output map at an operating point."""

    names: tuple[str, ...]  # output names
    units: tuple[str, ...]  # SI unit of each output
    C_q: np.ndarray  # len(names) x n, on Δq
    C_v: np.ndarray  # len(names) x n, on Δq̇
    steady: np.ndarray  # value of each output before the fault (static preload) [N, N m]

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"unknown output '{name}'; known: {', '.join(self.names)}") from None


def output_matrices(model: BogieModel, op: OperatingPoint) -> OutputMatrices:
    """All named outputs of both drives at ``op``."""
    names, units, rows_q, rows_v = [], [], [], []
    for connection in model.connections:
        for name, unit, row_q, row_v in connection.channels():
            names.append(name)
            units.append(unit)
            rows_q.append(row_q)
            rows_v.append(row_v)
    coefficients = creep_coefficients(model.parameters, op)
    G = longitudinal_creep_pattern(model)  # columns e_x − r0 e_ry per rim, in model.rims order
    r0 = model.parameters["wheel_radius"]
    rim_names = list(model.rims)
    for drive in DRIVES:
        adhesion = np.zeros(model.n)
        for k in RIM_NODES:
            column = rim_names.index(f"{drive}.rim{k}")
            row = -coefficients.b11 * G[:, column]  # ΔT = b11 (r0 ṙy − ẋ)
            names.append(f"{drive}.rim{k}.creep_force")
            units.append("N")
            rows_q.append(np.zeros(model.n))
            rows_v.append(row)
            adhesion += r0 * row
        names.append(f"{drive}.wheelset.adhesion_moment")
        units.append("N m")
        rows_q.append(np.zeros(model.n))
        rows_v.append(adhesion)
    C_q, C_v = np.array(rows_q), np.array(rows_v)
    q0 = static_deflection(model, op)
    steady = C_q @ q0
    # creep forces carry μ N0 each in the steady state
    for i, name in enumerate(names):
        if name.endswith("creep_force"):
            steady[i] = coefficients.mu * op.N0
        elif name.endswith("adhesion_moment"):
            steady[i] = 2 * coefficients.mu * op.N0 * r0
    return OutputMatrices(tuple(names), tuple(units), C_q, C_v, steady)


def static_load(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """Generalized forces of steady traction: both motors' torque M(s0, v) (with reactions on the
    stators), the creep forces μ N0 at the four contact points and the train's resistance at the
    car body that balances them [N, N m]."""
    torque = motor_torque(model.parameters, op)
    f = np.zeros(model.n)
    f += torque * model.short_circuit_force  # drive 1: the motor torque in its driving sense
    rotor2, stator2 = model.dofs.index("ID2.rotor.ry"), model.dofs.index("ID2.stator.ry")
    f[rotor2] -= torque
    f[stator2] += torque
    mu = creep_coefficients(model.parameters, op).mu
    G = longitudinal_creep_pattern(model)
    f += mu * op.N0 * G.sum(axis=1)  # T in +x at each contact point: f = T (e_x − r0 e_ry)
    # the train's resistance at the car body (drawbar pull): in the steady state it equals the
    # tractive effort, which the traction link passes from the frame to the car body
    f[model.dofs.index("CB.x")] -= mu * op.N0 * G.shape[1]
    return f


def static_deflection(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """Static deflection under steady traction, orthogonal to the rigid-body modes [m, rad].

    The load is self-equilibrated about each drivetrain's spin (motor torque × p = creep moment)
    when the motor torque is M(s0, v) of eq. 7, and along the vehicle's translation and yaw (the
    drawbar pull balances the creep forces, which have no moment about the bogie centre), so
    K q0 = f0 has a solution.
    """
    f = static_load(model, op)
    R = model.rigid_body_modes
    # K is singular only along R: solve the bordered system [K R; Rᵀ 0]
    n, r = model.n, R.shape[1]
    bordered = np.block([[model.K, R], [R.T, np.zeros((r, r))]])
    solution = np.linalg.solve(bordered, np.concatenate([f, np.zeros(r)]))
    return solution[:n]
