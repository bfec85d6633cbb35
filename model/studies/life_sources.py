"""The load sources of the fatigue life over a route (:mod:`model.studies.life`): each gives every
shaft section its contributions (damage a year) from what the route gives, and notes what it
leaves out.

* :class:`RippleSource` — the converters' ripple (:mod:`model.studies.ripple_case`);
* :class:`PolygonSource` — polygonal wheels (:func:`model.analysis.wheel_excitation.
  polygon_response`, the route's ``[wheel_polygon]``);
* :class:`TrackSource` — the track's random irregularity (:func:`model.analysis.track_spectrum.
  random_response`, the route's ``[track]``);
* :class:`ShortCircuitSource` — ID1's motor short circuit, the route's ``[short_circuit]``.

The steady ones are evaluated at speeds across every bin of the route from 10 km/h (the ripple
case's lowest speed; the time below does no damage from them): eleven evenly spaced per bin and
39 around every resonance found (from 0.01 % to 5 % of its speed either side), since a lightly
damped resonance is a fraction of a km/h wide; the random one at the bins' edges (its damage
rate follows the speed smoothly).  The wheels' sources take, at each speed, the creepages of
:class:`~model.studies.life.LifeOptions` at which the running system has no growing mode (the
envelope over those); a bin with an edge where none is stable is left out and named in the
result's notes.  SI units (speeds in m/s).
"""

from __future__ import annotations

import itertools

import numpy as np

from model.analysis.spectral_fatigue import SpectralMoments, dirlik_damage_rate
from model.mechanics.operating_point import KMH
from model.mechanics.parameters import Parameters
from model.studies.life import (
    Contribution,
    LifeContext,
    LifeError,
    event_contributions,
    spectral_contributions,
    steady_contributions,
)
from model.studies.route import Route

RIPPLE_FLOOR = 10.0 * KMH  # the lowest speed of the ripple source [m/s]
POINTS_PER_BIN = 11  # evenly spaced speeds across a bin, its edges included
# relative offsets from a resonance speed at which the steady sources are evaluated
RESONANCE_OFFSETS = np.concatenate([-np.logspace(-1.3, -4.0, 19), [0.0],
                                    np.logspace(-4.0, -1.3, 19)])


