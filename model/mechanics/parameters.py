"""Parameter sets: the schema, validation and TOML file I/O.

A parameter file is a TOML table of entries ``name = { value = …, unit = "…", note = "…" }``.
Every value is in SI units (the unit string must equal the schema's); the note says where the
value comes from (public fact, estimate and why, or calibration output).  Two schemas:
:data:`SCHEMA`, what the dynamics need, and :data:`ASSESSMENT_SCHEMA`, the strength data of the
checks (:mod:`model.analysis.assessment`: press fits, shaft sections, coupling ratings, required
safety factors), which do not enter the dynamics.  Unknown names are errors, and so are missing
names of :data:`SCHEMA`, with exceptions for files written before they existed: a missing
``train_mass`` is 0 (the locomotive alone, as in the study), a missing ``motor_bandwidth`` is 0
(no torque control: the study's motor slope at every frequency), and missing strength data take
the default set's values (each note says so).
"""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

ASSETS = Path(__file__).resolve().parents[2] / "assets" / "parameters"  # model/mechanics/ -> project
ESTIMATE_FILE = ASSETS / "estimate.toml"
CALIBRATED_FILE = ASSETS / "calibrated.toml"


class ParameterError(ValueError):
    """A parameter file or value is missing, malformed, unknown or out of range."""


