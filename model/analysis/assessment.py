"""From loads to verdicts: the capacity of every press fit, shaft section and coupling of both
drives, and the check of a load against it.

    components = drive_components(parameters)        # 16: 8 per drive
    check = verify(components[0], "short_circuit", load=42e3)
    check.safety_factor, check.ok

**Press-fit slip** (DIN 7190-1, Lamé's thick cylinders, elastic range).  A hub of outer diameter
D on a seat of diameter d (shaft bore d_i, 0 for a solid shaft) with diametral interference δ has
the contact pressure

    p = δ / (d [((D² + d²)/(D² − d²) + ν_hub)/E_hub + ((d² + d_i²)/(d² − d_i²) − ν_shaft)/E_shaft])

and slips under the torque T_slip = μ p π d² L / 2 (L the seat's length).  The capacity is taken
at the worst of the tolerances: the smallest interference and the lowest friction coefficient.
Smoothing of the surfaces at pressing, centrifugal expansion and the axial load of the fit are not
counted (they lower the capacity a little; DIN 7190-1 has them).

**Torsional shear** of a circular section of outer diameter D and bore d_i:
τ = 16 T D / (π (D⁴ − d_i⁴)); the capacity is the torque at the permissible stress,
T = τ_allow π (D⁴ − d_i⁴) / (16 D).  Torsion alone: bending from the wheel forces and fatigue are
what EN 13103-1 adds for an axle, and are not checked here.

**Coupling**: the torque against the coupling's rating.

A check's safety factor is capacity / load (load = the largest |torque| of the load case); it
passes when that is at least the required factor (a parameter with its source).

**Under alternating load** (a steady mean torque T_m with a steady oscillation of amplitude T_a
about it, over a range of speeds: :class:`AlternatingLoad`, :func:`verify_alternating`; the
components of :func:`alternating_components`):

* press-fit slip: the same capacity T_slip against the largest torque ``|T_m| + T_a``;
* torsional fatigue of the axle, the hollow shaft and the driving shaft (DIN 743, simplified:
  :mod:`model.analysis.fatigue`): the permissible amplitude ``T_ADK = τ_ADK(τ_m) W_t`` against
  ``T_a`` (``W_t = π (D⁴ − d_i⁴)/(16 D)``, ``τ_m = T_m / W_t``); the capacity depends on the mean;
* coupling vibratory torque: ``T_a`` against the coupling's permissible vibratory torque T_KW
  (DIN 740-2).

Each is taken at the speed where its utilisation (required / safety factor) is largest; the check
states that speed, the mean and the amplitude there, and each order's share of the amplitude.
SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from model.analysis.fatigue import TorsionalFatigue, permissible_amplitude, torsional_fatigue
from model.mechanics.assembly import DRIVES, RIM_NODES
from model.mechanics.excitation import Order
from model.mechanics.operating_point import KMH
from model.mechanics.parameters import Parameters

KINDS = ("press_fit_slip", "torsional_shear", "coupling", "torsional_fatigue",
         "coupling_vibratory")
KIND_NAMES = {"press_fit_slip": "press-fit slip", "torsional_shear": "torsional shear",
              "coupling": "coupling rating", "torsional_fatigue": "torsional fatigue",
              "coupling_vibratory": "coupling vibratory torque"}  # each kind in words (tables, reports)
# each verdict colour (:func:`verdict_colour`) in words
VERDICT_WORDS = {"green": "margin met", "amber": "margin short", "red": "overloaded"}


def contact_pressure(delta: float, d: float, D: float, d_i: float, E_hub: float, nu_hub: float,
                     E_shaft: float, nu_shaft: float) -> float:
    """Contact pressure p [Pa] of a press fit (Lamé, module docstring): diametral interference
    ``delta`` [m], seat diameter ``d`` [m], hub outer diameter ``D`` [m], shaft bore ``d_i`` [m]
    (0: solid), Young's moduli [Pa] and Poisson's ratios [-] of hub and shaft."""
    if not 0.0 <= d_i < d < D:
        raise ValueError(f"press fit: need 0 <= d_i < d < D, got d_i = {d_i:g} m, d = {d:g} m, "
                         f"D = {D:g} m")
    hub = ((D**2 + d**2) / (D**2 - d**2) + nu_hub) / E_hub
    shaft = ((d**2 + d_i**2) / (d**2 - d_i**2) - nu_shaft) / E_shaft
    return delta / (d * (hub + shaft))


def slip_torque(mu: float, p: float, d: float, L: float) -> float:
    """T_slip = μ p π d² L / 2 [N m]: friction ``mu`` [-], pressure ``p`` [Pa], seat diameter
    ``d`` [m] and length ``L`` [m]."""
    return mu * p * math.pi * d**2 * L / 2


def shear_stress(T: float, D: float, d_i: float = 0.0) -> float:
    """Torsional shear stress τ = 16 T D / (π (D⁴ − d_i⁴)) [Pa] at the surface of a circular
    section (outer diameter ``D`` [m], bore ``d_i`` [m]) under the torque ``T`` [N m]."""
    return 16 * T * D / (math.pi * (D**4 - d_i**4))


def shear_capacity(tau_allow: float, D: float, d_i: float = 0.0) -> float:
    """The torque [N m] at which the section's shear stress reaches ``tau_allow`` [Pa]:
    τ_allow π (D⁴ − d_i⁴) / (16 D)."""
    return tau_allow * math.pi * (D**4 - d_i**4) / (16 * D)


@dataclass(frozen=True)
class Component:
    """A part to check: what it is, which output loads it, its capacity and the data behind it."""

    name: str  # e.g. "ID1 wheel seat 12"
    kind: str  # one of KINDS
    output: str  # the output whose largest |value| is its load
    capacity: float  # [N m]
    required: float  # required safety factor [-]
    inputs: dict = field(default_factory=dict)  # the data the capacity comes from (SI)


def press_fit(name: str, output: str, p: Parameters, seat: str, d_i: float) -> Component:
    """A press fit's component at the worst tolerances (smallest interference, lowest μ)."""
    inputs = {"d": p[f"{seat}_diameter"], "L": p[f"{seat}_length"],
              "D": p[f"{seat.split('_')[0]}_hub_outer_diameter"], "d_i": d_i,
              "delta": p[f"{seat}_interference_min"], "mu": p[f"{seat}_friction_min"],
              "E_hub": p["hub_young_modulus"], "E_shaft": p["young_modulus"],
              "nu_hub": p["hub_poisson_ratio"], "nu_shaft": p["poisson_ratio"]}
    pressure = contact_pressure(inputs["delta"], inputs["d"], inputs["D"], d_i, inputs["E_hub"],
                                inputs["nu_hub"], inputs["E_shaft"], inputs["nu_shaft"])
    inputs["p"] = pressure
    return Component(name, "press_fit_slip", output,
                     slip_torque(inputs["mu"], pressure, inputs["d"], inputs["L"]),
                     p["required_factor_slip"], inputs)


