"""Route files: a histogram's running time from the annual distance and the mean speed, a sampled
run binned and scaled to the annual distance, the bundled example, bad files refused in one line.

Tolerances: the conversions are sums and products of the file's numbers, 1e-12 relative.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from model.mechanics.operating_point import KMH
from model.studies.route import RouteError, load_route, route_from_dict

EXAMPLE = Path(__file__).resolve().parents[3] / "assets" / "routes" / "mixed_passenger_200.toml"


def _histogram(**changes) -> dict:
    data = {"name": "two bins", "source": "a test", "annual_distance_km": 1000.0,
            "speeds": {"edges_kmh": [80, 100, 140], "share": [1, 3]}}
    data.update(changes)
    return data


def test_histogram_time_from_distance_and_mean_speed():
    route = route_from_dict(_histogram())
    mean_kmh = 0.25 * 90 + 0.75 * 120  # shares 1:3 of the running time, bin centres
    hours = 1000.0 / mean_kmh
    assert route.seconds_per_year == pytest.approx(np.array([0.25, 0.75]) * hours * 3600,
                                                   rel=1e-12)
    assert route.edges == pytest.approx(np.array([80, 100, 140]) * KMH, rel=1e-12)
    # the route runs its annual distance: Σ time × centre speed
    assert float(np.sum(route.seconds_per_year * route.centres)) == pytest.approx(1e6, rel=1e-12)


def test_sampled_run_binned_and_scaled(tmp_path):
    # 100 s at 36 km/h (1 km), then 50 s accelerating 36 -> 72 km/h (0.75 km): 1.75 km a run
    (tmp_path / "run.csv").write_text("t_s,v_kmh\n0,36\n100,36\n150,72\n", encoding="utf-8")
    path = tmp_path / "route.toml"
    path.write_text(
        'name = "run"\nsource = "a test"\nannual_distance_km = 175\n'
        '[speeds]\ncsv = "run.csv"\nbin_kmh = 10\n', encoding="utf-8")
    route = load_route(path)
    runs = 100.0  # 175 km / 1.75 km
    assert route.origin["runs_per_year"] == pytest.approx(runs, rel=1e-12)
    seconds = np.zeros(len(route.edges) - 1)
    seconds[3] = 100.0 * runs  # 36 km/h in the 30-40 bin
    seconds[5] = 50.0 * runs  # the acceleration counts at its mean 54 km/h
    assert route.seconds_per_year == pytest.approx(seconds, rel=1e-12)


def test_bundled_example():
    route = load_route(EXAMPLE)
    assert route.annual_distance == 250_000e3
    assert route.edges[0] == 0
    assert route.edges[-1] == pytest.approx(200 * KMH)
    assert route.short_circuit.per_year == 0.1
    assert sum(route.short_circuit.share) == pytest.approx(1.0)
    assert float(np.sum(route.seconds_per_year * route.centres)) == pytest.approx(250_000e3)
    assert route.source.startswith("estimate")
    assert route.track == "low"
    assert route.wheel_polygon is None


def test_track_and_polygon():
    route = route_from_dict(_histogram(track={"spectrum": "low"},
                                       wheel_polygon={"amplitudes_um": "20=30, 3=5"}))
    assert route.track == "low"
    assert route.wheel_polygon == {20: pytest.approx(30e-6), 3: pytest.approx(5e-6)}
    assert route.as_dict()["wheel_polygon_um"] == {"20": pytest.approx(30.0),
                                                   "3": pytest.approx(5.0)}


@pytest.mark.parametrize(("changes", "words"), [
    ({"annual_distance_km": -1}, "annual_distance_km"),
    ({"source": ""}, "source"),
    ({"speeds": {"edges_kmh": [0, 10], "share": [1, 2]}}, "share needs 1"),
    ({"speeds": {"edges_kmh": [10, 5], "share": [1]}}, "increasing"),
    ({"speeds": {"edges_kmh": [0, 10], "share": [-1]}}, "share"),
    ({"speeds": {"edges_kmh": [0, 10], "share": [1], "extra": 1}}, "unknown entry speeds.extra"),
    ({"speed": {}}, "unknown entry speed"),
    ({"annual_distance_km": 1e9}, "more than a year"),
    ({"short_circuit": {"per_year": 1, "s0": 0.005, "v_kmh": [80, 0]}}, "short_circuit"),
    ({"track": {"spectrum": "rough"}}, "unknown track spectrum"),
    ({"track": {"level": "low"}}, "takes spectrum"),
    ({"wheel_polygon": {"amplitudes_um": "20=30000"}}, "wheel_polygon"),
    ({"wheel_polygon": {"orders": "20=30"}}, "amplitudes_um"),
])
def test_bad_routes_refused(changes, words):
    with pytest.raises(RouteError, match=words) as error:
        route_from_dict(_histogram(**changes))
    assert "\n" not in str(error.value)


def test_bad_files_refused(tmp_path):
    with pytest.raises(RouteError, match="cannot read"):
        load_route(tmp_path / "missing.toml")
    (tmp_path / "bad.toml").write_text("name = ", encoding="utf-8")
    with pytest.raises(RouteError, match="not valid TOML"):
        load_route(tmp_path / "bad.toml")
    (tmp_path / "run.csv").write_text("t,v\n0,1\n", encoding="utf-8")
    (tmp_path / "r.toml").write_text('name = "r"\nsource = "s"\nannual_distance_km = 1\n'
                                     '[speeds]\ncsv = "run.csv"\n', encoding="utf-8")
    with pytest.raises(RouteError, match="header"):
        load_route(tmp_path / "r.toml")
    (tmp_path / "run.csv").write_text("t_s,v_kmh\n0,10\n0,20\n", encoding="utf-8")
    with pytest.raises(RouteError, match="increase"):
        load_route(tmp_path / "r.toml")
