"""The shaft sections' fatigue life over the bundled route as the dashboard shows it: computed
once per parameter set and operating data (kept in the results cache), each section's life in
km and years for the Verdicts table, and the least-life section's damage a year over speed by
source.

The life is :func:`model.studies.life.route_life` over :data:`ROUTE` (``bogie life --route
assets/routes/mixed_passenger_200.toml``) with the route's sources (:data:`SOURCES`: the
converters' ripple, the wheels' polygons where the route gives them, the track's irregularity,
the short circuits a year) and the default S–N curves, at the dashboard's parameter set with its
wheel force N0 and motor slope b_M as the set's ``wheel_force`` and ``motor_slope`` (the
sources take those).  It takes 25 s to 2 min: the dashboard runs it in a background worker
process (its runner: :func:`app.services.background.run`), asking the checkpoint it is given
(:func:`app.services.background.checkpoint`) between its sources.
"""

from __future__ import annotations

import math
from pathlib import Path

from bokeh.models import ColumnDataSource, HoverTool, Range1d
from bokeh.plotting import figure

from app.results import compute
from app.results.case import CaseBase

ROUTE = Path(__file__).resolve().parents[2] / "assets" / "routes" / "mixed_passenger_200.toml"
SOURCES = ("ripple", "polygon", "track", "short_circuit")  # the route's sources, in this order
SPEED_SOURCES = ("ripple", "polygon", "track")  # the sources over speed (the plot's lines)
SOURCE_COLOURS = {"ripple": "#9467bd", "polygon": "#ff7f0e", "track": "#2ca02c"}
LOWEST_SHOWN = 1e-25  # the plot's lowest damage a year, relative to the largest [-]
FATIGUE_CHECK = "torsional fatigue"  # the rows of the Verdicts table a life belongs to


def life_key(case: CaseBase) -> CaseBase:
    """What the life depends on: the parameter set, rail and operating data (N0, b_M); not the
    creepage, speed, short circuit or horizon of the dashboard's point (the route gives its own
    speeds, creepages and short circuits)."""
    return case.without("dt", "t_end", "v", "s0", "M0", "f", "D")


def _in_this_thread(function, *args):
    return function(*args)


def _no_checkpoint() -> None:
    pass


def life_result(case: CaseBase, strength: tuple = (), route: str = str(ROUTE),
                sources: tuple = SOURCES, runner=_in_this_thread, checkpoint=_no_checkpoint):
    """The life over ``route`` (a route file's path) from ``sources`` (names of
    :data:`SOURCES`) — a :class:`model.studies.life.LifeResult` — at the case's set and
    operating data with the strength data ``strength`` ((name, value) pairs) replacing the
    set's, kept in the results cache; ``runner(function, *args)`` computes it when the cache does
    not hold it (served: :func:`app.services.background.run` with a stop), ``checkpoint()``
    (a module-level function) is called before each source (it raises when the answer is no
    longer wanted)."""
    key = life_key(case)
    extra = (tuple(strength), str(route), tuple(sources))
    return compute.cached("route life", key,
                          lambda: runner(_route_life, key, *extra, checkpoint), *extra)


def known_life(case: CaseBase, strength: tuple = (), route: str = str(ROUTE),
               sources: tuple = SOURCES):
    """The kept life of :func:`life_result`'s arguments, or None (nothing is computed)."""
    from app.results.cache import RESULTS

    key = life_key(case)
    try:
        digest = compute.set_hash_for(key)
    except ValueError:
        return None
    return RESULTS.peek(("route life", digest, key, tuple(strength), str(route), tuple(sources)))


class _Checked:
    """A load source that calls ``checkpoint()`` before it starts."""

    def __init__(self, source, checkpoint):
        self.source, self.checkpoint = source, checkpoint
        self.name = source.name

    def contributions(self, context):
        self.checkpoint()
        return self.source.contributions(context)


def life_parameters(key: CaseBase, strength: tuple):
    """The set the life takes: the case's, its N0 and b_M as ``wheel_force`` and
    ``motor_slope``, the strength data replacing the set's."""
    parameters = compute.parameters_for(key)
    op = key.replace(s0=0.005, v=120.0).operating_point()
    changes = {name: value for name, value in (("wheel_force", op.N0), ("motor_slope", op.b_M))
               if not math.isclose(value, parameters[name], rel_tol=1e-9)}
    changes.update(dict(strength))
    return parameters.replace(**changes) if changes else parameters


def _route_life(key: CaseBase, strength: tuple, route: str, sources: tuple, checkpoint):
    """The life of :func:`life_result` (a background worker's task when served)."""
    from model.studies.life import route_life
    from model.studies.life_sources import default_sources
    from model.studies.route import load_route

    chosen = [s for s in default_sources() if s.name in sources]
    checkpoint()
    return route_life(life_parameters(key, strength), load_route(route),
                      [_Checked(s, checkpoint) for s in chosen])


def lives_by_component(result) -> dict[str, tuple[float, float]]:
    """Section name -> (life [km], life [years]) (inf: no source does damage)."""
    return {s.section.name: (s.life_km, s.life_years) for s in result.sections}


def life_words(life_km: float) -> str:
    """A life in km as the table writes it."""
    return "no damage" if not math.isfinite(life_km) else f"{life_km:.3g}"