def shaft(name: str, output: str, p: Parameters, D: float, d_i: float, allowable: str
          ) -> Component:
    inputs = {"D": D, "d_i": d_i, "tau_allow": p[allowable]}
    return Component(name, "torsional_shear", output, shear_capacity(p[allowable], D, d_i),
                     p["required_factor_shear"], inputs)


def coupling(name: str, output: str, p: Parameters, rating: str) -> Component:
    return Component(name, "coupling", output, p[rating], p["required_factor_coupling"],
                     {"rated_torque": p[rating]})


def drive_components(parameters: Parameters) -> list[Component]:
    """Every press fit, shaft section and coupling of both drives (8 each), in drive order."""
    p = parameters
    hollow_bore = 2 * p["hollow_shaft_inner_radius"]
    components = []
    for drive in DRIVES:
        for k in RIM_NODES:
            components.append(press_fit(f"{drive} wheel seat {k}",
                                        f"{drive}.axle.wheel_seat_{k}.torque", p, "wheel_seat",
                                        0.0))  # the axle is solid
        components.append(press_fit(f"{drive} gear seat", f"{drive}.hollow_shaft.gear_seat.torque",
                                    p, "gear_seat", hollow_bore))
        components.append(shaft(f"{drive} axle", f"{drive}.axle.centre.torque", p,
                                2 * p["axle_radius"], 0.0, "axle_shear_stress_allowable"))
        components.append(shaft(f"{drive} hollow shaft", f"{drive}.hollow_shaft.torque", p,
                                2 * p["hollow_shaft_outer_radius"], hollow_bore,
                                "hollow_shaft_shear_stress_allowable"))
        components.append(shaft(f"{drive} driving shaft", f"{drive}.driving_shaft.torque", p,
                                p["driving_shaft_diameter"], 0.0,
                                "driving_shaft_shear_stress_allowable"))
        components.append(coupling(f"{drive} disc clutch", f"{drive}.disc_clutch.torque", p,
                                   "disc_clutch_rated_torque"))
        components.append(coupling(f"{drive} claw clutch", f"{drive}.claw_clutch.torque", p,
                                   "claw_clutch_rated_torque"))
    return components


