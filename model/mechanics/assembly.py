"""Assembly of the bogie: subsystems ID1, BFCB, ID2 (in that order), from named elements.

Drive 1 is described once (:func:`_drive`); drive 2 is the same description turned by 180° about
the vertical axis through the bogie centre (positions and geometric directions mapped by
``diag(−1, −1, 1)``).  The constant matrices ``M``, ``B`` (structural damping), ``K`` are
assembled once; an operating point only adds the motor slope ``B_M`` and the creep blocks
``B_ad`` (see :mod:`model.mechanics.operating_point`).

DOF layout (197 coordinates; the study had 189 without stating its breakdown):

* per drive ``IDk`` (93): ``rotor.ry``, ``pinion.ry``, ``gear.ry`` (spins in the gear housing;
  they translate and tilt with the stator), ``stator.{x,y,z,rx,ry,rz}``, hollow shaft beam nodes
  ``hs5…hs9`` (6 each; disc clutch at 5, claw clutch at 9), axle beam nodes ``ax10…ax16``
  (6 each; claw clutch at 10, journals 11 and 15, wheels 12 and 14, centre 13, under the gear 16),
  wheel rims ``rim12``, ``rim14`` (6 each);
* ``BF.{x,y,z,rx,ry,rz}`` bogie frame; ``CB.x``, ``CB.z``, ``CB.rz`` half car body (longitudinal,
  vertical, yaw about the vertical through the bogie centre; its lateral, roll and pitch are held
  by the rest of the locomotive); ``secondary.yaw_damper_{left,right}.stroke`` the massless inner
  coordinates of the two yaw dampers (Maxwell elements: damper in series with its end bushes).

With a converter torque control on ID2 (``motor_bandwidth`` f_c > 0) one massless coordinate
follows, ``ID2.converter.filtered_angle`` [rad]: the rotor's angle relative to the stator and to
the vehicle's rolling, high-passed at f_c (:func:`converter_rows`).

Rigid-body modes (``K r = 0``, from the kinematics): the spin of each drivetrain (rotor at −p times
the wheel) and, since nothing in this model holds the vehicle to the track longitudinally or in
yaw but the creep (a damping), the longitudinal translation and the yaw about the bogie centre of
the whole vehicle (car body, frame, drives) — four in all.  One combination of them, the vehicle
rolling without slip (:attr:`BogieModel.rolling_mode`), meets no damping either: no creep, no
motor slope (eq. 6 measures the rotor's speed against the rolling the vehicle's speed implies), no
damper; with no running resistance in the model its velocity is a fifth neutral motion.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np

from model.mechanics.beam import TubeSection, beam_global_matrices
from model.mechanics.bodies import Body, carried_body, free_body, rigid_mass_matrix
from model.mechanics.connections import MaxwellDamper, Spring, SpringDamper, axis_springs
from model.mechanics.dofs import AXES6, FILTERED_ANGLE, DofMap
from model.mechanics.parameters import Parameters

# Beam nodes of a drive, in the study's numbering 5…16 (docs/model.md, "DOF count and layout"):
# the coordinates ``IDk.hs<node>.*``, ``IDk.ax<node>.*``, ``IDk.rim<node>.*``
# (model.mechanics.dofs).  Lateral places y are drive 1's (drive 2 is turned by 180°).
HOLLOW_SHAFT_NODES = (5, 6, 7, 8, 9)  # hollow shaft, evenly from the gear (5) to the claw end (9)
AXLE_NODES = (10, 11, 12, 13, 14, 15, 16)  # wheelset axle
RIM_NODES = (12, 14)  # the wheels (y = −c, +c): wheel discs on the axle, elastic rims on them
DISC_CLUTCH_NODE = 5  # hollow shaft at the gear: the disc clutch joins it to the gear
CLAW_CLUTCH_NODE = 9  # hollow shaft's claw end: the claw clutch's hollow-shaft side
AXLE_CLAW_NODE = 10  # axle under the hollow shaft's claw end: the claw clutch's axle side
JOURNAL_NODES = (11, 15)  # axle journals (y = −j, +j): axle boxes, primary suspension
AXLE_CENTRE_NODE = 13  # axle centre (y = 0)
AXLE_GEAR_NODE = 16  # axle under the gear (and the hollow shaft's gear end)
DRIVES = ("ID1", "ID2")
CENTRAL_SYMMETRY = np.diag([-1.0, -1.0, 1.0])  # drive 2 = drive 1 turned 180° about z
CAR_BODY_AXES = ("x", "z", "rz")  # the half car body's coordinates
YAW_DAMPERS = ("secondary.yaw_damper_left", "secondary.yaw_damper_right")  # +y, −y side
CONVERTER_FILTER = f"ID2.converter.{FILTERED_ANGLE}"  # massless coordinate of ID2's torque control


def dof_names(converter: bool = False) -> tuple[str, ...]:
    """All coordinate names in the order of q = [q_ID1, q_BFCB, q_ID2], then with ``converter``
    (a torque control on ID2, ``motor_bandwidth`` > 0) its filter's coordinate."""

    def drive(prefix: str) -> list[str]:
        names = [f"{prefix}.rotor.ry", f"{prefix}.pinion.ry", f"{prefix}.gear.ry"]
        names += [f"{prefix}.stator.{a}" for a in AXES6]
        for node in HOLLOW_SHAFT_NODES:
            names += [f"{prefix}.hs{node}.{a}" for a in AXES6]
        for node in AXLE_NODES:
            names += [f"{prefix}.ax{node}.{a}" for a in AXES6]
        for node in RIM_NODES:
            names += [f"{prefix}.rim{node}.{a}" for a in AXES6]
        return names

    return tuple(drive("ID1") + [f"BF.{a}" for a in AXES6] + [f"CB.{a}" for a in CAR_BODY_AXES]
                 + [f"{damper}.stroke" for damper in YAW_DAMPERS] + drive("ID2")
                 + ([CONVERTER_FILTER] if converter else []))


