"""Parameter sets: the shipped files load, TOML round trip, and every kind of bad input raises
:class:`ParameterError` with a message that names the problem."""

from __future__ import annotations

import math
import tomllib

import pytest

from model.mechanics.parameters import (
    ALL_SCHEMA,
    ASSESSMENT_SCHEMA,
    CALIBRATED_FILE,
    ESTIMATE_FILE,
    SCHEMA,
    ParameterError,
    Parameters,
    dumps_parameters,
    load_parameters,
    parameter_hash,
    parse_parameters,
    save_parameters,
)


@pytest.fixture(scope="module")
def estimate() -> Parameters:
    return load_parameters(ESTIMATE_FILE)


@pytest.fixture
def table(estimate) -> dict:
    """A fresh, valid TOML table (as tomllib returns it) to break in one place."""
    return tomllib.loads(dumps_parameters(estimate))


@pytest.mark.parametrize("path", [ESTIMATE_FILE, CALIBRATED_FILE, None])
def test_shipped_files_load_with_every_schema_entry(path):
    p = load_parameters(path)
    assert set(p.values) == set(ALL_SCHEMA)
    assert all(isinstance(v, float) and math.isfinite(v) for v in p.values.values())
    assert all(p.notes[name].strip() for name in ALL_SCHEMA), "every value needs a provenance note"
    # what the study gives nothing for is marked an estimate (or a standard value, or a public
    # fact of the locomotive with its source)
    assert all(p.notes[name].startswith(("estimate", "standard", "fact"))
               for name in ASSESSMENT_SCHEMA)
    assert p["train_mass"] == 0.0  # the study's: the half car body alone


def test_default_is_the_calibrated_file():
    assert load_parameters().values == load_parameters(CALIBRATED_FILE).values


def test_round_trip_dumps_parse(estimate, tmp_path):
    text = dumps_parameters(estimate, header="round trip\nsecond line")
    assert text.startswith("# round trip\n# second line\n")
    again = parse_parameters(tomllib.loads(text))
    assert again.values == estimate.values  # repr() of floats round-trips exactly
    assert again.notes == estimate.notes
    path = tmp_path / "p.toml"
    save_parameters(estimate, path)
    assert load_parameters(path).values == estimate.values


def test_notes_with_quotes_and_backslashes_round_trip(estimate):
    tricky = Parameters(estimate.values, {**estimate.notes, "wheel_radius": 'a "quoted" \\ note'})
    again = parse_parameters(tomllib.loads(dumps_parameters(tricky)))
    assert again.notes["wheel_radius"] == 'a "quoted" \\ note'


def test_replace_validates(estimate):
    assert estimate.replace(gear_ratio=4.0)["gear_ratio"] == 4.0
    assert estimate.replace(gear_ratio=4.0).values.keys() == estimate.values.keys()
    with pytest.raises(ParameterError, match="gear_ratio"):
        estimate.replace(gear_ratio=-1.0)
    with pytest.raises(ParameterError, match="unknown parameter 'gear_rati'"):
        estimate.replace(gear_rati=4.0)


def _break(table: dict, how: str) -> dict:
    if how == "unknown key":
        table["wheel_radiuss"] = {"value": 0.6, "unit": "m", "note": ""}
    elif how == "missing key":
        del table["track_damping"]
    elif how == "wrong unit":
        table["wheel_radius"]["unit"] = "mm"
    elif how == "string value":
        table["gear_ratio"]["value"] = "3.9"
    elif how == "boolean value":
        table["gear_ratio"]["value"] = True
    elif how == "nan":
        table["gear_ratio"]["value"] = math.nan
    elif how == "inf":
        table["rotor_mass"]["value"] = math.inf
    elif how == "negative mass":
        table["rotor_mass"]["value"] = -550.0
    elif how == "zero stiffness":
        table["driving_shaft_stiffness"]["value"] = 0.0
    elif how == "poisson too large":
        table["poisson_ratio"]["value"] = 0.5
    elif how == "not a table":
        table["wheel_radius"] = 0.625
    elif how == "no unit":
        del table["wheel_radius"]["unit"]
    elif how == "kS above kA":
        table["polach_kS"]["value"] = 1.0
        table["polach_kA"]["value"] = 0.5
    elif how == "inner radius above outer":
        table["hollow_shaft_inner_radius"]["value"] = 0.2
    return table


@pytest.mark.parametrize(("how", "message"), [
    ("unknown key", r"unknown parameter 'wheel_radiuss'"),
    ("missing key", r"missing parameter\(s\) track_damping"),
    ("wrong unit", r"'wheel_radius' has unit 'mm', expected 'm'"),
    ("string value", r"'gear_ratio' must be a number, got '3.9'"),
    ("boolean value", r"'gear_ratio' must be a number, got True"),
    ("nan", r"'gear_ratio' must be finite, got nan"),
    ("inf", r"'rotor_mass' must be finite, got inf"),
    ("negative mass", r"'rotor_mass' = -550.0 kg is outside \(0.0, inf\]"),
    ("zero stiffness", r"'driving_shaft_stiffness' = 0.0 N m/rad is outside \(0.0, inf\]"),
    ("poisson too large", r"'poisson_ratio' = 0.5 1 is outside \(0.0, 0.49\]"),
    ("not a table", r"'wheel_radius' must be a table"),
    ("no unit", r"'wheel_radius' must be a table"),
    ("kS above kA", r"polach_kS must not exceed polach_kA"),
    ("inner radius above outer", r"hollow_shaft_inner_radius must be below the outer radius"),
])
def test_bad_tables_raise_parameter_error_naming_the_problem(table, how, message):
    with pytest.raises(ParameterError, match=message):
        parse_parameters(_break(table, how), source="test.toml")


