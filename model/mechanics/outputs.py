"""Named output quantities ``y = C_q Δq + C_v Δq̇`` and the steady pre-fault loads.

Names follow the DOF scheme: ``<drive>.<element>.<quantity>``, e.g.

* ``ID1.driving_shaft.torque`` — M_DS = k_DS (φ_rotor − φ_pinion) + damping part [N m]
* ``ID1.disc_clutch.torque`` — M_xDC, torque about the shaft axis [N m]; ``…force_x|y|z`` [N]
* ``ID1.claw_clutch.torque`` [N m], ``ID1.gear_mesh.force`` (along the line of action) [N]
* ``ID1.rim12.creep_force`` — longitudinal creep force on the wheel [N]
* ``ID1.wheelset.adhesion_moment`` — r0 × (sum of the two creep forces) [N m]

Section torques of the two shafts, where the press fits sit (the torque a fit must hold) [N m]:

* ``ID1.hollow_shaft.gear_seat.torque`` — through the seat at the hollow shaft's gear end (node 5),
  where the gear's torque, passed on by the disc clutch, enters the hollow shaft: the torque in
  the shaft next to that node;
* ``ID1.hollow_shaft.torque`` — in the hollow shaft's middle section (node 7);
* ``ID1.axle.wheel_seat_12.torque``, ``ID1.axle.wheel_seat_14.torque`` — through the seat of wheel
  12 or 14: the torque the axle passes into that wheel (the axle's torque on the claw clutch's side
  of the wheel less what goes on to the journal);
* ``ID1.axle.centre.torque`` — in the axle between the wheels, at its centre (node 13).

A section torque is the beam elements' own torsion, ``G J / L (θ_up − θ_down)`` with its
stiffness-proportional damping part, θ the rotation about the axle (``ry``) of the element's end
nearer to the torque's source (up: the gear end of the hollow shaft, the claw clutch's end of the
axle) and of the other end (down); at a node between two elements, their mean.

Torques are about the global +y axis, forces along global axes (see :mod:`model.mechanics.dofs`), for
both drives, so that ID1 and ID2 compare directly; every torque of the drive train is positive in
traction (the side nearer to the motor leads).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.mechanics.assembly import (
    AXLE_CENTRE_NODE,
    AXLE_CLAW_NODE,
    AXLE_GEAR_NODE,
    DISC_CLUTCH_NODE,
    DRIVES,
    HOLLOW_SHAFT_NODES,
    JOURNAL_NODES,
    RIM_NODES,
    BogieModel,
)
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
    for name, row_q, row_v in section_torque_rows(model):
        names.append(name)
        units.append("N m")
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


# section -> the beam elements whose mean torque it is, each (upstream node, downstream node), and
# the elements whose torque it passes on (subtracted: a seat holds what stays in its wheel)
_HS_MIDDLE = HOLLOW_SHAFT_NODES[len(HOLLOW_SHAFT_NODES) // 2]  # node 7
SECTIONS: dict[str, tuple[tuple[tuple[str, str], ...], tuple[tuple[str, str], ...]]] = {
    "hollow_shaft.gear_seat": (((f"hs{DISC_CLUTCH_NODE}", f"hs{DISC_CLUTCH_NODE + 1}"),), ()),
    "hollow_shaft": (((f"hs{_HS_MIDDLE - 1}", f"hs{_HS_MIDDLE}"),
                      (f"hs{_HS_MIDDLE}", f"hs{_HS_MIDDLE + 1}")), ()),
    f"axle.wheel_seat_{RIM_NODES[0]}": (((f"ax{AXLE_CLAW_NODE}", f"ax{RIM_NODES[0]}"),),
                                         ((f"ax{RIM_NODES[0]}", f"ax{JOURNAL_NODES[0]}"),)),
    "axle.centre": (((f"ax{AXLE_CLAW_NODE}", f"ax{AXLE_CENTRE_NODE}"),
                     (f"ax{AXLE_CENTRE_NODE}", f"ax{AXLE_GEAR_NODE}")), ()),
    f"axle.wheel_seat_{RIM_NODES[1]}": (((f"ax{AXLE_GEAR_NODE}", f"ax{RIM_NODES[1]}"),),
                                         ((f"ax{RIM_NODES[1]}", f"ax{JOURNAL_NODES[1]}"),)),
}
SECTION_TORQUES = tuple(f"{drive}.{section}.torque" for drive in DRIVES for section in SECTIONS)


def torsional_stiffness(model: BogieModel, drive: str, up: str, down: str) -> float:
    """G J / L of the beam element between the nodes ``up`` and ``down`` of ``drive`` (e.g.
    "ax10", "ax12") [N m/rad]: the hollow shaft's tube or the solid axle, L the nodes' distance."""
    p = model.parameters
    if up.startswith("hs"):
        outer, inner = p["hollow_shaft_outer_radius"], p["hollow_shaft_inner_radius"]
    else:
        outer, inner = p["axle_radius"], 0.0
    shear_modulus = p["young_modulus"] / (2 * (1 + p["poisson_ratio"]))
    polar = np.pi / 2 * (outer**4 - inner**4)
    length = float(np.linalg.norm(np.real(model.positions[f"{drive}.{down}"]
                                          - model.positions[f"{drive}.{up}"])))
    return shear_modulus * polar / length


def section_torque_rows(model: BogieModel) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, row on Δq, row on Δq̇) of every section torque of :data:`SECTION_TORQUES` [N m]:
    the torsion of the beam elements (module docstring), their damping the shafts' loss time
    times their stiffness (as assembled)."""
    loss = model.parameters["shaft_loss_time"]
    rows = []
    for drive in DRIVES:
        for section, (means, passed) in SECTIONS.items():
            row = np.zeros(model.n)
            for elements, weight in ((means, 1.0 / len(means)), (passed, -1.0)):
                for up, down in elements:
                    k = weight * torsional_stiffness(model, drive, up, down)
                    row[model.dofs.index(f"{drive}.{up}.ry")] += k
                    row[model.dofs.index(f"{drive}.{down}.ry")] -= k
            rows.append((f"{drive}.{section}.torque", row, loss * row))
    return rows


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