@dataclass(frozen=True)
class Part:
    """A matrix contribution restricted to the coordinates it touches."""

    index: np.ndarray  # global coordinate indices
    matrix: np.ndarray  # len(index) x len(index)


@dataclass
class BogieModel:
    """The assembled linear model: constant matrices plus what an operating point needs."""

    parameters: Parameters
    dofs: DofMap
    M: np.ndarray  # mass matrix [kg, kg m, kg m^2]
    K: np.ndarray  # stiffness (incl. track) [N/m, N, N m/rad]
    B: np.ndarray  # structural damping (incl. track), without B_M and B_ad [N s/m, …]
    mass_parts: dict[str, Part]  # component name -> its share of M (kinetic energy bookkeeping)
    stiffness_parts: dict[str, Part]  # element group -> its share of K (strain energy)
    connections: list[SpringDamper | MaxwellDamper]  # every connection, for output quantities
    rims: dict[str, np.ndarray]  # "ID1.rim12" -> indices of [x, y, z, rx, ry, rz]
    motor_pattern: np.ndarray  # n x n: B_M for b_M = 1 (ID2's slope, :func:`motor_slope_rows`)
    short_circuit_force: np.ndarray  # generalized force per unit M_C on ID1 (rotor, stator)
    rigid_body_modes: np.ndarray  # n x 4: rigid spin of each whole drivetrain, longitudinal
    # translation and yaw of the whole vehicle (K r = 0)
    rolling_mode: np.ndarray  # n: the vehicle rolling without slip at 1 m/s (K r = 0, B r = 0)
    positions: dict[str, np.ndarray] = field(default_factory=dict)  # part -> reference point [m]

    @property
    def n(self) -> int:
        return len(self.dofs)


def _support(W: np.ndarray) -> np.ndarray:
    """Indices of the columns of W that are not zero (the coordinates a body's map touches)."""
    return np.flatnonzero(np.any(W != 0, axis=0))