def fatigue_shaft(name: str, output: str, p: Parameters, part: str, D: float, d_i: float
                  ) -> Component:
    """A shaft section's torsional fatigue component (:mod:`model.analysis.fatigue`; outer
    diameter ``D``, bore ``d_i`` [m]): its capacity is the permissible amplitude without a mean,
    T_WK = τ_WK W_t [N m]; a check takes the one at its mean (:func:`fatigue_capacity`).  ``part``
    names its data in the set (``{part}_tensile_strength``, ``{part}_strength_diameter``,
    ``{part}_torsional_notch_factor``, ``{part}_surface_roughness``; its yield limit
    ``{part}_shear_stress_allowable``)."""
    data = torsional_fatigue(p[f"{part}_tensile_strength"], p[f"{part}_strength_diameter"], D,
                             d_i, p[f"{part}_torsional_notch_factor"],
                             p[f"{part}_surface_roughness"], p[f"{part}_shear_stress_allowable"])
    return Component(name, "torsional_fatigue", output, data.tau_WK * data.section_modulus,
                     p["required_factor_fatigue"], data.as_dict())


def fatigue_capacity(component: Component, mean: float) -> float:
    """The permissible torque amplitude T_ADK = τ_ADK(τ_m) W_t [N m] of a torsional fatigue
    component about the mean torque ``mean`` [N m]."""
    data = _fatigue_data(component)
    W_t = data.section_modulus
    return permissible_amplitude(data, mean / W_t) * W_t


def fatigue_data(component: Component) -> TorsionalFatigue:
    """The DIN 743 data of a torsional fatigue component (:func:`fatigue_shaft`)."""
    return _fatigue_data(component)


def _fatigue_data(component: Component) -> TorsionalFatigue:
    fields = {name: component.inputs[name] for name in TorsionalFatigue.__dataclass_fields__}
    return TorsionalFatigue(**fields)


def vibratory_coupling(name: str, output: str, p: Parameters, vibratory: str) -> Component:
    """A coupling against its permissible vibratory torque T_KW [N m], the set's ``vibratory``."""
    return Component(name, "coupling_vibratory", output, p[vibratory],
                     p["required_factor_vibratory"], {"vibratory_torque": p[vibratory]})


