"""Shareable state: the dashboard's settings as a URL query with the CLI's option names and units.

    /app?s0=0.014&v=200&n0=100000&bm=3000&m0=50000&f=90&decay=0.04&t_end=2

``v`` [km/h], ``n0`` [N], ``bm`` [N m s/rad], ``m0`` [N m], ``f`` [Hz], ``decay`` [-],
``phase`` [s] (Δt; absent: automatic), ``t_end`` [s] as in ``bogie response``; ``rail``
(calibrated/dry/wet), ``locus`` (s0/v), ``zoom`` (all/low), ``mode`` (ν), ``tab`` (the view)
and ``variant`` (a design variant as its differences from the bundled set, ``name:value,…`` in SI
units, :mod:`app.results.variants`).  Opening such a link restores that state, controls included; a bad
value gives a notice naming it and leaves that setting at its default.

No Panel here: :func:`parse_query` and :func:`make_query` work on plain mappings.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from urllib.parse import urlencode

from app.results.variants import VariantError, apply_variant, base_parameters, decode, encode

MAX_QUERY_VALUE = 200  # characters of one query value read (longer: rejected), except variant

# query name -> (dashboard parameter, factor: parameter = query value × factor, unit of the query)
NUMBERS: dict[str, tuple[str, float, str]] = {
    "s0": ("s0", 1.0, "-"),
    "v": ("v", 1.0, "km/h"),
    "n0": ("N0", 1e-3, "N"),
    "bm": ("b_M", 1.0, "N m s/rad"),
    "m0": ("M0", 1e-3, "N m"),
    "f": ("f", 1.0, "Hz"),
    "decay": ("D", 1.0, "-"),
    "phase": ("dt", 1e3, "s"),
    "t_end": ("t_end", 1.0, "s"),
}
CHOICES = {"rail": "rail", "locus": "locus", "zoom": "zoom"}  # query name -> parameter


def _text(value) -> str:
    """A query value as text (Bokeh's session arguments are lists of bytes)."""
    if isinstance(value, list | tuple):
        value = value[-1] if value else ""
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    return str(value)


def parse_query(query: Mapping, parameters, tabs: list[str] | None, base: str = ""
                ) -> tuple[dict, str, str | None, list[str]]:
    """Read a query: (parameter values to set, variant text, tab name or None, notices).

    ``parameters`` is the dashboard's ``param`` namespace (bounds and choices are read from it),
    ``tabs`` the tab names (``None``: the tab is returned unchecked), ``base`` the bundled set
    a variant refers to.  Unknown names are ignored with a notice; each bad value gives a notice
    and is left out (its default stays)."""
    values: dict = {}
    notices: list[str] = []
    variant, tab = "", None
    for key in query:
        name = str(key)
        text = _text(query[key]).strip()
        if name != "variant" and len(text) > MAX_QUERY_VALUE:
            notices.append(f"{name}: value too long (at most {MAX_QUERY_VALUE} characters)")
            continue
        if name in NUMBERS:
            target, factor, unit = NUMBERS[name]
            try:
                number = float(text)
            except ValueError:
                notices.append(f"{name} = '{text[:40]}' is not a number [{unit}]")
                continue
            value = number * factor
            low, high = parameters[target].bounds
            if not math.isfinite(value) or not low <= value <= high:
                notices.append(f"{name} = {text[:40]} {unit} is outside "
                               f"[{low / factor:g}, {high / factor:g}] {unit}")
                continue
            values[target] = value
            if target == "dt":
                values["dt_auto"] = False
        elif name in CHOICES:
            objects = parameters[CHOICES[name]].objects
            if text not in objects:
                notices.append(f"{name} = '{text[:40]}' is not one of {', '.join(objects)}")
                continue
            values[CHOICES[name]] = text
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
    """The query (without '?') that restores ``dashboard``'s settings: the operating point and
    the excitation always (as in the CLI), the rest when it differs from the default."""
    items: list[tuple[str, str]] = []
    for name, (target, factor, _unit) in NUMBERS.items():
        if target == "dt" and dashboard.dt_auto:
            continue
        items.append((name, _number(getattr(dashboard, target) / factor)))
    for name, target in CHOICES.items():
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
