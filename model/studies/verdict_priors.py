"""Prior ranges of the assessment's strength data and the converters' ripple amplitudes, beside the
dynamics' priors of :data:`model.studies.uncertainty.UNCERTAIN_PARAMETERS`: what the verdict under
uncertainty (:mod:`model.studies.verdict_uncertainty`) samples.

Every strength datum of the default set is an estimate or a standard value with its reasoning
(``bogie parameters``); :data:`STRENGTH_PARAMETERS` gives those that are unknowns of the parts a
:class:`~model.studies.parameter_ranges.ParameterRange` each, its ``reason`` naming where the ends
come from: a tolerance class (ISO 286-1), a standard's spread (EN 13261, EN 10083-3, DIN 743), a
catalogue's proportions (DIN 740-2), or an estimate and why.  Every range contains the default
set's value.  Not sampled:

* the required safety factors: the board's rules, not unknowns (:data:`NOT_SAMPLED` refuses them);
* the locomotive's starting traction force and its number of driven wheelsets: its maker's data
  (refused too);
* the upper ends of the tolerances (``*_interference_max``, ``*_friction_max``): no check uses them
  (a press fit is checked at the smallest interference and the lowest friction);
* the geometry of the seats, hubs and shafts (the drawing's dimensions), the reference diameters of
  the tensile strengths (a definition of the datum), the hubs' Poisson's ratio (steel's 0.3):
  a file of ranges (:func:`load_ranges`) may add any of these.

A **file of ranges** (TOML) changes, adds or removes ranges by name::

    wheel_seat_friction_min = { low = 0.06, high = 0.14 }                 # uniform unless log = true
    disc_clutch_rated_torque = { low = 9e4, high = 1.5e5, log = true, reason = "maker's offer" }
    ripple_el12_amplitude = { fixed = true }                              # not sampled

Values in the parameter's schema unit (SI).  :func:`check_ranges` refuses, with one line naming the
datum (:class:`PriorRangeError`): an unknown name, a rule or a fact of :data:`NOT_SAMPLED`, a lower
end not below the upper, an end outside the parameter's schema bounds (a friction coefficient ≤ 0,
a notch factor below 1, …), a range that leaves out the set's value, or two ranges whose ends
together make a geometry the set refuses (an interference's smallest value above its largest, a
hub not wider than its seat).  A dynamics parameter (:data:`model.mechanics.parameters.SCHEMA`)
belongs to the group ``"dynamics"`` (a new model per sample), a datum of
:data:`~model.mechanics.parameters.ASSESSMENT_SCHEMA` to ``"strength data"`` (the ripple amplitudes
too: the ripple case's loads scale with them, no new dynamics).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Iterable, Mapping
from functools import partial
from itertools import combinations, product
from pathlib import Path

from model.mechanics.parameters import ALL_SCHEMA, SCHEMA, ParameterError, Parameters
from model.studies.parameter_ranges import ParameterRange
from model.studies.uncertainty import UNCERTAIN_PARAMETERS

GROUPS = ("dynamics", "strength data")


class VerdictUncertaintyError(ValueError):
    """Bad input for the verdict under uncertainty (one-line message)."""


class PriorRangeError(VerdictUncertaintyError):
    """A prior range that cannot be sampled (one-line message naming the datum)."""


STRENGTH_PARAMETERS: tuple[ParameterRange, ...] = (
    # --- press fits ---------------------------------------------------------------------------------
    ParameterRange("wheel_seat_interference_min", 1.28e-4, 2.36e-4,  # 190 µm - 46 - 16 … + 46
                   "tolerance class: the fit the drawing prescribes is not known; one ISO 286-1 "
                   "IT7 width (46 µm at 180-250 mm) either side of the set's 0.9 per mille of the "
                   "seat, the lower end a further 16 µm for DIN 7190's smoothing at pressing "
                   "(0.8 (R_z,hub + R_z,shaft), R_z = 10 µm), which the check does not count",
                   log=False),
    ParameterRange("gear_seat_interference_min", 2.32e-4, 3.52e-4,  # 300 µm - 52 - 16 … + 52
                   "tolerance class: as the wheel seat, one IT7 width (52 µm at 250-315 mm) either "
                   "side of the set's 1.0 per mille, the lower end a further 16 µm of smoothing",
                   log=False),
    ParameterRange("wheel_seat_friction_min", 0.08, 0.16,
                   "estimate: steel on steel press fits take 0.1-0.2 in handbooks after DIN 7190, "
                   "lower when pressed on with oil; the set's 0.12 in the middle of 0.08-0.16",
                   log=False),
    ParameterRange("gear_seat_friction_min", 0.08, 0.16,
                   "estimate: as the wheel seat; a shrink fit on degreased surfaces lies at the "
                   "upper end", log=False),
    ParameterRange("hub_young_modulus", 2.0e11, 2.15e11,
                   "estimate: carbon and low-alloy steels 200-215 GPa in handbooks, a cast wheel "
                   "centre at the low end; the set's 210 GPa", log=False),
    # --- shaft sections: permissible shear stress (yield) -------------------------------------------
    ParameterRange("axle_shear_stress_allowable", 320e6 / 2, 420e6 / math.sqrt(3),
                   "standard's spread: EN 13261's axle steels EA1N (R_eH >= 320 MPa) to EA4T (>= "
                   "420 MPa) as handbooks quote them, the shear yield R_eH/2 (Tresca) to "
                   "R_eH/sqrt(3) (von Mises); the set: EA1N, von Mises"),
    ParameterRange("hollow_shaft_shear_stress_allowable", 500e6 / 2, 750e6 / math.sqrt(3),
                   "standard's spread: 42CrMo4 quenched and tempered, EN 10083-3's R_e >= 500 MPa "
                   "(160-250 mm, the outer diameter) to >= 750 MPa (16-40 mm, the 15 mm wall as "
                   "the ruling section) as handbooks quote them, R_e/2 to R_e/sqrt(3); the set: "
                   "650 MPa, von Mises"),
    ParameterRange("driving_shaft_shear_stress_allowable", 550e6 / 2, 650e6 / math.sqrt(3),
                   "standard's spread: 42CrMo4 quenched and tempered at 120 mm, EN 10083-3's R_e >= "
                   "550 MPa (100-160 mm) up to the set's 650 MPa (40-100 mm), R_e/2 to "
                   "R_e/sqrt(3): the set's value is the upper end"),
    # --- shaft sections: torsional fatigue (DIN 743) ------------------------------------------------
    ParameterRange("axle_tensile_strength", 550e6, 800e6,
                   "standard's spread: EN 13261's R_m of EA1N (550-650 MPa) to EA4T (650-800 MPa), "
                   "the grade not known; the set: EA1N's minimum"),
    ParameterRange("hollow_shaft_tensile_strength", 900e6, 1300e6,
                   "standard's spread: R_m at DIN 743-3's 16 mm, EN 10083-3's 1100-1300 MPa for "
                   "42CrMo4 up to 16 mm; the set's 1000 MPa allows for the hollow forging, down to "
                   "900 MPa"),
    ParameterRange("driving_shaft_tensile_strength", 900e6, 1300e6,
                   "standard's spread: as the hollow shaft (42CrMo4 at DIN 743-3's 16 mm)"),
    ParameterRange("axle_torsional_notch_factor", 1.2, 1.5,
                   "estimate: the shoulder to the wheel seat (D/d = 1.1), 1.2-1.4 in handbooks "
                   "after DIN 743-2 and Peterson for a generous fillet, to 1.5 for a smaller one",
                   log=False),
    ParameterRange("hollow_shaft_torsional_notch_factor", 1.3, 2.0,
                   "estimate: the flanged or splined ends, between a plain shoulder (1.2-1.4) and "
                   "a spline (1.8-2.0)", log=False),
    ParameterRange("driving_shaft_torsional_notch_factor", 1.6, 2.2,
                   "estimate: the pinion's fit or spline, 1.6-2.2 in handbooks after DIN 743-2",
                   log=False),
    ParameterRange("axle_surface_roughness", 6.3e-6, 25e-6,
                   "estimate: R_z of a ground (6.3 µm) to a turned (25 µm) surface; the set: "
                   "finely turned, 10 µm"),
    ParameterRange("hollow_shaft_surface_roughness", 6.3e-6, 25e-6,
                   "estimate: as the axle"),
    ParameterRange("driving_shaft_surface_roughness", 4e-6, 16e-6,
                   "estimate: R_z of a fine-ground (4 µm) to a finely turned (16 µm) seat; the "
                   "set: ground, 6.3 µm"),
    # --- couplings -------------------------------------------------------------------------------
    ParameterRange("disc_clutch_rated_torque", 120e3 / 1.5, 120e3 * 1.5,
                   "estimate: the coupling actually chosen is not known; one catalogue size "
                   "either way (x/÷ 1.5) around the set's 2.3 M_ad"),
    ParameterRange("claw_clutch_rated_torque", 150e3 / 1.5, 150e3 * 1.5,
                   "estimate: as the disc clutch, around the set's 2.9 M_ad"),
    ParameterRange("disc_clutch_vibratory_torque", 10e3, 30e3,
                   "catalogue: DIN 740-2's proportions in makers' catalogues, T_KW = 0.25-0.5 T_KN "
                   "and T_Kmax = 2-3 T_KN: 10-30 kN m for T_Kmax = 120 kN m"),
    ParameterRange("claw_clutch_vibratory_torque", 12.5e3, 37.5e3,
                   "catalogue: as the disc clutch, 12.5-37.5 kN m for T_Kmax = 150 kN m"),
    # --- the converters' torque ripple (per motor) ------------------------------------------------
    ParameterRange("ripple_el6_amplitude", 128.0, 640.0,
                   "estimate: 1-5 % of the pre-fault motor torque 12.8 kN m (the set's 2 %: its "
                   "note's source); the converter's modulation is not known"),
    ParameterRange("ripple_el12_amplitude", 64.0, 384.0,
                   "estimate: 0.5-3 % of the pre-fault motor torque (the set's 1 %)"),
)

NOT_SAMPLED = {
    **{name: "a required safety factor is the board's rule, not an unknown"
       for name in ALL_SCHEMA if name.startswith("required_factor_")},
    "starting_traction_force": "the locomotive maker's data, a fact of the set",
    "driven_wheelsets": "the locomotive's wheelset layout, a fact of the set",
}

# the data only the ripple case uses: the converters' amplitudes, the fatigue data, T_KW
RIPPLE_ONLY = frozenset({"ripple_el6_amplitude", "ripple_el12_amplitude",
                         *(f"{part}_{datum}" for part in ("axle", "hollow_shaft", "driving_shaft")
                           for datum in ("tensile_strength", "strength_diameter",
                                         "torsional_notch_factor", "surface_roughness")),
                         "disc_clutch_vibratory_torque", "claw_clutch_vibratory_torque"})
RANGE_KEYS = ("low", "high", "log", "reason", "fixed")


def group_of(name: str) -> str:
    """``"dynamics"`` for a parameter of the dynamics (:data:`SCHEMA`: a sample needs a new model
    and new loads), ``"strength data"`` for a datum of the checks (the loads are reused)."""
    return GROUPS[0] if name in SCHEMA else GROUPS[1]


def default_ranges() -> tuple[ParameterRange, ...]:
    """The dynamics' priors followed by the strength data's: every range sampled by default."""
    return (*UNCERTAIN_PARAMETERS, *STRENGTH_PARAMETERS)


def parse_ranges(table: Mapping[str, object], source: str = "<memory>"
                 ) -> dict[str, ParameterRange | None]:
    """The ranges of a parsed TOML table (module docstring): name -> range, or None for
    ``{ fixed = true }`` (not sampled).  Refuses a malformed entry (:class:`PriorRangeError`); the
    ranges themselves are checked against a set by :func:`check_ranges`."""
    ranges: dict[str, ParameterRange | None] = {}
    for name, entry in table.items():
        where = f"{source}: prior range of '{name}'"
        if name not in ALL_SCHEMA:
            raise PriorRangeError(f"{where}: unknown parameter (see bogie parameters)")
        if not isinstance(entry, Mapping):
            raise PriorRangeError(f"{where}: give a table {{ low = …, high = … }} or "
                                  "{ fixed = true }")
        unknown = [key for key in entry if key not in RANGE_KEYS]
        if unknown:
            raise PriorRangeError(f"{where}: unknown key '{unknown[0]}' (allowed: "
                                  f"{', '.join(RANGE_KEYS)})")
        if "fixed" in entry:
            if entry["fixed"] is not True or len(entry) > 1:
                raise PriorRangeError(f"{where}: 'fixed' stands alone and is true")
            ranges[name] = None
            continue
        ends = []
        for key in ("low", "high"):
            value = entry.get(key)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise PriorRangeError(f"{where}: '{key}' must be a number, got {value!r}")
            ends.append(float(value))
        log = entry.get("log", False)
        if not isinstance(log, bool):
            raise PriorRangeError(f"{where}: 'log' must be true or false, got {log!r}")
        reason = entry.get("reason", f"given in {source}")
        if not isinstance(reason, str):
            raise PriorRangeError(f"{where}: 'reason' must be a string")
        ranges[name] = ParameterRange(name, ends[0], ends[1], reason, log=log)
    return ranges


def load_ranges(path: str | Path) -> dict[str, ParameterRange | None]:
    """The ranges of a TOML file (:func:`parse_ranges`; :class:`PriorRangeError` for a missing or
    malformed file)."""
    path = Path(path)
    if not path.is_file():
        raise PriorRangeError(f"ranges file '{path}' does not exist")
    try:
        table = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise PriorRangeError(f"ranges file '{path}' is not valid TOML: "
                              f"{str(error).splitlines()[0]}") from None
    return parse_ranges(table, str(path))


def merge_ranges(overrides: Mapping[str, ParameterRange | None] | None = None,
                 defaults: Iterable[ParameterRange] | None = None) -> tuple[ParameterRange, ...]:
    """``defaults`` (:func:`default_ranges`) with ``overrides`` applied: a range replaces the
    default of its name or is added after them, None removes the name."""
    overrides = dict(overrides or {})
    merged = []
    for item in default_ranges() if defaults is None else defaults:
        if item.name in overrides:
            replacement = overrides.pop(item.name)
            if replacement is not None:
                merged.append(replacement)
        else:
            merged.append(item)
    merged += [item for item in overrides.values() if item is not None]
    return tuple(merged)


def relevant_ranges(ranges: Iterable[ParameterRange], options
                    ) -> tuple[tuple[ParameterRange, ...], dict[str, str]]:
    """The ranges that can change the verdict under ``options``
    (:class:`~model.studies.assessment.AssessmentOptions`), and the names left out with why: the
    wheel force and the motor slope when the options fix them, the ripple amplitudes when the
    options give their own ripple, the ripple case's data when it is not computed."""
    fixed: dict[str, str] = {}
    if options.N0 is not None:
        fixed["wheel_force"] = "the options fix the wheel force"
    if options.b_M is not None:
        fixed["motor_slope"] = "the options fix the motor slope"
    if "ripple" not in options.cases:
        fixed.update({name: "the ripple case is not computed" for name in RIPPLE_ONLY})
    elif options.ripple is not None:
        fixed.update({name: "the options give the ripple's orders and amplitudes"
                      for name in ("ripple_el6_amplitude", "ripple_el12_amplitude")})
    ranges = tuple(ranges)
    kept = tuple(item for item in ranges if item.name not in fixed)
    return kept, {item.name: fixed[item.name] for item in ranges if item.name in fixed}


