"""What excites the drive at frequencies tied to speed, and at fixed ones: the excitation orders of
a Campbell diagram.

Per speed v [m/s] the wheel turns at ``f_wheel = v / (2π r0)`` [Hz] and the motor's rotor (with
the pinion) at ``f_rotor = p f_wheel`` (p: the gear ratio).  The orders:

* ``wheel:k`` — k per revolution of the wheel (out-of-round wheels, a wheel flat), ``k f_wheel``;
* ``rotor:k`` — k per revolution of the rotor (unbalance, misalignment), ``k f_rotor``;
* ``mesh:k`` — the k-th harmonic of the gear mesh, ``k z f_rotor`` (z: the pinion's teeth);
* ``el:k`` — the k-th harmonic of the motor's electrical frequency ``P f_rotor`` (P: pole pairs;
  the slip of an asynchronous motor, about 1 %, is neglected).  An inverter-fed three-phase motor's
  air-gap torque ripples at 6 and 12 times the stator frequency, an unbalance of the supply at 2
  times;
* ``fixed:f`` — a fixed frequency f [Hz] (the inverter's switching frequency and its side bands).

The motor's pole pairs and the pinion's teeth are not published for the 109E: they are estimates in
``assets/parameters/excitation.toml`` (value, unit and the reasoning for each), read by
:func:`load_excitation`.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from model.mechanics.parameters import ASSETS, Parameters

EXCITATION_FILE = ASSETS / "excitation.toml"
FAMILIES = ("wheel", "rotor", "mesh", "el", "fixed")
FAMILY_WORDS = {"wheel": "per wheel revolution", "rotor": "per rotor revolution",
                "mesh": "gear mesh harmonic", "el": "electrical harmonic", "fixed": "fixed"}
DEFAULT_ORDERS = "wheel:1,rotor:1,mesh:1,el:1,el:2,el:6,el:12"
MAX_ORDER = 1000.0  # orders above this are refused (a typo, not an excitation)
MAX_ORDERS = 24  # orders in one list (each is a line, and a column of solves in a ripple)
_SCHEMA = {"motor_pole_pairs": ("1", "pole pairs P of the traction motor"),
           "pinion_teeth": ("1", "teeth z of the pinion (the driving gear)")}


class ExcitationError(ValueError):
    """A bad excitation order, frequency or excitation file (one-line message)."""


@dataclass(frozen=True)
class DriveExcitation:
    """The counts the speed-tied orders need (whole numbers ≥ 1), with where they come from."""

    pole_pairs: int  # P of the traction motor [-]
    pinion_teeth: int  # z of the pinion [-]
    notes: dict[str, str] = field(default_factory=dict, compare=False, hash=False)
    source: str = "<memory>"

    def __post_init__(self) -> None:
        for label, value in (("motor_pole_pairs", self.pole_pairs),
                             ("pinion_teeth", self.pinion_teeth)):
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 1000:
                raise ExcitationError(f"{label} must be a whole number from 1 to 1000, got {value!r}")


def load_excitation(path: str | Path | None = None) -> DriveExcitation:
    """Read an excitation file (default ``assets/parameters/excitation.toml``)."""
    path = Path(path) if path is not None else EXCITATION_FILE
    try:
        table = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ExcitationError(f"excitation file '{path}' does not exist") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ExcitationError(f"excitation file '{path}' is not valid TOML: {error}") from None
    values, notes = {}, {}
    for name, entry in table.items():
        if name not in _SCHEMA:
            raise ExcitationError(f"{path}: unknown entry '{name}'; known: {', '.join(_SCHEMA)}")
        if not isinstance(entry, dict) or "value" not in entry or entry.get("unit") != _SCHEMA[name][0]:
            raise ExcitationError(f"{path}: '{name}' must be {{ value = …, unit = \"1\", note = … }}")
        values[name], notes[name] = entry["value"], str(entry.get("note", ""))
    missing = [name for name in _SCHEMA if name not in values]
    if missing:
        raise ExcitationError(f"{path}: missing {', '.join(missing)}")
    return DriveExcitation(values["motor_pole_pairs"], values["pinion_teeth"], notes, str(path))


@dataclass(frozen=True)
class Order:
    """One excitation line: ``family`` (:data:`FAMILIES`) and its order k (> 0; for ``fixed`` the
    frequency [Hz])."""

    family: str
    order: float

    def __post_init__(self) -> None:
        if self.family not in FAMILIES:
            raise ExcitationError(f"unknown order family '{self.family}': use one of "
                                  f"{', '.join(FAMILIES)}")
        if not (math.isfinite(self.order) and self.order > 0):
            raise ExcitationError(f"order {self.family}:{self.order:g} is not allowed: orders "
                                  "and frequencies must be > 0")
        if self.family != "fixed" and self.order > MAX_ORDER:
            raise ExcitationError(f"order {self.family}:{self.order:g} is not allowed: at most "
                                  f"{MAX_ORDER:g}")

    @property
    def name(self) -> str:
        """``family:k`` as written on the command line (``el:6``, ``fixed:450``)."""
        return f"{self.family}:{self.order:g}"

    @property
    def label(self) -> str:
        """Words for plots: "6× electrical", "1× wheel", "450 Hz fixed"."""
        if self.family == "fixed":
            return f"{self.order:g} Hz fixed"
        words = {"wheel": "wheel", "rotor": "rotor", "mesh": "gear mesh", "el": "electrical"}
        return f"{self.order:g}× {words[self.family]}"

    def per_speed_hz(self, parameters: Parameters, excitation: DriveExcitation) -> float:
        """d f / d v [Hz per m/s] of the line (0 for a fixed frequency)."""
        if self.family == "fixed":
            return 0.0
        wheel = 1.0 / (2 * math.pi * parameters["wheel_radius"])  # revolutions per metre
        rotor = parameters["gear_ratio"] * wheel
        per_revolution = {"wheel": wheel, "rotor": rotor, "mesh": excitation.pinion_teeth * rotor,
                          "el": excitation.pole_pairs * rotor}[self.family]
        return self.order * per_revolution

    def frequency_hz(self, v, parameters: Parameters, excitation: DriveExcitation) -> np.ndarray:
        """The line's frequency [Hz] at speeds ``v`` [m/s]: a straight line through 0 (a constant
        for ``fixed``)."""
        v = np.asarray(v, dtype=float)
        if self.family == "fixed":
            return np.full(v.shape, self.order)
        return self.per_speed_hz(parameters, excitation) * v


_TOKEN = re.compile(r"^\s*(?:([a-z]+)\s*:)?\s*([^:\s]+)\s*$")


def parse_orders(text: str) -> tuple[Order, ...]:
    """``"wheel:1,rotor:1,mesh:1,el:6,12"`` -> orders (a bare number is an electrical harmonic);
    duplicates are dropped, the order kept.  Raises :class:`ExcitationError`."""
    orders: list[Order] = []
    tokens = [token for token in text.split(",") if token.strip()]
    if not tokens:
        raise ExcitationError("no excitation orders given")
    if len(tokens) > MAX_ORDERS:
        raise ExcitationError(f"{len(tokens)} orders given: at most {MAX_ORDERS}")
    for token in tokens:
        match = _TOKEN.match(token)
        if match is None:
            raise ExcitationError(f"'{token.strip()}' is not an order: write family:k "
                                  f"({', '.join(FAMILIES)}) or k for an electrical harmonic")
        family = match.group(1) or "el"
        try:
            value = float(match.group(2))
        except ValueError:
            raise ExcitationError(f"'{token.strip()}': the order must be a number") from None
        order = Order(family, value)
        if order not in orders:
            orders.append(order)
    return tuple(orders)


def parse_amplitudes(text: str) -> dict[Order, float]:
    """``"el:6=250,el:12=120"`` -> {order: amplitude [N m]} (amplitudes ≥ 0).  Raises
    :class:`ExcitationError`."""
    amplitudes: dict[Order, float] = {}
    tokens = [token for token in text.split(",") if token.strip()]
    if not tokens:
        raise ExcitationError("no ripple given: write order=amplitude, e.g. el:6=250")
    if len(tokens) > MAX_ORDERS:
        raise ExcitationError(f"{len(tokens)} orders given: at most {MAX_ORDERS}")
    for token in tokens:
        if token.count("=") != 1:
            raise ExcitationError(f"'{token.strip()}' is not order=amplitude (e.g. el:6=250)")
        left, right = token.split("=")
        (order,) = parse_orders(left)
        try:
            amplitude = float(right)
        except ValueError:
            raise ExcitationError(f"'{token.strip()}': the amplitude must be a number [N m]") from None
        if not (math.isfinite(amplitude) and 0 <= amplitude <= 1e7):
            raise ExcitationError(f"'{token.strip()}': the amplitude must be in [0, 1e7] N m")
        if order in amplitudes:
            raise ExcitationError(f"order {order.name} is given twice")
        amplitudes[order] = amplitude
    return amplitudes
