"""What the Resonances view and the report compute (:mod:`model.analysis.campbell`,
:mod:`model.analysis.frequency_response`, :mod:`model.analysis.wheel_excitation`,
:mod:`model.analysis.track_spectrum`), kept in the results cache, as plain data.

Arguments are a case record (:class:`app.results.case.Case`) and the view's settings; orders
and ripples are their command-line texts (``"wheel:1,el:6"``, ``"el:6=250"``), a wheel polygon
``bogie ripple --wheel-polygon``'s (``"20=30"``: order = radial amplitude in µm), parsed here (a
bad text raises the model's one-line :class:`ValueError`).  The Campbell diagram spans the
dashboard's speeds and names its modes at the middle of them, so it does not depend on the
speed slider (the slider only moves the FRF's operating point and the line marking it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from app.results import compute
from app.results.case import Case, CaseBase
from model.analysis.campbell import campbell, ripple_response, speeds_kmh
from model.analysis.frequency_response import (
    DEFAULT_INPUT,
    MODEL_FREQUENCY_LIMIT_HZ,
    FrequencyResponse,
    frequency_response,
    input_names,
)
from model.analysis.track_spectrum import LOW, RandomResponse, random_response
from model.analysis.wheel_excitation import PolygonResponse, parse_polygon, polygon_response
from model.mechanics.excitation import (
    DEFAULT_ORDERS,
    MAX_ORDERS,
    Order,
    load_excitation,
    parse_amplitudes,
    parse_orders,
)
from model.mechanics.irregularity import is_irregularity
from model.mechanics.outputs import output_matrices

SPEEDS_KMH = Case.quantity("v").bounds  # the dashboard's speed range [km/h]
CAMPBELL_SPEEDS = 200  # speeds of the diagram
RIPPLE_SPEEDS = 241  # speeds of the forced response (1 km/h apart)
POLYGON_SPEEDS = 49  # speeds of the polygon's response (5 km/h apart; its resonances are
# refined in speed by the model, so a coarser grid loses no peak and keeps the view's wait short)
TRACK_POINTS = 300  # frequencies of the random track's PSD (plus the resonances' points)
FRF_POINTS = 2000  # log-spaced frequencies of the FRF (plus the resonances' points)
# an illustrative ripple [N m]: 2 % and 1 % of the published pre-fault torque M = 12 800 N m
# at 6 and 12 times the electrical frequency (the harmonics an inverter-fed motor's air-gap
# torque has); the view and `bogie ripple` take any other
DEFAULT_RIPPLE = "el:6=256,el:12=128"
DEFAULT_OUTPUT = "ID1.driving_shaft.torque"


@dataclass(frozen=True)
class CampbellMode:
    """One line of the diagram."""

    name: str  # its character (Table 2 style)
    f_hz: np.ndarray  # (V,) [Hz] (0: overdamped there)
    zeta: np.ndarray  # (V,) damping ratio [-]
    eigenvalues: np.ndarray  # (V,) [1/s]


@dataclass(frozen=True)
class CampbellCrossing:
    mode: str
    order: str  # "el:6"
    label: str  # "6× electrical"
    v_kmh: float
    f_hz: float
    zeta: float
    worst_output: str  # the torque output with the largest amplitude
    severity: float  # its |H| [N m per N m]


@dataclass(frozen=True)
class CampbellView:
    """The Campbell diagram for the views (read-only, shared between sessions)."""

    case: Case  # its point, the speed left out
    v_kmh: np.ndarray  # (V,) [km/h]
    reference_kmh: float  # the speed the modes are named at [km/h]
    modes: tuple[CampbellMode, ...]
    orders: tuple[tuple[str, str, np.ndarray], ...]  # (name, label, f_hz (V,))
    crossings: tuple[CampbellCrossing, ...]  # by severity, largest first
    input: str


def campbell_result(case: CaseBase, orders: str = DEFAULT_ORDERS,
                    fixed_hz: tuple[float, ...] = (), input: str = DEFAULT_INPUT) -> CampbellView:
    """The diagram over :data:`SPEEDS_KMH` at the case's creepage, wheel force, motor slope and
    set (``orders``: their text; ``fixed_hz``: fixed frequencies [Hz])."""
    point = case.point().without("v")
    fixed_hz = tuple(float(f) for f in fixed_hz)

    def compute_diagram() -> CampbellView:
        chosen = parse_orders(orders) + tuple(Order("fixed", f) for f in fixed_hz)
        chosen = tuple(dict.fromkeys(chosen))
        reference = 0.5 * (SPEEDS_KMH[0] + SPEEDS_KMH[1])
        op = point.replace(v=reference).operating_point()
        diagram = campbell(compute.model_for(point), op,
                           speeds_kmh(*SPEEDS_KMH, CAMPBELL_SPEEDS), chosen, load_excitation(),
                           input=input)
        modes = tuple(CampbellMode(mode.name, mode.f_hz, mode.zeta, mode.eigenvalues)
                      for mode in diagram.modes)
        lines = tuple((o.name, o.label, line) for o, line in zip(diagram.orders,
                                                                  diagram.lines_hz, strict=True))
        crossings = tuple(CampbellCrossing(c.mode, c.order.name, c.order.label, c.v_kmh, c.f_hz,
                                           c.zeta, *c.worst) for c in diagram.crossings)
        return CampbellView(point, diagram.v_kmh, reference, modes, lines, crossings, input)
    return compute.cached("campbell", point, compute_diagram, orders, fixed_hz, input)


def frf_result(case: CaseBase, input: str = DEFAULT_INPUT) -> FrequencyResponse:
    """H(f) from ``input`` to every output at the case's point (0.1…1000 Hz, the static gain
    first)."""
    point = case.point()
    return compute.cached("frf", point, lambda: frequency_response(
        compute.model_for(point), point.operating_point(), input=input, points=FRF_POINTS), input)


@dataclass(frozen=True)
class RippleView:
    """Steady amplitudes over speed under a ripple (read-only)."""

    case: Case  # its point, the speed left out
    ripple: str  # the ripple's text
    input: str  # the rippling motor
    v_kmh: np.ndarray  # (V,) [km/h]
    orders: tuple[str, ...]  # "el:6", …
    labels: tuple[str, ...]  # "6× electrical", …
    amplitudes: np.ndarray  # (orders,) [N m]
    names: tuple[str, ...]
    units: tuple[str, ...]
    by_order: np.ndarray  # (orders, outputs, V); NaN beyond the model's frequency limit
    total: np.ndarray  # (outputs, V)


def ripple_result(case: CaseBase, ripple: str = DEFAULT_RIPPLE,
                  input: str = DEFAULT_INPUT) -> RippleView:
    """The forced response over :data:`SPEEDS_KMH` to the ripple text ``ripple``."""
    point = case.point().without("v")

    def compute_ripple() -> RippleView:
        amplitudes = parse_amplitudes(ripple)
        op = point.replace(v=SPEEDS_KMH[0]).operating_point()
        result = ripple_response(compute.model_for(point), op,
                                 speeds_kmh(*SPEEDS_KMH, RIPPLE_SPEEDS), amplitudes,
                                 load_excitation(), input=input)
        return RippleView(point, ripple, input, result.v_kmh,
                          tuple(o.name for o in result.orders),
                          tuple(o.label for o in result.orders), result.amplitudes,
                          result.names, result.units, result.by_order, result.total)
    return compute.cached("ripple", point, compute_ripple, ripple, input)


def polygon_result(case: CaseBase, polygon: str) -> PolygonResponse:
    """The steady response over :data:`SPEEDS_KMH` to polygonal wheels (``polygon``: the text
    ``order=µm,…``; every wheel, the rear wheelset a wheelbase later) at the case's creepage,
    wheel force, motor slope and set (:func:`model.analysis.wheel_excitation.polygon_response`)."""
    point = case.point().without("v")

    def compute_polygon() -> PolygonResponse:
        wheels = parse_polygon(polygon)
        op = point.replace(v=SPEEDS_KMH[0]).operating_point()
        return polygon_response(compute.model_for(point), op,
                                speeds_kmh(*SPEEDS_KMH, POLYGON_SPEEDS), wheels)
    return compute.cached("polygon", point, compute_polygon, polygon)


def track_result(case: CaseBase) -> RandomResponse:
    """Every output's PSD and RMS at the case's point under the random vertical track, the
    ERRI/ORE low-level spectrum (:data:`model.analysis.track_spectrum.LOW`)."""
    point = case.point()
    return compute.cached("track", point, lambda: random_response(
        compute.model_for(point), point.operating_point(), LOW, points=TRACK_POINTS))


def frf_inputs(set_key: str) -> tuple[str, ...]:
    """The FRF's inputs the view offers: each motor's torque [N m], then each wheel's rail–wheel
    surface deviation ``IDk.rimNN.irregularity`` [m] (the set's model)."""
    point = Case(set_key=set_key, **Case.defaults(compute.parameters(set_key))).point()
    names = input_names(compute.model_for(point))
    return (tuple(n for n in names if n.endswith(".motor.torque"))
            + tuple(n for n in names if is_irregularity(n)))


def output_names(set_key: str) -> tuple[tuple[str, str], ...]:
    """(name, unit) of every named output of the set's model (the calibrated creep law)."""
    point = Case(set_key=set_key, **Case.defaults(compute.parameters(set_key))).point()

    def names() -> tuple[tuple[str, str], ...]:
        matrices = output_matrices(compute.model_for(point), point.operating_point())
        return tuple(zip(matrices.names, matrices.units, strict=True))
    return compute.cached("output names", point, names)


def parse_fixed(text: str) -> tuple[float, ...]:
    """Fixed frequencies [Hz] from "450, 900" (empty: none); a bad text raises ValueError with
    a one-line message."""
    values = []
    tokens = [token for token in text.replace(";", ",").split(",") if token.strip()]
    if len(tokens) > MAX_ORDERS:
        raise ValueError(f"{len(tokens)} fixed frequencies given: at most {MAX_ORDERS}")
    for token in tokens:
        try:
            value = float(token)
        except ValueError:
            raise ValueError(f"fixed frequency '{token.strip()}' is not a number [Hz]") from None
        if not (np.isfinite(value) and 0 < value <= MODEL_FREQUENCY_LIMIT_HZ):
            raise ValueError(f"fixed frequency {value:g} Hz is not allowed: must be in (0, "
                             f"{MODEL_FREQUENCY_LIMIT_HZ:g}] Hz (the model's validity)")
        values.append(value)
    return tuple(values)


def check_polygon(text: str) -> str:
    """The polygon text if the model takes it (empty: none); else the model's one-line
    ValueError."""
    if text.strip():
        parse_polygon(text)
    return text.strip()
