"""What the Resonances view and the report compute (:mod:`model.analysis.campbell`,
:mod:`model.analysis.frequency_response`), cached across sessions, as plain data.

Arguments are primitives (``panel.cache`` keys them by value) in the units of
:mod:`app.results.compute` (``v_kmh`` [km/h], ``N0_kN`` [kN]); orders and ripples are their
command-line texts (``"wheel:1,el:6"``, ``"el:6=250"``), parsed here (a bad text raises the
model's one-line :class:`ValueError`).  The Campbell diagram spans the dashboard's speeds and
names its modes at the middle of them, so it does not depend on the speed slider (the slider
only moves the FRF's operating point and the line marking it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import panel as pn

from app.results import compute
from model.analysis.campbell import campbell, ripple_response, speeds_kmh
from model.analysis.frequency_response import (
    DEFAULT_INPUT,
    MODEL_FREQUENCY_LIMIT_HZ,
    FrequencyResponse,
    frequency_response,
)
from model.mechanics.excitation import (
    DEFAULT_ORDERS,
    MAX_ORDERS,
    Order,
    load_excitation,
    parse_amplitudes,
    parse_orders,
)
from model.mechanics.outputs import output_matrices

SPEEDS_KMH = (10.0, 250.0)  # the dashboard's speed range [km/h]
CAMPBELL_SPEEDS = 200  # speeds of the diagram
RIPPLE_SPEEDS = 241  # speeds of the forced response (1 km/h apart)
FRF_POINTS = 2000  # log-spaced frequencies of the FRF (plus the resonances' points)
# an illustrative ripple [N m]: 2 % and 1 % of the published pre-fault torque M = 12 800 N m
# at 6 and 12 times the electrical frequency (the harmonics an inverter-fed motor's air-gap
# torque has); the view and `bogie ripple` take any other
DEFAULT_RIPPLE = "el:6=256,el:12=128"
DEFAULT_OUTPUT = "ID1.driving_shaft.torque"
MOTOR_INPUTS = ("ID1.motor.torque", "ID2.motor.torque")


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

    key: tuple
    v_kmh: np.ndarray  # (V,) [km/h]
    reference_kmh: float  # the speed the modes are named at [km/h]
    modes: tuple[CampbellMode, ...]
    orders: tuple[tuple[str, str, np.ndarray], ...]  # (name, label, f_hz (V,))
    crossings: tuple[CampbellCrossing, ...]  # by severity, largest first
    input: str


@pn.cache(max_items=16)
def campbell_result(params_path: str, rail: str, s0: float, N0_kN: float, b_M: float,
                    orders: str = DEFAULT_ORDERS, fixed_hz: tuple[float, ...] = (),
                    input: str = DEFAULT_INPUT) -> CampbellView:
    """The diagram over :data:`SPEEDS_KMH` at s0, N0, b_M (``orders``: their text;
    ``fixed_hz``: fixed frequencies [Hz])."""
    chosen = parse_orders(orders) + tuple(Order("fixed", float(f)) for f in fixed_hz)
    chosen = tuple(dict.fromkeys(chosen))
    m = compute.model(params_path, rail)
    reference = 0.5 * (SPEEDS_KMH[0] + SPEEDS_KMH[1])
    op = compute.operating_point(params_path, rail, s0, reference, N0_kN, b_M)
    diagram = campbell(m, op, speeds_kmh(*SPEEDS_KMH, CAMPBELL_SPEEDS), chosen, load_excitation(),
                       input=input)
    modes = tuple(CampbellMode(mode.name, mode.f_hz, mode.zeta, mode.eigenvalues)
                  for mode in diagram.modes)
    lines = tuple((o.name, o.label, line) for o, line in zip(diagram.orders, diagram.lines_hz,
                                                              strict=True))
    crossings = tuple(CampbellCrossing(c.mode, c.order.name, c.order.label, c.v_kmh, c.f_hz,
                                       c.zeta, *c.worst) for c in diagram.crossings)
    return CampbellView((params_path, rail, s0, N0_kN, b_M, orders, fixed_hz, input),
                        diagram.v_kmh, reference, modes, lines, crossings, input)


@pn.cache(max_items=32)
def frf_result(params_path: str, rail: str, s0: float, v_kmh: float, N0_kN: float, b_M: float,
               input: str = DEFAULT_INPUT) -> FrequencyResponse:
    """H(f) from ``input`` to every output at the point (0.1…1000 Hz, the static gain first)."""
    m = compute.model(params_path, rail)
    op = compute.operating_point(params_path, rail, s0, v_kmh, N0_kN, b_M)
    return frequency_response(m, op, input=input, points=FRF_POINTS)


@dataclass(frozen=True)
class RippleView:
    """Steady amplitudes over speed under a ripple (read-only)."""

    key: tuple
    v_kmh: np.ndarray  # (V,) [km/h]
    orders: tuple[str, ...]  # "el:6", …
    labels: tuple[str, ...]  # "6× electrical", …
    amplitudes: np.ndarray  # (orders,) [N m]
    names: tuple[str, ...]
    units: tuple[str, ...]
    by_order: np.ndarray  # (orders, outputs, V); NaN beyond the model's frequency limit
    total: np.ndarray  # (outputs, V)


@pn.cache(max_items=16)
def ripple_result(params_path: str, rail: str, s0: float, N0_kN: float, b_M: float,
                  ripple: str = DEFAULT_RIPPLE, input: str = DEFAULT_INPUT) -> RippleView:
    """The forced response over :data:`SPEEDS_KMH` to the ripple text ``ripple``."""
    amplitudes = parse_amplitudes(ripple)
    m = compute.model(params_path, rail)
    op = compute.operating_point(params_path, rail, s0, SPEEDS_KMH[0], N0_kN, b_M)
    result = ripple_response(m, op, speeds_kmh(*SPEEDS_KMH, RIPPLE_SPEEDS), amplitudes,
                             load_excitation(), input=input)
    return RippleView((params_path, rail, s0, N0_kN, b_M, ripple, input), result.v_kmh,
                      tuple(o.name for o in result.orders), tuple(o.label for o in result.orders),
                      result.amplitudes, result.names, result.units, result.by_order, result.total)


@pn.cache(max_items=8)
def output_names(params_path: str, rail: str) -> tuple[tuple[str, str], ...]:
    """(name, unit) of every named output of the set's model."""
    m = compute.model(params_path, rail)
    matrices = output_matrices(m, compute.operating_point(params_path, rail, 0.005, 120.0,
                                                          m.parameters["wheel_force"] / 1e3,
                                                          m.parameters["motor_slope"]))
    return tuple(zip(matrices.names, matrices.units, strict=True))


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