class _Assembler:
    """Adds each contribution on the coordinates it touches (a contribution is a few of the
    ~200 coordinates: dense n x n products made an assembly 3-4x slower, and the complex-step
    sensitivities assemble once per parameter)."""

    def __init__(self, dofs: DofMap, dtype=float):
        self.dofs = dofs
        n = len(dofs)
        self.M = np.zeros((n, n), dtype=dtype)
        self.K = np.zeros((n, n), dtype=dtype)
        self.B = np.zeros((n, n), dtype=dtype)
        # name -> contributions (index, matrix) of each component (M) and element group (K)
        self.mass_parts: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
        self.stiffness_parts: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
        self.connections: list[SpringDamper | MaxwellDamper] = []
        self.bodies: list[Body] = []  # free bodies and beam nodes (rigid-body modes)

    @staticmethod
    def _add_part(store: dict, name: str, index: np.ndarray, matrix: np.ndarray) -> None:
        store.setdefault(name, []).append((index, matrix))

    def free(self, name: str, origin, axes=AXES6) -> Body:
        """A free body owning ``name.<axis>`` (kept for the rigid-body modes)."""
        body = free_body(name, origin, self.dofs, axes)
        self.bodies.append(body)
        return body

    def add_mass(self, component: str, body: Body, M6: np.ndarray) -> None:
        index = _support(body.W)
        W = body.W[:, index]
        contribution = W.T @ M6 @ W
        contribution = 0.5 * (contribution + contribution.T)  # exactly symmetric
        self.M[np.ix_(index, index)] += contribution
        self._add_part(self.mass_parts, component, index, contribution)

    def add_beam(self, group: str, component: str, node_a: Body, node_b: Body,
                 section: TubeSection, p: Parameters) -> None:
        K12, M12 = beam_global_matrices(node_a.origin, node_b.origin, section, p["young_modulus"],
                                        p["poisson_ratio"], p["steel_density"])
        G = np.vstack([node_a.W, node_b.W])
        index = _support(G)
        G = G[:, index]
        K = G.T @ K12 @ G
        M = G.T @ M12 @ G
        K, M = 0.5 * (K + K.T), 0.5 * (M + M.T)  # exactly symmetric
        block = np.ix_(index, index)
        self.K[block] += K
        self.B[block] += p["shaft_loss_time"] * K
        self.M[block] += M
        self._add_part(self.stiffness_parts, group, index, K)
        self._add_part(self.mass_parts, component, index, M)

    def add_connection(self, connection: SpringDamper | MaxwellDamper) -> None:
        index, K, B = connection.local_matrices()
        block = np.ix_(index, index)
        self.K[block] += K
        self.B[block] += B
        self._add_part(self.stiffness_parts, connection.group, index, K)
        self.connections.append(connection)

    def add_ground_spring(self, group: str, index: int, stiffness: float, damping: float,
                          mass: float, component: str) -> None:
        self.K[index, index] += stiffness
        self.B[index, index] += damping
        self.M[index, index] += mass
        at = np.array([index])
        self._add_part(self.stiffness_parts, group, at, np.array([[stiffness]]))
        self._add_part(self.mass_parts, component, at, np.array([[mass]]))


def _parts(store: dict[str, list[tuple[np.ndarray, np.ndarray]]]) -> dict[str, Part]:
    """Each name's contributions summed on the union of their coordinates, without the rows and
    columns that stay zero."""
    parts = {}
    for name, items in store.items():
        union = np.unique(np.concatenate([index for index, _ in items]))
        dtype = np.result_type(*[matrix for _, matrix in items])
        matrix = np.zeros((len(union), len(union)), dtype=dtype)
        for index, contribution in items:
            position = np.searchsorted(union, index)
            matrix[np.ix_(position, position)] += contribution
        keep = np.any(matrix != 0, axis=0) | np.any(matrix != 0, axis=1)
        parts[name] = Part(union[keep], matrix[np.ix_(keep, keep)].copy())
    return parts


@dataclass(frozen=True)
class _DriveLayout:
    """Where a drive's parts sit: drive 1's geometry mapped by ``sign`` (identity for drive 1,
    the bogie's central symmetry for drive 2); places in m."""

    sign: np.ndarray  # 3 x 3: drive-1 geometry -> this drive's
    axle_x: float  # longitudinal place of the wheelset axle (drive 1) [m]
    x_motor: float  # longitudinal place of the motor axis (drive 1), towards the bogie centre [m]
    r_pinion: float  # pitch radius of the pinion [m]
    y_gear: float  # lateral place of the gear mesh (pinion, gear, hollow shaft node 5) [m]
    y_claw: float  # lateral place of the claw clutch (hollow shaft node 9, axle node 10) [m]

    @classmethod
    def of(cls, p: Parameters, sign: np.ndarray, axle_x: float) -> _DriveLayout:
        r_gear = p["gear_radius"]
        r_pinion = r_gear / p["gear_ratio"]
        return cls(sign, axle_x, axle_x - (r_gear + r_pinion), r_pinion,
                   p["gear_lateral_position"], p["claw_clutch_lateral_position"])

    def pos(self, x, y, z) -> np.ndarray:
        """This drive's point for drive 1's point (x, y, z) [m]."""
        return self.sign @ np.array([x, y, z], dtype=np.result_type(x, y, z, float))

    def direction(self, v) -> np.ndarray:
        """This drive's direction for drive 1's direction ``v``."""
        return self.sign @ np.asarray(v, dtype=np.result_type(*v, float))


