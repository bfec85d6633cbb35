"""Design variants: a parameter set given as its differences from a bundled set.

A variant is a mapping ``name -> value`` (SI, the units of :data:`model.mechanics.parameters.SCHEMA`) of
the parameters a review changes.  It travels as a compact, canonical text
``name:value,name:value`` (sorted, shortest round-trip float repr) — in the URL (``variant=``)
and inside the *set key* that the cached computations of :mod:`app.results.compute` take instead of a
file name: ``"FILE|name:value,…"`` (``FILE`` empty for the calibrated default).  Sets stay in
the session and in these keys: nothing is written to the server's disk.

No Panel here: the editor is :mod:`app.dashboard.variant_view`.
"""

from __future__ import annotations

import hashlib
import math
import tomllib
from collections.abc import Mapping

from model.mechanics.parameters import (
    ALL_SCHEMA,
    SCHEMA,
    ParameterError,
    Parameters,
    dumps_parameters,
    load_parameters,
    parse_parameters,
)

MAX_UPLOAD_BYTES = 200_000  # an uploaded TOML set larger than this is refused (a full set: ~15 kB)
MAX_VARIANT_CHARS = 4_000  # longest variant text accepted from a URL
REVIEW_FACTOR = 100.0  # a variant's value stays within this factor of the bundled set's value
# (the schema's bounds only say what is physically meaningful, e.g. a gear ratio > 0; a gear
# ratio of 1e300 passes them but breaks the numerics: a review changes a design, not its scale)

# what a design review changes, by subsystem (names of model.parameters.SCHEMA)
EDITABLE: dict[str, tuple[str, ...]] = {
    "drive: driving shaft and gearing": (
        "driving_shaft_stiffness", "gear_mesh_stiffness", "gear_ratio"),
    "drive: disc clutch": (
        "disc_clutch_torsional_stiffness", "disc_clutch_axial_stiffness",
        "disc_clutch_radial_stiffness", "disc_clutch_tilt_stiffness"),
    "drive: claw clutch": (
        "claw_clutch_torsional_stiffness", "claw_clutch_axial_stiffness",
        "claw_clutch_radial_stiffness", "claw_clutch_tilt_stiffness"),
    "drive: hollow shaft": ("hollow_shaft_outer_radius", "hollow_shaft_inner_radius"),
    "motor": ("rotor_inertia", "rotor_mass", "stator_mass", "stator_inertia_y", "motor_slope"),
    "silent blocks": ("silent_block_stiffness_x", "silent_block_stiffness_y",
                      "silent_block_stiffness_z"),
    "primary suspension": ("primary_stiffness_x", "primary_stiffness_y", "primary_stiffness_z",
                           "primary_damping_z"),
    "secondary suspension": ("secondary_stiffness_x", "secondary_stiffness_y",
                             "secondary_stiffness_z", "secondary_damping_y",
                             "secondary_damping_z", "yaw_damping"),
    "creep law (Polach)": ("polach_mu0", "polach_A", "polach_B", "polach_kA", "polach_kS",
                           "creep_slope"),
}
EDITABLE_NAMES = tuple(name for names in EDITABLE.values() for name in names)


class VariantError(ValueError):
    """A variant, its text or an uploaded set is malformed or out of range (message shown)."""


def base_parameters(base: str) -> Parameters:
    """The bundled set a variant refers to (``""``: the calibrated default)."""
    return load_parameters(base or None)


def apply_variant(base: Parameters, changes: Mapping[str, float]) -> Parameters:
    """``base`` with ``changes`` applied and the whole set validated: each value within
    REVIEW_FACTOR of the bundled value (when that is not zero), the schema's bounds and the
    constraints between values (as for a file); raises :class:`VariantError`."""
    for name, value in changes.items():
        reference = base.values.get(name)
        if reference and isinstance(value, int | float) and math.isfinite(value) and not (
                abs(reference) / REVIEW_FACTOR <= abs(value) <= abs(reference) * REVIEW_FACTOR
                and value * reference > 0):
            unit = SCHEMA[name][0]
            raise VariantError(
                f"parameter '{name}' = {value:g} {unit} is outside the review range "
                f"{reference / REVIEW_FACTOR:g} … {reference * REVIEW_FACTOR:g} {unit} "
                f"(a factor {REVIEW_FACTOR:g} around the bundled {reference:g})")
    try:
        changed = base.replace(**dict(changes))
        # the constraints between values (kS <= kA, inner < outer radius) are checked by the
        # file parser: run the set through it
        return parse_parameters(_table(changed), source="variant")
    except ParameterError as error:
        raise VariantError(str(error)) from None


def review_range(base: Parameters, name: str) -> tuple[float, float]:
    """(lowest, highest) value of ``name`` a variant may take [SI]: within REVIEW_FACTOR of the
    bundled value, and within the schema's bounds."""
    low, high, _ = SCHEMA[name][2]
    reference = base.values[name]
    if reference > 0:
        low, high = max(low, reference / REVIEW_FACTOR), min(high, reference * REVIEW_FACTOR)
    return low, high


