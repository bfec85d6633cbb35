"""The worked example of docs/assessment.md's fatigue life: `bogie life --route
assets/routes/mixed_passenger_200.toml` at the default set, with the three choices beyond the
S–N curve's knee and with the converters' ripple raised.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/example_life.py

Writes ``docs/results/life.json`` (every number the page quotes; the default case is ``bogie
life --route … --json``'s) in about two minutes.
"""

from __future__ import annotations

import sys
from pathlib import Path

from model import load_parameters
from model.studies.life import LifeOptions, route_life
from model.studies.life_sources import default_sources
from model.studies.ripple_case import ripple_amplitudes
from model.studies.route import load_route

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

ROUTE = ROOT / "assets" / "routes" / "mixed_passenger_200.toml"
RIPPLE_FACTORS = (3.0, 5.0)  # the converters' ripple raised by these factors


def key(name: str) -> str:
    return name.replace(" ", "_")


def top_groups(life, n: int = 3) -> list[dict]:
    """The largest contributions grouped by source, speed and order (an event's amplitude
    classes together), with their share of the section's damage."""
    groups: dict[tuple, float] = {}
    for c in life.contributions:
        k = (c.source, c.v_kmh, c.detail.get("order"))
        groups[k] = groups.get(k, 0.0) + c.damage
    ranked = sorted(groups.items(), key=lambda item: -item[1])[:n]
    return [{"source": s, "v_kmh": v, "order": o,
             "share": d / life.damage if life.damage else 0.0} for (s, v, o), d in ranked]


def summary(result) -> dict:
    least = result.least_life
    return {"least_life": {"name": least.section.name, "damage": least.damage,
                           "life_km": least.life_km if least.damage else None,
                           "life_years": least.life_years if least.damage else None},
            "sections": {key(s.section.name): {
                "damage": s.damage, "life_km": s.life_km if s.damage else None,
                "life_years": s.life_years if s.damage else None,
                "tau_WK": s.section.fatigue.tau_WK, "shares": s.shares(),
                "top": top_groups(s)} for s in result.sections}}


def main() -> None:
    parameters = load_parameters()
    route = load_route(ROUTE)
    result = route_life(parameters, route, default_sources())
    data = {"route": route.as_dict(), "default": summary(result),
            "sn": {key(s.section.name): s.section.sn.as_dict() for s in result.sections},
            "beyond_knee": {}, "ripple_factor": {}}
    for beyond in ("elementary", "limit"):
        data["beyond_knee"][beyond] = summary(route_life(parameters, route, default_sources(),
                                                         LifeOptions(beyond_knee=beyond)))
    base = ripple_amplitudes(parameters)
    for factor in RIPPLE_FACTORS:
        ripple = {order: factor * amplitude for order, amplitude in base.items()}
        data["ripple_factor"][f"{factor:g}"] = {
            "ripple": {o.name: a for o, a in ripple.items()},
            **summary(route_life(parameters, route, default_sources(),
                                 LifeOptions(ripple=ripple)))}
    least = result.least_life
    print(f"least life: {least.section.name}: {least.life_km:.3g} km, "
          f"{least.life_years:.3g} years")
    print(f"wrote {write_results('life', data, 'scripts/example_life.py')}")


if __name__ == "__main__":
    main()
