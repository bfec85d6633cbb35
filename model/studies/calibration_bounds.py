"""The calibration's free parameters: each with its bounds and the reason for them (a
:class:`~model.studies.parameter_ranges.ParameterRange`), the physical constraints between them (a
rigid body's principal inertias, Polach's kS <= kA), and the parameter table that
``bogie parameters`` and the dashboard's Variant tab show (with whether a value sits on a bound).
Plain data and arithmetic: no model is built here.
"""

from __future__ import annotations

import numpy as np

from model.mechanics.parameters import ALL_SCHEMA, Parameters
from model.studies.parameter_ranges import ParameterRange

# --- published data the bounds come from (each range below names the ones it uses) -------------
# Suspension sets of real vehicles, as published (per axle box / per spring where the source's
# 2-D reduction doubled them, halved back):
MANCHESTER = ("Manchester benchmark coach (Iwnicki 1998, VSD 30(3-4) 295-313): primary vertical "
              "1.2 MN/m and 4 kN s/m per axle box, secondary vertical 0.43 MN/m and 20 kN s/m "
              "per side, 2.6 t bogie frame with 1 476 kg m^2 pitch inertia")
ZHAI_POWER_CAR = ("'China Star' power car (Zhai, Wang & Cai 2009, VSD 47(11) 1349-1376): primary "
                  "vertical 2.40 MN/m and 30 kN s/m per axle box, secondary vertical 0.89 MN/m "
                  "and 45 kN s/m per side, 5.6 t bogie frame with 9 487 kg m^2 pitch inertia")
EUROSTAR_POWER_CAR = ("Eurostar power car (Doménech Monforte 2014, PhD thesis UPV, "
                      "doi:10.4995/Thesis/10251/36740): primary vertical 2.6 MN/m and 12 kN s/m, "
                      "secondary 3.26 MN/m and 90 kN s/m per bogie in its plane model")
PIONEER = ("Pioneer coaches (Antolín et al. 2013, JSV 332(5) 1231-1251): primary vertical "
           "0.7 MN/m and 38 kN s/m per axle, secondary 0.35 MN/m and 40 kN s/m per bogie in "
           "their plane model")
POLACH = ("Polach 2005, Creep forces in simulations of traction vehicles running on adhesion "
          "limit, Wear 258 992-1000: friction μ = μ0((1 − A) e^(−B w) + A), reduction factors kA, "
          "kS of the initial and the large-creep slope, recommended dry and wet sets")
STUDY = ("Zeman & Hlaváč (CITATION.cff): the 109E drive, p <= M_ad/M = 4.06, N0 = 1e5 N, "
         "12 800 N m at 120 km/h")
# where no published set of this class gives the part, the range is an engineering estimate from
# the part's geometry and material, and says so
ESTIMATE = "engineering estimate from the part's geometry (no published set of this class found)"