def test_a_set_from_before_the_yaw_damper_height_says_how_to_update_it(table):
    """Sets written before the calibration by rank lack yaw_damper_height: the error names it and how to
    reproduce the earlier model (the dampers then sat at the secondary spring height)."""
    del table["yaw_damper_height"]
    with pytest.raises(ParameterError, match=r"missing parameter\(s\) yaw_damper_height;.*"
                                             r"secondary spring height"):
        parse_parameters(table, source="old.toml")


def test_errors_from_files_name_the_file(table, tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text(dumps_parameters(parse_parameters(table)).replace(
        'gear_ratio = { value = ', 'gear_ratio = { value = -'), encoding="utf-8")
    with pytest.raises(ParameterError, match=r"broken\.toml.*'gear_ratio'.*outside"):
        load_parameters(path)


@pytest.mark.parametrize(("text", "message"), [
    ("wheel_radius = { value = 0.6, unit = \"m\"\n", r"not valid TOML"),
    ("wheel_radius = = 3\n", r"not valid TOML"),
    ("\x00\x01", r"not valid TOML"),
])
def test_malformed_toml(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ParameterError, match=message):
        load_parameters(path)


def test_not_utf8(tmp_path):
    path = tmp_path / "latin1.toml"
    text = "wheel_radius = { value = 0.6, unit = \"m\", note = \"\xe9\" }"
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(ParameterError, match="not valid TOML"):
        load_parameters(path)


def test_missing_file(tmp_path):
    with pytest.raises(ParameterError, match=r"does not exist"):
        load_parameters(tmp_path / "nowhere.toml")
    with pytest.raises(ParameterError, match=r"does not exist"):
        load_parameters(tmp_path)  # a directory is not a parameter file


def test_every_schema_entry_has_unit_description_and_sane_bounds():
    for name, (unit, description, (low, high, _)) in SCHEMA.items():
        assert unit, name
        assert description, name
        assert low < high, name


def test_sets_written_before_the_strength_data_and_train_mass_still_load(table):
    """A file without the strength data and the train mass: the strength data are the default
    set's (the notes say so), the train mass 0; the dynamics' hash is that of the same file with
    them (what a stored study was written with)."""
    full = parse_parameters(table, source="full.toml")
    for name in [*ASSESSMENT_SCHEMA, "train_mass"]:
        del table[name]
    old = parse_parameters(table, source="old.toml")
    default = load_parameters()
    assert old["train_mass"] == 0.0
    assert "not in old.toml" in old.notes["train_mass"]
    for name in ASSESSMENT_SCHEMA:
        assert old[name] == default[name]
        assert old.notes[name].startswith("not in old.toml: the default set's value (")
    assert parameter_hash(old) == parameter_hash(full)


def test_hash_ignores_strength_data_and_a_zero_train_mass(estimate):
    """Strength data do not enter the dynamics; the train mass does once it is not 0."""
    assert parameter_hash(estimate.replace(wheel_seat_friction_min=0.1)) == parameter_hash(estimate)
    assert parameter_hash(estimate.replace(train_mass=1e5)) != parameter_hash(estimate)


@pytest.mark.parametrize(("changes", "message"), [
    ({"wheel_hub_outer_diameter": 0.2}, r"'wheel_hub_outer_diameter' = 0.2 m must exceed the "
                                        r"seat's diameter wheel_seat_diameter = 0.21 m"),
    ({"gear_hub_outer_diameter": 0.25}, r"'gear_hub_outer_diameter' = 0.25 m must exceed"),
    ({"gear_seat_diameter": 0.2}, r"'gear_seat_diameter' = 0.2 m must exceed the hollow "
                                  r"shaft's bore"),
    ({"wheel_seat_interference_min": -1e-4}, r"'wheel_seat_interference_min' = -0.0001 m is "
                                             r"outside \(0.0, inf\]"),
    ({"gear_seat_friction_min": 0.0}, r"'gear_seat_friction_min' = 0.0 1 is outside"),
    ({"wheel_seat_interference_min": 4e-4}, r"'wheel_seat_interference_min' = 0.0004 m must "
                                            r"not exceed 'wheel_seat_interference_max'"),
    ({"wheel_seat_friction_max": 0.1}, r"'wheel_seat_friction_min' = 0.12 must not exceed"),
    ({"ripple_el6_amplitude": -256.0}, r"'ripple_el6_amplitude' = -256.0 N m is outside \[0.0, "),
    ({"axle_tensile_strength": 0.0}, r"'axle_tensile_strength' = 0.0 Pa is outside \(0.0, "),
    ({"driving_shaft_tensile_strength": -1e9}, r"'driving_shaft_tensile_strength' = -1000000000.0 "
                                               r"Pa is outside"),
    ({"hollow_shaft_torsional_notch_factor": 0.8}, r"'hollow_shaft_torsional_notch_factor' = 0.8 1 "
                                                   r"is outside \[1.0, 10.0\]"),
    ({"axle_surface_roughness": 0.0}, r"'axle_surface_roughness' = 0.0 m is outside"),
    ({"claw_clutch_vibratory_torque": 0.0}, r"'claw_clutch_vibratory_torque' = 0.0 N m is outside"),
])
def test_unphysical_strength_data_are_refused_naming_the_parameter(table, estimate, changes,
                                                                   message):
    for name, value in changes.items():
        table[name]["value"] = value
    with pytest.raises(ParameterError, match=r"test\.toml: parameter " + message):
        parse_parameters(table, source="test.toml")
    with pytest.raises(ParameterError, match=message):
        estimate.replace(**changes)
