"""Export of the linear system at an operating point as ``.npz`` (for other tools).

Arrays: ``M``, ``B`` (all damping at the point: structural + b_M B_M + B_ad), ``K``, ``dofs``
(names), ``dof_units``, ``massless`` (indices of the coordinates without mass: the yaw dampers'
strokes and, with a torque control on ID2's converter, its filter's ``ID2.converter.filtered_angle``
[rad], whose rows and columns of M are zero — they are first order, ``B_mm q̇_m + B_mi q̇_i +
K_m q = 0``; a first-order form keeps their displacements but not their velocities as states,
see :mod:`model.analysis.linear_system`), ``f_mc`` (generalized force per unit short-circuit torque M_C [1 or 1/m…]),
``motor_torque`` (M(s0, v) [N m]), ``C_q``, ``C_v``, ``outputs`` (names of y = C_q Δq + C_v Δq̇),
``output_units``, ``output_steady`` (pre-fault values), ``operating_point`` (s0 [-], v [m/s],
N0 [N], b_M [N m s/rad]), ``motor_bandwidth`` (the torque control's bandwidth f_c [Hz]; 0: none).
Strings are numpy unicode arrays: load with ``allow_pickle=False``.

For an independent nonlinear integrator (the quantities :mod:`model.analysis.nonlinear` steps with):
``B_without_longitudinal_creep`` (n x n, B_nl: ``B`` without eq. 19's b11 terms),
``creep_velocity_map`` (contacts x n, rows H_i: ``Δs_i v = H_i Δq̇`` [m/s]), ``creep_force_map``
(n x contacts, columns of G: a unit longitudinal creep force), ``contacts`` (rim names),
``f_m2`` (generalized force of a unit driving torque of ID2's motor), and the creep law at the
operating speed ``creep_s`` [-], ``creep_mu`` [-] (4001 points, s from −0.1 to 0.1).  Identity:
``B == B_without_longitudinal_creep − G · diag(N0 μ'(s0)/v) · H``.

The rail–wheel surface deviations Δ (one per wheel, ``irregularity_inputs``: ``IDk.rimNN.irregularity``
[m]; :mod:`model.mechanics.irregularity`): the generalized force is ``G_irr_q Δ + G_irr_v Δ̇ +
G_irr_a Δ̈`` (n x 4 each: the track's k_R, b_R, m_R on the rim's z and, times μ(s0, v), on the
contact's longitudinal pattern), on the running system ``(M + M_irr_coupling) q̈ + (B +
B_irr_coupling) q̇ + (K + K_irr_coupling) q`` (n x n each: the creep force's share μ(s0) ΔN of the
rims' own vertical motion, the wheel-force coupling; zero but in the rims' z columns).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from model.analysis.linear_system import massless_coordinates
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import OperatingPoint, damping_matrix, motor_torque
from model.mechanics.outputs import output_matrices


def export_system(model: BogieModel, op: OperatingPoint, path: str | Path) -> None:
    path = Path(path)
    if path.suffix != ".npz":
        raise ValueError(f"export file must end in .npz, got '{path.name}'")
    if not path.parent.exists():
        raise ValueError(f"directory '{path.parent}' does not exist")
    from model.analysis.nonlinear import (
        contact_names,
        creep_force_map,
        creep_velocity_map,
        damping_without_longitudinal_creep,
        motor2_force,
    )
    from model.mechanics.irregularity import irregularity_forces
    from model.mechanics.operating_point import creep_law

    outputs = output_matrices(model, op)
    creep_s = np.linspace(-0.1, 0.1, 4001)
    irregularity = irregularity_forces(model, op)
    np.savez(
        path,
        M=model.M, B=damping_matrix(model, op), K=model.K,
        dofs=np.array(model.dofs.names, dtype=str),
        dof_units=np.array([model.dofs.unit(n) for n in model.dofs.names], dtype=str),
        massless=massless_coordinates(model.M),
        f_mc=model.short_circuit_force,
        motor_torque=np.float64(motor_torque(model.parameters, op)),
        C_q=outputs.C_q, C_v=outputs.C_v,
        outputs=np.array(outputs.names, dtype=str),
        output_units=np.array(outputs.units, dtype=str),
        output_steady=outputs.steady,
        operating_point=np.array([op.s0, op.v, op.N0, op.b_M]),
        motor_bandwidth=np.float64(model.parameters["motor_bandwidth"]),
        B_without_longitudinal_creep=damping_without_longitudinal_creep(model, op),
        creep_velocity_map=creep_velocity_map(model), creep_force_map=creep_force_map(model),
        contacts=np.array(contact_names(model), dtype=str), f_m2=motor2_force(model),
        creep_s=creep_s, creep_mu=np.asarray(creep_law(model.parameters, op.N0).mu(creep_s, op.v)),
        G_irr_q=irregularity.G_q, G_irr_v=irregularity.G_v, G_irr_a=irregularity.G_a,
        irregularity_inputs=np.array(irregularity.names, dtype=str),
        M_irr_coupling=irregularity.M_c, B_irr_coupling=irregularity.B_c,
        K_irr_coupling=irregularity.K_c,
    )
