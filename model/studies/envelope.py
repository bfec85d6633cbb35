"""Design loads: the largest and smallest value of every output over a grid of short-circuit
scenarios (the envelope), where each occurs, and the store that keeps it.

API::

    study = EnvelopeStudy(s0=[0.005], v=[120 / 3.6], N0=[1e5], b_M=[3000.0], outputs=…, units=…)
    result = run_envelope(study, parameters)  # in this process, or on Dask: map_unordered=…

**Scenario.**  One short circuit of ID1's motor as ``bogie response`` computes it: rail (creep
law: the set's own or Polach's dry/wet preset), s0 [-], v [m/s], N0 [N], b_M [N m s/rad], the
torque-control bandwidth f_c [Hz] of ID2's converter (a list, or the set's own), the
excitation M0 [N m], f [Hz], D [-], the fault instant Δt [s] and, with nonlinear creep, the
anti-slip protection (off/on) and its delay [s].  Its **peaks** are the max and the min over the
time grid ``t = k/fs``, k = 0 … round(t_end·fs), of each output's *total* (pre-fault value plus
perturbation, as in :mod:`model.analysis.response`).  The **envelope** is the max (min) of those over the
scenarios, with the scenario and time where it occurs.

**Fault instant.**  Three treatments (:mod:`model.analysis.fault_instant` derives them):

* ``"roots"`` (default): the two instants per period at which the total motor torque is
  continuous, ``sin φ = M(s0,v)/M0``; physics first, the machine's flux linkages cannot jump;
* ``"grid"``: the given Δt values;
* ``"all"`` (linear creep only): every Δt, in closed form — explicitly conservative.

The grid study (:class:`EnvelopeStudy`) follows the chunk protocol of :mod:`model.studies.maps` and the
store layout protocol of :mod:`model.studies.store`, so the study engine (Dask) runs it and a Zarr
store keeps it resumable.  Results are plain data (:class:`PhaseFamily`, :class:`WorstFaultInstant`,
:class:`HistoryPeaks`, :class:`Envelope`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from model.analysis.fault_instant import (  # noqa: F401 - re-exported for the envelope's users
    DesignLoadError,
    HistoryPeaks,
    PhaseFamily,
    WorstFaultInstant,
    continuity_phases,
    history_peaks,
    phase_families,
    worst_fault_instant,
    wrap_shift,
)
from model.analysis.response import ShortCircuit, output_rows, time_grid_points
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import KMH, OperatingPoint, motor_torque
from model.mechanics.parameters import Parameters

RAILS = ("calibrated", "dry", "wet")  # the set's own creep law, Polach's dry and wet presets
FAULT_TREATMENTS = ("roots", "grid", "all")
FAULT_DESCRIPTIONS = {
    "roots": "continuity roots: the two fault instants per period with a continuous motor torque, "
             "sin(ωΔt) = M(s0, v)/M0",
    "grid": "a grid of fault instants Δt",
    "all": "every fault instant (closed form over Δt, linear creep): conservative",
}
CREEP_MODELS = ("linear", "nonlinear", "tangent")
SCENARIO_DIMS = ("rail", "s0", "v", "N0", "b_M", "M0", "f", "D", "fault", "anti_slip",
                 "anti_slip_delay")
# the parameter set's values a study may take a list of (each a dimension after b_M when given;
# not given: the set's own value, no dimension — so a store written before stays readable)
SET_VALUE_DIMS = ("motor_bandwidth",)
SET_VALUE_UNITS = {"motor_bandwidth": "Hz"}
PEAK_VARIABLES = ("max", "min", "time_of_max", "time_of_min", "phase_of_max", "phase_of_min")


# --- the scenario grid ---------------------------------------------------------------------------------

def rail_parameters(parameters: Parameters, rail: str) -> Parameters:
    """The parameter set with the creep law of ``rail``: "calibrated" (its own), "dry" or "wet"
    (Polach's presets, :data:`model.contact.creep.CREEP_PRESETS`)."""
    from model.contact.creep import CREEP_PRESETS

    if rail == "calibrated":
        return parameters
    if rail not in CREEP_PRESETS:
        raise DesignLoadError(f"rail '{rail}' is not known: use {', '.join(RAILS)}")
    return parameters.replace(**CREEP_PRESETS[rail])


def _axis(values, label: str) -> tuple[float, ...]:
    values = tuple(float(x) for x in np.atleast_1d(np.asarray(values, dtype=float)))
    if not values:
        raise DesignLoadError(f"{label}: empty grid")
    if not all(math.isfinite(x) for x in values):
        raise DesignLoadError(f"{label}: values must be finite")
    if len(set(values)) != len(values):
        raise DesignLoadError(f"{label}: a value is repeated")
    return values


def set_value_axis(values, label: str) -> tuple[float, ...]:
    """A list of the parameter set's values a study varies (empty: the set's own; else finite,
    distinct, >= 0 — the set's own checks come when a chunk replaces the value)."""
    if values is None or len(values) == 0:
        return ()
    values = _axis(values, label)
    if min(values) < 0:
        raise DesignLoadError(f"{label}: {min(values):g} is not allowed, must be >= 0")
    return values


@dataclass(frozen=True)
class EnvelopeStudy:
    """A grid of short-circuit scenarios (SI units; module docstring).  Axes are tuples; the grid
    is their product.  A chunk is one operating point (rail, s0, v, N0, b_M, f_c) with linear creep
    (every M0, f, D and fault instant from :func:`phase_families`), one scenario with nonlinear
    creep (every anti-slip delay of it)."""

    s0: tuple[float, ...]  # creepages [-]
    v: tuple[float, ...]  # speeds [m/s]
    N0: tuple[float, ...]  # wheel forces [N]
    b_M: tuple[float, ...]  # motor slopes [N m s/rad]
    outputs: tuple[str, ...]  # output names (resolved: :func:`resolve_outputs`)
    units: tuple[str, ...]  # their units
    # torque-control bandwidths f_c of ID2's converter [Hz] (empty: the parameter set's own)
    motor_bandwidth: tuple[float, ...] = ()
    rail: tuple[str, ...] = ("calibrated",)
    M0: tuple[float, ...] = (50_000.0,)  # amplitudes [N m]
    f: tuple[float, ...] = (90.0,)  # frequencies [Hz]
    D: tuple[float, ...] = (0.04,)  # decays [-]
    fault: str = "roots"  # "roots", "grid" or "all"
    phase: tuple[float, ...] = ()  # fault instants Δt [s] of fault = "grid"
    creep: str = "linear"  # "linear" (closed form), "nonlinear" or "tangent"
    anti_slip: tuple[str, ...] = ("off",)  # "off" and/or "on" (nonlinear creep)
    anti_slip_delay: tuple[float, ...] = ()  # delays [s] with "on" (default: AntiSlip's)
    anti_slip_threshold: float | None = None  # [m/s] (None: AntiSlip's default)
    anti_slip_rate: float | None = None  # [1/s]
    anti_slip_floor: float | None = None  # [-]
    t_end: float = 2.0  # horizon [s]
    fs: float = 10_000.0  # sampling rate [Hz]
    method: str = "auto"  # closed-form evaluation (linear creep)
    kind: str = field(default="envelope", init=False)

    def __post_init__(self) -> None:
        for name, label in (("s0", "--s0"), ("v", "--v"), ("N0", "--n0"), ("b_M", "--bm"),
                            ("M0", "--m0"), ("f", "--f"), ("D", "--decay")):
            object.__setattr__(self, name, _axis(getattr(self, name), label))
        object.__setattr__(self, "motor_bandwidth", set_value_axis(self.motor_bandwidth,
                                                                   "--motor-bandwidth"))
        object.__setattr__(self, "rail", tuple(self.rail))
        object.__setattr__(self, "anti_slip", tuple(self.anti_slip))
        object.__setattr__(self, "outputs", tuple(self.outputs))
        object.__setattr__(self, "units", tuple(self.units))
        if not self.rail or len(set(self.rail)) != len(self.rail):
            raise DesignLoadError("--rail: give each of calibrated, dry, wet at most once")
        for rail in self.rail:
            if rail not in RAILS:
                raise DesignLoadError(f"--rail: '{rail}' is not known, use {', '.join(RAILS)}")
        if self.creep not in CREEP_MODELS:
            raise DesignLoadError(f"creep model '{self.creep}' is not allowed: "
                                  f"{', '.join(CREEP_MODELS)}")
        if self.fault not in FAULT_TREATMENTS:
            raise DesignLoadError(f"fault treatment '{self.fault}' is not allowed: "
                                  f"{', '.join(FAULT_TREATMENTS)}")
        if self.fault == "grid":
            object.__setattr__(self, "phase", _axis(self.phase, "--phase"))
        elif self.phase:
            raise DesignLoadError(f"phases are given only with fault = 'grid', not '{self.fault}'")
        if self.fault == "all" and self.creep != "linear":
            raise DesignLoadError("--phase all needs --creep linear (the closed form over the "
                                  "fault instant is a superposition); give a grid of --phase "
                                  "values with nonlinear creep")
        if not self.outputs or len(self.outputs) != len(self.units):
            raise DesignLoadError("outputs and their units must be given, one unit each")
        # each value within the model's domain (the domains are boxes: one value at a time)
        for s0, v, N0, b_M in itertools.chain(
                ((x, self.v[0], self.N0[0], self.b_M[0]) for x in self.s0),
                ((self.s0[0], x, self.N0[0], self.b_M[0]) for x in self.v),
                ((self.s0[0], self.v[0], x, self.b_M[0]) for x in self.N0),
                ((self.s0[0], self.v[0], self.N0[0], x) for x in self.b_M)):
            OperatingPoint(s0, v, N0, b_M)
        for M0, f, D in itertools.chain(((x, self.f[0], self.D[0]) for x in self.M0),
                                        ((self.M0[0], x, self.D[0]) for x in self.f),
                                        ((self.M0[0], self.f[0], x) for x in self.D)):
            ShortCircuit(M0=M0, f=f, D=D)
        for dt in self.phase:
            ShortCircuit(dt=dt)
        time_grid_points(self.t_end, self.fs, DesignLoadError)
        if self.method not in ("auto", "modal", "expm"):
            raise DesignLoadError(f"method '{self.method}' is not allowed: auto, modal or expm")
        self._check_anti_slip()

    def _check_anti_slip(self) -> None:
        if not self.anti_slip or len(set(self.anti_slip)) != len(self.anti_slip) \
                or not set(self.anti_slip) <= {"off", "on"}:
            raise DesignLoadError(f"--anti-slip must be off, on or off,on, got "
                                  f"'{','.join(self.anti_slip)}'")
        options = (self.anti_slip_threshold, self.anti_slip_rate, self.anti_slip_floor)
        if "on" in self.anti_slip:
            if self.creep == "linear":
                raise DesignLoadError("--anti-slip on needs --creep nonlinear or tangent (the "
                                      "closed form has no protection)")
            if not self.anti_slip_delay:
                from model.analysis.nonlinear import AntiSlip

                object.__setattr__(self, "anti_slip_delay", (AntiSlip().delay,))
            object.__setattr__(self, "anti_slip_delay",
                               _axis(self.anti_slip_delay, "--anti-slip-delay"))
            for delay in self.anti_slip_delay:
                self.protection(delay)  # validates
        elif self.anti_slip_delay or any(x is not None for x in options):
            raise DesignLoadError("the anti-slip options need --anti-slip on")

    # --- the grid ---------------------------------------------------------------------------------

    @property
    def scenario_dims(self) -> tuple[str, ...]:
        """The dimensions of the scenario grid: :data:`SCENARIO_DIMS` with, after b_M, each
        value of the parameter set the study gives a list of (:data:`SET_VALUE_DIMS`)."""
        given = tuple(name for name in SET_VALUE_DIMS if getattr(self, name))
        at = SCENARIO_DIMS.index("b_M") + 1
        return SCENARIO_DIMS[:at] + given + SCENARIO_DIMS[at:]

    def chunk_parameters(self, parameters: Parameters, key: dict[str, int]) -> Parameters:
        """The parameter set of the scenarios at ``key`` (dimension -> index): the rail's creep
        law and the set's values the study varies."""
        parameters = rail_parameters(parameters, self.rail[key.get("rail", 0)])
        changes = {name: getattr(self, name)[key.get(name, 0)] for name in SET_VALUE_DIMS
                   if getattr(self, name)}
        return parameters.replace(**changes) if changes else parameters

    @property
    def fault_count(self) -> int:
        """Entries of the fault-instant axis: 2 roots, the grid's phases, or 1 (all)."""
        return {"roots": 2, "grid": len(self.phase), "all": 1}[self.fault]

    @property
    def sizes(self) -> dict[str, int]:
        """Dimension -> length of the scenario grid (and "output")."""
        sizes = {name: len(getattr(self, name)) for name in self.scenario_dims[:-3]}
        sizes["fault"] = self.fault_count
        sizes["anti_slip"] = len(self.anti_slip)
        sizes["anti_slip_delay"] = max(1, len(self.anti_slip_delay))
        return {"output": len(self.outputs), **sizes}

    @property
    def scenarios(self) -> int:
        """Distinct scenarios (protection off counts once whatever the delays)."""
        sizes = self.sizes
        rest = math.prod(sizes[d] for d in self.scenario_dims[:-2])
        protections = sum(1 if a == "off" else sizes["anti_slip_delay"] for a in self.anti_slip)
        return rest * protections

    @property
    def marker_dims(self) -> tuple[str, ...]:
        """Dimensions a chunk key indexes."""
        dims = self.scenario_dims
        return dims[:dims.index("M0")] if self.creep == "linear" else dims[:-1]

    def chunks(self) -> list[tuple[int, ...]]:
        sizes = self.sizes
        return list(itertools.product(*(range(sizes[d]) for d in self.marker_dims)))

    def arguments(self) -> dict:
        """The study's arguments (JSON-able; stored with the results, compared on resume)."""
        names = [f for f in self.__dataclass_fields__ if f != "kind"]
        data = {"kind": self.kind}
        for name in names:
            value = getattr(self, name)
            if name in SET_VALUE_DIMS and not value:
                continue  # the set's own: as a study written before the option existed
            data[name] = list(value) if isinstance(value, tuple) else value
        return data

    def protection(self, delay: float | None):
        """The :class:`model.analysis.nonlinear.AntiSlip` of a delay [s] (None: no protection)."""
        from model.analysis.nonlinear import AntiSlip

        if delay is None:
            return None
        defaults = AntiSlip()
        pick = lambda value, default: default if value is None else value  # noqa: E731
        return AntiSlip(delay=delay,
                        threshold=pick(self.anti_slip_threshold, defaults.threshold),
                        rate=pick(self.anti_slip_rate, defaults.rate),
                        floor=pick(self.anti_slip_floor, defaults.floor))

    def fault_phases(self, step: float, M0: float, f: float) -> tuple[float, ...]:
        """The fault instants Δt [s] of the fault axis for pre-fault torque ``step`` [N m],
        ``M0`` [N m], ``f`` [Hz] (for "all": nan, the closed form finds its own)."""
        if self.fault == "roots":
            return continuity_phases(step, M0, f)
        if self.fault == "grid":
            return self.phase
        return (math.nan,)

    def store_layout(self):
        """The store layout (:class:`model.studies.store.StoreLayout`)."""
        from model.studies.store import StoreLayout

        sizes = self.sizes
        dims = ("output", *self.scenario_dims)
        delays = np.array(self.anti_slip_delay) if self.anti_slip_delay else np.array([np.nan])
        fault_phase = np.array(self.phase) if self.fault == "grid" \
            else np.full(self.fault_count, np.nan)
        text = lambda values: np.array(list(values), dtype=object)  # noqa: E731 (Zarr 3 strings)
        coords = {
            "output": (("output",), text(self.outputs), {"units": "-"}),
            "unit": (("output",), text(self.units), {"description": "unit of the output"}),
            "rail": (("rail",), text(self.rail), {"description": "creep law"}),
            "s0": (("s0",), np.array(self.s0), {"units": "-"}),
            "v": (("v",), np.array(self.v), {"units": "m/s"}),
            "v_kmh": (("v",), np.array(self.v) / KMH, {"units": "km/h"}),
            "N0": (("N0",), np.array(self.N0), {"units": "N"}),
            "b_M": (("b_M",), np.array(self.b_M), {"units": "N m s/rad"}),
            **{name: ((name,), np.array(getattr(self, name)), {"units": SET_VALUE_UNITS[name]})
               for name in SET_VALUE_DIMS if getattr(self, name)},
            "M0": (("M0",), np.array(self.M0), {"units": "N m"}),
            "f": (("f",), np.array(self.f), {"units": "Hz"}),
            "D": (("D",), np.array(self.D), {"units": "-"}),
            "fault": (("fault",), np.arange(self.fault_count),
                      {"description": FAULT_DESCRIPTIONS[self.fault]}),
            "fault_phase": (("fault",), fault_phase,
                            {"units": "s", "description": "the grid's Δt (nan: roots or all; "
                                                          "see phase_of_max)"}),
            "anti_slip": (("anti_slip",), text(self.anti_slip), {"description": "protection"}),
            "anti_slip_delay": (("anti_slip_delay",), delays, {"units": "s"}),
        }
        described = {
            "max": ("largest total over the time grid", "unit of the output"),
            "min": ("smallest total over the time grid", "unit of the output"),
            "time_of_max": ("time of the max after the fault", "s"),
            "time_of_min": ("time of the min after the fault", "s"),
            "phase_of_max": ("fault instant Δt of the history with the max", "s"),
            "phase_of_min": ("fault instant Δt of the history with the min", "s"),
        }
        variables = {name: (dims, np.float64, np.nan, {"units": unit, "description": text_})
                     for name, (text_, unit) in described.items()}
        variables["truncated_at"] = (self.scenario_dims, np.float64, np.nan, {
            "units": "s", "description": "linear growth beyond 1e250: the grid ends here "
                                         "(nan: the whole horizon)"})
        variables["highest_excited_hz"] = (self.marker_dims, np.float64, np.nan, {
            "units": "Hz", "description": "max of f and the highest mode with more than 1 % of "
                                          "an output's peak (linear creep; nan otherwise)"})
        return StoreLayout(sizes, coords, variables, self.marker_dims)

    # --- a chunk ---------------------------------------------------------------------------------

    def run_chunk(self, parameters: Parameters, key: tuple[int, ...]) -> dict:
        """The peaks of chunk ``key`` as plain arrays (what the store writes)."""
        from model.studies.maps import cached_model

        key = dict(zip(self.marker_dims, key, strict=True))
        model = cached_model(self.chunk_parameters(parameters, key))
        op = OperatingPoint(self.s0[key["s0"]], self.v[key["v"]], self.N0[key["N0"]],
                            self.b_M[key["b_M"]])
        if self.creep == "linear":
            return self._linear_chunk(model, op)
        return self._nonlinear_chunk(model, op, key)

    def _linear_chunk(self, model: BogieModel, op: OperatingPoint) -> dict:
        sizes = self.sizes
        inner = (sizes["M0"], sizes["f"], sizes["D"], sizes["fault"], 1, 1)
        result = {name: np.full((len(self.outputs), *inner), np.nan) for name in PEAK_VARIABLES}
        truncated = np.full(inner, np.nan)
        grid = [(f, D) for f in self.f for D in self.D]
        families = phase_families(model, op, grid, self.t_end, self.fs, list(self.outputs),
                                  self.method)
        excited = []
        for (jf, jd), family in zip(itertools.product(range(len(self.f)), range(len(self.D))),
                                    families, strict=True):
            if family.highest_excited_hz is not None:
                excited.append(family.highest_excited_hz)
            for jm, M0 in enumerate(self.M0):
                phases = self.fault_phases(family.motor_torque, M0, family.f)
                for jp, dt in enumerate(phases):
                    if self.fault == "all":
                        peaks = worst_fault_instant(family, M0, histories=False).peaks
                    else:
                        peaks = history_peaks(family.t, family.totals(M0, dt), dt)
                    for name in PEAK_VARIABLES:
                        result[name][:, jm, jf, jd, jp, 0, 0] = getattr(peaks, name)
                    if family.truncated_at is not None:
                        truncated[jm, jf, jd, jp, 0, 0] = family.truncated_at
        result["truncated_at"] = truncated
        result["highest_excited_hz"] = max(excited) if len(excited) == len(families) else np.nan
        return result

    def _nonlinear_chunk(self, model: BogieModel, op: OperatingPoint, key) -> dict:
        from model.analysis.nonlinear import nonlinear_response

        M0, f, D = self.M0[key["M0"]], self.f[key["f"]], self.D[key["D"]]
        step = motor_torque(model.parameters, op)
        dt = self.fault_phases(step, M0, f)[key["fault"]]
        excitation = ShortCircuit(M0=M0, f=f, D=D, dt=dt)
        delays = [None] if self.anti_slip[key["anti_slip"]] == "off" else list(self.anti_slip_delay)
        runs = []
        for delay in delays:
            r = nonlinear_response(model, op, excitation, self.t_end, self.fs, creep=self.creep,
                                   anti_slip=self.protection(delay), outputs=list(self.outputs))
            totals = np.column_stack([r.outputs[name] for name in self.outputs])
            runs.append(history_peaks(r.t, totals, dt))
        n_delay = self.sizes["anti_slip_delay"]
        if len(runs) == 1:
            runs = runs * n_delay  # protection off: the same run for every delay
        result = {name: np.column_stack([getattr(peaks, name) for peaks in runs])
                  for name in PEAK_VARIABLES}
        result["truncated_at"] = np.full(n_delay, np.nan)
        result["highest_excited_hz"] = np.nan
        return result


def resolve_outputs(model: BogieModel, op: OperatingPoint, names: list[str] | None,
                    creep: str = "linear") -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(names, units) of the requested outputs (None: all loads); with nonlinear creep only the
    loads of :func:`model.mechanics.outputs.output_matrices` (no DOF names)."""
    from model.mechanics.outputs import output_matrices

    resolved, _, units, _ = output_rows(model, op, names)
    if creep != "linear":
        known = output_matrices(model, op).names
        for name in resolved:
            if name not in known:
                raise DesignLoadError(f"output '{name}' is not available with nonlinear creep: "
                                      f"use a load ({', '.join(known[:3])}, …)")
    return tuple(resolved), tuple(units[name] for name in resolved)


# --- the envelope -----------------------------------------------------------------------------------

@dataclass(frozen=True)
class OutputEnvelope:
    """Max and min of one output over the scenarios, and where they occur."""

    name: str
    unit: str
    max: float  # [unit]
    min: float  # [unit]
    max_at: dict  # scenario (s0, v_kmh, phase_s, rail, n0, bm, m0, f, decay, …) and time_s
    min_at: dict


@dataclass(frozen=True)
class Envelope:
    """The envelope of a study (plain data)."""

    scenarios: int  # distinct scenarios
    fault_instants: str  # "roots", "grid" or "all"
    creep: str
    outputs: list[OutputEnvelope]
    truncated: int  # scenarios whose linear response was cut (growth beyond 1e250)
    highest_excited_hz: float | None  # over the linear chunks [Hz]

    def as_dict(self) -> dict:
        return {"scenarios": self.scenarios,
                "fault_instants": {"treatment": self.fault_instants,
                                   "description": FAULT_DESCRIPTIONS[self.fault_instants]},
                "creep": self.creep, "truncated_scenarios": self.truncated,
                "highest_excited_hz": self.highest_excited_hz,
                "outputs": [{"name": o.name, "unit": o.unit, "max": o.max, "min": o.min,
                             "max_at": o.max_at, "min_at": o.min_at} for o in self.outputs]}


def _scenario(study: EnvelopeStudy, index: tuple[int, ...], phase: float, time: float) -> dict:
    """The scenario at grid ``index`` (over the study's scenario dimensions) as the JSON
    ``…_at`` dict (a value of the set the study varies under its name: ``motor_bandwidth``)."""
    i = dict(zip(study.scenario_dims, index, strict=True))
    at = {"s0": study.s0[i["s0"]], "v_kmh": study.v[i["v"]] / KMH, "phase_s": float(phase),
          "rail": study.rail[i["rail"]], "n0": study.N0[i["N0"]], "bm": study.b_M[i["b_M"]],
          "m0": study.M0[i["M0"]], "f": study.f[i["f"]], "decay": study.D[i["D"]]}
    at.update({name: getattr(study, name)[i[name]] for name in SET_VALUE_DIMS if name in i})
    if study.creep != "linear":
        on = study.anti_slip[i["anti_slip"]] == "on"
        at["anti_slip"] = "on" if on else "off"
        at["anti_slip_delay_s"] = study.anti_slip_delay[i["anti_slip_delay"]] if on else None
    at["time_s"] = float(time)
    return at


def envelope(study: EnvelopeStudy, arrays: dict[str, np.ndarray]) -> Envelope:
    """The envelope of the per-scenario peaks ``arrays`` (name -> array over ("output",
    *study.scenario_dims), as :meth:`EnvelopeStudy.store_layout` lays them out)."""
    maxima, minima = arrays["max"], arrays["min"]
    if np.isnan(maxima).any() or np.isnan(minima).any():
        raise DesignLoadError("the study is not complete: some scenarios have no peaks")
    outputs = []
    for j, (name, unit) in enumerate(zip(study.outputs, study.units, strict=True)):
        i_max = np.unravel_index(int(np.argmax(maxima[j])), maxima.shape[1:])
        i_min = np.unravel_index(int(np.argmin(minima[j])), minima.shape[1:])
        outputs.append(OutputEnvelope(
            name, unit, float(maxima[j][i_max]), float(minima[j][i_min]),
            _scenario(study, i_max, arrays["phase_of_max"][j][i_max],
                      arrays["time_of_max"][j][i_max]),
            _scenario(study, i_min, arrays["phase_of_min"][j][i_min],
                      arrays["time_of_min"][j][i_min])))
    truncated = int(np.isfinite(arrays["truncated_at"]).sum())
    highest = arrays["highest_excited_hz"]
    highest = float(np.nanmax(highest)) if np.isfinite(highest).any() else None
    return Envelope(study.scenarios, study.fault, study.creep, outputs, truncated, highest)


def run_envelope(study: EnvelopeStudy, parameters: Parameters, map_unordered=None,
                 progress=None) -> Envelope:
    """Every scenario of ``study`` (``map_unordered``: the study engine's, default in this
    process) and its envelope, without a store.

    Example::

        >>> from model import EnvelopeStudy, KMH, build_model, load_parameters, run_envelope
        >>> from model.studies.envelope import resolve_outputs
        >>> from model import default_operating_point
        >>> parameters = load_parameters()
        >>> op = default_operating_point(parameters)
        >>> names = ["ID1.driving_shaft.torque"]
        >>> outputs, units = resolve_outputs(build_model(parameters), op, names, "linear")
        >>> study = EnvelopeStudy(s0=(0.005,), v=(120 * KMH,), N0=(op.N0,), b_M=(op.b_M,),
        ...                       outputs=outputs, units=units, fault="all", t_end=0.5)
        >>> envelope = run_envelope(study, parameters)
        >>> envelope.outputs[0].max > 2e4               # the worst fault instant [N m]
        True
    """
    from model.studies.engine import serial_map_unordered
    from model.studies.store import run_in_memory

    arrays = run_in_memory(study, parameters, map_unordered or serial_map_unordered, progress)
    return envelope(study, arrays)
