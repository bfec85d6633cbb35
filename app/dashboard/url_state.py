"""Shareable state: the dashboard's settings as a URL query with the CLI's option names and units.

    /app?s0=0.014&v=200&n0=100000&bm=3000&m0=50000&f=90&decay=0.04&t_end=2

The case's quantities by their declared link names and units (:data:`app.results.case.QUANTITIES`,
the command line's: ``v`` [km/h], ``n0`` [N], ``bm`` [N m s/rad], ``m0`` [N m], ``f`` [Hz],
``decay`` [-], ``phase`` [s] (Δt; absent: automatic), ``t_end`` [s] as in ``bogie response``;
``rail`` (calibrated/dry/wet)); ``locus`` (s0/v), ``zoom`` (all/low), ``mode`` (ν), ``tab`` (the
view) and ``variant`` (a design variant as its differences from the bundled set,
``name:value,…`` in SI units, :mod:`app.results.variants`).  Opening such a link restores that
state, controls included; a bad value gives a notice naming it and leaves that setting at its
default.

No Panel here: :func:`parse_query` and :func:`make_query` work on plain mappings.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from urllib.parse import urlencode

from app.results.case import QUANTITIES, Quantity
from app.results.variants import VariantError, apply_variant, base_parameters, decode, encode

MAX_QUERY_VALUE = 200  # characters of one query value read (longer: rejected), except variant
VIEW_CHOICES = {"locus": "locus", "zoom": "zoom"}  # query name -> parameter of the view


def numbers(quantities=QUANTITIES) -> dict[str, Quantity]:
    """query name -> the number quantity it sets (value in the query's unit, the declared
    outer unit)."""
    return {q.link: q for q in quantities if q.link and not q.choice}


def choices(quantities=QUANTITIES) -> dict[str, str]:
    """query name -> the parameter of a choice: the case's choices and the view's."""
    return {**{q.link: q.name for q in quantities if q.link and q.choice}, **VIEW_CHOICES}


def _text(value) -> str:
    """A query value as text (Bokeh's session arguments are lists of bytes)."""
    if isinstance(value, list | tuple):
        value = value[-1] if value else ""
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    return str(value)


def parse_query(query: Mapping, parameters, tabs: list[str] | None, base: str = "",
                quantities=QUANTITIES) -> tuple[dict, str, str | None, list[str]]:
    """Read a query: (parameter values to set, variant text, tab name or None, notices).

    ``parameters`` is the dashboard's ``param`` namespace (bounds and choices are read from it),
    ``tabs`` the tab names (``None``: the tab is returned unchecked), ``base`` the bundled set
    a variant refers to, ``quantities`` the dashboard's case quantities.  Unknown names are
    ignored with a notice; each bad value gives a notice and is left out (its default stays)."""
    by_link, choice_of = numbers(quantities), choices(quantities)
    values: dict = {}
    notices: list[str] = []
    variant, tab = "", None
    for key in query:
        name = str(key)
        text = _text(query[key]).strip()
        if name != "variant" and len(text) > MAX_QUERY_VALUE:
            notices.append(f"{name}: value too long (at most {MAX_QUERY_VALUE} characters)")
            continue
        if name in by_link:
            q = by_link[name]
            unit = q.outer_unit
            try:
                number = float(text)
            except ValueError:
                notices.append(f"{name} = '{text[:40]}' is not a number [{unit}]")
                continue
            value = q.from_outer(number)
            low, high = parameters[q.name].bounds
            if not math.isfinite(value) or not low <= value <= high:
                notices.append(f"{name} = {text[:40]} {unit} is outside "
                               f"[{q.to_outer(low):g}, {q.to_outer(high):g}] {unit}")
                continue
            values[q.name] = value
            if q.automatic:  # a value given: not automatic
                values[f"{q.name}_auto"] = False
        elif name in choice_of:
            objects = parameters[choice_of[name]].objects
            if text not in objects:
                notices.append(f"{name} = '{text[:40]}' is not one of {', '.join(objects)}")
                continue
            values[choice_of[name]] = text
        elif name == "mode":
            low, high = parameters["mode"].bounds
            if not text.isdigit() or not low <= int(text) <= high:
                notices.append(f"mode = '{text[:40]}' is not a mode number {low}…{high}")
                continue
            values["mode"] = int(text)
        elif name == "tab":
            if tabs is not None and text not in tabs:
                notices.append(f"tab = '{text[:40]}' is not one of {', '.join(tabs)}")
                continue
            tab = text
        elif name == "variant":
            try:
                changes = decode(text)
                apply_variant(base_parameters(base), changes)  # every value and the whole set
            except (VariantError, ValueError) as error:
                notices.append(f"variant: {error}")
                continue
            variant = encode(changes)
        else:
            notices.append(f"unknown setting '{name[:40]}' ignored")
    return values, variant, tab, notices


def _number(value: float) -> str:
    return f"{value:.12g}"


def make_query(dashboard, tab: str | None = None) -> str:
    """The query (without '?') that restores ``dashboard``'s settings: the case's numbers always
    (as in the CLI; one that is automatic: absent), the rest when it differs from the
    default."""
    quantities = dashboard.case_type.quantities
    items: list[tuple[str, str]] = []
    for name, q in numbers(quantities).items():
        if q.automatic and getattr(dashboard, f"{q.name}_auto"):
            continue
        items.append((name, _number(q.to_outer(getattr(dashboard, q.name)))))
    for name, target in choices(quantities).items():
        if getattr(dashboard, target) != dashboard.param[target].default:
            items.append((name, getattr(dashboard, target)))
    if dashboard.mode != dashboard.param["mode"].default:
        items.append(("mode", str(dashboard.mode)))
    if tab:
        items.append(("tab", tab))
    if dashboard.variant:
        items.append(("variant", dashboard.variant))
    return urlencode(items, safe=":,")


def fit_phase(phase: float, period: float, limit: float = 0.010) -> float | None:
    """A fault instant Δt [s] moved by whole periods ``period`` [s] (the same short circuit) into
    the dashboard's range [−``limit``, ``limit``] [s]; None if no shift fits."""
    if not math.isfinite(phase):
        return None
    if abs(phase) <= limit:
        return phase
    if period > 0 and math.isfinite(period):
        shifted = phase - round(phase / period) * period
        if abs(shifted) <= limit:
            return shifted
    return None


def scenario_query(scenario: Mapping, t_end: float, variant: str = "",
                   tab: str | None = "response") -> str:
    """The query (without '?') that opens one scenario of a design-load envelope (the
    ``max_at``/``min_at`` dicts of :func:`model.studies.envelope.envelope`: ``s0``, ``v_kmh``,
    ``n0`` [N], ``bm``, ``m0`` [N m], ``f`` [Hz], ``decay``, ``phase_s`` [s], ``rail``) with the
    simulated time ``t_end`` [s]; the fault instant is moved by whole periods into the
    dashboard's range (left out, automatic, if none fits)."""
    items = [("s0", _number(scenario["s0"])), ("v", _number(scenario["v_kmh"])),
             ("n0", _number(scenario["n0"])), ("bm", _number(scenario["bm"])),
             ("m0", _number(scenario["m0"])), ("f", _number(scenario["f"])),
             ("decay", _number(scenario["decay"]))]
    phase = fit_phase(float(scenario["phase_s"]), 1.0 / float(scenario["f"]))
    if phase is not None:
        items.append(("phase", _number(phase)))
    items += [("t_end", _number(t_end)), ("rail", str(scenario["rail"]))]
    if tab:
        items.append(("tab", tab))
    if variant:
        items.append(("variant", variant))
    return urlencode(items, safe=":,")