def _motor_and_gear(asm: _Assembler, p: Parameters, prefix: str,
                    at: _DriveLayout) -> tuple[Body, Body, Body, Body]:
    """The stator with the gear housing (a free body) and the rotor, pinion and gear it carries,
    with their masses [kg] and inertias [kg m²]: (stator, rotor, pinion, gear)."""
    dofs = asm.dofs
    stator = asm.free(f"{prefix}.stator", at.pos(at.x_motor + p["stator_offset_x"], 0.0,
                                                 p["stator_offset_z"]))
    rotor = carried_body(f"{prefix}.rotor", at.pos(at.x_motor, 0.0, 0.0), stator, dofs)
    pinion = carried_body(f"{prefix}.pinion", at.pos(at.x_motor, at.y_gear, 0.0), stator, dofs)
    gear = carried_body(f"{prefix}.gear", at.pos(at.axle_x, at.y_gear, 0.0), stator, dofs)
    asm.add_mass(f"{prefix}.stator", stator, rigid_mass_matrix(
        p["stator_mass"], (p["stator_inertia_x"], p["stator_inertia_y"], p["stator_inertia_z"])))
    for body, mass, inertia in ((rotor, "rotor_mass", "rotor_inertia"),
                                (pinion, "pinion_mass", "pinion_inertia"),
                                (gear, "gear_mass", "gear_inertia")):
        J = p[inertia]
        asm.add_mass(body.name, body, rigid_mass_matrix(p[mass], (J / 2, J, J / 2)))
    return stator, rotor, pinion, gear


def _hollow_shaft_and_axle(asm: _Assembler, p: Parameters, prefix: str,
                           at: _DriveLayout) -> tuple[dict[int, Body], dict[int, Body]]:
    """The hollow shaft's and the wheelset axle's beam nodes (free bodies) and beams, the wheel
    discs [kg, kg m²] and the axle boxes [kg] lumped at their nodes: (hollow shaft nodes, axle
    nodes) by node number."""
    hs_y = np.linspace(at.y_gear, at.y_claw, len(HOLLOW_SHAFT_NODES))
    hs = {k: asm.free(f"{prefix}.hs{k}", at.pos(at.axle_x, y, 0.0))
          for k, y in zip(HOLLOW_SHAFT_NODES, hs_y, strict=True)}
    c, j = p["contact_half_distance"], p["journal_half_distance"]
    (journal_a, journal_b), (wheel_a, wheel_b) = JOURNAL_NODES, RIM_NODES
    axle_y = {journal_a: -j, wheel_a: -c, AXLE_CLAW_NODE: at.y_claw, AXLE_CENTRE_NODE: 0.0,
              AXLE_GEAR_NODE: at.y_gear, wheel_b: c, journal_b: j}  # lateral places (drive 1)
    ax = {k: asm.free(f"{prefix}.ax{k}", at.pos(at.axle_x, y, 0.0)) for k, y in axle_y.items()}
    hollow = TubeSection(p["hollow_shaft_outer_radius"], p["hollow_shaft_inner_radius"])
    for k1, k2 in pairwise(HOLLOW_SHAFT_NODES):
        asm.add_beam(f"{prefix}.hollow_shaft", f"{prefix}.hollow_shaft", hs[k1], hs[k2], hollow, p)
    axle_order = sorted(axle_y, key=lambda k: np.real(axle_y[k]))
    solid = TubeSection(p["axle_radius"])
    for k1, k2 in pairwise(axle_order):
        asm.add_beam(f"{prefix}.axle", f"{prefix}.wheelset", ax[k1], ax[k2], solid, p)
    for k in RIM_NODES:  # wheel discs
        Jd = p["wheel_disc_diametral_inertia"]
        asm.add_mass(f"{prefix}.wheelset", ax[k], rigid_mass_matrix(
            p["wheel_disc_mass"], (Jd, p["wheel_disc_polar_inertia"], Jd)))
    for k in JOURNAL_NODES:  # axle boxes: translate with the journal, do not spin
        asm.add_mass(f"{prefix}.wheelset", ax[k], np.diag([p["axle_box_mass"]] * 3 + [0, 0, 0]))
    return hs, ax


def _rims_and_track(asm: _Assembler, p: Parameters, prefix: str,
                    ax: dict[int, Body]) -> dict[int, Body]:
    """The elastic wheels' rims (free bodies at the wheel nodes; mass [kg], inertias [kg m²],
    rim springs [N/m, N m/rad] with rubber damping) and the track under each [N/m, N s/m, kg]:
    the rims by node number."""
    loss_rubber = p["rubber_loss_time"]
    rims = {}
    for k in RIM_NODES:
        rim = asm.free(f"{prefix}.rim{k}", ax[k].origin)
        rims[k] = rim
        Jr = p["rim_diametral_inertia"]
        asm.add_mass(rim.name, rim, rigid_mass_matrix(p["rim_mass"], (Jr, p["rim_polar_inertia"], Jr)))
        kt = np.array([p["rim_radial_stiffness"], p["rim_axial_stiffness"], p["rim_radial_stiffness"]])
        kr = np.array([p["rim_tilt_stiffness"], p["rim_torsional_stiffness"], p["rim_tilt_stiffness"]])
        asm.add_connection(SpringDamper(
            f"{prefix}.rim{k}_spring", f"{prefix}.rim_springs", ax[k], rim, rim.origin,
            axis_springs(kt, loss_rubber * kt) + axis_springs(kr, loss_rubber * kr, rotational=True)))
        asm.add_ground_spring("track", asm.dofs.index(f"{rim.name}.z"), p["track_stiffness"],
                              p["track_damping"], p["track_mass"], "track")
    return rims