# stage A: creep law and gear ratio against the operating data (exactly determined)
CREEP_PARAMETERS = (
    ParameterRange("polach_mu0", 0.3, 0.8, "dry rail friction coefficient", source=POLACH),
    ParameterRange("polach_A", 0.2, 0.9, "Polach's A (0.4 in his presets)", source=POLACH),
    ParameterRange("polach_B", 0.05, 3.0, "Polach's B [s/m] (0.2–0.6 in his presets)",
                   source=POLACH),
    ParameterRange("gear_ratio", 3.0, 4.06, "p <= M_ad/M = 4.06 (spec), > 3 for a 200 km/h loco",
                   source=STUDY),
)
# the creep law's shape, searched with the structure (stage A re-solved for each shape): Polach's
# reduction factors within his published range (wet 0.3/0.1 … dry 1.0/0.4, kS <= kA), the initial
# slope between Kalker's value for this contact (~130) and 5x the spec's starting fit
CREEP_SHAPE_PARAMETERS = (
    ParameterRange("polach_kA", 0.3, 1.0, "Polach's range: wet 0.3 … dry 1.0", source=POLACH),
    ParameterRange("polach_kS", 0.1, 0.4, "Polach's range: wet 0.1 … dry 0.4; kS <= kA",
                   source=POLACH),
    ParameterRange("creep_slope", 130.0, 3000.0, "Kalker's slope for this contact (~130) … 5x the "
                   "spec's starting fit (600)", source=POLACH + "; Kalker's coefficients for "
                   "this contact (docs/model.md)"),
)
# stage J: the structure, the dampers and the motor slope against Table 1.  Inertias and
# stiffnesses within about x3 of their estimate and within what the part can be: the inertias
# within the physical limits of the frame (4.9 t with its equipment) and of a 2.6 t motor with
# its gear housing
STRUCTURAL_PARAMETERS = (
    ParameterRange("secondary_stiffness_z", 2e5, 1.8e6, "x3 around 0.6 MN/m (1.26 Hz with 28 t)",
                   source="secondary vertical 0.35–3.26 MN/m in " + "; ".join(
                       (MANCHESTER, ZHAI_POWER_CAR, EUROSTAR_POWER_CAR, PIONEER))),
    ParameterRange("disc_clutch_torsional_stiffness", 2.3e4, 2.1e5, "x3 around 7e4 N m/rad",
                   source=STUDY + "; the 2.694 Hz rotor mode with J_rotor p^2; " + ESTIMATE),
    ParameterRange("primary_stiffness_z", 3.7e5, 3.3e6, "coil springs per axle box, x3 around "
                   "1.1 MN/m", source="primary vertical 0.35–2.6 MN/m per axle box in "
                   + "; ".join((MANCHESTER, ZHAI_POWER_CAR, EUROSTAR_POWER_CAR, PIONEER))),
    ParameterRange("primary_stiffness_y", 3.3e5, 1e7, "coil spring shear 0.3–1 MN/m up to a "
                   "rubber-bushed lateral guide 10 MN/m per axle box", source=ESTIMATE),
    ParameterRange("primary_stiffness_x", 1.7e6, 1.5e7, "longitudinal guide (rubber bushes), x3 "
                   "around 5 MN/m", source=ESTIMATE),
    ParameterRange("silent_block_stiffness_x", 2.7e6, 2.4e7, "rubber-metal block, x3 around 8 MN/m",
                   source=ESTIMATE),
    ParameterRange("silent_block_stiffness_y", 1.3e6, 1.2e7, "rubber-metal block, x3 around 4 MN/m",
                   source=ESTIMATE),
    ParameterRange("silent_block_stiffness_z", 2.7e6, 2.4e7, "rubber-metal block, x3 around 8 MN/m",
                   source=ESTIMATE),
    ParameterRange("rim_torsional_stiffness", 6.7e6, 6e7, "rubber-sprung wheel, x3 around "
                   "2e7 N m/rad", source=ESTIMATE),
    ParameterRange("driving_shaft_stiffness", 2.1e6, 1.9e7, "steel quill shaft, x3 around "
                   "6.4 MN m/rad", source=STUDY + ": the 298.4 Hz driving-shaft mode; " + ESTIMATE),
    # the frame with what it carries, 4.9 t (the rest of the 16 t bogie): a 3.5 t structure
    # (side members, ~60 % of it, at y = ±1.0 m over x = ±1.75 m; cross members near the centre)
    # and ~1.4 t of equipment near the wheels; all of it at the outer edges (the physical limit)
    # would give I_x ≈ 4 900 · 1.1² ≈ 5 900, I_y ≈ 4 900 · 1.6² ≈ 12 500 kg m^2
    ParameterRange("frame_inertia_x", 1400.0, 4200.0, "4.9 t frame with equipment, 2.2 m wide: "
                   "~2 800 kg m^2; x½ … x1.5", source=ESTIMATE),
    ParameterRange("frame_inertia_y", 2300.0, 7000.0, "4.9 t frame with equipment, 3.5 m long: "
                   "~4 600 kg m^2; x½ … x1.5", source="pitch inertia 1 476 kg m^2 for a 2.6 t "
                   "coach frame and 9 487 kg m^2 for a 5.6 t power-car frame, scaled to 4.9 t: "
                   + MANCHESTER + "; " + ZHAI_POWER_CAR),
    ParameterRange("frame_inertia_z", 3500.0, 11000.0, "~7 000 kg m^2, x½ … x1.6; |I_x − I_y| <= "
                   "I_z <= I_x + I_y (see constraint_values)", source=ESTIMATE),
    # 2.6 t: a 0.7 m motor (cylinder, m r²/2 ≈ 160 kg m^2) plus a gear housing reaching to the axle
    ParameterRange("stator_inertia_y", 90.0, 400.0, "2.6 t motor (~160 kg m^2 as a 0.7 m "
                   "cylinder) with its gear housing towards the axle (~150 kg m^2)",
                   source=ESTIMATE),
    # the yaw dampers act between frame and car body (which moves longitudinally and in yaw),
    # each in series with its end bushes
    ParameterRange("yaw_damping", 5e4, 1e6, "yaw damper of a 200 km/h loco, 0.05–1 MN s/m",
                   source=ESTIMATE),
    ParameterRange("yaw_damper_height", 0.05, 0.6, "between the axle height and the car body "
                   "floor; decides how the yaw dampers couple the frame's pitch",
                   source=ESTIMATE),
    ParameterRange("yaw_damper_series_stiffness", 3e6, 3e7, "rubber end bushes of a hydraulic "
                   "damper, 5–15 MN/m, x½ … x2", source=ESTIMATE),
    ParameterRange("traction_link_stiffness", 3e6, 3e7, "rubber-bushed traction rod, 5–20 MN/m, "
                   "x0.6 … x1.5", source=ESTIMATE),
    ParameterRange("anti_roll_bar_stiffness", 3e5, 5e6, "torsion bar of a locomotive or coach, "
                   "1–3 MN m/rad, x⅓ … x1.7", source=ESTIMATE),
    ParameterRange("traction_link_height", -0.45, 0.3, "between ~0.2 m above the rail and the "
                   "frame's upper chord", log=False, source=ESTIMATE),
    # the vertical dampers of real vehicles of this class: tens of kN s/m (a car body that rings
    # for minutes is not a bogie that exists, whatever Table 1's real parts ask)
    ParameterRange("primary_damping_z", 1e4, 1e5, "primary vertical damper per axle box: "
                   "power cars 12–30 kN s/m, up to 100 for locomotives",
                   source="; ".join((ZHAI_POWER_CAR, EUROSTAR_POWER_CAR, PIONEER, MANCHESTER))),
    ParameterRange("secondary_damping_z", 1e4, 1.2e5, "secondary vertical damper per spring: "
                   "10–120 kN s/m", source="; ".join((MANCHESTER, ZHAI_POWER_CAR,
                                                      EUROSTAR_POWER_CAR, PIONEER))),
    ParameterRange("secondary_damping_y", 2e3, 1e5, "secondary lateral damper per side",
                   source=ESTIMATE),
    ParameterRange("rotor_inertia", 6.0, 24.0, "rotor of 550 kg, radius of gyration 0.10–0.21 m; "
                   "x½ … x2 around 12 kg m^2", source=ESTIMATE),
    # b_M (docs/validation.md, "The motor slope"): the converter holds the healthy motor's torque
    # for slow motions — on the constant-power hyperbola M ω = P the slope is M/ω = 12 800 N m /
    # 212 rad/s ≈ 60 N m s/rad; faster than its torque control the motor shows its natural
    # characteristic, M/(s_n ω_s) ≈ 12 800 / (0.005 · 214) ≈ 12 000 N m s/rad at 0.5 % slip
    ParameterRange("motor_slope", 60.0, 12000.0, "asynchronous drive between its controlled "
                   "characteristic (constant power, M/ω ≈ 60) and its natural one at 0.5 % slip "
                   "(≈ 12 000 N m s/rad)", source=STUDY + "; asynchronous traction motors at "
                   "0.5–2 % rated slip (docs/validation.md, 'The motor slope')"),
)
SEARCH_PARAMETERS = CREEP_SHAPE_PARAMETERS + STRUCTURAL_PARAMETERS
FREE_PARAMETERS = CREEP_PARAMETERS + SEARCH_PARAMETERS