# name -> (unit, short description, (lower, upper, lower bound allowed?)); the upper bound is
# inclusive.  These are validity bounds (what the model can compute with), not calibration bounds.
_POS = (0.0, math.inf, False)
_NONNEG = (0.0, math.inf, True)
SCHEMA: dict[str, tuple[str, str, tuple[float, float, bool]]] = {
    # --- wheel/rail geometry and contact -------------------------------------------------------
    "wheel_radius": ("m", "nominal rolling radius r0", _POS),
    "contact_half_distance": ("m", "half lateral distance of the wheel-rail contact points", _POS),
    "rail_head_radius": ("m", "transverse radius of the rail head (Hertz contact)", _POS),
    "young_modulus": ("Pa", "Young's modulus of wheel, rail, shafts (steel)", _POS),
    "poisson_ratio": ("1", "Poisson's ratio of steel", (0.0, 0.49, False)),
    "steel_density": ("kg/m^3", "density of the shafts' steel", _POS),
    "wheel_force": ("N", "static vertical wheel force N0", _POS),
    # --- creep law (Polach) --------------------------------------------------------------------
    "polach_mu0": ("1", "Polach: maximum friction coefficient at zero slip velocity", _POS),
    "polach_A": ("1", "Polach: ratio of limit friction at infinite slip velocity to mu0", (0.0, 1.0, True)),
    "polach_B": ("s/m", "Polach: exponential friction decrease rate with slip velocity", (0.0, 1e3, False)),
    "polach_kA": ("1", "Polach: reduction factor in the area of adhesion", (0.0, 1.0, True)),
    "polach_kS": ("1", "Polach: reduction factor in the area of slip (kS <= kA)", (0.0, 1.0, True)),
    "creep_slope": ("1", "initial creep slope G*pi*a*b*C11/(4*N0) of the creep law", _POS),
    # --- geometry of the bogie ------------------------------------------------------------------
    "wheelbase": ("m", "distance of the two wheelsets", _POS),
    "journal_half_distance": ("m", "half lateral distance of the axle journals (axle boxes)", _POS),
    "frame_height": ("m", "height of the bogie frame's centre of mass above the axle centres", (-2, 2, False)),
    "secondary_half_base_x": ("m", "longitudinal half distance of the secondary springs", _POS),
    "secondary_half_base_y": ("m", "lateral half distance of the secondary springs", _POS),
    "secondary_height": ("m", "height of the secondary spring seats above the axle centres", (-2, 2, False)),
    "yaw_damper_half_base_y": ("m", "lateral half distance of the longitudinal (yaw) dampers", _POS),
    "yaw_damper_height": ("m", "height of the yaw dampers' line of action above the axle centres", (-2, 2, False)),
    "traction_link_height": ("m", "height of the traction link above the axle centres", (-2, 2, False)),
    "gear_radius": ("m", "pitch radius of the driven gear; pinion radius = gear_radius/gear_ratio", _POS),
    "gear_ratio": ("1", "gear ratio p = rotor speed / wheel speed", _POS),
    "pressure_angle": ("rad", "working pressure angle of the gear mesh", (0.0, 0.8, False)),
    "gear_lateral_position": ("m", "lateral position y of gear and disc clutch (drive 1)", (-1, 1, False)),
    "claw_clutch_lateral_position": ("m", "lateral position y of the claw clutch (drive 1)", (-1, 1, False)),
    "stator_offset_x": ("m", "stator centre of mass: x offset from the motor axis", (-1, 1, False)),
    "stator_offset_z": ("m", "vertical offset of the stator's centre of mass from the motor axis", (-1, 1, False)),
    "silent_block_upper_x": ("m", "silent blocks A, B: x offset to the bogie centre", (-2, 2, False)),
    "silent_block_half_y": ("m", "lateral half distance of silent blocks A and B", _POS),
    "silent_block_upper_z": ("m", "height of silent blocks A, B above the motor axis", (-2, 2, False)),
    "silent_block_lower_x": ("m", "silent block C: x offset towards the axle", (-2, 2, False)),
    "silent_block_lower_z": ("m", "height of silent block C above the motor axis", (-2, 2, False)),
    "hollow_shaft_outer_radius": ("m", "outer radius of the hollow shaft", _POS),
    "hollow_shaft_inner_radius": ("m", "inner radius of the hollow shaft", _POS),
    "axle_radius": ("m", "radius of the (solid) wheelset axle", _POS),
    # --- masses and inertias ----------------------------------------------------------------------
    "car_body_mass": ("kg", "half car body mass carried by this bogie", _POS),
    "train_mass": ("kg", "mass of the train this bogie hauls, beyond its half car body: added to "
                   "the car body's longitudinal inertia (0: the locomotive alone)", _NONNEG),
    "car_body_yaw_inertia": ("kg m^2", "half car body yaw inertia about the vertical through the bogie centre", _POS),
    "frame_mass": ("kg", "bogie frame mass", _POS),
    "frame_inertia_x": ("kg m^2", "bogie frame roll inertia", _POS),
    "frame_inertia_y": ("kg m^2", "bogie frame pitch inertia", _POS),
    "frame_inertia_z": ("kg m^2", "bogie frame yaw inertia", _POS),
    "stator_mass": ("kg", "stator with gear housing (without rotor, pinion, gear)", _POS),
    "stator_inertia_x": ("kg m^2", "stator+housing inertia about x through its centre of mass", _POS),
    "stator_inertia_y": ("kg m^2", "stator+housing inertia about y through its centre of mass", _POS),
    "stator_inertia_z": ("kg m^2", "stator+housing inertia about z through its centre of mass", _POS),
    "rotor_mass": ("kg", "rotor mass", _POS),
    "rotor_inertia": ("kg m^2", "rotor polar moment of inertia", _POS),
    "pinion_mass": ("kg", "pinion mass", _POS),
    "pinion_inertia": ("kg m^2", "pinion polar moment of inertia", _POS),
    "gear_mass": ("kg", "driven gear mass", _POS),
    "gear_inertia": ("kg m^2", "driven gear polar moment of inertia", _POS),
    "wheel_disc_mass": ("kg", "wheel disc (centre) mass, lumped at the wheel node", _POS),
    "wheel_disc_polar_inertia": ("kg m^2", "wheel disc inertia about the axle", _POS),
    "wheel_disc_diametral_inertia": ("kg m^2", "wheel disc inertia about a diameter", _POS),
    "axle_box_mass": ("kg", "axle box mass (translates with the journal, does not spin)", _POS),
    "rim_mass": ("kg", "wheel rim (tyre) mass", _POS),
    "rim_polar_inertia": ("kg m^2", "wheel rim inertia about the axle", _POS),
    "rim_diametral_inertia": ("kg m^2", "wheel rim inertia about a diameter", _POS),
    "track_mass": ("kg", "track mass m_R under each wheel (eq. 11)", _POS),
    # --- stiffnesses -------------------------------------------------------------------------------
    "driving_shaft_stiffness": ("N m/rad", "torsional stiffness k_DS of the driving shaft rotor-pinion", _POS),
    "gear_mesh_stiffness": ("N/m", "gear mesh stiffness k_G along the line of action", _POS),
    "disc_clutch_torsional_stiffness": ("N m/rad", "disc clutch torsional stiffness k_DC", _POS),
    "disc_clutch_axial_stiffness": ("N/m", "disc clutch axial stiffness", _POS),
    "disc_clutch_radial_stiffness": ("N/m", "disc clutch radial stiffness (x and z)", _POS),
    "disc_clutch_tilt_stiffness": ("N m/rad", "disc clutch tilting stiffness (about x and z)", _POS),
    "claw_clutch_torsional_stiffness": ("N m/rad", "claw clutch torsional stiffness k_CC", _POS),
    "claw_clutch_axial_stiffness": ("N/m", "claw clutch axial stiffness", _POS),
    "claw_clutch_radial_stiffness": ("N/m", "claw clutch radial stiffness (x and z)", _POS),
    "claw_clutch_tilt_stiffness": ("N m/rad", "claw clutch tilting stiffness (about x and z)", _POS),
    "rim_radial_stiffness": ("N/m", "wheel rim to disc radial stiffness (x and z)", _POS),
    "rim_axial_stiffness": ("N/m", "wheel rim to disc axial stiffness (y)", _POS),
    "rim_torsional_stiffness": ("N m/rad", "wheel rim to disc torsional stiffness (about the axle)", _POS),
    "rim_tilt_stiffness": ("N m/rad", "wheel rim to disc tilting stiffness (about x and z)", _POS),
    "silent_block_stiffness_x": ("N/m", "silent block stiffness, longitudinal, per block", _POS),
    "silent_block_stiffness_y": ("N/m", "silent block stiffness, lateral, per block", _POS),
    "silent_block_stiffness_z": ("N/m", "silent block stiffness, vertical, per block", _POS),
    "primary_stiffness_x": ("N/m", "longitudinal wheelset guide stiffness per axle box", _POS),
    "primary_stiffness_y": ("N/m", "primary lateral stiffness per axle box", _POS),
    "primary_stiffness_z": ("N/m", "primary vertical stiffness per axle box", _POS),
    "secondary_stiffness_x": ("N/m", "secondary longitudinal (shear) stiffness per spring", _POS),
    "secondary_stiffness_y": ("N/m", "secondary lateral stiffness per spring", _POS),
    "secondary_stiffness_z": ("N/m", "secondary vertical stiffness per spring", _POS),
    "traction_link_stiffness": ("N/m", "longitudinal stiffness of the traction link between frame and car body", _POS),
    "yaw_damper_series_stiffness": ("N/m", "series stiffness of each yaw damper (its rubber end bushes)", _POS),
    "anti_roll_bar_stiffness": ("N m/rad", "roll stiffness of the anti-roll bar between frame and car body", _NONNEG),
    "track_stiffness": ("N/m", "track stiffness k_R under each wheel (eq. 11)", _POS),
    # --- damping -----------------------------------------------------------------------------------
    "primary_damping_z": ("N s/m", "primary vertical damper per axle box", _NONNEG),
    "secondary_damping_z": ("N s/m", "secondary vertical damper per spring position", _NONNEG),
    "secondary_damping_y": ("N s/m", "secondary lateral damper per bogie side", _NONNEG),
    "yaw_damping": ("N s/m", "longitudinal (yaw) damper per bogie side (in series with its end bushes)", _POS),
    "track_damping": ("N s/m", "track damping b_R under each wheel (eq. 11)", _NONNEG),
    "shaft_loss_time": ("s", "stiffness-proportional damping of steel parts", (0.0, 1.0, True)),
    "rubber_loss_time": ("s", "stiffness-proportional damping of rubber parts", (0.0, 1.0, True)),
    "motor_slope": ("N m s/rad", "b_M: falling slope of the healthy motor's torque-speed characteristic", _NONNEG),
    "motor_bandwidth": ("Hz", "f_c: torque-control bandwidth of the healthy motor's converter; below it the "
                        "converter holds the set-point torque, above it the slope b_M acts (0: no torque "
                        "control, the slope at every frequency)", (0.0, 1e3, True)),
}

