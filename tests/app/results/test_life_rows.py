"""The Verdicts table's life column and the damage-over-speed data (app.results.life), on small
hand-made results: a fatigue row of a section gets its life in km and its years in the note,
"computing…" before the life is there, "no damage" where nothing shortens it; other rows get
nothing; the damage over speed sums a bin's orders per source and keeps the events apart."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from app.results.life import damage_by_speed, with_life


def _row(component: str, check: str, note: str = "") -> dict:
    return {"component": component, "check": check, "load case": "ripple", "note": note}


def _life(name: str, km: float, years: float, contributions=()):
    return SimpleNamespace(section=SimpleNamespace(name=name), life_km=km, life_years=years,
                           contributions=list(contributions))


ROWS = [_row("ID1 driving shaft", "torsional fatigue", "a note"),
        _row("ID1 driving shaft", "torsional shear"),
        _row("ID2 axle", "torsional fatigue")]


def test_fatigue_rows_say_computing_before_the_life_is_there():
    rows = with_life(ROWS, None)
    assert [r["life [km]"] for r in rows] == ["computing…", "", "computing…"]
    assert [r["note"] for r in rows] == ["a note", "", ""]


def test_fatigue_rows_get_the_life_in_km_and_the_years_in_the_note():
    result = SimpleNamespace(sections=[_life("ID1 driving shaft", 7.515955e12, 3.006382e7),
                                       _life("ID2 axle", math.inf, math.inf)])
    rows = with_life(ROWS, result)
    assert [r["life [km]"] for r in rows] == ["7.52e+12", "", "no damage"]
    assert rows[0]["note"] == "a note; route life 3.01e+07 years"
    assert rows[2]["note"] == "no damage over the route"
    assert ROWS[0]["note"] == "a note"  # the rows given are not changed


def test_damage_over_speed_sums_a_bins_orders_and_keeps_the_events_apart():
    c = SimpleNamespace
    life = _life("ID1 axle", 1.0, 1.0, [
        c(source="ripple", v_kmh=115.0, damage=1e-9), c(source="ripple", v_kmh=115.0, damage=2e-9),
        c(source="ripple", v_kmh=105.0, damage=4e-9), c(source="track", v_kmh=105.0, damage=5e-9),
        c(source="short_circuit", v_kmh=None, damage=3e-8),
        c(source="short_circuit", v_kmh=None, damage=1e-8)])
    lines, events = damage_by_speed(life)
    speeds, damage = lines["ripple"]
    assert speeds == [105.0, 115.0]
    assert damage == pytest.approx([4e-9, 3e-9], rel=1e-12)
    assert lines["track"] == ([105.0], [5e-9])
    assert math.isclose(events, 4e-8)
