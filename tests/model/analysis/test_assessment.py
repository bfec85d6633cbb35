"""The checks' formulas against worked examples and hand values, and the checks themselves (under a
largest torque, and under a steady alternating load at its worst speed)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from model.analysis.assessment import (
    KIND_NAMES,
    KINDS,
    AlternatingLoad,
    alternating_components,
    contact_pressure,
    drive_components,
    fatigue_capacity,
    governing,
    shear_capacity,
    shear_stress,
    slip_torque,
    verdict_colour,
    verify,
    verify_alternating,
)
from model.analysis.fatigue import TorsionalFatigue, permissible_amplitude, torsional_fatigue
from model.mechanics.excitation import Order
from model.mechanics.operating_point import KMH
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


def test_components_under_alternating_load():
    """The same 16 sections: the press fits as under a largest torque, the shafts' fatigue data
    from the set (DIN 743 with the set's strength, notch, roughness and shear yield), the
    couplings' permissible vibratory torques."""
    parameters = load_parameters()
    components = alternating_components(parameters)
    assert len(components) == 16
    assert [c.output for c in components] == [c.output for c in drive_components(parameters)]
    assert {c.kind for c in components} == {"press_fit_slip", "torsional_fatigue",
                                            "coupling_vibratory"}
    assert set(KIND_NAMES) == set(KINDS)
    by_name = {(c.name, c.kind): c for c in components}
    fit = by_name[("ID1 gear seat", "press_fit_slip")]
    assert fit == {(c.name, c.kind): c for c in drive_components(parameters)}[fit.name, fit.kind]
    shaft = by_name[("ID2 driving shaft", "torsional_fatigue")]
    data = torsional_fatigue(parameters["driving_shaft_tensile_strength"],
                             parameters["driving_shaft_strength_diameter"],
                             parameters["driving_shaft_diameter"], 0.0,
                             parameters["driving_shaft_torsional_notch_factor"],
                             parameters["driving_shaft_surface_roughness"],
                             parameters["driving_shaft_shear_stress_allowable"])
    assert shaft.capacity == pytest.approx(data.tau_WK * data.section_modulus, rel=1e-12)
    assert shaft.required == parameters["required_factor_fatigue"]
    hollow = by_name[("ID1 hollow shaft", "torsional_fatigue")]
    assert hollow.inputs["d_i"] == 2 * parameters["hollow_shaft_inner_radius"]
    assert hollow.inputs["D"] == 2 * parameters["hollow_shaft_outer_radius"]
    clutch = by_name[("ID1 claw clutch", "coupling_vibratory")]
    assert clutch.capacity == parameters["claw_clutch_vibratory_torque"]
    assert clutch.required == parameters["required_factor_vibratory"]


def _load(mean, alternating):
    """Two orders over four speeds; the first order carries 3/4 of each amplitude."""
    alternating = np.asarray(alternating, dtype=float)
    v = np.array([20.0, 60.0, 87.0, 150.0]) * KMH
    frequencies = np.array([2.0, 4.0])[:, None] * v[None, :]
    frequencies[1, -1] = np.nan  # beyond the model's range at the top speed
    return AlternatingLoad(v, np.asarray(mean, dtype=float), alternating,
                           (Order("el", 6.0), Order("el", 12.0)), np.array([256.0, 128.0]),
                           frequencies, np.vstack([0.75 * alternating, 0.25 * alternating]),
                           tuple({"s0": s0} for s0 in (0.005, 0.002, 0.005, 0.002)))


def test_each_alternating_check_is_taken_at_its_own_worst_speed():
    """Press fit: the largest |mean| + amplitude; fatigue: the largest amplitude over the
    permissible amplitude at that speed's mean (which the mean lowers); coupling: the largest
    amplitude.  Each check states the speed, the mean, the amplitude, the orders' shares there."""
    components = {c.kind: c for c in alternating_components(load_parameters())
                  if c.name.startswith("ID1 driving shaft") or c.name == "ID1 gear seat"
                  or c.name == "ID1 disc clutch"}
    fit, fatigue, coupling = (components["press_fit_slip"], components["torsional_fatigue"],
                              components["coupling_vibratory"])
    mean = [-60e3, 0.0, 30e3, 55e3]
    amplitude = [1e3, 9e3, 8e3, 2e3]
    load = _load(mean, amplitude)

    slip = verify_alternating(fit, "ripple", load)
    assert slip.v_kmh == pytest.approx(20.0)  # |−60| + 1 > |55| + 2 > …
    assert slip.load == pytest.approx(61e3)
    assert slip.signed_load == pytest.approx(-61e3)
    assert slip.capacity == fit.capacity
    assert slip.safety_factor == pytest.approx(fit.capacity / 61e3)

    # fatigue: the mean lowers the permissible amplitude; compare each speed's utilisation
    W_t = fatigue.inputs["W_t"]
    permissible = [fatigue_capacity(fatigue, m) for m in mean]
    worst = int(np.argmax(np.array(amplitude) / np.array(permissible)))
    check = verify_alternating(fatigue, "ripple", load)
    assert check.v_kmh == pytest.approx(load.v[worst] / KMH)
    assert check.load == amplitude[worst]
    assert check.capacity == pytest.approx(permissible[worst], rel=1e-12)
    assert permissible[1] == pytest.approx(fatigue.capacity, rel=1e-12)  # no mean: T_WK
    assert permissible[2] < fatigue.capacity
    assert check.inputs["tau_m"] == pytest.approx(mean[worst] / W_t)
    assert check.inputs["tau_a"] == pytest.approx(amplitude[worst] / W_t)
    assert check.inputs["tau_ADK"] * W_t == pytest.approx(check.capacity)
    assert check.mean == mean[worst]
    assert check.alternating == amplitude[worst]
    assert check.scenario["s0"] == load.scenarios[worst]["s0"]

    vibratory = verify_alternating(coupling, "ripple", load, note="a note")
    assert vibratory.v_kmh == pytest.approx(60.0)
    assert vibratory.load == 9e3
    assert vibratory.safety_factor == pytest.approx(coupling.capacity / 9e3)
    assert vibratory.note == "a note"
    assert [o["order"] for o in vibratory.orders] == ["el:6", "el:12"]
    assert [o["amplitude"] for o in vibratory.orders] == pytest.approx([0.75 * 9e3, 0.25 * 9e3])
    assert [o["ripple_amplitude"] for o in vibratory.orders] == [256.0, 128.0]
    assert vibratory.orders[0]["f_hz"] == pytest.approx(2.0 * 60.0 * KMH)

    top = verify_alternating(coupling, "ripple", _load(mean, [1.0, 2.0, 3.0, 4e3]))
    assert top.v_kmh == pytest.approx(150.0)
    assert top.orders[1]["f_hz"] is None  # not excited beyond the model's range
    for c in (slip, check, vibratory, top):
        data = c.as_dict()
        assert {"mean", "alternating", "v_kmh", "orders", "load", "capacity", "safety_factor",
                "inputs", "scenario"} <= set(data)
        json.loads(json.dumps(data, allow_nan=False))
    assert governing([slip, check, vibratory]) is max((slip, check, vibratory),
                                                      key=lambda c: c.utilisation)


def test_checks_of_a_largest_torque_state_no_alternating_load():
    component = drive_components(load_parameters())[0]
    data = verify(component, "case", 1e3).as_dict()
    assert data["mean"] is None
    assert data["alternating"] is None
    assert data["v_kmh"] is None
    assert data["orders"] == []


def test_fatigue_capacity_is_the_permissible_amplitude_at_the_mean():
    fatigue = next(c for c in alternating_components(load_parameters())
                   if c.kind == "torsional_fatigue" and c.name == "ID1 hollow shaft")
    W_t = fatigue.inputs["W_t"]
    data = TorsionalFatigue(**{name: fatigue.inputs[name]
                               for name in TorsionalFatigue.__dataclass_fields__})
    assert W_t == pytest.approx(data.section_modulus, rel=1e-12)
    for mean in (0.0, 40e3, -40e3, 500e3):
        assert fatigue_capacity(fatigue, mean) == pytest.approx(
            permissible_amplitude(data, mean / W_t) * W_t, rel=1e-12)