def alternating_components(parameters: Parameters) -> list[Component]:
    """What a steady alternating load is checked against (8 per drive, in drive order, the
    sections of :func:`drive_components`): the press fits against slip under mean + amplitude,
    the axle, hollow shaft and driving shaft against torsional fatigue, the disc and claw
    clutches against their permissible vibratory torque."""
    p = parameters
    hollow_bore = 2 * p["hollow_shaft_inner_radius"]
    press_fits = [c for c in drive_components(p) if c.kind == "press_fit_slip"]
    components = []
    for drive in DRIVES:
        components += [c for c in press_fits if c.name.startswith(f"{drive} ")]
        components.append(fatigue_shaft(f"{drive} axle", f"{drive}.axle.centre.torque", p,
                                        "axle", 2 * p["axle_radius"], 0.0))
        components.append(fatigue_shaft(f"{drive} hollow shaft", f"{drive}.hollow_shaft.torque", p,
                                        "hollow_shaft", 2 * p["hollow_shaft_outer_radius"],
                                        hollow_bore))
        components.append(fatigue_shaft(f"{drive} driving shaft", f"{drive}.driving_shaft.torque",
                                        p, "driving_shaft", p["driving_shaft_diameter"], 0.0))
        components.append(vibratory_coupling(f"{drive} disc clutch", f"{drive}.disc_clutch.torque",
                                             p, "disc_clutch_vibratory_torque"))
        components.append(vibratory_coupling(f"{drive} claw clutch", f"{drive}.claw_clutch.torque",
                                             p, "claw_clutch_vibratory_torque"))
    return components


@dataclass(frozen=True)
class Check:
    """One component under one load case."""

    component: str
    kind: str
    output: str
    load_case: str
    load: float  # largest |torque| of the case [N m]
    capacity: float  # [N m]
    safety_factor: float  # capacity / load [-] (inf for no load)
    required: float  # [-]
    ok: bool  # safety_factor >= required
    inputs: dict
    signed_load: float = math.nan  # the value whose magnitude is the load [N m]
    time: float = math.nan  # when it occurs [s] (nan: a steady case)
    scenario: dict = field(default_factory=dict)  # where: s0, v_kmh, phase_s, …
    note: str = ""  # what qualifies the load (e.g. linear creep beyond the adhesion limit)
    # under alternating load (nan / empty otherwise), at the check's worst speed:
    mean: float = math.nan  # the steady mean torque [N m]
    alternating: float = math.nan  # the amplitude of the oscillation about it [N m]
    v_kmh: float = math.nan  # the speed [km/h]
    orders: tuple = ()  # per order: {"order", "f_hz", "amplitude" (its share of the amplitude,
    #                     N m), "ripple_amplitude" (the excitation's amplitude, N m)}; in the
    #                     running case the wheel polygon's: {"order", "f_hz", "input_amplitude"
    #                     [m], "wheels": [{"input", "phase_deg"}], "amplitude" [N m]}
    rms: float = math.nan  # the running case: the random track's RMS of the torque [N m]
    amplitude: float = math.nan  # the running case: the wheel polygon's amplitude [N m]

    @property
    def utilisation(self) -> float:
        """required / safety factor [-]: above 1 the check fails."""
        return self.required / self.safety_factor

    def as_dict(self) -> dict:
        return {"component": self.component, "kind": self.kind, "output": self.output,
                "load_case": self.load_case, "load": self.load, "capacity": self.capacity,
                "safety_factor": self.safety_factor, "required": self.required,
                "ok": self.ok, "inputs": dict(self.inputs), "signed_load": self.signed_load,
                "time_s": None if math.isnan(self.time) else self.time,
                "scenario": dict(self.scenario), "note": self.note,
                "mean": _number_or_none(self.mean), "alternating": _number_or_none(self.alternating),
                "v_kmh": _number_or_none(self.v_kmh), "orders": [dict(o) for o in self.orders],
                "rms": _number_or_none(self.rms), "amplitude": _number_or_none(self.amplitude)}


def _number_or_none(value: float) -> float | None:
    return None if math.isnan(value) else value


def verify(component: Component, load_case: str, load: float, signed_load: float = math.nan,
           time: float = math.nan, scenario: dict | None = None, note: str = "") -> Check:
    """The check of ``component`` under the largest |torque| ``load`` [N m] of ``load_case``
    (``note``: what qualifies that load, shown beside it)."""
    load = abs(float(load))
    factor = component.capacity / load if load > 0 else math.inf
    return Check(component.name, component.kind, component.output, load_case, load,
                 component.capacity, factor, component.required, factor >= component.required,
                 component.inputs, float(signed_load), float(time), dict(scenario or {}), note)