def _driving_shaft_and_gear_mesh(asm: _Assembler, p: Parameters, prefix: str, at: _DriveLayout,
                                 rotor: Body, pinion: Body, gear: Body) -> np.ndarray:
    """The driving shaft (rotor to pinion, torsion [N m/rad]) and the gear mesh (pinion to gear,
    a spring along the line of action [N/m]), both with steel damping: the pitch point [m]."""
    loss_steel = p["shaft_loss_time"]
    asm.add_connection(SpringDamper(
        f"{prefix}.driving_shaft", f"{prefix}.driving_shaft", pinion, rotor, rotor.origin,
        (Spring(np.array([0.0, -1.0, 0.0]), p["driving_shaft_stiffness"],
                loss_steel * p["driving_shaft_stiffness"], True, "torque"),)))
    # driving-shaft torque in the motor's driving sense (the rotor turns −ry when running forward):
    # M_DS = k_DS (φ_rotor − φ_pinion) with angles counted in that sense, positive in traction
    alpha = p["pressure_angle"]
    pitch_point = at.pos(at.x_motor + at.r_pinion, at.y_gear, 0.0)
    asm.add_connection(SpringDamper(
        f"{prefix}.gear_mesh", f"{prefix}.gear_mesh", pinion, gear, pitch_point,
        (Spring(at.direction([-np.sin(alpha), 0.0, -np.cos(alpha)]), p["gear_mesh_stiffness"],
                loss_steel * p["gear_mesh_stiffness"], False, "force"),)))
    return pitch_point


def _clutches(asm: _Assembler, p: Parameters, prefix: str, gear: Body, hs: dict[int, Body],
              ax: dict[int, Body]) -> None:
    """The disc clutch (gear to the hollow shaft's gear end) and the claw clutch (the hollow
    shaft's claw end to the axle): springs [N/m, N m/rad] with rubber damping."""
    loss_rubber = p["rubber_loss_time"]
    k_dc = np.array([p["disc_clutch_radial_stiffness"], p["disc_clutch_axial_stiffness"],
                     p["disc_clutch_radial_stiffness"]])
    k_dc_rot = np.array([p["disc_clutch_tilt_stiffness"], p["disc_clutch_torsional_stiffness"],
                         p["disc_clutch_tilt_stiffness"]])
    disc = hs[DISC_CLUTCH_NODE]
    asm.add_connection(SpringDamper(
        f"{prefix}.disc_clutch", f"{prefix}.disc_clutch", disc, gear, disc.origin,
        axis_springs(k_dc, loss_rubber * k_dc, channels=("force_x", "force_y", "force_z"))
        + axis_springs(k_dc_rot, loss_rubber * k_dc_rot, True, ("", "torque", ""))))
    k_cc = np.array([p["claw_clutch_radial_stiffness"], p["claw_clutch_axial_stiffness"],
                     p["claw_clutch_radial_stiffness"]])
    k_cc_rot = np.array([p["claw_clutch_tilt_stiffness"], p["claw_clutch_torsional_stiffness"],
                         p["claw_clutch_tilt_stiffness"]])
    claw = hs[CLAW_CLUTCH_NODE]
    asm.add_connection(SpringDamper(
        f"{prefix}.claw_clutch", f"{prefix}.claw_clutch", ax[AXLE_CLAW_NODE], claw, claw.origin,
        axis_springs(k_cc, loss_rubber * k_cc)
        + axis_springs(k_cc_rot, loss_rubber * k_cc_rot, True, ("", "torque", ""))))


def _silent_blocks(asm: _Assembler, p: Parameters, prefix: str, at: _DriveLayout, frame: Body,
                   stator: Body, positions: dict[str, np.ndarray]) -> None:
    """The drive hung in the frame: silent blocks A, B (upper) and C (lower) between the frame
    and the stator [N/m, rubber damping]; their places [m] into ``positions``."""
    loss_rubber = p["rubber_loss_time"]
    x_motor, y_gear, pos = at.x_motor, at.y_gear, at.pos
    k_sb = np.array([p["silent_block_stiffness_x"], p["silent_block_stiffness_y"],
                     p["silent_block_stiffness_z"]])
    blocks = {"A": pos(x_motor - p["silent_block_upper_x"], p["silent_block_half_y"], p["silent_block_upper_z"]),
              "B": pos(x_motor - p["silent_block_upper_x"], -p["silent_block_half_y"], p["silent_block_upper_z"]),
              "C": pos(x_motor + p["silent_block_lower_x"], y_gear, p["silent_block_lower_z"])}
    for label, point in blocks.items():
        asm.add_connection(SpringDamper(f"{prefix}.silent_block_{label}", f"{prefix}.silent_blocks",
                                        frame, stator, point, axis_springs(k_sb, loss_rubber * k_sb)))
        positions[f"{prefix}.silent_block_{label}"] = point


