"""The fatigue life over a route: Miner's sum of a two-level spectrum against a hand calculation,
cycles per speed = frequency × time at that speed, the mean-stress correction as the section's
check, the event and spectral sources against their definitions, and on the model (a short route
through the driving shaft's resonance, the ripple and a short circuit) every section's damage
equal to the sum of its contributions and every counted contribution equal to
cycles / N(stress_amplitude).

Tolerances: the hand calculations are a handful of products and powers, 1e-12 relative; the
contributions' identities are sums of up to a few hundred terms and one power law and its
inverse, 1e-9 relative (the contract of ``bogie life --json``).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from model import load_parameters
from model.analysis.fatigue import permissible_amplitude, torsional_fatigue
from model.analysis.load_spectrum import rainflow_cycles
from model.analysis.spectral_fatigue import (
    dirlik_damage_rate,
    dirlik_exceedance,
    spectral_moments,
)
from model.mechanics.operating_point import KMH
from model.studies.life import (
    LifeError,
    LifeOptions,
    Section,
    event_contributions,
    route_life,
    spectral_contributions,
    steady_contributions,
)
from model.studies.life_sources import PolygonSource, TrackSource, default_sources
from model.studies.route import route_from_dict

MPA = 1e6


def _section(beyond_knee: str = "haibach") -> Section:
    data = torsional_fatigue(sigma_B=1000e6, strength_diameter=0.016, D=0.12, d_i=0.0,
                             beta_tau=1.8, R_z=6.3e-6, tau_yield=375e6)
    return Section("test shaft", "test.torque", data,
                   LifeOptions(beyond_knee=beyond_knee).curve(data.tau_WK))


def _route(edges_kmh, share, annual_km=1000.0, **more):
    return route_from_dict({"name": "test", "source": "a test", "annual_distance_km": annual_km,
                            "speeds": {"edges_kmh": edges_kmh, "share": share}, **more})


def _grid(edges_kmh, points=11):
    return np.unique(np.concatenate([np.linspace(a, b, points) for a, b in
                                     itertools.pairwise(edges_kmh)])) * KMH


def test_two_level_spectrum_by_hand():
    """Two speed bins, each a constant amplitude at 50 Hz: 1.5 τ_WK (above the knee, slope 8)
    and 0.8 τ_WK (below it, Haibach's 15), no mean: D = n1/N1 + n2/N2 with
    N = 1e6 (τ_WK/τ)^k."""
    section = _section()
    W_t = section.fatigue.section_modulus
    tau_WK = section.fatigue.tau_WK
    edges = [80, 100, 110, 130]
    route = _route(edges, [1, 0, 2])
    v = _grid(edges)
    amplitude = np.where(v <= 100 * KMH + 1e-9, 1.5 * tau_WK * W_t, 0.8 * tau_WK * W_t)
    frequency = np.full((1, len(v)), 50.0)
    found = steady_contributions("ripple", section, route, v, np.zeros(len(v)),
                                 amplitude[None, :], frequency, ["el:6"])
    T1, T2 = route.seconds_per_year[0], route.seconds_per_year[2]
    n1, n2 = 50.0 * T1, 50.0 * T2
    N1, N2 = 1e6 * (1 / 1.5) ** 8, 1e6 * (1 / 0.8) ** 15
    assert [c.v_kmh for c in found] == [90.0, 120.0]
    assert [c.cycles for c in found] == pytest.approx([n1, n2], rel=1e-12)
    assert [c.damage for c in found] == pytest.approx([n1 / N1, n2 / N2], rel=1e-12)
    assert math.fsum(c.damage for c in found) == pytest.approx(n1 / N1 + n2 / N2, rel=1e-12)
    assert [c.stress_amplitude for c in found] == pytest.approx([1.5 * tau_WK, 0.8 * tau_WK],
                                                                rel=1e-12)
    # Miner's original rule: the cycles below the limit do nothing and are not counted
    limited = steady_contributions("ripple", _section("limit"), route, v, np.zeros(len(v)),
                                   amplitude[None, :], frequency, ["el:6"])
    assert [c.v_kmh for c in limited] == [90.0]
    assert limited[0].damage == pytest.approx(n1 / N1, rel=1e-12)


def test_cycles_per_speed_are_frequency_times_time():
    """An order whose frequency grows with speed (f = 2 v_kmh Hz, linear): each bin's cycles are
    the frequency at its centre speed × its time, the time below the floor left out."""
    section = _section()
    edges = [0, 20, 60, 100]
    route = _route(edges, [1, 2, 3])
    v = _grid(edges)
    f = 2.0 * v / KMH
    amplitude = np.full(len(v), 0.5 * section.fatigue.tau_WK * section.fatigue.section_modulus)
    found = steady_contributions("ripple", section, route, v, np.zeros(len(v)),
                                 amplitude[None, :], f[None, :], ["el:6"], floor=10 * KMH)
    T = route.seconds_per_year
    # the first bin counts from 10 km/h: half its time, at its upper half's centre 15 km/h
    assert [c.cycles for c in found] == pytest.approx(
        [2 * 15 * T[0] / 2, 2 * 40 * T[1], 2 * 80 * T[2]], rel=1e-12)
    assert [c.detail["seconds"] for c in found] == pytest.approx([T[0] / 2, T[1], T[2]],
                                                                 rel=1e-12)


def test_mean_stress_as_the_check():
    section = _section()
    data, W_t = section.fatigue, section.fatigue.section_modulus
    tau_m = 150 * MPA
    at_limit = permissible_amplitude(data, tau_m) * W_t  # the check's permissible amplitude
    assert float(section.equivalent_amplitude(at_limit, tau_m * W_t)) == pytest.approx(
        data.tau_WK, rel=1e-12)
    assert float(section.equivalent_amplitude(at_limit, -tau_m * W_t)) == pytest.approx(
        data.tau_WK, rel=1e-12)  # the mean's sign does not matter in torsion
    assert float(section.equivalent_amplitude(0.3 * data.tau_WK * W_t, 0.0)) == pytest.approx(
        0.3 * data.tau_WK, rel=1e-12)


def test_event_classes_sum_to_the_rainflow_damage():
    section = _section()
    W_t, tau_WK = section.fatigue.section_modulus, section.fatigue.tau_WK
    t = np.linspace(0.0, 0.5, 5001)
    history = W_t * tau_WK * (0.4 + 2.0 * np.exp(-8 * t) * np.sin(2 * np.pi * 90 * t))
    events = [(history, 0.3), (0.5 * history, 0.2)]
    found = event_contributions("short_circuit", section, events)
    direct = 0.0
    for h, rate in events:
        cycles = rainflow_cycles(h)
        tau = section.equivalent_amplitude(cycles[:, 0] / 2, cycles[:, 1])
        direct += rate * float(np.sum(cycles[:, 2] / section.sn.cycles_to_failure(tau)))
    assert math.fsum(c.damage for c in found) == pytest.approx(direct, rel=1e-12)
    for c in found:
        assert c.v_kmh is None
        assert c.damage == pytest.approx(
            c.cycles / float(section.sn.cycles_to_failure(c.stress_amplitude)), rel=1e-9)
        low, high = c.detail["class_tau_range"]
        assert low * (1 - 1e-12) <= c.stress_amplitude <= high * (1 + 1e-12)


def test_spectral_source_is_dirlik_on_the_corrected_stress():
    """A bin with the same torque spectrum at both edges: its damage is the time × Dirlik's rate
    of the stress spectrum scaled by the mean-stress correction, its cycles the peaks."""
    section = _section()
    W_t = section.fatigue.section_modulus
    edges = [50, 70]
    route = _route(edges, [1])
    f = np.linspace(0.0, 200.0, 801)
    G = np.where((f > 20) & (f < 120), 1.0, 0.0) * (0.5 * section.fatigue.tau_WK * W_t) ** 2 / 100
    torque = spectral_moments(f, G)
    mean = 100 * MPA * W_t
    found = spectral_contributions("track", section, route, np.array(edges) * KMH,
                                   lambda i: (torque, mean))
    scale = section.fatigue.tau_WK / permissible_amplitude(section.fatigue, 100 * MPA) / W_t
    stress = spectral_moments(f, G * scale**2)
    T = route.seconds_per_year[0]
    assert found[0].damage == pytest.approx(T * dirlik_damage_rate(stress, section.sn),
                                            rel=1e-12)
    assert found[0].cycles == pytest.approx(T * torque.peak_rate, rel=1e-12)
    assert found[0].damage == pytest.approx(
        found[0].cycles / float(section.sn.cycles_to_failure(found[0].stress_amplitude)),
        rel=1e-9)
    # Miner's original rule: only the peaks reaching the limit are counted, and they do the damage
    limited = _section("limit")
    found_limited = spectral_contributions("track", limited, route, np.array(edges) * KMH,
                                           lambda i: (torque, mean))
    assert found_limited[0].cycles == pytest.approx(
        T * torque.peak_rate * dirlik_exceedance(limited.sn.fatigue_limit, stress), rel=1e-12)
    assert found_limited[0].damage == pytest.approx(
        found_limited[0].cycles / float(limited.sn.cycles_to_failure(
            found_limited[0].stress_amplitude)), rel=1e-9)
        # a speed without a stationary response leaves its bin out
    assert spectral_contributions("track", section, route, np.array(edges) * KMH,
                                  lambda i: None if i == 1 else (torque, mean)) == []


def test_bad_options_refused():
    with pytest.raises(LifeError, match="beyond the knee"):
        LifeOptions(beyond_knee="none")
    with pytest.raises(LifeError, match="slope"):
        LifeOptions(slope=0.0)


@pytest.fixture(scope="module")
def short_route_life():
    """The default set over 80-95 km/h (the driving shaft's resonance with the 6th harmonic at
    87.5 km/h) with a short circuit a year at 90 km/h."""
    route = _route([80, 85, 90, 95], [1, 2, 1], annual_km=100_000.0,
                   short_circuit={"per_year": 1.0, "s0": 0.005, "v_kmh": [90]})
    return route_life(load_parameters(), route, default_sources(),
                      LifeOptions(short_circuit_t_end=1.0, short_circuit_fs=5000.0))


@pytest.mark.slow
def test_route_life_sums_its_contributions(short_route_life):
    result = short_route_life
    assert result.sources == ("ripple", "polygon", "track", "short_circuit")
    assert len(result.sections) == 6
    least = result.least_life
    assert least.section.name == "ID1 driving shaft"  # the resonance of docs/assessment.md
    for life in result.sections:
        assert life.damage == pytest.approx(math.fsum(c.damage for c in life.contributions),
                                            rel=1e-9)
        assert life.life_km == pytest.approx(100_000.0 / life.damage, rel=1e-12)
    sources = {c.source for c in least.contributions}
    assert sources == {"ripple", "short_circuit"}  # the route gives no polygon, no track
    assert any(note.startswith("polygon: the route gives no") for note in result.notes)
    for c in least.contributions:
        assert c.cycles is not None
        assert c.cycles > 0
        N = float(least.section.sn.cycles_to_failure(c.stress_amplitude))
        assert c.damage == pytest.approx(c.cycles / N, rel=1e-9)
    ripple = [c for c in least.contributions if c.source == "ripple"]
    # cycles per bin and order: the order's frequency at the bin's centre × the bin's time (the
    # frequency is linear in speed)
    for c in ripple:
        assert c.cycles == pytest.approx(c.detail["f_hz"] * c.detail["seconds"], rel=1e-9)
    assert max(ripple, key=lambda c: c.damage).v_kmh == 87.5  # the bin holding the resonance


@pytest.mark.slow
def test_polygon_and_track_sources_on_the_model():
    """A route with the track's spectrum and a wheel polygon: both sources give every section
    contributions that obey damage = cycles / N(stress_amplitude); the polygon's cycles are its
    frequency n v / (2π r0) × the time at the bin's centre speed."""
    route = _route([60, 80, 100], [1, 2], annual_km=100_000.0, track={"spectrum": "low"},
                   wheel_polygon={"amplitudes_um": "20=30"})
    result = route_life(load_parameters(), route, (PolygonSource(), TrackSource()))
    assert result.notes == ()
    r0 = load_parameters()["wheel_radius"]
    for life in result.sections:
        assert {c.source for c in life.contributions} == {"polygon", "track"}
        assert life.damage == pytest.approx(math.fsum(c.damage for c in life.contributions),
                                            rel=1e-9)
        for c in life.contributions:
            N = float(life.section.sn.cycles_to_failure(c.stress_amplitude))
            assert c.damage == pytest.approx(c.cycles / N, rel=1e-9)
            if c.source == "polygon":
                f = 20 * c.v_kmh * KMH / (2 * math.pi * r0)
                assert c.cycles == pytest.approx(f * c.detail["seconds"], rel=1e-9)


@pytest.mark.slow
def test_track_left_out_where_the_running_system_grows():
    """At s0 = 0.007 (near the stability limit) the running system grows from about 175 km/h:
    the bin 160-180 km/h has no stationary response and is left out, with a note."""
    route = _route([140, 160, 180], [1, 1], track={"spectrum": "low"})
    result = route_life(load_parameters(), route, (TrackSource(),), LifeOptions(s0=(0.007,)))
    assert result.notes == ("track: left out in 160-180 km/h, where the running system has a "
                            "growing mode at every creepage of 0.007 (no steady or stationary "
                            "response)",)
    for life in result.sections:
        assert [c.v_kmh for c in life.contributions] == [150.0]
