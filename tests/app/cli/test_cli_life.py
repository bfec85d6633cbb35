"""``bogie life``: the JSON contract on the bundled route (sections with damage, life, S–N curve and
contributions; the least-life section's damage the sum of its contributions and each counted
contribution cycles / N(stress_amplitude), to 1e-9), the table, and bad input refused in one
line with exit status 2."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from test_cli import assert_one_line_error, run

ROUTE = """name = "short"
source = "a test: 80-95 km/h around the driving shaft's resonance"
annual_distance_km = 100000
[speeds]
edges_kmh = [80, 85, 90, 95]
share = [1, 2, 1]
[short_circuit]
per_year = 1.0
s0 = 0.005
v_kmh = [90]
"""


@pytest.fixture
def route_file(tmp_path):
    path = tmp_path / "short.toml"
    path.write_text(ROUTE, encoding="utf-8")
    return str(path)


def _n(sn: dict, amplitude: float) -> float:
    """N(σ) of the JSON's S–N curve, written out from its definition."""
    limit, knee = sn["fatigue_limit"], sn["knee_cycles"]
    if amplitude >= limit:
        return knee * (limit / amplitude) ** sn["slope"]
    if sn["slope_beyond_knee"] is None:
        return math.inf
    return knee * (limit / amplitude) ** sn["slope_beyond_knee"]


EXAMPLE = str(Path(__file__).resolve().parents[3] / "assets" / "routes" /
              "mixed_passenger_200.toml")


@pytest.mark.slow
def test_json_contract_on_the_bundled_route(capsys):
    # the bundled route's track source (its spectra at 20 speeds and two creepages, about two
    # minutes) is left out here; tests/model/studies/test_life.py computes it on a short route
    code, out, err = run(["life", "--route", EXAMPLE, "--sources", "ripple,short_circuit",
                          "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["route"]["annual_distance_km"] == 250000
    assert data["route"]["track"] == "low"
    assert data["sources"] == ["ripple", "short_circuit"]
    sections = data["sections"]
    assert len(sections) == 6
    for s in sections:
        assert set(s["sn"]) == {"fatigue_limit", "knee_cycles", "slope", "slope_beyond_knee"}
        assert s["sn"]["slope_beyond_knee"] == 2 * s["sn"]["slope"] - 1  # Haibach by default
        assert s["damage"] >= 0
        for c in s["contributions"]:
            assert c["source"] in ("ripple", "short_circuit")
            assert (c["v_kmh"] is None) == (c["source"] == "short_circuit")
    least = min(sections, key=lambda s: s["life_km"])
    assert least["name"] == data["least_life"]
    assert least["damage"] == pytest.approx(math.fsum(c["damage"] for c in
                                                      least["contributions"]), rel=1e-9)
    assert least["life_km"] == pytest.approx(250000 / least["damage"], rel=1e-9)
    assert {c["source"] for c in least["contributions"]} == {"ripple", "short_circuit"}
    for c in least["contributions"]:
        assert c["damage"] == pytest.approx(c["cycles"] / _n(least["sn"], c["stress_amplitude"]),
                                            rel=1e-9)


@pytest.mark.slow
def test_table_with_miners_original_rule(route_file, capsys):
    code, out, err = run(["life", "--route", route_file, "--sources", "ripple",
                          "--beyond-knee", "limit"], capsys)
    assert code == 0, err
    # Miner's original rule: the ripple stays below every fatigue limit (the assessment's
    # fatigue safety factors are all above 1), so nothing is damaged
    assert "least life: none" in out
    assert "short_circuit" not in out.split("\n")[1]  # the sources line


@pytest.mark.parametrize(("argv", "words"), [
    (["--sources", "ripple,wheels"], "--sources"),
    (["--sources", "ripple,ripple"], "--sources"),
    (["--slope", "-3"], "slope"),
    (["--ripple", "el:6=-5"], "amplitude"),
])
def test_bad_options_refused(route_file, capsys, argv, words):
    code, out, err = run(["life", "--route", route_file, *argv], capsys)
    assert_one_line_error(code, out, err)
    assert words in err


def test_unstable_short_circuit_refused(tmp_path, capsys):
    path = tmp_path / "unstable.toml"
    path.write_text(ROUTE.replace("s0 = 0.005", "s0 = 0.014"), encoding="utf-8")
    code, out, err = run(["life", "--route", str(path), "--sources", "short_circuit"], capsys)
    assert_one_line_error(code, out, err)
    assert "not stable" in err


def test_bad_route_files_refused(tmp_path, capsys):
    code, out, err = run(["life", "--route", str(tmp_path / "missing.toml")], capsys)
    assert_one_line_error(code, out, err)
    bad = tmp_path / "bad.toml"
    bad.write_text(ROUTE.replace("share = [1, 2, 1]", "share = [1, 2]"), encoding="utf-8")
    code, out, err = run(["life", "--route", str(bad)], capsys)
    assert_one_line_error(code, out, err)
    assert "share needs 3" in err
    code, out, err = run(["life"], capsys)
    assert_one_line_error(code, out, err)