# Strength data of the checks (model.analysis.assessment); they do not enter the dynamics.  The
# shafts' own elastic constants are young_modulus and poisson_ratio; the axle is solid and the
# hollow shaft's bore is 2 hollow_shaft_inner_radius, as in the dynamics.
_AMPLITUDE = (0.0, 1e7, True)  # a ripple amplitude [N m]: 0 (none) up to 10 MN m
_STRENGTH = (0.0, 3e9, False)  # a steel's tensile strength [Pa]: > 0, at most 3 GPa
_NOTCH = (1.0, 10.0, True)  # a fatigue notch factor [-]: 1 (no notch) … 10
_ROUGHNESS = (0.0, 1e-3, False)  # a mean roughness depth R_z [m]: > 0, at most 1 mm
ASSESSMENT_SCHEMA: dict[str, tuple[str, str, tuple[float, float, bool]]] = {
    "wheel_seat_diameter": ("m", "wheel seat: diameter d of the axle's seat", _POS),
    "wheel_seat_length": ("m", "wheel seat: length L of the fit", _POS),
    "wheel_hub_outer_diameter": ("m", "wheel seat: outer diameter D of the wheel's hub", _POS),
    "wheel_seat_interference_min": ("m", "wheel seat: smallest diametral interference of the tolerances", _POS),
    "wheel_seat_interference_max": ("m", "wheel seat: largest diametral interference of the tolerances", _POS),
    "wheel_seat_friction_min": ("1", "wheel seat: lowest friction coefficient of the fit", _POS),
    "wheel_seat_friction_max": ("1", "wheel seat: highest friction coefficient of the fit", _POS),
    "gear_seat_diameter": ("m", "gear seat: diameter d of the hollow shaft's seat", _POS),
    "gear_seat_length": ("m", "gear seat: length L of the fit", _POS),
    "gear_hub_outer_diameter": ("m", "gear seat: outer diameter D of the hub on the hollow shaft", _POS),
    "gear_seat_interference_min": ("m", "gear seat: smallest diametral interference of the tolerances", _POS),
    "gear_seat_interference_max": ("m", "gear seat: largest diametral interference of the tolerances", _POS),
    "gear_seat_friction_min": ("1", "gear seat: lowest friction coefficient of the fit", _POS),
    "gear_seat_friction_max": ("1", "gear seat: highest friction coefficient of the fit", _POS),
    "hub_young_modulus": ("Pa", "Young's modulus of the hubs (wheel centre, gear hub)", _POS),
    "hub_poisson_ratio": ("1", "Poisson's ratio of the hubs", (0.0, 0.5, False)),
    "driving_shaft_diameter": ("m", "diameter of the (solid) driving shaft between rotor and pinion", _POS),
    "axle_shear_stress_allowable": ("Pa", "permissible torsional shear stress of the axle", _POS),
    "hollow_shaft_shear_stress_allowable": ("Pa", "permissible torsional shear stress of the hollow shaft", _POS),
    "driving_shaft_shear_stress_allowable": ("Pa", "permissible torsional shear stress of the driving shaft", _POS),
    "starting_traction_force": ("N", "the locomotive's starting traction force at the rails, all its "
                                "driven wheelsets together (what its converters and motors can give)", _POS),
    "driven_wheelsets": ("1", "number of driven wheelsets of the locomotive", (1.0, 64.0, True)),
    "disc_clutch_rated_torque": ("N m", "largest torque the disc clutch is rated for", _POS),
    "claw_clutch_rated_torque": ("N m", "largest torque the claw clutch is rated for", _POS),
    "required_factor_slip": ("1", "required safety factor of a press fit against slip", _POS),
    "required_factor_shear": ("1", "required safety factor of a shaft against its permissible shear stress", _POS),
    "required_factor_coupling": ("1", "required safety factor of a coupling against its rating", _POS),
    # --- under alternating load: the converters' torque ripple (the ripple load case) ------------
    "ripple_el6_amplitude": ("N m", "each converter's air-gap torque ripple at 6 times the motor's "
                             "electrical frequency (amplitude per motor)", _AMPLITUDE),
    "ripple_el12_amplitude": ("N m", "each converter's air-gap torque ripple at 12 times the motor's "
                              "electrical frequency (amplitude per motor)", _AMPLITUDE),
    "axle_tensile_strength": ("Pa", "tensile strength R_m of the axle steel at axle_strength_diameter "
                              "(fatigue check, DIN 743)", _STRENGTH),
    "axle_strength_diameter": ("m", "diameter for which axle_tensile_strength is given: DIN 743-3's "
                               "reference diameter d_B of its table, or the part's own size", _POS),
    "axle_torsional_notch_factor": ("1", "fatigue notch factor beta_tau of the axle's centre section in "
                                    "torsion (DIN 743-2)", _NOTCH),
    "axle_surface_roughness": ("m", "mean roughness depth R_z of the axle's centre section",
                               _ROUGHNESS),
    "hollow_shaft_tensile_strength": ("Pa", "tensile strength R_m of the hollow shaft's steel at "
                                      "hollow_shaft_strength_diameter (fatigue check, DIN 743)",
                                      _STRENGTH),
    "hollow_shaft_strength_diameter": ("m", "diameter for which hollow_shaft_tensile_strength is "
                                       "given: DIN 743-3's reference diameter d_B of its table, or "
                                       "the part's own size", _POS),
    "hollow_shaft_torsional_notch_factor": ("1", "fatigue notch factor beta_tau of the hollow shaft's "
                                            "middle section in torsion (DIN 743-2)", _NOTCH),
    "hollow_shaft_surface_roughness": ("m", "mean roughness depth R_z of the hollow shaft's middle "
                                       "section", _ROUGHNESS),
    "driving_shaft_tensile_strength": ("Pa", "tensile strength R_m of the driving shaft's steel at "
                                       "driving_shaft_strength_diameter (fatigue check, DIN 743)",
                                       _STRENGTH),
    "driving_shaft_strength_diameter": ("m", "diameter for which driving_shaft_tensile_strength is "
                                        "given: DIN 743-3's reference diameter d_B of its table, "
                                        "or the part's own size", _POS),
    "driving_shaft_torsional_notch_factor": ("1", "fatigue notch factor beta_tau of the driving shaft "
                                             "in torsion (DIN 743-2)", _NOTCH),
    "driving_shaft_surface_roughness": ("m", "mean roughness depth R_z of the driving shaft at its "
                                        "notch", _ROUGHNESS),
    "disc_clutch_vibratory_torque": ("N m", "permissible vibratory torque T_KW of the disc clutch "
                                     "(DIN 740-2: the amplitude it bears indefinitely)", _POS),
    "claw_clutch_vibratory_torque": ("N m", "permissible vibratory torque T_KW of the claw clutch "
                                     "(DIN 740-2: the amplitude it bears indefinitely)", _POS),
    "required_factor_fatigue": ("1", "required safety factor of a shaft section against its fatigue "
                                "limit (DIN 743's S_min)", _POS),
    "required_factor_vibratory": ("1", "required safety factor of a coupling against its permissible "
                                  "vibratory torque", _POS),
}
ALL_SCHEMA = {**SCHEMA, **ASSESSMENT_SCHEMA}  # every name a parameter file may hold
# names a file may leave out (written before they existed): train_mass -> 0, motor_bandwidth -> 0,
# strength data -> the default set's values
OPTIONAL_DEFAULTS = {"train_mass": 0.0, "motor_bandwidth": 0.0}
_OPTIONAL_MEANING = {"train_mass": "the locomotive alone as in the study",
                     "motor_bandwidth": "no torque control, the study's slope at every frequency"}