def _primary_suspension(asm: _Assembler, p: Parameters, prefix: str, frame: Body,
                        ax: dict[int, Body]) -> None:
    """Wheelset to frame at the journals: primary springs and longitudinal wheelset guides
    [N/m], vertical primary dampers [N s/m]."""
    k_p = np.array([p["primary_stiffness_x"], p["primary_stiffness_y"], p["primary_stiffness_z"]])
    c_p = np.array([0.0, 0.0, p["primary_damping_z"]])
    for k in JOURNAL_NODES:
        asm.add_connection(SpringDamper(f"{prefix}.primary{k}", f"{prefix}.primary", frame, ax[k],
                                        ax[k].origin, axis_springs(k_p, c_p)))


def _drive(asm: _Assembler, p: Parameters, prefix: str, frame: Body, sign: np.ndarray,
           axle_x: float, positions: dict[str, np.ndarray]) -> dict[str, Body]:
    """Add one individual wheelset drive.  ``sign`` maps drive-1 geometry to this drive's;
    ``axle_x`` [m]: drive 1's axle place.  Its parts' places [m] go into ``positions``; returns
    its bodies by part name ("stator", "hs5", "ax10", "rim12", …)."""
    at = _DriveLayout.of(p, sign, axle_x)
    stator, rotor, pinion, gear = _motor_and_gear(asm, p, prefix, at)
    hs, ax = _hollow_shaft_and_axle(asm, p, prefix, at)
    rims = _rims_and_track(asm, p, prefix, ax)
    pitch_point = _driving_shaft_and_gear_mesh(asm, p, prefix, at, rotor, pinion, gear)
    _clutches(asm, p, prefix, gear, hs, ax)
    _silent_blocks(asm, p, prefix, at, frame, stator, positions)
    _primary_suspension(asm, p, prefix, frame, ax)
    bodies = {"stator": stator, "rotor": rotor, "pinion": pinion, "gear": gear,
              **{f"hs{k}": b for k, b in hs.items()}, **{f"ax{k}": b for k, b in ax.items()},
              **{f"rim{k}": b for k, b in rims.items()}}
    for name, body in bodies.items():
        positions[f"{prefix}.{name}"] = body.origin
    positions[f"{prefix}.pitch_point"] = pitch_point
    return bodies


def _rigid_motion(bodies: list[Body], dofs: DofMap, translation: np.ndarray,
                  rotation: np.ndarray) -> np.ndarray:
    """q of a rigid motion of every free body (displacement ``translation + rotation × r`` at a
    body's reference point r, rotation ``rotation``): carried bodies follow their carriers with
    no spin of their own; the yaw dampers' strokes stay zero (both ends move alike)."""
    q = np.zeros(len(dofs))
    for body in bodies:
        motion = np.concatenate([translation + np.cross(rotation, np.real(body.origin)), rotation])
        for k, axis in enumerate(AXES6):
            name = f"{body.name}.{axis}"
            if name in dofs._index:  # type: ignore[attr-defined]
                q[dofs.index(name)] = motion[k]
            elif abs(motion[k]) > 0:
                raise ValueError(f"a rigid motion moves {body.name} along {axis}, which it does "
                                 "not own")
    return q


