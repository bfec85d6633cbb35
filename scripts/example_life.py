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


def running_margins(parameters, route) -> dict:
    """Per creepage of the life's options: the running system's largest real part of a
    non-neutral eigenvalue [1/s] at the route's bin edges from 10 km/h (> 0: growing), and its
    frequency [Hz]: where the track's and the polygons' responses are near their stability
    limit."""
    import numpy as np

    from model.analysis.eigen import non_neutral, running_system
    from model.mechanics.operating_point import KMH, OperatingPoint
    from model.studies.maps import cached_model

    model = cached_model(parameters)
    out = {}
    for s0 in LifeOptions().s0:
        rows = []
        for v in route.edges[route.edges >= 10 * KMH]:
            lam = running_system(model, OperatingPoint(s0, float(v), parameters["wheel_force"],
                                                       parameters["motor_slope"])).eigen[0]
            lam = lam[non_neutral(lam)]
            k = int(np.argmax(lam.real))
            rows.append({"v_kmh": float(v / KMH), "growth": float(lam[k].real),
                         "f_hz": float(abs(lam[k].imag) / (2 * np.pi))})
        out[f"{s0:g}"] = rows
    return out


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
    data["running_system"] = running_margins(parameters, route)
    least = result.least_life
    print(f"least life: {least.section.name}: {least.life_km:.3g} km, "
          f"{least.life_years:.3g} years")
    print(f"wrote {write_results('life', data, 'scripts/example_life.py')}")


if __name__ == "__main__":
    main()