@dataclass(frozen=True)
class Parameters:
    """A complete, validated parameter set (SI units)."""

    values: Mapping[str, float]  # name -> value in the schema's unit
    notes: Mapping[str, str] = field(default_factory=dict)  # name -> provenance note
    source: str = "<memory>"  # file it was read from

    def __getitem__(self, name: str) -> float:
        return self.values[name]

    def replace(self, **changes: float) -> Parameters:
        """A copy with some values changed (validated; strength data as in
        :func:`check_strength_data`)."""
        values = dict(self.values)
        for name, value in changes.items():
            values[name] = _check_value(name, value)
        if any(name in ASSESSMENT_SCHEMA or name == "hollow_shaft_inner_radius"
               for name in changes):
            check_strength_data(values)
        return Parameters(values, self.notes, self.source)


def parameter_hash(parameters: Parameters) -> str:
    """SHA-256 (hex) of the values the dynamics depend on (:data:`SCHEMA`): names in schema
    order, each value as the shortest decimal that round-trips (``repr``).  Notes, the source
    file and the strength data do not count: two sets with equal dynamics have equal hashes.  A
    parameter of :data:`OPTIONAL_DEFAULTS` counts only when it differs from its default, so a set
    hashes as it did before that parameter existed.  Results of studies carry it, and a stored
    study is resumed only with the same hash."""
    canonical = json.dumps([[name, repr(float(parameters.values[name]))] for name in SCHEMA
                            if name not in OPTIONAL_DEFAULTS
                            or parameters.values[name] != OPTIONAL_DEFAULTS[name]],
                           separators=(",", ":"))
    return hashlib.sha256(canonical.encode("utf-8")).hexdigest()