def _table(parameters: Parameters) -> dict:
    return {name: {"value": parameters.values[name], "unit": ALL_SCHEMA[name][0],
                   "note": parameters.notes.get(name, "")} for name in ALL_SCHEMA}


def _number(value: float) -> str:
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def encode(changes: Mapping[str, float]) -> str:
    """Canonical text of a variant: ``name:value,…`` sorted by name ("" for no changes)."""
    return ",".join(f"{name}:{_number(changes[name])}" for name in sorted(changes))


def decode(text: str) -> dict[str, float]:
    """The variant of :func:`encode`'s text; raises :class:`VariantError` naming the fault
    (unknown parameter, not a number, not finite; bounds are checked by :func:`apply_variant`)."""
    if len(text) > MAX_VARIANT_CHARS:
        raise VariantError(f"variant text too long ({len(text)} characters, at most "
                           f"{MAX_VARIANT_CHARS})")
    changes: dict[str, float] = {}
    for item in filter(None, text.split(",")):
        name, sep, value = item.partition(":")
        if not sep:
            raise VariantError(f"variant entry '{item[:60]}' is not name:value")
        if name not in SCHEMA:
            raise VariantError(f"variant: unknown parameter '{name[:60]}'")
        try:
            number = float(value)
        except ValueError:
            raise VariantError(f"variant: {name} must be a number, got '{value[:60]}'") from None
        if not math.isfinite(number):
            raise VariantError(f"variant: {name} must be finite, got '{value[:60]}'")
        changes[name] = number
    return changes


def set_key(base: str, changes: Mapping[str, float]) -> str:
    """The key of a parameter set for :mod:`app.results.compute`: the base file, plus ``|`` and the
    variant's canonical text when it changes anything."""
    text = encode(changes)
    return f"{base}|{text}" if text else base


def split_key(key: str) -> tuple[str, dict[str, float]]:
    """(base file, changes) of a set key."""
    base, _, text = key.partition("|")
    return base, decode(text)


def parameters_of_key(key: str) -> Parameters:
    """The validated parameter set a key stands for."""
    base, changes = split_key(key)
    parameters = base_parameters(base)
    return apply_variant(parameters, changes) if changes else parameters


def differences(base: Parameters, other: Parameters) -> dict[str, tuple[float, float]]:
    """name -> (base value, other value) of every value that differs (schema order)."""
    return {name: (base.values[name], other.values[name]) for name in SCHEMA
            if base.values[name] != other.values[name]}


def set_hash(parameters: Parameters) -> str:
    """Short fingerprint of the values of a set (12 hex digits of SHA-256 over the values in
    schema order): equal hashes, equal numbers, whatever the notes say."""
    text = ";".join(f"{name}={parameters.values[name]!r}" for name in SCHEMA)
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def full_hash(parameters: Parameters) -> str:
    """SHA-256 (hex) of every value of a set, the strength data included (names in
    :data:`model.mechanics.parameters.ALL_SCHEMA` order, each value's ``repr``): the key of a
    set in the results cache (:mod:`app.results.cache`); two sets with equal hashes are equal
    in every number (:func:`model.mechanics.parameters.parameter_hash` leaves the strength data
    out: equal dynamics)."""
    text = ";".join(f"{name}={float(parameters.values[name])!r}" for name in ALL_SCHEMA)
    return hashlib.sha256(text.encode()).hexdigest()


def changes_from_toml(data: bytes, base: Parameters) -> dict[str, float]:
    """The differences from ``base`` of an uploaded parameter file (bytes of TOML in the format
    of :mod:`model.mechanics.parameters`); raises :class:`VariantError` for an oversized, undecodable,
    malformed or invalid file."""
    if len(data) > MAX_UPLOAD_BYTES:
        raise VariantError(f"file too large ({len(data):,} bytes, at most {MAX_UPLOAD_BYTES:,})")
    try:
        table = tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise VariantError("file is not UTF-8 text") from None
    except tomllib.TOMLDecodeError as error:
        raise VariantError(f"file is not valid TOML: {error}") from None
    try:
        uploaded = parse_parameters(table, source="uploaded file")
    except ParameterError as error:
        raise VariantError(str(error)) from None
    return {name: new for name, (_, new) in differences(base, uploaded).items()}


def dumps_variant(parameters: Parameters, base_name: str, changes: Mapping[str, float]) -> str:
    """TOML text of a variant's full set, with its base and changes in the header."""
    header = (f"design variant of {base_name or 'the calibrated set'} "
              f"(hash {set_hash(parameters)})\nchanges: {encode(changes) or 'none'}")
    return dumps_parameters(parameters, header)