def _route_speeds(route: Route, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """(the route's bin edges from ``floor`` on, evenly spaced points across every bin) [m/s]."""
    edges = route.edges[route.edges >= floor]
    if route.edges[0] < floor < route.edges[-1]:
        edges = np.unique(np.concatenate([[floor], edges]))
    inner = [np.linspace(a, b, POINTS_PER_BIN) for a, b in itertools.pairwise(edges)]
    return edges, np.unique(np.concatenate(inner)) if inner else edges


def _clusters(speeds: np.ndarray, rtol: float = 2e-3) -> list[float]:
    """One speed [m/s] per cluster of resonance speeds closer than ``rtol`` of each other (the
    same mode found for another motor or creepage): the cluster's middle; the offsets around it
    reach 5 % either side, far beyond the cluster's width."""
    kept: list[list[float]] = []
    for speed in np.sort(np.asarray(speeds, dtype=float)):
        if kept and speed - kept[-1][-1] <= rtol * speed:
            kept[-1].append(float(speed))
        else:
            kept.append([float(speed)])
    return [0.5 * (c[0] + c[-1]) for c in kept]


class RippleSource:
    """The converters' ripple (:mod:`model.studies.ripple_case`): both motors' steady response
    at each order over the route's speeds from 10 km/h, as the assessment's ripple case (its
    creepages' envelope: largest amplitude, largest mean), densely around each resonance."""

    name = "ripple"

    def contributions(self, context: LifeContext) -> dict[str, list[Contribution]]:
        from model.analysis.campbell import MOTOR_INPUTS, resonant_speeds
        from model.mechanics.excitation import load_excitation
        from model.mechanics.operating_point import OperatingPoint
        from model.studies.maps import cached_model
        from model.studies.ripple_case import (
            RippleCaseError,
            envelope_loads,
            ripple_amplitudes,
            ripple_sweep,
        )

        route, options = context.route, context.options
        edges, points = _route_speeds(route, RIPPLE_FLOOR)
        if len(edges) < 2:
            return {s.output: [] for s in context.sections}
        parameters = context.parameters
        model = cached_model(parameters)
        ops = [OperatingPoint(s0, float(edges[0]), parameters["wheel_force"],
                              parameters["motor_slope"]) for s0 in options.s0]
        ripple = ripple_amplitudes(parameters) if options.ripple is None else options.ripple
        outputs = [s.output for s in context.sections]
        drive = load_excitation()
        found = [resonant_speeds(model, op, edges, tuple(ripple), drive, motor)
                 for op in ops for motor in MOTOR_INPUTS]
        refined = np.concatenate([np.asarray(f, dtype=float) for f in found])
        resonances = [r * (1 + RESONANCE_OFFSETS) for r in _clusters(refined)]
        extra = np.concatenate([points, *resonances]) if resonances else points
        extra = extra[(extra >= edges[0]) & (extra <= edges[-1])]
        try:
            sweep = ripple_sweep(model, ops, edges, ripple, drive, outputs, extra)
        except RippleCaseError as error:
            raise LifeError(str(error)) from None
        loads = envelope_loads(sweep)
        labels = [o.name for o in sweep.orders]
        return {s.output: steady_contributions(
            self.name, s, route, sweep.v, loads[s.output].mean, loads[s.output].by_order,
            loads[s.output].frequencies_hz, labels, RIPPLE_FLOOR) for s in context.sections}


def _running_ops(context: LifeContext, v: float) -> list:
    """The operating points at speed ``v`` [m/s], one per creepage of the options, at which the
    running system (:func:`model.analysis.eigen.running_system`: the bogie with the wheel-force
    coupling the wheels' deviations act through) has no growing mode."""
    from model.analysis.eigen import non_neutral, running_system
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.maps import cached_model

    p = context.parameters
    model = cached_model(p)
    stable = []
    for s0 in context.options.s0:
        op = OperatingPoint(s0, float(v), p["wheel_force"], p["motor_slope"])
        lam = running_system(model, op).eigen[0]
        if np.all(lam[non_neutral(lam)].real <= 0):
            stable.append(op)
    return stable


def traction_mean(model, op, outputs: list[str]) -> np.ndarray:
    """The steady traction's static load of ``outputs`` at ``op`` [N m] (the ripple case's mean)."""
    from model.analysis.frequency_response import output_indices
    from model.mechanics.outputs import static_deflection

    matrices, rows = output_indices(model, op, outputs)
    return (matrices.C_q @ static_deflection(model, op))[rows]


def _stable_bins(context: LifeContext, edges: np.ndarray, source: str):
    """(per edge speed: its stable operating points, per bin: True where both edges have one);
    a note names the bins left out."""
    ops = [_running_ops(context, v) for v in edges]
    usable = [bool(a) and bool(b) for a, b in itertools.pairwise(ops)]
    left = [f"{a / KMH:g}-{b / KMH:g}" for (a, b), ok in
            zip(itertools.pairwise(edges), usable, strict=True) if not ok]
    if left:
        context.notes.append(
            f"{source}: left out in {', '.join(left)} km/h, where the running system has a "
            f"growing mode at every creepage of {', '.join(f'{x:g}' for x in context.options.s0)}"
            " (no steady or stationary response)")
    return ops, usable


class PolygonSource:
    """Polygonal wheels (:func:`model.analysis.wheel_excitation.polygon_response`, the route's
    ``[wheel_polygon]``): every section's steady amplitude per polygon order over the route's
    speeds from 10 km/h, at the options' creepages where the running system is stable at both
    ends of a bin (the envelope: the largest amplitude and mean), densely around each resonance
    the response's own search finds; as the ripple, per bin and order."""

    name = "polygon"

    def contributions(self, context: LifeContext) -> dict[str, list[Contribution]]:
        from dataclasses import replace

        from model.analysis.wheel_excitation import WheelExcitationError, polygon_response
        from model.mechanics.operating_point import OperatingPoint
        from model.studies.maps import cached_model

        polygon = context.route.wheel_polygon
        edges, points = _route_speeds(context.route, RIPPLE_FLOOR)
        if not polygon:
            context.notes.append("polygon: the route gives no [wheel_polygon]")
        if not polygon or len(edges) < 2:
            return {s.output: [] for s in context.sections}
        model = cached_model(context.parameters)
        outputs = [s.output for s in context.sections]
        ops, usable = _stable_bins(context, edges, self.name)
        # per creepage: the bins where it is stable at both edges
        creepages = sorted({op.s0 for at in ops for op in at})
        stable_bins = {s0: [any(o.s0 == s0 for o in a) and any(o.s0 == s0 for o in b)
                            for a, b in itertools.pairwise(ops)] for s0 in creepages}

        def inside(speeds: np.ndarray, bins: list[bool]) -> np.ndarray:
            mask = np.zeros(len(speeds), dtype=bool)
            for (a, b), ok in zip(itertools.pairwise(edges), bins, strict=True):
                if ok:
                    mask |= (speeds >= a) & (speeds <= b)
            return mask

        v = points[inside(points, usable)]
        if len(v) < 2:
            return {s.output: [] for s in context.sections}
        p = context.parameters
        template = [OperatingPoint(s0, float(v[0]), p["wheel_force"], p["motor_slope"])
                    for s0 in creepages]
        try:  # the resonances the response's own search finds, then one grid for all
            found = np.concatenate([np.setdiff1d(polygon_response(model, op, v, polygon,
                                                                  outputs).v, v)
                                    for op in template])
            dense = [r * (1 + RESONANCE_OFFSETS) for r in _clusters(found)]
            grid = np.unique(np.concatenate([v, *dense])) if dense else v
            grid = grid[inside(grid, usable)]
            responses = [polygon_response(model, op, grid, polygon, outputs, refine=False)
                         for op in template]
        except WheelExcitationError as error:
            raise LifeError(str(error)) from None
        amplitude = np.full(responses[0].by_order.shape, -np.inf)  # (orders, outputs, V)
        mean = np.zeros((len(outputs), len(grid)))
        for op, r in zip(template, responses, strict=True):
            mask = inside(grid, stable_bins[op.s0])
            means = np.array([traction_mean(model, replace(op, v=float(x)), outputs)
                              for x in grid]).T
            amplitude = np.where(mask, np.maximum(amplitude, np.nan_to_num(r.by_order)),
                                 amplitude)
            mean = np.where(mask & (np.abs(means) > np.abs(mean)), means, mean)
        amplitude[~np.isfinite(amplitude)] = 0.0
        labels = [f"polygon:{n}" for n in responses[0].orders]
        route = _usable_route(context.route, edges, usable)
        return {s.output: steady_contributions(self.name, s, route, grid, mean[j],
                                                amplitude[:, j, :], responses[0].frequencies_hz,
                                                labels, RIPPLE_FLOOR)
                for j, s in enumerate(context.sections)}


def _usable_route(route: Route, edges: np.ndarray, usable: list[bool]) -> Route:
    """``route`` with no time in the bins (between ``edges`` [m/s]) a source leaves out."""
    from dataclasses import replace

    seconds = route.seconds_per_year.copy()
    for (a, b), ok in zip(itertools.pairwise(edges), usable, strict=True):
        if not ok:
            centre = 0.5 * (a + b)
            seconds[(route.edges[:-1] <= centre) & (route.edges[1:] >= centre)] = 0.0
    return replace(route, seconds_per_year=seconds)


class TrackSource:
    """The track's random vertical irregularity (:func:`model.analysis.track_spectrum.
    random_response`, the route's ``[track] spectrum``): every section's torque spectrum (its
    moments by adaptive quadrature) at the route's bin edges from 10 km/h, Dirlik's damage of
    the mean-corrected stress, averaged over each bin; at each speed the creepage of the
    options with the larger damage among those where the running system is stable (a bin with
    an edge where none is, is left out and noted)."""

    name = "track"

    def contributions(self, context: LifeContext) -> dict[str, list[Contribution]]:
        from model.analysis.track_spectrum import random_response, track_spectrum
        from model.studies.maps import cached_model

        route = context.route
        edges, _ = _route_speeds(route, RIPPLE_FLOOR)
        if route.track is None:
            context.notes.append("track: the route gives no [track] spectrum")
        if route.track is None or len(edges) < 2:
            return {s.output: [] for s in context.sections}
        model = cached_model(context.parameters)
        spectrum = track_spectrum(route.track)
        outputs = [s.output for s in context.sections]
        ops, _ = _stable_bins(context, edges, self.name)
        # per edge and stable creepage: (moments (outputs, 4), means (outputs,))
        computed = []
        for at in ops:
            here = []
            for op in at:
                r = random_response(model, op, spectrum, outputs)
                here.append((r.moments, traction_mean(model, op, outputs)))
            computed.append(here)
        out = {}
        for j, s in enumerate(context.sections):
            def at_speed(i, j=j, s=s):
                best, best_damage = None, -1.0
                for moments, means in computed[i]:
                    m = SpectralMoments(*(float(x) for x in moments[j]))
                    if not (m.m0 > 0 and m.m2 > 0 and m.m4 > 0):
                        damage = 0.0
                        if damage > best_damage:
                            best, best_damage = (m, float(means[j])), damage
                        continue
                    per_torque = float(s.equivalent_amplitude(1.0, means[j]))
                    damage = dirlik_damage_rate(SpectralMoments(
                        m.m0 * per_torque**2, m.m1 * per_torque**2, m.m2 * per_torque**2,
                        m.m4 * per_torque**2), s.sn)
                    if damage > best_damage:
                        best, best_damage = (m, float(means[j])), damage
                return best
            out[s.output] = spectral_contributions(self.name, s, route, edges, at_speed,
                                                   RIPPLE_FLOOR)
        return out


def check_events(parameters: Parameters, route: Route) -> None:
    """Refuse a route whose short circuits happen at an unstable operating point
    (:class:`LifeError`, one line): the response is a linear one about a stable state."""
    from model.analysis.eigen import bogie_system
    from model.analysis.load_peaks import GROWTH_RATE
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.maps import cached_model

    events = route.short_circuit
    if events is None:
        return
    model = cached_model(parameters)
    for v in events.v:
        op = OperatingPoint(events.s0, v, parameters["wheel_force"], parameters["motor_slope"])
        growth = float(np.max(bogie_system(model, op).eigenvalues().real))
        if growth > GROWTH_RATE:
            raise LifeError(f"short circuit: s0 = {op.s0:g} at {op.v_kmh:g} km/h is not stable "
                            f"(growth rate {growth:.3g} 1/s): the route's short circuits take "
                            "stable creepages")


class ShortCircuitSource:
    """ID1's motor short circuit (:func:`model.analysis.response.short_circuit_response` at the
    set's excitation, its fault instant where the motor torque is continuous): the rainflow
    cycles of each section's torque history over the options' horizon, per event, at the route's
    events a year at each speed and its creepage."""

    name = "short_circuit"

    def contributions(self, context: LifeContext) -> dict[str, list[Contribution]]:
        from model.analysis.response import short_circuit_response
        from model.mechanics.operating_point import OperatingPoint
        from model.studies.maps import cached_model

        events = context.route.short_circuit
        if events is None:
            context.notes.append("short_circuit: the route gives no [short_circuit] events")
        if events is None or events.per_year == 0:
            return {s.output: [] for s in context.sections}
        p = context.parameters
        model = cached_model(p)
        check_events(p, context.route)
        outputs = [s.output for s in context.sections]
        histories = {name: [] for name in outputs}
        for v, per_year in events.per_year_at():
            op = OperatingPoint(events.s0, v, p["wheel_force"], p["motor_slope"])
            r = short_circuit_response(model, op, None, context.options.short_circuit_t_end,
                                       context.options.short_circuit_fs, outputs)
            for name in outputs:
                histories[name].append((r.outputs[name], per_year))
        return {s.output: event_contributions(self.name, s, histories[s.output])
                for s in context.sections}


def default_sources() -> tuple:
    """The four sources, in the order of the result: ripple, polygon, track, short circuit."""
    return (RippleSource(), PolygonSource(), TrackSource(), ShortCircuitSource())