def _check_value(name: str, value: object) -> float:
    if name not in ALL_SCHEMA:
        raise ParameterError(f"unknown parameter '{name}'; allowed: see model/mechanics/parameters.py SCHEMA")
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"parameter '{name}' must be a number, got {value!r}")
    value = float(value)
    unit, _, (low, high, low_allowed) = ALL_SCHEMA[name]
    if not math.isfinite(value):
        raise ParameterError(f"parameter '{name}' must be finite, got {value}")
    if not (low < value <= high or (low_allowed and value == low)):
        bracket = "[" if low_allowed else "("
        raise ParameterError(
            f"parameter '{name}' = {value} {unit} is outside {bracket}{low}, {high}]")
    return value


def parse_entries(table: Mapping[str, object], source: str = "<memory>",
                  unit_required: bool = True) -> tuple[dict[str, float], dict[str, str]]:
    """(values, notes) of a parameter file's entries ``name = { value = …, unit = "…", note =
    "…" }`` (the one reader of that format): each name known, each value a finite number within
    its bounds in the schema's unit (``unit_required`` False: an entry without a unit is taken
    in the schema's); raises :class:`ParameterError` naming ``source`` and the entry."""
    values: dict[str, float] = {}
    notes: dict[str, str] = {}
    for name, entry in table.items():
        if name not in ALL_SCHEMA:
            raise ParameterError(f"{source}: unknown parameter '{name}'")
        if not isinstance(entry, Mapping) or "value" not in entry or (
                unit_required and "unit" not in entry):
            raise ParameterError(
                f"{source}: parameter '{name}' must be a table {{ value = …, unit = \"…\", note = \"…\" }}")
        unit = ALL_SCHEMA[name][0]
        if entry.get("unit", unit) != unit:
            raise ParameterError(
                f"{source}: parameter '{name}' has unit '{entry['unit']}', expected '{unit}'")
        try:
            values[name] = _check_value(name, entry["value"])
        except ParameterError as error:
            raise ParameterError(f"{source}: {error}") from None
        notes[name] = str(entry.get("note", ""))
    return values, notes