def assembled_matrices(parameters: Parameters) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, B, K) of a parameter set without the rest of the model (the complex-step
    sensitivities need only these, once per parameter)."""
    asm, _, _ = _assemble(parameters)
    return asm.M, asm.B, asm.K


def build_model(parameters: Parameters) -> BogieModel:
    """Assemble the constant matrices of the bogie for a parameter set.

    Example::

        >>> from model import build_model, load_parameters
        >>> model = build_model(load_parameters())
        >>> model.n, model.dofs.names[0]                # coordinates, the first one's name
        (197, 'ID1.rotor.ry')
    """
    p = parameters
    asm, dofs, positions = _assemble(p)
    n = len(dofs)
    dtype = asm.K.dtype
    motor = motor_slope_rows(p, dofs, asm)

    # short circuit torque on ID1: M_C in the driving sense.  Forward running spins the wheels
    # +ry and, through one external gear mesh, the rotor −ry: a driving torque is −ry on the rotor
    # and its reaction +ry on the stator.
    short_circuit = np.zeros(n)
    short_circuit[dofs.index("ID1.rotor.ry")] = -1.0
    short_circuit[dofs.index("ID1.stator.ry")] = 1.0

    rigid = np.zeros((n, 4), dtype=dtype)
    for column, prefix in enumerate(DRIVES):
        for name in dofs.names:
            if name.startswith(prefix) and name.endswith(".ry") and ".stator." not in name:
                rigid[dofs.index(name), column] = 1.0
        for part in ("rotor", "pinion"):
            rigid[dofs.index(f"{prefix}.{part}.ry"), column] = -p["gear_ratio"]
    # the whole vehicle: longitudinal translation, yaw about the vertical through the bogie centre
    rigid[:, 2] = _rigid_motion(asm.bodies, dofs, np.array([1.0, 0.0, 0.0]), np.zeros(3))
    rigid[:, 3] = _rigid_motion(asm.bodies, dofs, np.zeros(3), np.array([0.0, 0.0, 1.0]))
    # rolling without slip at 1 m/s: the translation, every wheel spinning at 1/r0
    rolling = rigid[:, 2] + (rigid[:, 0] + rigid[:, 1]) / p["wheel_radius"]

    rims = {f"{prefix}.rim{k}": dofs.indices([f"{prefix}.rim{k}.{a}" for a in AXES6])
            for prefix in DRIVES for k in RIM_NODES}
    return BogieModel(p, dofs, asm.M, asm.K, asm.B, _parts(asm.mass_parts),
                      _parts(asm.stiffness_parts), asm.connections, rims, motor, short_circuit,
                      rigid, rolling, positions)


def motor_speed_row(parameters: Parameters, dofs: DofMap) -> np.ndarray:
    """g (n): ``Δφ̇ = g · q̇``, the speed of ID2's rotor relative to its stator less the rotation
    that the vehicle's current speed implies (eq. 6: "with respect to rotation corresponding to
    vehicle forward velocity v").  Rolling without slip at ẋ spins the wheels at ẋ/r0 and, through
    one external gear mesh, the rotor at −p ẋ/r0; the vehicle's speed is its half car body's
    ``CB.x``.  A vehicle rolling faster without slip changes no Δφ̇ [1, rad/m]."""
    ratio = parameters["gear_ratio"] / parameters["wheel_radius"]
    g = np.zeros(len(dofs), dtype=np.result_type(ratio, float))  # complex in a complex step
    g[dofs.index("ID2.rotor.ry")] = 1.0
    g[dofs.index("ID2.stator.ry")] = -1.0
    g[dofs.index("CB.x")] = ratio
    return g


def motor_slope_rows(parameters: Parameters, dofs: DofMap, asm: _Assembler) -> np.ndarray:
    """B_M (n x n) for b_M = 1: ID2's slope torque ``−b_M Δφ̇`` on the rotor, its reaction on the
    stator (eq. 6).  Without torque control (``motor_bandwidth`` = 0) ``Δφ̇ = g · q̇``
    (:func:`motor_speed_row`); with it the slope acts on Δφ̇ high-passed at f_c, the velocity of
    the filter's coordinate (:func:`converter_rows`, which adds that coordinate's own row to B and
    K of ``asm``).  Not symmetric: the vehicle's speed enters the measure, not the torque."""
    n = len(dofs)
    force = np.zeros(n)  # a unit slope torque: −1 on the rotor, +1 on the stator (as M_C's sense)
    force[dofs.index("ID2.rotor.ry")] = 1.0
    force[dofs.index("ID2.stator.ry")] = -1.0
    speed = motor_speed_row(parameters, dofs)
    if parameters["motor_bandwidth"].real > 0.0:
        speed = converter_rows(parameters, dofs, asm, speed)
    return np.outer(force, speed)


def converter_rows(parameters: Parameters, dofs: DofMap, asm: _Assembler,
                   speed: np.ndarray) -> np.ndarray:
    """The torque control of ID2's converter, a first-order high-pass at f_c on the motor's
    relative speed Δφ̇ = ``speed`` · q̇: the massless coordinate z (:data:`CONVERTER_FILTER`, rad)
    obeys ``ż + ω_c z = Δφ̇`` (ω_c = 2π f_c), so that ż = Δφ̇ s/(s + ω_c): below f_c the
    converter restores the set-point torque (ż → 0 for a slow change of speed), above it the
    slope acts as without control.  Its row goes into the constant B (``ż − speed · q̇``) and K
    (``ω_c z``) of ``asm``; returns the row e_z on which the slope then acts."""
    z = dofs.index(CONVERTER_FILTER)
    asm.B[z, :] -= speed
    asm.B[z, z] += 1.0
    asm.K[z, z] += 2 * np.pi * parameters["motor_bandwidth"]
    row = np.zeros(len(dofs))
    row[z] = 1.0
    return row