def check_ranges(parameters: Parameters, ranges: Iterable[ParameterRange]) -> None:
    """Refuse ranges that cannot be sampled on ``parameters`` (module docstring), one line naming
    the datum (:class:`PriorRangeError`)."""
    ranges = tuple(ranges)
    seen: set[str] = set()
    for item in ranges:
        where = f"prior range of '{item.name}'"
        if item.name not in ALL_SCHEMA:
            raise PriorRangeError(f"{where}: unknown parameter (see bogie parameters)")
        if item.name in NOT_SAMPLED:
            raise PriorRangeError(f"{where}: not sampled, {NOT_SAMPLED[item.name]}")
        if item.name in seen:
            raise PriorRangeError(f"{where}: given twice")
        seen.add(item.name)
        quantity = partial(_quantity, unit=ALL_SCHEMA[item.name][0])
        if not (math.isfinite(item.low) and math.isfinite(item.high)):
            raise PriorRangeError(f"{where}: its ends must be finite numbers")
        if not item.low < item.high:
            raise PriorRangeError(f"{where}: the lower end {quantity(item.low)} is not below the "
                                  f"upper end {quantity(item.high)}")
        if item.log and item.low <= 0:
            raise PriorRangeError(f"{where}: a log-uniform range needs a lower end above 0, got "
                                  f"{quantity(item.low)}")
        for label, end in (("lower", item.low), ("upper", item.high)):
            try:
                parameters.replace(**{item.name: end})
            except ParameterError as error:
                raise PriorRangeError(f"{where}: the {label} end {quantity(end)} is not allowed: "
                                      f"{error}") from None
        value = parameters[item.name]
        if not item.low <= value <= item.high:
            raise PriorRangeError(f"{where}: {item.low:g} … {quantity(item.high)} leaves out the "
                                  f"set's value {quantity(value)}")
    for first, second in combinations(ranges, 2):
        for a, b in product((first.low, first.high), (second.low, second.high)):
            try:
                parameters.replace(**{first.name: a, second.name: b})
            except ParameterError as error:
                raise PriorRangeError(f"prior ranges of '{first.name}' and '{second.name}' "
                                      f"together: {first.name} = {a:g} with {second.name} = "
                                      f"{b:g} is not allowed: {error}") from None


def _quantity(value: float, unit: str) -> str:
    """``value`` with its unit (none for a pure number)."""
    return f"{value:g}" if unit == "1" else f"{value:g} {unit}"