def parse_parameters(table: Mapping[str, object], source: str = "<memory>") -> Parameters:
    """Validate a parsed TOML table into :class:`Parameters` (raises :class:`ParameterError`)."""
    values, notes = parse_entries(table, source)
    for name, default in OPTIONAL_DEFAULTS.items():
        if name not in values:
            values[name] = default
            notes[name] = f"not in {source}: {default:g}, {_OPTIONAL_MEANING[name]}"
    missing_strength = [name for name in ASSESSMENT_SCHEMA if name not in values]
    if missing_strength:
        defaults, default_notes = _default_strength_data()
        for name in missing_strength:
            values[name] = defaults[name]
            notes[name] = f"not in {source}: the default set's value ({default_notes[name]})"
    missing = [name for name in SCHEMA if name not in values]
    if missing:
        hint = ""
        if "yaw_damper_height" in missing:  # a set written before the parameter existed
            hint = ("; yaw_damper_height (m, added with the calibration by rank) was the "
                    "secondary spring height in earlier sets: yaw_damper_height = { value = "
                    "<secondary_height>, unit = \"m\" } reproduces them")
        raise ParameterError(f"{source}: missing parameter(s) {', '.join(missing)}{hint}")
    if values["polach_kS"] > values["polach_kA"]:
        raise ParameterError(f"{source}: polach_kS must not exceed polach_kA")
    if values["hollow_shaft_inner_radius"] >= values["hollow_shaft_outer_radius"]:
        raise ParameterError(f"{source}: hollow_shaft_inner_radius must be below the outer radius")
    try:
        check_strength_data(values)
    except ParameterError as error:
        raise ParameterError(f"{source}: {error}") from None
    return Parameters(values, notes, source)


