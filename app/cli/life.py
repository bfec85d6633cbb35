"""``bogie life``: how long each shaft section lasts over a route — Miner's damage sum a year from
the converters' ripple, the wheels' polygons and the track's irregularity over the route's
speeds and the short circuits a year, the life in kilometres and years, and where the damage
comes from.

    bogie life --route FILE [--beyond-knee haibach|elementary|limit] [--slope K]
               [--knee-cycles N] [--sources ripple,polygon,track,short_circuit]
               [--ripple ORDER=AMPLITUDE,…]
               [--rail calibrated|dry|wet] [--params FILE] [--json]

The route file (TOML: a speed histogram or a ``t_s,v_kmh`` CSV, the annual distance, short
circuits a year, the track's spectrum, the wheels' polygon) is described in
model.studies.route; the computation in model.studies.life and model.studies.life_sources.
``--json`` prints ``{"route": …, "sections": [{"name", "damage", "life_km", "life_years", "sn":
{"fatigue_limit", "knee_cycles", "slope", "slope_beyond_knee"}, "contributions": [{"source",
"v_kmh", "damage", "cycles", "stress_amplitude", …}]}], …}`` (damage a year; stress amplitudes in
Pa, mean-stress corrected as the fatigue check does; a life that no source shortens is null).
Bad input (a route file that is not one, an unknown source): one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import math
import sys

from app.cli.options import (
    PARAMETER_FILE,
    UsageError,
    add_rail,
    input_errors,
    input_file,
    load_parameters_from,
    number,
)
from app.cli.output import emit

SOURCES = ("ripple", "polygon", "track", "short_circuit")
TOP_CONTRIBUTIONS = 3  # per section in the table


def register(subparsers) -> None:
    p = subparsers.add_parser("life", help="fatigue life of every shaft section over a route: "
                              "damage a year, life in km and years, and where it comes from")
    p.add_argument("--route", type=input_file(_load_route), required=True, metavar="FILE",
                   help="route file (TOML; e.g. assets/routes/mixed_passenger_200.toml)")
    p.add_argument("--beyond-knee", choices=("haibach", "elementary", "limit"), default="haibach",
                   help="the S-N curve below the fatigue limit: Haibach's slope 2k-1, the slope "
                        "k continued, or no damage (default %(default)s)")
    p.add_argument("--slope", type=number("--slope", 1.0, 50.0, low_open=False, high_open=False,
                                          allowed="a slope k of 1 … 50"),
                   default=None, metavar="K",
                   help="finite-life slope k of the shear S-N curve (default 8, FKM)")
    p.add_argument("--knee-cycles", type=number("--knee-cycles", 1e3, 1e10, low_open=False,
                                                high_open=False, allowed="1e3 … 1e10 cycles"),
                   default=None, metavar="N",
                   help="cycles N_D at the knee (default 1e6, FKM)")
    p.add_argument("--sources", default=",".join(SOURCES), metavar="LIST",
                   help="load sources, of " + ", ".join(SOURCES) + " (default all)")
    p.add_argument("--ripple", default=None, metavar="ORDER=AMPLITUDE,…",
                   help="each converter's ripple [N m] per order (default: the set's)")
    add_rail(p)
    p.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set)")
    p.add_argument("--json", action="store_true", help="machine-readable JSON output")
    p.set_defaults(func=cmd_life)


def _load_route(path: str):
    from model.studies.route import load_route

    return load_route(path)


def options_from_args(args: argparse.Namespace):
    """(parameters, route, LifeOptions, sources) from the options; bad input raises."""
    from model.mechanics.excitation import parse_amplitudes
    from model.studies.assessment import check_ripple
    from model.studies.envelope import rail_parameters
    from model.studies.life import LifeOptions
    from model.studies.life_sources import (
        PolygonSource,
        RippleSource,
        ShortCircuitSource,
        TrackSource,
    )
    from model.studies.route import load_route

    names = [name.strip() for name in args.sources.split(",") if name.strip()]
    unknown = [name for name in names if name not in SOURCES]
    if not names or unknown or len(set(names)) != len(names):
        raise UsageError(f"--sources: give distinct names of {', '.join(SOURCES)}"
                         + (f" (not {', '.join(unknown)})" if unknown else ""))
    parameters = rail_parameters(load_parameters_from(args), args.rail)
    route = load_route(args.route)
    ripple = None
    if args.ripple is not None:
        try:
            ripple = parse_amplitudes(args.ripple)
            check_ripple(ripple)
        except input_errors() as error:
            raise UsageError(f"--ripple: {error}") from None
    defaults = LifeOptions()
    options = LifeOptions(
        knee_cycles=defaults.knee_cycles if args.knee_cycles is None else args.knee_cycles,
        slope=defaults.slope if args.slope is None else args.slope,
        beyond_knee=args.beyond_knee, ripple=ripple)
    by_name = {"ripple": RippleSource(), "polygon": PolygonSource(), "track": TrackSource(),
               "short_circuit": ShortCircuitSource()}
    return parameters, route, options, tuple(by_name[name] for name in names)


def _life(value: float | None, unit: str) -> str:
    return "no damage" if value is None or not math.isfinite(value) else f"{value:.3g} {unit}"


def life_table(result) -> str:
    """The sections' lives as text, least life first, each with its largest contributions."""
    route = result.route
    lines = [f"route: {route.name} — {route.annual_distance / 1e3:g} km a year, "
             f"{route.running_hours_per_year:.0f} running hours"
             + ("" if route.short_circuit is None else
                f", {route.short_circuit.per_year:g} short circuits a year"),
             f"sources: {', '.join(result.sources)}; S-N: N_D = {result.options.knee_cycles:g}, "
             f"k = {result.options.slope:g}, beyond the knee: {result.options.beyond_knee}",
             "",
             f"{'section':<18} {'tau_WK [MPa]':>12} {'damage/year':>12} {'life [km]':>14} "
             f"{'life [years]':>14}  where the damage comes from"]
    for life in sorted(result.sections, key=lambda s: (s.life_km, s.section.name)):
        groups: dict[tuple, float] = {}
        for c in life.contributions:  # an event's amplitude classes are one entry
            key = (c.source, c.v_kmh, c.detail.get("order"))
            groups[key] = groups.get(key, 0.0) + c.damage
        top = sorted(groups.items(), key=lambda item: -item[1])[:TOP_CONTRIBUTIONS]
        where = "; ".join(
            source + ("" if v_kmh is None else f" at {v_kmh:g} km/h")
            + ("" if order is None else f" ({order})") + f" {100 * damage / life.damage:.3g} %"
            for (source, v_kmh, order), damage in top) if life.damage else "-"
        lines.append(f"{life.section.name:<18} {life.section.fatigue.tau_WK / 1e6:>12.4g} "
                     f"{life.damage:>12.3g} {_life(life.life_km, ''):>14} "
                     f"{_life(life.life_years, ''):>14}  {where}")
    least = result.least_life
    lines += ["", f"least life: {least.section.name}, {_life(least.life_km, 'km')} "
                  f"({_life(least.life_years, 'years')})" if least.damage > 0 else
              "least life: none — no source does damage to any section",
              *result.notes,
              "Miner's linear damage sum with the FKM guideline's shear S-N curve through DIN "
              "743's fatigue limit: a comparison of sections and speeds, not a certified life "
              "(docs/assessment.md). Not counted: the axle's bending, fretting at the seats."]
    return "\n".join(lines)


def cmd_life(args: argparse.Namespace) -> None:
    from model.studies.life import route_life
    from model.studies.life_sources import check_events

    parameters, route, options, sources = options_from_args(args)
    if any(source.name == "short_circuit" for source in sources):
        check_events(parameters, route)  # an unstable event refused before any work
    print(f"life: {route.name}: {', '.join(s.name for s in sources)} …", file=sys.stderr)
    result = route_life(parameters, route, sources, options)
    emit(args, {**result.as_dict(), "rail": args.rail}, life_table(result))