@dataclass(frozen=True)
class AlternatingLoad:
    """The steady torque of one output over a speed grid: a mean and the amplitude of the
    oscillation about it, with each excitation order's share."""

    v: np.ndarray  # (V,) speeds [m/s]
    mean: np.ndarray  # (V,) signed mean torque [N m]
    alternating: np.ndarray  # (V,) amplitude [N m]: the sum of by_order over the orders
    orders: tuple[Order, ...]
    ripple: np.ndarray  # (orders,) the excitation's amplitude of each order [N m]
    frequencies_hz: np.ndarray  # (orders, V) each order's frequency [Hz] (nan: not excited)
    by_order: np.ndarray  # (orders, V) each order's share of the amplitude [N m]
    scenarios: tuple[dict, ...] = ()  # (V,) what else defines each speed's values (s0, …)


def verify_alternating(component: Component, load_case: str, load: AlternatingLoad,
                       note: str = "") -> Check:
    """The check of ``component`` under the alternating ``load``, at the speed where its
    utilisation is largest (module docstring): a press fit (or any peak check) against
    ``|T_m| + T_a``, a fatigue section's amplitude against T_ADK(T_m), a coupling's amplitude
    against T_KW."""
    mean = np.asarray(load.mean, dtype=float)
    amplitude = np.asarray(load.alternating, dtype=float)
    if component.kind == "torsional_fatigue":
        loads = amplitude
        capacities = np.array([fatigue_capacity(component, m) for m in mean])
    elif component.kind == "coupling_vibratory":
        loads, capacities = amplitude, np.full(len(mean), component.capacity)
    else:  # a largest-torque check: the peak of the oscillation
        loads, capacities = np.abs(mean) + amplitude, np.full(len(mean), component.capacity)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(loads > 0, loads / capacities, 0.0)
    i = int(np.argmax(np.where(np.isnan(ratio), np.inf, ratio)))
    if component.kind in ("torsional_fatigue", "coupling_vibratory"):
        signed = float(amplitude[i])
    else:
        signed = float(mean[i] + math.copysign(amplitude[i], mean[i]))
    capacity, value = float(capacities[i]), float(loads[i])
    factor = capacity / value if value > 0 else math.inf
    inputs = dict(component.inputs)
    if component.kind == "torsional_fatigue":
        W_t = _fatigue_data(component).section_modulus
        inputs.update(tau_m=float(mean[i]) / W_t, tau_a=float(amplitude[i]) / W_t,
                      tau_ADK=capacity / W_t)
    v_kmh = float(load.v[i]) / KMH
    scenario = {**(dict(load.scenarios[i]) if load.scenarios else {}), "v_kmh": v_kmh}
    orders = tuple({"order": order.name, "f_hz": _number_or_none(float(load.frequencies_hz[k, i])),
                    "amplitude": float(load.by_order[k, i]),
                    "ripple_amplitude": float(load.ripple[k])}
                   for k, order in enumerate(load.orders))
    return Check(component.name, component.kind, component.output, load_case, value, capacity,
                 factor, component.required, factor >= component.required, inputs, signed,
                 math.nan, scenario, note, float(mean[i]), float(amplitude[i]), v_kmh, orders)


def governing(checks: list[Check]) -> Check:
    """The check with the least margin: the largest required factor / safety factor."""
    if not checks:
        raise ValueError("no checks")
    return max(checks, key=lambda c: c.utilisation)


def verdict_colour(check: Check) -> str:
    """"green" (the required factor is met), "amber" (the capacity holds, the margin is short:
    1 <= safety factor < required) or "red" (the load exceeds the capacity)."""
    if check.ok:
        return "green"
    return "amber" if check.safety_factor >= 1.0 else "red"