# a rigid body's principal inertias obey the triangle inequalities |I_x − I_y| <= I_z <= I_x + I_y
# (equality on the right for a flat body); Polach's kS <= kA
def constraint_values(parameters: Parameters) -> np.ndarray:
    """The constraints as g <= 0 (dimensionless): I_z <= I_x + I_y, I_z >= I_y − I_x,
    I_z >= I_x − I_y of the frame, kS <= kA."""
    Ix, Iy, Iz = (parameters[f"frame_inertia_{a}"] for a in "xyz")
    return np.array([(Iz - Ix - Iy) / (Ix + Iy), (Iy - Ix - Iz) / (Ix + Iy),
                     (Ix - Iy - Iz) / (Ix + Iy),
                     (parameters["polach_kS"] - parameters["polach_kA"]) / parameters["polach_kA"]])


def with_constraints(parameters: Parameters) -> Parameters:
    """``parameters`` with the frame's yaw inertia kept within |I_x − I_y| … I_x + I_y and
    Polach's kS limited to kA."""
    changes = {}
    Ix, Iy, Iz = (parameters[f"frame_inertia_{a}"] for a in "xyz")
    if Iz > Ix + Iy:
        changes["frame_inertia_z"] = float(Ix + Iy)
    elif Iz < abs(Ix - Iy):
        changes["frame_inertia_z"] = float(abs(Ix - Iy))
    if parameters["polach_kS"] > parameters["polach_kA"]:
        changes["polach_kS"] = float(parameters["polach_kA"])
    return parameters.replace(**changes) if changes else parameters


def parameter_rows(parameters: Parameters) -> list[dict]:
    """One dict per parameter (schema order, the strength data last): name, value [SI], unit,
    note, and for the parameters the calibration fits its bounds ``lower``, ``upper`` [SI],
    ``on_bound`` and ``bounds_source`` (the reason for the ends and the published data they come
    from; None otherwise): what ``bogie parameters`` and the dashboard's Variant tab
    show."""
    free = {f.name: f for f in FREE_PARAMETERS}
    rows = []
    for name, (unit, _, _) in ALL_SCHEMA.items():
        value = float(parameters[name])
        f = free.get(name)
        rows.append({"name": name, "value": value, "unit": unit,
                     "note": parameters.notes.get(name, ""),
                     "lower": None if f is None else f.low, "upper": None if f is None else f.high,
                     "on_bound": None if f is None else f.on_bound(value),
                     "bounds_source": None if f is None else f.bounds_source})
    return rows
