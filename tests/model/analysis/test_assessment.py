"""The checks' formulas against worked examples and hand values, and the checks themselves."""

from __future__ import annotations

import math

import pytest

from model.analysis.assessment import (
    contact_pressure,
    drive_components,
    governing,
    shear_capacity,
    shear_stress,
    slip_torque,
    verdict_colour,
    verify,
)
from model.mechanics.parameters import load_parameters


def test_press_fit_hollow_shaft_against_shigley():
    """Budynas & Nisbett, Shigley's Mechanical Engineering Design (9th ed., Example 3-15): two
    steel tubes shrink-fitted, nominal diameters 40, 45 and 50 mm, diametral interference
    0.062 mm, E = 207 GPa: the contact pressure is 15.8 MPa (three digits in the book).  The inner
    tube is the hollow shaft (d_i = 40 mm), the outer the hub."""
    p = contact_pressure(0.062e-3, 0.045, 0.050, 0.040, 207e9, 0.292, 207e9, 0.292)
    assert p == pytest.approx(15.8e6, abs=0.05e6)


def test_press_fit_solid_shaft_against_din_7190_closed_form_and_a_worked_example():
    """A solid shaft in a hub of the same material: Poisson's ratio cancels and DIN 7190-1's
    closed form is p = E ξ (1 − Q_A²) / 2 (ξ = δ/d, Q_A = d/D).  Worked example (d = 50 mm,
    D = 80 mm, L = 40 mm, δ = 0.04 mm, E = 210 GPa, μ = 0.12; aionlinecalculator.com's press-fit
    page): p ≈ 51 MPa, T ≈ 965 N m."""
    d, D, L, delta, E, mu = 0.050, 0.080, 0.040, 0.04e-3, 210e9, 0.12
    for nu in (0.0, 0.28, 0.3):
        p = contact_pressure(delta, d, D, 0.0, E, nu, E, nu)
        assert p == pytest.approx(E * delta / d * (1 - (d / D) ** 2) / 2, rel=1e-12)
    assert p == pytest.approx(51e6, abs=0.5e6)
    assert slip_torque(mu, p, d, L) == pytest.approx(965.0, abs=1.0)
    # the slip torque T = μ p π d² L / 2
    assert slip_torque(mu, p, d, L) == pytest.approx(mu * p * math.pi * d**2 * L / 2, rel=1e-15)


def test_press_fit_refuses_a_hub_thinner_than_its_seat():
    with pytest.raises(ValueError, match="d_i < d < D"):
        contact_pressure(1e-4, 0.2, 0.2, 0.0, 2e11, 0.3, 2e11, 0.3)
    with pytest.raises(ValueError, match="d_i < d < D"):
        contact_pressure(1e-4, 0.2, 0.3, 0.2, 2e11, 0.3, 2e11, 0.3)


def test_shear_against_hand_values():
    """A solid 100 mm shaft under 10 kN m: τ = 16 T / (π D³) = 16e4 / (π 1e-3) = 50.93 MPa; a tube
    100/80 mm: J = π (D⁴ − d⁴)/32 = 5.796e-6 m⁴, τ = T (D/2) / J = 86.27 MPa."""
    assert shear_stress(10e3, 0.1) == pytest.approx(50.93e6, rel=1e-4)
    assert shear_stress(10e3, 0.1, 0.08) == pytest.approx(86.27e6, rel=1e-4)
    for d_i in (0.0, 0.08):
        assert shear_capacity(shear_stress(10e3, 0.1, d_i), 0.1, d_i) == pytest.approx(10e3)


def test_components_of_both_drives_and_their_capacities():
    parameters = load_parameters()
    components = drive_components(parameters)
    assert len(components) == 16
    assert {c.kind for c in components} == {"press_fit_slip", "torsional_shear", "coupling"}
    by_name = {c.name: c for c in components}
    seat = by_name["ID1 wheel seat 12"]
    i = seat.inputs
    assert set(i) >= {"d", "L", "D", "d_i", "delta", "mu", "E_hub", "E_shaft", "nu_hub",
                      "nu_shaft"}
    # the worst of the tolerances
    assert i["delta"] == parameters["wheel_seat_interference_min"]
    assert i["mu"] == parameters["wheel_seat_friction_min"]
    assert i["d_i"] == 0.0
    p = i["delta"] / (i["d"] * (((i["D"] ** 2 + i["d"] ** 2) / (i["D"] ** 2 - i["d"] ** 2)
                                 + i["nu_hub"]) / i["E_hub"]
                                + (1 - i["nu_shaft"]) / i["E_shaft"]))
    assert seat.capacity == pytest.approx(i["mu"] * p * math.pi * i["d"] ** 2 * i["L"] / 2)
    gear = by_name["ID2 gear seat"]
    assert gear.inputs["d_i"] == 2 * parameters["hollow_shaft_inner_radius"]
    hollow = by_name["ID1 hollow shaft"]
    assert hollow.capacity == pytest.approx(
        parameters["hollow_shaft_shear_stress_allowable"] * math.pi
        * (hollow.inputs["D"] ** 4 - hollow.inputs["d_i"] ** 4) / (16 * hollow.inputs["D"]))
    assert by_name["ID1 disc clutch"].capacity == parameters["disc_clutch_rated_torque"]


def test_safety_factor_is_capacity_over_load_and_the_verdict():
    component = drive_components(load_parameters())[0]
    required = component.required
    load = component.capacity / (required * 1.1)
    check = verify(component, "case", -load, -load, 0.2)
    assert check.load == pytest.approx(load)
    assert check.safety_factor == pytest.approx(component.capacity / load)
    assert check.ok
    assert verdict_colour(check) == "green"
    short = verify(component, "case", component.capacity / (0.5 * (1 + required)))
    assert not short.ok
    assert verdict_colour(short) == "amber"
    broken = verify(component, "case", 2 * component.capacity)
    assert verdict_colour(broken) == "red"
    assert governing([check, short, broken]) is broken
    assert verify(component, "case", 0.0).safety_factor == math.inf