def years_words(life_years: float) -> str:
    """A life in years as the note writes it."""
    return ("no damage over the route" if not math.isfinite(life_years)
            else f"route life {life_years:.3g} years")


def description(result, route_file: str = str(ROUTE)) -> str:
    """What the life over the route file ``route_file`` includes (markdown, one paragraph)."""
    route = result.route
    events = ("" if route.short_circuit is None else
              f", {route.short_circuit.per_year:g} short circuits a year")
    notes = "".join(f" {note}." for note in result.notes)
    least = result.least_life
    first = ("" if least.damage <= 0 else f" Least life: **{least.section.name}**, "
             f"{least.life_km:.3g} km ({least.life_years:.3g} years).")
    return (f"**Life over the route** (column *life [km]*, the years in the note):{first} "
            f"{route.name}, {route.annual_distance / 1e3:g} km a year{events}; sources: "
            f"{', '.join(result.sources)}; Miner's sum with the FKM guideline's shear S–N curve "
            f"through DIN 743's fatigue limit (N_D = {result.options.knee_cycles:g}, k = "
            f"{result.options.slope:g}, beyond the knee: {result.options.beyond_knee}), as "
            f"`bogie life --route {_shown_path(route_file)}`.{notes} A comparison of sections "
            "and speeds, not a certified life (docs/assessment.md).")


def _shown_path(route_file: str) -> str:
    """The route file's path relative to the project (the bundled ones), else its name."""
    path = Path(route_file)
    try:
        return str(path.resolve().relative_to(ROUTE.parents[2]))
    except ValueError:
        return path.name


def damage_by_speed(section_life) -> tuple[dict[str, tuple[list, list]], float]:
    """({source: (speeds [km/h], damage a year [1/year])} of the sources over speed, the
    orders of a bin summed; the events' damage a year [1/year])."""
    by_source: dict[str, dict[float, float]] = {}
    events = 0.0
    for c in section_life.contributions:
        if c.v_kmh is None:
            events += c.damage
            continue
        speeds = by_source.setdefault(c.source, {})
        speeds[c.v_kmh] = speeds.get(c.v_kmh, 0.0) + c.damage
    return ({source: (sorted(v), [v[x] for x in sorted(v)]) for source, v in by_source.items()},
            events)


def damage_figure(result):
    """The least-life section's damage a year over speed (the route's bin centres), one line per
    source over speed (log scale); the short circuits' damage, events not over speed, in the
    title."""
    least = result.least_life
    lines, events = damage_by_speed(least)
    route = result.route
    per_year = 0.0 if route.short_circuit is None else route.short_circuit.per_year
    life = ("no damage" if not math.isfinite(least.life_km) else
            f"{least.life_km:.3g} km = {least.life_years:.3g} years")
    largest = max((d for v, damage in lines.values() for d in damage), default=0.0)
    # the tails far from the resonances reach 1e-50: the axis shows 25 decades below the largest
    y_range = (Range1d(largest * LOWEST_SHOWN, largest * 10.0) if largest > 0 else
               Range1d(1e-20, 1.0))
    fig = figure(y_axis_type="log", y_range=y_range, height=330, sizing_mode="stretch_width", name="life-damage",
                 x_axis_label="speed [km/h] (the route's bin centres)",
                 y_axis_label="damage a year [1/year] (25 decades below the largest)", toolbar_location="above",
                 title=f"Damage a year over speed: {least.section.name} (least life, {life}); "
                       f"short circuits ({per_year:g} a year, not over speed): {events:.3g} "
                       "1/year")
    drawn = False
    for source in SPEED_SOURCES:
        if source not in lines:
            continue
        v, damage = lines[source]
        keep = [i for i, d in enumerate(damage) if d > 0]
        if not keep:
            continue
        data = ColumnDataSource({"v": [v[i] for i in keep], "damage": [damage[i] for i in keep],
                                 "source": [source] * len(keep)})
        colour = SOURCE_COLOURS[source]
        fig.line("v", "damage", source=data, color=colour, legend_label=source, line_width=2)
        fig.scatter("v", "damage", source=data, color=colour, size=6)
        drawn = True
    fig.add_tools(HoverTool(tooltips=[("source", "@source"), ("speed [km/h]", "@v{0.0}"),
                                      ("damage a year [1/year]", "@damage{0.000e0}")]))
    if drawn:
        fig.legend.location = "top_left"
    return fig


def with_life(rows: list[dict], result, pending: str = "computing…") -> list[dict]:
    """The Verdicts table's rows (:func:`app.results.verdicts.check_rows`) with the column
    ``life [km]``: on each shaft section's fatigue row its life over the route (``pending``
    while ``result`` is None; "no damage" where no source shortens it) and the years in its
    note; "" on the other rows."""
    lives = {} if result is None else lives_by_component(result)
    out = []
    for row in rows:
        row = dict(row, **{"life [km]": ""})
        if row["check"] == FATIGUE_CHECK:
            if result is None:
                row["life [km]"] = pending
            elif row["component"] in lives:
                km, years = lives[row["component"]]
                row["life [km]"] = life_words(km)
                row["note"] = "; ".join(n for n in (row["note"], years_words(years)) if n)
        out.append(row)
    return out
