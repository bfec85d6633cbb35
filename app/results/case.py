"""The case a result is computed for — the parameter set, the operating point, the short circuit
and the simulated time — each quantity declared once.

A :class:`Quantity` holds everything about one of them: its name (the record's field, the
dashboard's parameter, the control's CSS class ``ctl-<name>``), label, unit, the dashboard's
range and step, its default, the decimals a record keeps, its name and unit in links, on the
command line and in files, the interval the command line accepts, and its *role*: what it
changes in the computation.

* ``"set"``: a choice that changes the parameter set (the rail's creep law);
* ``"point"``: an argument of :class:`model.mechanics.operating_point.OperatingPoint`
  (``target`` names it);
* ``"override"``: a value of the parameter set (``target`` names it): applied as
  ``parameters.replace(target=value)``, so the model is rebuilt per value (and cached per set);
* ``"short_circuit"``: an argument of :class:`model.analysis.response.ShortCircuit`;
* ``"horizon"``: the simulated time.

Everything else is derived from :data:`QUANTITIES` by iterating over it: the record
(:class:`Case`, made by :func:`case_type`), the command line's options
(:func:`app.cli.options.add_case_options`), the dashboard's parameters and sliders
(:func:`app.dashboard.controls.case_parameters`), the link's query (:mod:`app.dashboard.url_state`),
the files (the JSON download) and the report's table (:meth:`CaseBase.rows`).  Code reads a
record's values by name (``case.b_M``), never by position.

A record holds its values in the dashboard's units (:attr:`Quantity.unit`: ``v`` in km/h, ``N0``
in kN, ``M0`` in kN m, ``dt`` in ms), rounded to :attr:`Quantity.digits` decimals (the results
cache's keys carry no float noise); ``None`` for a quantity left out of a key
(:meth:`CaseBase.point`), and for ``dt`` "automatic".  No Panel here.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import ClassVar

from model.mechanics.operating_point import KMH, OperatingPoint
from model.studies.envelope import RAILS

ROLES = ("set", "point", "override", "short_circuit", "horizon")
# the roles a model and an eigen-analysis depend on (the others: a history's)
POINT_ROLES = ("set", "point", "override")


@dataclass(frozen=True)
class Quantity:
    """One quantity of a case, declared once (see the module's docstring)."""

    name: str  # the record's field, the dashboard's parameter, the control's class ctl-<name>
    label: str  # short label: "wheel force N0" (the slider: label [unit])
    doc: str  # what it is: the command line's help, the dashboard parameter's doc
    role: str  # one of ROLES
    target: str = ""  # its name in the model (OperatingPoint, ShortCircuit, a set's value)
    unit: str = "-"  # the record's and the dashboard's unit
    default: float | str | None = None  # default (None: see from_set / automatic)
    from_set: str = ""  # default: this value of the parameter set [SI] (the set's N0, b_M …)
    optional: bool = False  # a record may leave it out: then ``default``, the value a set
    # takes that leaves the parameter out (model.mechanics.parameters.OPTIONAL_DEFAULTS)
    automatic: str = ""  # None allowed, meaning this ("" : a value is needed)
    choices: tuple[str, ...] = ()  # a choice among these instead of a number
    low: float = -math.inf  # the dashboard's range [unit]
    high: float = math.inf
    step: float = 1.0  # the dashboard's slider step [unit]
    format: str = "0"  # the slider's number format
    digits: int = 6  # decimals a record keeps [unit]
    si: float = 1.0  # SI value = value × si (what the model takes)
    link: str = ""  # the name in a link's query
    outer_unit: str = "-"  # the unit in links, on the command line and in files
    outer: float = 1.0  # value in links, on the command line, in files = value × outer
    option: str = ""  # the command-line option, "--n0"
    option_label: str = ""  # how the command line names it in a message, "--n0 (wheel force, N)"
    option_interval: str = ""  # what the command line accepts [outer unit], "[1e3, 1e6]"
    files: tuple[str, ...] = ()  # its keys in the files the program writes

    def __post_init__(self) -> None:
        if self.role not in ROLES:
            raise ValueError(f"quantity {self.name}: role '{self.role}' is not one of {ROLES}")

    @property
    def choice(self) -> bool:
        """Whether the quantity is a choice among names (else a number)."""
        return bool(self.choices)

    @property
    def symbol(self) -> str:
        """The quantity's symbol, the last word of its label (``N0``, ``Δt``)."""
        return self.label.split()[-1]

    def said(self, value) -> str:
        """``symbol = value unit`` (the record's unit)."""
        unit = "" if self.choice or self.unit == "-" else f" {self.unit}"
        return f"{self.symbol} = {value:g}{unit}" if not self.choice else f"{self.name} = {value}"

    @property
    def bounds(self) -> tuple[float, float]:
        """The dashboard's range [unit]."""
        return self.low, self.high

    @property
    def slider_label(self) -> str:
        """The dashboard's label with the unit: ``wheel force N0 [kN]``."""
        return self.label if self.choice else f"{self.label} [{self.unit}]"

    def keep(self, value):
        """``value`` as a record keeps it: rounded to :attr:`digits` (None and choices as they
        are)."""
        if value is None or self.choice:
            return value
        return float(round(float(value), self.digits))

    def to_outer(self, value: float) -> float:
        """The record's value in the unit of links, the command line and files."""
        return value * self.outer

    def from_outer(self, value: float) -> float:
        """A value of a link, the command line or a file in the record's unit."""
        return value / self.outer

    def to_si(self, value: float) -> float:
        """The record's value in SI units (what the model takes)."""
        return value * self.si

    def outer_to_si(self, value: float) -> float:
        """A value of a link, the command line or a file in SI units (as it is where the two
        units agree)."""
        return value if self.si == self.outer else value / self.outer * self.si


QUANTITIES: tuple[Quantity, ...] = (
    Quantity("s0", "creepage s0", "longitudinal creepage s0", "point", "s0", "-", 0.005,
             low=0.0005, high=0.03, step=0.0001, format="0.0000", digits=7, link="s0",
             option="--s0", option_label="--s0 (creepage)", option_interval="(0, 1)",
             files=("s0",)),
    Quantity("v", "speed v", "speed v", "point", "v", "km/h", 120.0, low=10.0, high=250.0,
             step=5.0, format="0", digits=3, si=KMH, link="v", outer_unit="km/h", option="--v",
             option_label="--v (speed, km/h)", option_interval="[1, 500]", files=("v_kmh",)),
    Quantity("N0", "wheel force N0", "static wheel force N0", "point", "N0", "kN", 100.0,
             from_set="wheel_force", low=40.0, high=160.0, step=1.0, format="0", digits=3,
             si=1e3, link="n0", outer_unit="N", outer=1e3, option="--n0",
             option_label="--n0 (wheel force, N)", option_interval="[1e3, 1e6]",
             files=("N0", "wheel_force")),
    Quantity("b_M", "motor slope b_M", "motor slope b_M", "point", "b_M", "N m s/rad", 3000.0,
             from_set="motor_slope", low=0.0, high=20000.0, step=100.0, format="0", digits=3,
             link="bm", outer_unit="N m s/rad", option="--bm",
             option_label="--bm (motor slope, N m s/rad)", option_interval="[0, 1e9]",
             files=("b_M", "motor_slope")),
    Quantity("motor_bandwidth", "motor torque control f_c",
             "torque-control bandwidth f_c of the healthy motor's converter: below it the "
             "converter holds its torque, above it the slope b_M acts (0: no torque control)",
             "override", "motor_bandwidth", "Hz", 0.0, from_set="motor_bandwidth", optional=True,
             low=0.0,
             high=50.0, step=0.5, format="0.0", digits=3, link="fc", outer_unit="Hz",
             option="--motor-bandwidth", option_label="--motor-bandwidth (f_c, Hz)",
             option_interval="[0, 1000]", files=("motor_bandwidth",)),
    Quantity("rail", "rail condition (creep law)",
             "creep law: the set's own (calibrated) or Polach's dry/wet preset", "set", "rail",
             "", "calibrated", choices=RAILS, link="rail", option="--rail", files=("rail",)),
    Quantity("M0", "short circuit M0", "short-circuit amplitude M0 (oscillating part)",
             "short_circuit", "M0", "kN m", 50.0, low=0.0, high=200.0, step=1.0, format="0",
             digits=3, si=1e3, link="m0", outer_unit="N m", outer=1e3, option="--m0",
             option_label="--m0 (amplitude, N m)", option_interval="[0, 1e8]", files=("M0",)),
    Quantity("f", "frequency f", "short-circuit frequency f (oscillating part)", "short_circuit",
             "f", "Hz", 90.0, low=10.0, high=300.0, step=1.0, format="0", digits=3, link="f",
             outer_unit="Hz", option="--f", option_label="--f (frequency, Hz)",
             option_interval="(0, 1e5)", files=("f",)),
    Quantity("D", "decay D", "short-circuit decay D: envelope e^(-D 2π f t)", "short_circuit",
             "D", "-", 0.04, low=0.0, high=0.3, step=0.005, format="0.000", digits=5,
             link="decay", option="--decay", option_label="--decay (D)",
             option_interval="[0, 10]", files=("D",)),
    Quantity("dt", "time shift Δt", "time shift Δt of the short circuit", "short_circuit", "dt",
             "ms", None, automatic="continuous motor torque", low=-10.0,
             high=10.0, step=0.05, format="0.00", digits=4, si=1e-3, link="phase",
             outer_unit="s", outer=1e-3, option="--phase", option_label="--phase (Δt, s)",
             option_interval="[-10, 10]", files=("phase_s",)),
    Quantity("t_end", "simulated time", "simulated time", "horizon", "t_end", "s", 2.0, low=0.2,
             high=5.0, step=0.1, format="0.0", digits=3, link="t_end", outer_unit="s",
             option="--t-end", option_label="--t-end (horizon, s)", option_interval="(0, 60]",
             files=("t",)),
)


class CaseBase:
    """What every record of :func:`case_type` can do (its fields: ``set_key`` and one per
    quantity)."""

    quantities: ClassVar[tuple[Quantity, ...]] = ()
    set_key: str  # the parameter set: a bundled file or a variant of it (app.results.variants)

    def __post_init__(self) -> None:
        for q in self.quantities:
            object.__setattr__(self, q.name, q.keep(getattr(self, q.name)))

    # --- the declarations ---------------------------------------------------------------------

    @classmethod
    def quantity(cls, name: str) -> Quantity:
        """The declaration of ``name`` (KeyError if there is none)."""
        for q in cls.quantities:
            if q.name == name:
                return q
        raise KeyError(name)

    @classmethod
    def of_role(cls, *roles: str) -> tuple[Quantity, ...]:
        """The quantities of these roles, in declaration order."""
        return tuple(q for q in cls.quantities if q.role in roles)

    @classmethod
    def names(cls, *roles: str) -> tuple[str, ...]:
        """The names of the quantities of these roles (every one without roles)."""
        return tuple(q.name for q in cls.quantities if not roles or q.role in roles)

    @classmethod
    def defaults(cls, parameters=None) -> dict:
        """name -> default value [unit]: the declared default, or the set's value (``parameters``,
        :class:`model.mechanics.parameters.Parameters`) for a quantity with ``from_set``."""
        values = {}
        for q in cls.quantities:
            value = q.default
            if q.from_set and parameters is not None:
                value = parameters[q.from_set] / q.si
            values[q.name] = value
        return values

    @classmethod
    def from_outer(cls, set_key: str, values: Mapping[str, object], parameters=None):
        """A record of values in the outer units (links, command line, files) by quantity name;
        a value missing or None takes its default (``parameters``: the set's values)."""
        fields = cls.defaults(parameters)
        for q in cls.quantities:
            value = values.get(q.name)
            if value is not None:
                fields[q.name] = value if q.choice else q.from_outer(float(value))
        return cls(set_key=set_key, **fields)

    # --- the values -------------------------------------------------------------------------

    def values(self) -> dict:
        """name -> value [unit] of every quantity, in declaration order."""
        return {q.name: getattr(self, q.name) for q in self.quantities}

    def replace(self, **changes):
        """A copy with some values changed (rounded as the record keeps them)."""
        return dataclasses.replace(self, **changes)

    def without(self, *names: str):
        """A copy with the quantities ``names`` left out (None): the key of a result that does
        not depend on them."""
        return dataclasses.replace(self, **dict.fromkeys(names))

    def point(self):
        """The record of the parameter set and the operating point only (the short circuit and
        the horizon left out): what a model, an eigen-analysis or a sweep depends on."""
        return self.without(*(q.name for q in self.quantities if q.role not in POINT_ROLES))

    def limit_key(self):
        """What s0*(v) depends on: the point without s0."""
        return self.point().without("s0")

    def sweep(self, parameter: str) -> Sweep:
        """The root locus over ``parameter`` ("s0" or "v") through this case's point: what it
        depends on."""
        return Sweep(parameter, self.point().without(parameter))

    def overrides(self) -> tuple[tuple[str, float, float], ...]:
        """(name, SI value, SI tolerance) of the parameter set's values the case replaces (role
        ``override``), sorted: a key.  The tolerance is half the record's last decimal: a
        value that close to the set's own is the set's (its default, rounded, is no change)."""
        return tuple(sorted((q.target, q.to_si(getattr(self, q.name)),
                             q.to_si(0.5 * 10.0 ** -q.digits))
                            for q in self.of_role("override") if getattr(self, q.name) is not None))

    def operating_point(self) -> OperatingPoint:
        """The model's operating point (SI); raises OperatingPointError for one outside the
        model's domain."""
        values = {}
        for q in self.of_role("point"):
            value = getattr(self, q.name)
            if value is None:
                raise ValueError(f"the case has no {q.name}: {self!r}")
            values[q.target] = q.to_si(value)
        return OperatingPoint(**values)

    def short_circuit(self):
        """The short circuit (:class:`model.analysis.response.ShortCircuit`, SI); a quantity
        left out (None) and allowed to be automatic is automatic."""
        from model.analysis.response import ShortCircuit

        values = {q.target: None if getattr(self, q.name) is None else q.to_si(getattr(self, q.name))
                  for q in self.of_role("short_circuit")}
        return ShortCircuit(**values)

    # --- what the interfaces show -----------------------------------------------------------

    def outer(self) -> dict:
        """name -> value in the outer unit (links, command line, files); None as it is."""
        return {q.name: (getattr(self, q.name) if q.choice or getattr(self, q.name) is None
                         else q.to_outer(getattr(self, q.name))) for q in self.quantities}

    def files(self) -> dict:
        """The quantities as the files write them: each quantity's first file key -> value in
        the outer unit (a quantity left out or automatic: None)."""
        return {q.files[0]: value for q, value in zip(self.quantities, self.outer().values(),
                                                       strict=True) if q.files}

    def rows(self) -> list[tuple[str, str]]:
        """(what [outer unit], value) of every quantity: the report's table."""
        rows = []
        for q, value in zip(self.quantities, self.outer().values(), strict=True):
            if q.choice:
                rows.append((q.label, str(value)))
            elif value is None:
                rows.append((f"{q.label} [{q.outer_unit}]", f"automatic ({q.automatic})"
                             if q.automatic else "—"))
            else:
                rows.append((f"{q.label} [{q.outer_unit}]", f"{value:g}"))
        return rows


@dataclass(frozen=True)
class Sweep:
    """A root locus: the swept quantity and the point without it (a record of
    :func:`case_type`)."""

    parameter: str  # "s0" [-] or "v" [km/h]
    case: CaseBase  # the point the sweep passes through, the swept quantity left out

    def at(self, value: float):
        """The point of the sweep at ``value`` of the swept quantity [its unit]."""
        return self.case.replace(**{self.parameter: value})


def case_type(quantities: Iterable[Quantity], name: str = "Case") -> type:
    """The record of ``quantities``: a frozen dataclass with ``set_key`` and one keyword field
    per quantity (a quantity whose default is the set's value has no default, give it — unless
    it declares one: the value a set takes that leaves the parameter out, such as no torque
    control)."""
    quantities = tuple(quantities)
    fields = [("set_key", str, dataclasses.field(default=""))]
    for q in quantities:
        kind = str if q.choice else (float | None)
        if q.from_set and not q.optional:
            spec = dataclasses.field(metadata={"quantity": q})
        else:
            spec = dataclasses.field(default=q.default, metadata={"quantity": q})
        fields.append((q.name, kind, spec))
    return dataclasses.make_dataclass(name, fields, bases=(CaseBase,), frozen=True, kw_only=True,
                                      namespace={"quantities": quantities,
                                                 "__module__": __name__})


Case = case_type(QUANTITIES)