def check_strength_data(values: Mapping[str, float]) -> None:
    """Refuse strength data whose geometry or tolerances are not physical, naming the parameter
    (:class:`ParameterError`): a hub not wider than its seat (d ≥ D), a bore not narrower than
    the seat (d_i ≥ d), a tolerance range upside down.  Non-positive interferences and friction
    coefficients, negative ripple amplitudes, tensile strengths (whence the fatigue limits) and
    roughnesses ≤ 0, and notch factors below 1 are refused by the schema's bounds."""
    pairs = (("wheel_hub_outer_diameter", "wheel_seat_diameter",
              "must exceed the seat's diameter wheel_seat_diameter"),
             ("gear_hub_outer_diameter", "gear_seat_diameter",
              "must exceed the seat's diameter gear_seat_diameter"))
    for outer, inner, what in pairs:
        if values[outer] <= values[inner]:
            raise ParameterError(f"parameter '{outer}' = {values[outer]:g} m {what} = "
                                 f"{values[inner]:g} m")
    bore = 2 * values["hollow_shaft_inner_radius"]
    if values["gear_seat_diameter"] <= bore:
        raise ParameterError(f"parameter 'gear_seat_diameter' = {values['gear_seat_diameter']:g} "
                             f"m must exceed the hollow shaft's bore 2 hollow_shaft_inner_radius "
                             f"= {bore:g} m")
    for seat in ("wheel_seat", "gear_seat"):
        for quantity, unit in (("interference", " m"), ("friction", "")):
            low, high = f"{seat}_{quantity}_min", f"{seat}_{quantity}_max"
            if values[low] > values[high]:
                raise ParameterError(f"parameter '{low}' = {values[low]:g}{unit} must not exceed "
                                     f"'{high}' = {values[high]:g}{unit}")


def _default_strength_data() -> tuple[dict[str, float], dict[str, str]]:
    """(values, notes) of the strength data in the default set's file."""
    table = tomllib.loads(CALIBRATED_FILE.read_text(encoding="utf-8"))
    missing = [name for name in ASSESSMENT_SCHEMA if name not in table]
    if missing:
        raise ParameterError(f"{CALIBRATED_FILE}: strength datum '{missing[0]}' is missing")
    return parse_entries({name: table[name] for name in ASSESSMENT_SCHEMA}, str(CALIBRATED_FILE))


def load_parameters(path: str | Path | None = None) -> Parameters:
    """Read a parameter file; ``None`` gives the calibrated default set.

    Example::

        >>> from model import load_parameters
        >>> parameters = load_parameters()              # the calibrated default set
        >>> parameters["wheel_force"]                   # N0 [N]
        100000.0
        >>> parameters.replace(driving_shaft_stiffness=6e6)["driving_shaft_stiffness"]
        6000000.0
    """
    path = Path(path) if path is not None else CALIBRATED_FILE
    if not path.is_file():
        raise ParameterError(f"parameter file '{path}' does not exist")
    try:
        table = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ParameterError(f"parameter file '{path}' is not valid TOML: {error}") from None
    return parse_parameters(table, source=str(path))


def _toml_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def dumps_parameters(parameters: Parameters, header: str = "") -> str:
    """TOML text of a parameter set, in schema order, each value with unit and note."""
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    if lines:
        lines.append("")
    for name, (unit, _, _) in ALL_SCHEMA.items():
        if name == next(iter(ASSESSMENT_SCHEMA)):
            lines.append("# strength data of the checks (bogie assess); they do not enter the "
                         "dynamics")
        value = parameters.values[name]
        note = parameters.notes.get(name, "")
        lines.append(f"{name} = {{ value = {value!r}, unit = {_toml_string(unit)}, "
                     f"note = {_toml_string(note)} }}")
    return "\n".join(lines) + "\n"


def save_parameters(parameters: Parameters, path: str | Path, header: str = "") -> None:
    """Write a parameter set as TOML (see :func:`dumps_parameters`)."""
    Path(path).write_text(dumps_parameters(parameters, header), encoding="utf-8")
