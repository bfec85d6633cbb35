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
passes when that is at least the required factor (a parameter with its source).  SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from model.mechanics.assembly import DRIVES, RIM_NODES
from model.mechanics.parameters import Parameters

KINDS = ("press_fit_slip", "torsional_shear", "coupling")
KIND_NAMES = {"press_fit_slip": "press-fit slip", "torsional_shear": "torsional shear",
              "coupling": "coupling rating"}  # each kind in words (tables, reports)
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
                "scenario": dict(self.scenario), "note": self.note}


def verify(component: Component, load_case: str, load: float, signed_load: float = math.nan,
           time: float = math.nan, scenario: dict | None = None, note: str = "") -> Check:
    """The check of ``component`` under the largest |torque| ``load`` [N m] of ``load_case``
    (``note``: what qualifies that load, shown beside it)."""
    load = abs(float(load))
    factor = component.capacity / load if load > 0 else math.inf
    return Check(component.name, component.kind, component.output, load_case, load,
                 component.capacity, factor, component.required, factor >= component.required,
                 component.inputs, float(signed_load), float(time), dict(scenario or {}), note)


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