def _assemble(parameters: Parameters) -> tuple[_Assembler, DofMap, dict[str, np.ndarray]]:
    """Every body and element of the bogie added: (assembler, DOF map, drawn positions)."""
    p = parameters
    dofs = DofMap(dof_names(converter=p["motor_bandwidth"].real > 0.0))
    # complex values (a complex-step perturbation, model.analysis.sensitivity) give complex matrices
    dtype = complex if any(isinstance(value, complex) for value in p.values.values()) else float
    asm = _Assembler(dofs, dtype)
    positions: dict[str, np.ndarray] = {}

    frame = asm.free("BF", (0.0, 0.0, p["frame_height"]))
    asm.add_mass("BF", frame, rigid_mass_matrix(
        p["frame_mass"], (p["frame_inertia_x"], p["frame_inertia_y"], p["frame_inertia_z"])))
    # the half car body: longitudinal, vertical and yaw about the vertical through the bogie
    # centre (its reference point lies on that axis)
    car_body = asm.free("CB", (0.0, 0.0, p["secondary_height"] + 1.0), axes=CAR_BODY_AXES)
    m_cb = p["car_body_mass"]
    # longitudinally the bogie also drives the train it hauls (train_mass; 0: the locomotive alone)
    asm.add_mass("CB", car_body, np.diag([m_cb + p["train_mass"], 0, m_cb, 0, 0,
                                          p["car_body_yaw_inertia"]]))
    positions["BF"], positions["CB"] = frame.origin, car_body.origin

    half_base = p["wheelbase"] / 2
    drives = {}
    for prefix, sign in (("ID1", np.eye(3)), ("ID2", CENTRAL_SYMMETRY)):
        drives[prefix] = _drive(asm, p, prefix, frame, sign, half_base, positions)

    # secondary suspension: frame to half car body
    sx, sy, sh = p["secondary_half_base_x"], p["secondary_half_base_y"], p["secondary_height"]
    k_s = np.array([p["secondary_stiffness_x"], p["secondary_stiffness_y"], p["secondary_stiffness_z"]])
    c_s = np.array([0.0, 0.0, p["secondary_damping_z"]])
    for i, (x, y) in enumerate(((sx, sy), (-sx, sy), (sx, -sy), (-sx, -sy)), start=1):
        point = np.array([x, y, sh])
        asm.add_connection(SpringDamper(f"secondary.P{i}", "secondary", frame, car_body, point,
                                        axis_springs(k_s, c_s)))
        positions[f"secondary.P{i}"] = point
    for side in (1.0, -1.0):
        asm.add_connection(SpringDamper(
            "secondary.lateral_damper", "secondary", frame, car_body, np.array([0.0, side * sy, sh]),
            axis_springs((0, 0, 0), (0, p["secondary_damping_y"], 0))))
    # yaw dampers: longitudinal dampers between frame and car body, each in series with its
    # rubber end bushes (a Maxwell element with a massless inner coordinate, the damper's stroke)
    k_bush = p["yaw_damper_series_stiffness"]
    for damper, side in zip(YAW_DAMPERS, (1.0, -1.0), strict=True):
        point = np.array([0.0, side * p["yaw_damper_half_base_y"], p["yaw_damper_height"]])
        asm.add_connection(MaxwellDamper(
            damper, "yaw_dampers", frame, car_body, point, np.array([1.0, 0.0, 0.0]), k_bush,
            p["yaw_damping"], dofs.index(f"{damper}.stroke"),
            spring_damping=p["rubber_loss_time"] * k_bush))
        positions[damper] = point
    # anti-roll bar: a torsion bar between frame and car body, stiff in their relative roll (the
    # half car body does not roll: it acts on the frame's roll alone)
    k_roll = p["anti_roll_bar_stiffness"]
    asm.add_connection(SpringDamper(
        "secondary.anti_roll_bar", "anti_roll_bar", frame, car_body, np.array([0.0, 0.0, sh]),
        axis_springs((k_roll, 0, 0), (p["shaft_loss_time"] * k_roll, 0, 0), rotational=True)))
    # traction linkage: frame to car body on the bogie's centre line, longitudinal
    k_link = p["traction_link_stiffness"]
    link_point = np.array([0.0, 0.0, p["traction_link_height"]])
    asm.add_connection(SpringDamper(
        "secondary.traction_link", "traction_link", frame, car_body, link_point,
        axis_springs((k_link, 0, 0), (p["rubber_loss_time"] * k_link, 0, 0),
                     channels=("force", "", ""))))
    positions["secondary.traction_link"] = link_point

    return asm, dofs, positions
