"""What the dashboard computes, as plain data, kept in the one results cache.

Every function here takes a case record (:class:`app.results.case.Case`: the parameter set, the
operating point, the short circuit, the horizon) and the result's own arguments, and returns
read-only plain data from :data:`app.results.cache.RESULTS`, keyed by the kind of result, the
parameter set's full hash and the part of the record the result depends on
(:meth:`app.results.case.CaseBase.point`, ``limit_key``, ``sweep``): results are shared between
sessions and never mutated.  The physics is in :mod:`model`; this module only calls it and
reshapes the results for plotting.  Units: SI, except where a name says otherwise (a record's
units: ``v`` [km/h], ``N0`` [kN], ``M0`` [kN m], ``dt`` [ms]; ``im_hz`` [Hz]).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from app.results.cache import RESULTS
from app.results.case import Case, CaseBase, Sweep
from app.results.locus_geometry import locus_jumps, refine_grid
from app.results.mode_drawing import point_displacements
from app.results.variants import full_hash, parameters_of_key
from model import (
    NoStabilityLimit,
    adhesion_moment,
    build_model,
    creep_law,
    eigen_analysis,
    mode_character,
)
from model.analysis.load_peaks import LoadPeaks
from model.analysis.nonlinear import AntiSlip
from model.studies.envelope import RAILS, rail_parameters
from model.studies.maps import set_model_source

N_COMPLEX_TABLE = 10  # complex pairs in the eigenvalue / mode tables (Table 1 and 2 layout)
N_REAL_TABLE = 10  # real eigenvalues in the eigenvalue table
LOCUS_MAX_HZ = 20.0  # branches tracked up to this frequency [Hz]
# the locus's eigenvalues to 1e-6 relative, or 1e-6 1/s absolute below |λ| = 1 1/s (a pixel of
# the plot is ≈ 0.1 1/s): a drivetrain spin passing through λ = 0 is then not solved densely at
# every point near its zero (model.analysis.locus)
LOCUS_LAMBDA_FLOOR = 1.0  # [1/s]
LOCUS_POINTS = 25  # points of the coarse root-locus sweep (shown first, brackets s0*)
LOCUS_DENSE_POINTS = 200  # points of the dense sweep that replaces it
LOCUS_S0 = (0.001, 0.02)  # s0 range of the creepage sweep [-]
LIMIT_XTOL = 1e-6  # s0*(v) to 1e-6 (shown with 5 decimals)
LOCUS_V_KMH = (40.0, 200.0)  # speed range of the speed sweep [km/h]
GROWTH_CUT = 4.0  # plotted histories end when a torque exceeds this multiple of M_ad
PLOT_BUCKETS = 1000  # min/max decimation of each time history for the browser (CSV keeps all)
RESPONSE_FS = 10_000.0  # sampling of the time histories [Hz]: 33 samples per period of the
# 298 Hz driving-shaft mode, so a sampled peak is within 1 − cos(π/33) = 0.5 % of the true one

TORQUES = ("driving_shaft.torque", "disc_clutch.torque")
FORCES = ("disc_clutch.force_x", "disc_clutch.force_y", "disc_clutch.force_z")
RESPONSE_OUTPUTS = tuple(f"{d}.{q}" for d in ("ID1", "ID2") for q in TORQUES + FORCES)  # plotted
# the drive parts a design review signs off (docs/design-loads.md): torques [N m], the gear
# mesh force [N]
PARTS = ("driving_shaft.torque", "disc_clutch.torque", "claw_clutch.torque", "gear_mesh.force")
PART_LABELS = {"driving_shaft.torque": "driving shaft torque", "disc_clutch.torque":
               "disc clutch torque", "claw_clutch.torque": "claw clutch torque",
               "gear_mesh.force": "gear mesh force"}
DRIVE_PARTS = tuple(f"{d}.{q}" for d in ("ID1", "ID2") for q in PARTS)
# every history the dashboard computes (peak table, CSV, spectra): the plotted outputs and the
# drive parts
HISTORY_OUTPUTS = RESPONSE_OUTPUTS + tuple(n for n in DRIVE_PARTS if n not in RESPONSE_OUTPUTS)
LINEAR_HISTORY = "linear creep"  # the name of the linear closed form's history
# the anti-slip key (enabled, delay [s], threshold [m/s], rate [1/s]) of the protection off, its
# parameters the defaults (model.analysis.nonlinear.AntiSlip)
ANTI_SLIP_OFF = (False, AntiSlip().delay, AntiSlip().threshold, AntiSlip().rate)
PATH_POINTS = 1500  # points of each wheel's creepage path (nonlinear creep) sent to the browser
RAINFLOW_BINS = 24  # bins of the rainflow matrix along the range and the mean


class ModelRejected(ValueError):
    """A parameter combination the model rejects (message shown to the user)."""


# --- the parameter set and its model ------------------------------------------------------------

def _parameter_set(set_key: str, rail: str, overrides: tuple) -> tuple:
    """(parameters, full hash) of a set key with the rail's creep law and the case's overrides
    (kept: a file is read and validated once)."""
    def make():
        if rail not in RAILS:
            raise ModelRejected(f"unknown rail condition '{rail}'; allowed: {', '.join(RAILS)}")
        p = rail_parameters(parameters_of_key(set_key), rail)
        changes = {name: value for name, value, tolerance in overrides
                   if abs(value - p[name]) > tolerance}  # else the set's own value
        if changes:
            p = p.replace(**changes)
        return p, full_hash(p)
    return RESULTS.get(("parameters", set_key, rail, overrides), make)


def parameters(set_key: str, rail: str = "calibrated", overrides: tuple = ()):
    """The parameter set in use: the set key's (``""``: the calibrated default; a design
    variant ``"FILE|name:value,…"``, :mod:`app.results.variants`) with the rail's creep law
    (``"calibrated"`` keeps the set's, ``"dry"``/``"wet"``: Polach's presets) and ``overrides``
    ((name, SI value, SI tolerance), …: a case's override quantities,
    :meth:`app.results.case.CaseBase.overrides`; a value within its tolerance of the set's own
    is the set's)."""
    return _parameter_set(set_key, rail, tuple(overrides))[0]


def parameters_for(case: CaseBase):
    """The parameter set of a case (its set key, rail and override quantities)."""
    return parameters(case.set_key, case.rail, case.overrides())


def set_hash_for(case: CaseBase) -> str:
    """The full hash (:func:`app.results.variants.full_hash`) of a case's parameter set."""
    return _parameter_set(case.set_key, case.rail, case.overrides())[1]


def model_of(parameters):
    """The assembled model of a parameter set: one object per set (its full hash), shared
    read-only between sessions, kept with the decompositions of its last operating points."""
    return RESULTS.get(("model", full_hash(parameters)), lambda: build_model(parameters),
                       growing=True)


# the checks and studies this process runs (model.studies.assessment, a study run here) take
# their models from the same cache: one model object per parameter set
set_model_source(model_of)


def model(set_key: str, rail: str = "calibrated", overrides: tuple = ()):
    """The assembled model of :func:`parameters`' set."""
    p, digest = _parameter_set(set_key, rail, tuple(overrides))
    return RESULTS.get(("model", digest), lambda: build_model(p), growing=True)


def model_for(case: CaseBase):
    """The assembled model of a case's parameter set."""
    return model(case.set_key, case.rail, case.overrides())


def cached(kind: str, case: CaseBase, compute, *extra):
    """``compute()`` kept in the results cache under (kind, the case's set hash, the case,
    extra): the key of every result the app computes."""
    return RESULTS.get((kind, set_hash_for(case), case, *extra), compute)


def _known(kind: str, case: CaseBase, *extra):
    """The kept result of :func:`cached`'s key, or None (nothing is computed)."""
    try:
        digest = set_hash_for(case)
    except ValueError:
        return None
    return RESULTS.peek((kind, digest, case, *extra))


# --- eigenvalues, modes, creep characteristic at the current point ---------------------------

@dataclass(frozen=True)
class Mode:
    """One complex mode (upper eigenvalue of a pair)."""

    number: int  # ν, by ascending frequency
    eigenvalue: complex  # [1/s]
    im_hz: float  # Im λ / 2π [Hz]
    damping_ratio: float  # −Re λ / |λ| [-]
    description: str  # generated from energy shares (model.analysis.modes)
    displacement: dict[str, np.ndarray]  # drawn point -> real translation (x, y, z), unit max
    kinetic: dict[str, float] = field(default_factory=dict)  # component -> kinetic-energy share
    strain: dict[str, float] = field(default_factory=dict)  # element group -> strain-energy share


@dataclass(frozen=True)
class PointResult:
    """Eigen-analysis of one operating point, reshaped for the views."""

    case: Case  # the point (the record's point(): the short circuit and the horizon left out)
    eigenvalues: np.ndarray  # all non-rigid eigenvalues [1/s]
    stable: bool
    max_real_part: float  # [1/s]
    flutter: int  # unstable complex pairs
    divergence: int  # positive real eigenvalues
    n_rigid: int  # identified rigid-body zero eigenvalues
    modes: list[Mode]  # first N_COMPLEX_TABLE complex pairs
    real: np.ndarray  # real eigenvalues, largest first (first N_REAL_TABLE) [1/s]
    creep_s: np.ndarray  # creepage grid [-]
    creep_mu: np.ndarray  # μ(s, v) on it [-]
    mu0: float  # μ(s0, v) [-]
    s_max: float  # creepage of the creep maximum [-]
    mu_max: float  # μ_max(v) [-]
    M_ad: float  # maximal adhesion moment 2 N0 r0 μ_max [N m]


def _mode(m, result, index: int, number: int) -> Mode:
    character = mode_character(m, result, index)
    lam = complex(result.eigenvalues[index])
    return Mode(number, lam, lam.imag / (2 * math.pi), character.damping_ratio,
                character.description, point_displacements(m, result.mode_shape(index)),
                dict(character.kinetic), dict(character.strain))


def point_result(case: CaseBase) -> PointResult:
    """Eigenvalues, stability, mode descriptions and creep characteristic at the case's point."""
    point = case.point()

    def compute() -> PointResult:
        m = model_for(point)
        op = point.operating_point()
        result = eigen_analysis(m, op, vectors="on_demand")  # the table's modes' vectors only
        modes = [_mode(m, result, int(i), number)
                 for number, i in enumerate(result.complex_index[:N_COMPLEX_TABLE], start=1)]
        law = creep_law(m.parameters, op.N0)
        s_max, mu_max = law.maximum(op.v)
        s_grid = np.linspace(0.0, max(0.03, 1.5 * op.s0), 301)
        return PointResult(
            case=point, eigenvalues=result.eigenvalues, stable=result.stable,
            max_real_part=result.max_real_part, flutter=result.flutter,
            divergence=result.divergence, n_rigid=result.n_rigid, modes=modes,
            real=result.real_eigenvalues[:N_REAL_TABLE], creep_s=s_grid,
            creep_mu=np.asarray(law.mu(s_grid, op.v)), mu0=float(law.mu(op.s0, op.v)),
            s_max=s_max, mu_max=mu_max, M_ad=adhesion_moment(m.parameters, op.v, op.N0))
    return cached("point", point, compute)


def known_point(case: CaseBase) -> PointResult | None:
    """:func:`point_result` of the case if it has been computed (and is kept), else None
    (nothing is computed)."""
    return _known("point", case.point())


def mode_near(case: CaseBase, re: float, im: float) -> Mode:
    """The mode whose eigenvalue is nearest to re + i·im [1/s] at the case's point (a tapped
    root-locus point): shape, description and energy shares; ``number`` is its rank among the
    complex pairs by frequency (0 for a real eigenvalue)."""
    point = case.point()

    def compute() -> Mode:
        m = model_for(point)
        result = eigen_analysis(m, point.operating_point(), vectors="on_demand")
        index = int(np.argmin(np.abs(result.eigenvalues - complex(re, im))))
        ranks = {int(i): k for k, i in enumerate(result.complex_index, start=1)}
        return _mode(m, result, index, ranks.get(index, 0))
    return cached("mode", point, compute, float(re), float(im))


# --- stability limit ---------------------------------------------------------------------------

@dataclass(frozen=True)
class LimitResult:
    s0_limit: float | None  # s0*(v) [-], None if there is none in the searched range
    message: str  # why there is none ("" otherwise)


def limit_result(case: CaseBase, before_each=None) -> LimitResult:
    """The stability limit s0*(v) at the case's speed, wheel force, motor slope and set
    (model.analysis.stability; ``before_each()`` before each of its eigen-analyses, which may
    stop the search by raising :class:`app.results.cache.Superseded`)."""
    key = case.limit_key()

    def compute() -> LimitResult:
        from model.analysis.stability import stability_limit

        m = model_for(key)
        # the root locus over s0 at this speed (usually kept: the dashboard shows it) brackets
        # the first crossing between two of its points: ≈ 8 eigen-analyses instead of ≈ 20
        locus = locus_result(Sweep("s0", key))
        turns = np.flatnonzero(~locus.stable[1:] & locus.stable[:-1])
        bracket = None
        if len(turns) and locus.stable[:turns[0] + 1].all():
            bracket = (float(locus.values[turns[0]]), float(locus.values[turns[0] + 1]))
        op = key.replace(s0=LOCUS_S0[0]).operating_point()
        try:
            limit = stability_limit(m, op.v, op.N0, op.b_M, s0_low=LOCUS_S0[0] / 2,
                                    xtol=LIMIT_XTOL, bracket=bracket,
                                    before_each=before_each)
            return LimitResult(limit.s0_limit, "")
        except NoStabilityLimit as error:
            return LimitResult(None, str(error))
    return cached("limit", key, compute)


def known_limit(case: CaseBase) -> LimitResult | None:
    """:func:`limit_result` of the case if it has been computed, else None (nothing is
    computed)."""
    return _known("limit", case.limit_key())


# --- root locus --------------------------------------------------------------------------------

@dataclass(frozen=True)
class LocusResult:
    parameter: str  # "s0" [-] or "v" (values in km/h here)
    values: np.ndarray  # (n_points,) in display units ([-] or [km/h])
    eigenvalues: np.ndarray  # (n_points, n_branches) upper branches [1/s]
    stable: np.ndarray  # (n_points,) bool
    dense: bool = False  # the dense sweep (else the coarse one shown first)
    # (n_points - 1, n_branches) bool: the step from point i to i + 1 is a jump (a branch that
    # meets another one, or moves faster than the grid resolves): the line is broken there
    jumps: np.ndarray | None = field(default=None, repr=False)


def _sweep_range(parameter: str) -> tuple[float, float]:
    if parameter == "s0":
        return LOCUS_S0
    if parameter == "v":
        return LOCUS_V_KMH
    raise ModelRejected(f"root locus parameter must be 's0' or 'v', got '{parameter}'")


def _sweep(sweep: Sweep, shown: np.ndarray, dense: bool) -> LocusResult:
    """Root locus over ``shown`` (the swept quantity's unit) through the sweep's point."""
    from model.analysis.locus import root_locus

    m = model_for(sweep.case)
    op = sweep.at(float(shown[0])).operating_point()
    q = sweep.case.quantity(sweep.parameter)
    locus = root_locus(m, op, sweep.parameter, shown * q.si, max_frequency_hz=LOCUS_MAX_HZ,
                       lambda_floor=LOCUS_LAMBDA_FLOOR)
    upper = np.flatnonzero(locus.eigenvalues[0].imag >= 0)
    lam = locus.eigenvalues[:, upper]
    return LocusResult(sweep.parameter, shown, lam, np.asarray(locus.stable), dense,
                       locus_jumps(shown, lam))


def locus_result(sweep: Sweep) -> LocusResult:
    """The coarse sweep (LOCUS_POINTS evenly spaced): tracked branches over s0 (at the point's
    speed) or over v (at its creepage).  Shown first; brackets s0*(v)."""
    def compute() -> LocusResult:
        shown = np.linspace(*_sweep_range(sweep.parameter), LOCUS_POINTS)
        return _sweep(sweep, shown, dense=False)
    return cached("locus", sweep.case, compute, sweep.parameter)


def dense_locus_result(sweep: Sweep) -> LocusResult:
    """The dense sweep (LOCUS_DENSE_POINTS), denser where the coarse sweep's branches move fast
    (:func:`refine_grid`); replaces the coarse one on screen."""
    def compute() -> LocusResult:
        coarse = locus_result(sweep)
        shown = refine_grid(coarse.values, coarse.eigenvalues, LOCUS_DENSE_POINTS)
        return _sweep(sweep, shown, dense=True)
    return cached("dense locus", sweep.case, compute, sweep.parameter)


def known_locus(sweep: Sweep) -> LocusResult | None:
    """The dense root locus of the sweep if it has been computed, else the coarse one, else
    None (nothing is computed)."""
    return (_known("dense locus", sweep.case, sweep.parameter)
            or _known("locus", sweep.case, sweep.parameter))


def reduced_estimate(sweep: Sweep, case: CaseBase):
    """The eigenvalues at the case's point from the reduced model of the root locus ``sweep``
    (:func:`model.analysis.locus.kept_sweep_estimate`: one small eigenproblem, no dense solve),
    or None if that sweep's start is not kept."""
    from model.analysis.locus import kept_sweep_estimate

    m = model_for(sweep.case)
    ends = [sweep.at(x).operating_point() for x in _sweep_range(sweep.parameter)]
    return kept_sweep_estimate(m, case.operating_point(), *ends, max_frequency_hz=LOCUS_MAX_HZ,
                               lambda_floor=LOCUS_LAMBDA_FLOOR)


# --- short-circuit response --------------------------------------------------------------------

@dataclass(frozen=True)
class ResponseView:
    """Time histories of both drives, full resolution (CSV, spectra) and decimated (plots); the
    linear closed form or the nonlinear creep model (``history`` says which)."""

    t: np.ndarray  # [s]
    outputs: dict[str, np.ndarray]  # HISTORY_OUTPUTS -> total value [N m or N]
    M_C: np.ndarray  # short-circuit torque [N m]
    peaks: dict[str, float]  # signed total of largest magnitude
    peak_times: dict[str, float]  # [s]
    units: dict[str, str]
    M_ad: float  # [N m]
    truncated_at: float | None  # [s]
    crossings: list[tuple[str, str, float, float]]  # (output, limit name, time [s], value)
    # the limits the totals are checked against: "M_ad" [N m], "M_ad/p" [N m], "mu_max N0" [N]
    limits: dict[str, float] = field(default_factory=dict)
    plot_cut: float | None = None  # plots end here [s]: a torque exceeded GROWTH_CUT x M_ad
    # per series (outputs and "M_C"): (t [s], value), min/max-decimated, float32 for the browser
    plot: dict[str, tuple[np.ndarray, np.ndarray]] = field(repr=False, default=None)
    history: str = LINEAR_HISTORY  # which history: "linear creep", "nonlinear creep, …"
    fault_instant: float = math.nan  # the fault's time shift Δt of this history [s]
    # what the peak table reads: max, min, swing and its split per output, or the growth
    # (model.analysis.load_peaks.LoadPeaks)
    load_peaks: LoadPeaks | None = field(repr=False, default=None)

    @property
    def nonlinear(self) -> bool:
        """Whether this is the history of the nonlinear creep model."""
        return self.history.startswith("nonlinear")


def decimate(t: np.ndarray, ys: list[np.ndarray], buckets: int = PLOT_BUCKETS):
    """Min/max decimation for plotting: keeps every extreme (peaks stay visible).  The samples
    are cut into ``buckets`` runs of equal length; each run keeps its first sample and, of every
    series, its largest and smallest."""
    n = len(t)
    if n <= 2 * buckets:
        return t, ys
    size = -(-n // buckets)
    runs = -(-n // size)
    starts = np.arange(runs) * size
    picks = [starts, [n - 1]]
    for y in ys:
        padded = np.concatenate([y, np.full(runs * size - n, y[-1])]).reshape(runs, size)
        picks.append(starts + padded.argmax(axis=1))
        picks.append(starts + padded.argmin(axis=1))
    kept = np.zeros(n, dtype=bool)  # the picks in time order, each once
    kept[np.minimum(np.concatenate(picks), n - 1)] = True
    index = np.flatnonzero(kept)
    return t[index], [y[index] for y in ys]


def _growth_stop(t: np.ndarray, outputs: dict[str, np.ndarray], M_ad: float) -> int:
    """Samples to plot: up to where a plotted torque first exceeds GROWTH_CUT x M_ad (unstable:
    exponential growth would flatten everything before it), else all."""
    torques = np.array([np.abs(outputs[n]) for n in RESPONSE_OUTPUTS if n.endswith("torque")])
    beyond = np.flatnonzero(torques.max(axis=0) > GROWTH_CUT * M_ad)
    return int(beyond[0]) + 1 if len(beyond) else len(t)


def history_view(r, history: str, cut_growth: bool, peaks,
                 plotted: tuple[str, ...] = HISTORY_OUTPUTS) -> ResponseView:
    """A linear (:class:`model.analysis.response.ResponseResult`) or nonlinear
    (:class:`model.analysis.nonlinear.NonlinearResult`) response of HISTORY_OUTPUTS as the
    dashboard and the report show it: the full histories, their peaks and limit crossings (one
    rule for both: :mod:`model.analysis.load_peaks`), what the peak table reads (``peaks``,
    :class:`model.analysis.load_peaks.LoadPeaks`), the decimated plot series of ``plotted``
    and M_C (``cut_growth``: they end where a torque grows beyond GROWTH_CUT x M_ad)."""
    outputs = {name: np.asarray(r.outputs[name]) for name in HISTORY_OUTPUTS}
    M_ad = float(r.limits["M_ad"])
    stop = _growth_stop(r.t, outputs, M_ad) if cut_growth else len(r.t)
    plot = {}
    for name, y in [*((n, outputs[n]) for n in plotted), ("M_C", r.M_C)]:
        td, (yd,) = decimate(r.t[:stop], [y[:stop]])
        plot[name] = (td.astype(np.float32), yd.astype(np.float32))
    return ResponseView(
        t=r.t, outputs=outputs, M_C=np.asarray(r.M_C),
        peaks={k: float(r.peaks[k]) for k in HISTORY_OUTPUTS},
        peak_times={k: float(r.peak_times[k]) for k in HISTORY_OUTPUTS},
        units={k: r.units[k] for k in HISTORY_OUTPUTS}, M_ad=M_ad,
        plot_cut=float(r.t[stop - 1]) if stop < len(r.t) else None,
        truncated_at=getattr(r, "truncated_at", None),
        crossings=[(c.output, c.limit_name, c.time, c.value) for c in r.limit_crossings
                   if c.output in outputs],
        limits={name: float(value) for name, value in r.limits.items()},
        plot=plot, history=history, fault_instant=float(r.excitation.shift(r.motor_torque)),
        load_peaks=peaks)


def sampling_rate(f: float) -> float:
    """The histories' sampling rate [Hz]: RESPONSE_FS, at least 20 samples per period of f."""
    return max(RESPONSE_FS, 20.0 * float(f))


def response_result(case: CaseBase) -> ResponseView:
    """Short-circuit response of both drives (model.analysis.response), linear creep."""
    def compute() -> ResponseView:
        from model.analysis.response import linear_load_peaks, short_circuit_response

        m = model_for(case)
        r = short_circuit_response(m, case.operating_point(), case.short_circuit(),
                                   t_end=float(case.t_end), fs=sampling_rate(case.f),
                                   outputs=list(HISTORY_OUTPUTS))
        # the Response tab's plots (the Design loads tab draws the drive parts of its own
        # result)
        return history_view(r, LINEAR_HISTORY, cut_growth=True, peaks=linear_load_peaks(m, r),
                            plotted=RESPONSE_OUTPUTS)
    return cached("response", case, compute)


# --- the nonlinear creep model ----------------------------------------------------------------------

def anti_slip_description(anti_slip: tuple | None) -> str:
    """The history's name for an anti-slip key ``(enabled, delay [s], threshold [m/s], rate
    [1/s])`` (None: linear creep)."""
    if anti_slip is None:
        return LINEAR_HISTORY
    enabled, delay, threshold, rate = anti_slip
    if not enabled:
        return "nonlinear creep, anti-slip off"
    return (f"nonlinear creep, anti-slip on ID2 (delay {delay:g} s, threshold {threshold:g} m/s, "
            f"ramp {rate:g} 1/s)")


@dataclass(frozen=True)
class NonlinearHistories:
    """The nonlinear response (full histories, peaks, crossings: ``response``) and what the
    dashboard draws besides: the creepage paths and a few numbers."""

    response: ResponseView  # the nonlinear history, as the peak table, CSV and spectra read it
    paths: dict[str, tuple[np.ndarray, np.ndarray]] = field(repr=False)  # rim -> (s, μ)
    detection_time: float | None  # [s]
    action_time: float | None  # [s]
    max_creepage: float  # largest creepage of any wheel [-]
    M_ad: float  # [N m]

    @property
    def plot(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """The decimated histories (t [s], value) for the plots."""
        return self.response.plot

    @property
    def peaks(self) -> dict[str, float]:
        """Signed total of largest magnitude of each output."""
        return self.response.peaks


def nonlinear_histories(case: CaseBase, anti_slip: tuple, runner=None,
                        checkpoint=None) -> NonlinearHistories:
    """The nonlinear response (model.analysis.nonlinear) of HISTORY_OUTPUTS; ``anti_slip``:
    (enabled, delay [s], threshold [m/s], rate [1/s]) of ID2's protection.  Kept in the results
    cache; ``runner(function, *args)`` computes it where the cache does not hold it (default: in
    this thread), ``checkpoint()`` is asked between the integration's blocks (what it raises
    stops the run)."""
    anti_slip = tuple(anti_slip)

    def compute() -> NonlinearHistories:
        if runner is None:
            return _nonlinear_histories(case, anti_slip, checkpoint)
        return runner(_nonlinear_histories, case, anti_slip, checkpoint)
    return cached("nonlinear", case, compute, anti_slip)


def _nonlinear_histories(case: CaseBase, anti_slip: tuple, checkpoint=None) -> NonlinearHistories:
    """:func:`nonlinear_histories` computed (a module-level function: a background worker's
    task when served)."""
    from model.analysis.load_peaks import load_peaks
    from model.analysis.nonlinear import nonlinear_response

    enabled, delay, threshold, rate = anti_slip
    protection = AntiSlip(True, delay, threshold, rate) if enabled else None
    r = nonlinear_response(model_for(case), case.operating_point(), case.short_circuit(),
                           float(case.t_end), sampling_rate(case.f), anti_slip=protection,
                           outputs=list(HISTORY_OUTPUTS), checkpoint=checkpoint)
    stride = max(1, len(r.t) // PATH_POINTS)
    paths = {rim: (s[::stride].astype(np.float32),
                   (r.utilisation[rim][::stride] * r.mu_max).astype(np.float32))
             for rim, s in r.creepage.items()}
    return NonlinearHistories(
        # every drive part plotted: the Design loads tab overlays the nonlinear history
        response=history_view(r, anti_slip_description(anti_slip), cut_growth=False,
                              peaks=load_peaks(r.t, r.outputs, r.steady, r.units,
                                               r.limit_crossings, "nonlinear",
                                               split_note="nonlinear creep: not split")),
        paths=paths, detection_time=r.detection_time, action_time=r.action_time,
        max_creepage=float(max(s.max() for s in r.creepage.values())),
        M_ad=float(r.limits["M_ad"]))


@dataclass(frozen=True)
class HistoryKey:
    """Which history: the case and the creep model (``anti_slip``: the nonlinear creep model
    with ID2's anti-slip key (enabled, delay [s], threshold [m/s], rate [1/s]); None: the linear
    closed form)."""

    case: Case
    anti_slip: tuple | None = None

    @property
    def result(self) -> ResponseView:
        """The history (:func:`history_result`)."""
        return history_result(self.case, self.anti_slip)


def history_result(case: CaseBase, anti_slip: tuple | None) -> ResponseView:
    """The history the dashboard describes (peak table, CSV, spectra, report): the linear one
    (``anti_slip`` None) or the nonlinear one with that anti-slip key (both kept)."""
    if anti_slip is None:
        return response_result(case)
    return nonlinear_histories(case, tuple(anti_slip)).response


# --- design loads: the worst fault instant and the load spectrum -----------------------------------

@dataclass(frozen=True)
class WorstCaseView:
    """The worst case over every fault instant Δt of the drive parts at one point (linear creep,
    closed form: :mod:`model.analysis.fault_instant`), beside the history at the dashboard's Δt.
    Dicts are keyed by the DRIVE_PARTS names; values in the output's unit (N m or N)."""

    case: Case  # what it was computed for
    units: dict[str, str]
    max: dict[str, float]  # largest total over every Δt and the time grid
    min: dict[str, float]  # smallest
    phase_of_max: dict[str, float]  # the Δt [s] that gives it, in (−T/2, T/2]
    phase_of_min: dict[str, float]  # [s]
    time_of_max: dict[str, float]  # [s] after the fault
    time_of_min: dict[str, float]  # [s]
    at_dt_max: dict[str, float]  # largest total of the history at the dashboard's Δt
    at_dt_min: dict[str, float]
    at_dt_time_of_max: dict[str, float]  # [s]
    at_dt_time_of_min: dict[str, float]  # [s]
    dt: float  # the dashboard's Δt [s] (the continuity root when automatic)
    dt_auto: bool  # Δt is the continuity root (else given)
    roots: tuple[float, float]  # both continuity roots [s]
    period: float  # T = 1/f [s]
    M_ad: float  # [N m]
    truncated_at: float | None  # [s]: the time grid was cut (growth beyond 1e250)
    plot_cut: float | None  # plots end here [s]: a torque exceeded GROWTH_CUT x M_ad
    # name -> (t [s], upper, lower, history at Δt) min/max-decimated on common points, float32
    plot: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = field(repr=False)


def worst_case_result(case: CaseBase) -> WorstCaseView:
    """Max and min over every fault instant of each drive part's total, at each time and over
    the time grid of :func:`response_result` (three closed-form evaluations), and the history at
    the dashboard's Δt for comparison."""
    def compute() -> WorstCaseView:
        from model.analysis.fault_instant import history_peaks, phase_families, worst_fault_instant

        m = model_for(case)
        op = case.operating_point()
        shock = case.short_circuit()
        family = phase_families(m, op, [(shock.f, shock.D)], float(case.t_end),
                                sampling_rate(case.f), list(DRIVE_PARTS))[0]
        worst = worst_fault_instant(family, shock.M0)
        dt = shock.shift(family.motor_torque)
        at_dt = family.totals(shock.M0, dt)
        peaks = history_peaks(family.t, at_dt, dt)
        M_ad = adhesion_moment(m.parameters, op.v, op.N0)
        names = family.names
        # plots end where a torque of the worst case grows beyond GROWTH_CUT x M_ad (unstable)
        torque = [j for j, name in enumerate(names) if family.units[name] == "N m"]
        reach = np.maximum(np.abs(worst.upper[:, torque]),
                           np.abs(worst.lower[:, torque])).max(axis=1)
        beyond = np.flatnonzero(reach > GROWTH_CUT * M_ad)
        stop = int(beyond[0]) + 1 if len(beyond) else len(family.t)
        plot = {}
        for j, name in enumerate(names):
            td, ys = decimate(family.t[:stop], [worst.upper[:stop, j], worst.lower[:stop, j],
                                                at_dt[:stop, j]])
            plot[name] = (td.astype(np.float32), *(y.astype(np.float32) for y in ys))

        def by_name(values):
            return {name: float(values[j]) for j, name in enumerate(names)}
        return WorstCaseView(
            case=case, units={name: family.units[name] for name in names},
            max=by_name(worst.peaks.max), min=by_name(worst.peaks.min),
            phase_of_max=by_name(worst.peaks.phase_of_max),
            phase_of_min=by_name(worst.peaks.phase_of_min),
            time_of_max=by_name(worst.peaks.time_of_max),
            time_of_min=by_name(worst.peaks.time_of_min),
            at_dt_max=by_name(peaks.max), at_dt_min=by_name(peaks.min),
            at_dt_time_of_max=by_name(peaks.time_of_max),
            at_dt_time_of_min=by_name(peaks.time_of_min),
            dt=float(dt), dt_auto=case.dt is None, roots=family.continuity_phases(shock.M0),
            period=1.0 / shock.f, M_ad=float(M_ad), truncated_at=family.truncated_at,
            plot_cut=float(family.t[stop - 1]) if stop < len(family.t) else None, plot=plot)
    return cached("worst case", case, compute)


@dataclass(frozen=True)
class SpectraView:
    """Load spectra of the drive parts' histories (one history: ``history``)."""

    history: str  # which history: "linear creep" or "nonlinear creep, …"
    fault_instant: float  # its Δt [s]
    spectra: dict[str, object]  # DRIVE_PARTS -> model.analysis.load_spectrum.LoadSpectrum
    matrices: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = field(repr=False)
    # name -> rainflow matrix (counts: range bins x mean bins [-], range edges, mean edges [unit])


def spectra_result(case: CaseBase, anti_slip: tuple | None) -> SpectraView:
    """Rainflow cycles, load collective, damage-equivalent ranges (m = 3 and 5, N_ref = 10⁷) and
    the rainflow matrix of each drive part's total in the history of :func:`history_result`."""
    anti_slip = None if anti_slip is None else tuple(anti_slip)

    def compute() -> SpectraView:
        from model.analysis.load_spectrum import load_spectrum, rainflow_matrix

        response = history_result(case, anti_slip)
        spectra = {name: load_spectrum(response.outputs[name], name, response.units[name])
                   for name in DRIVE_PARTS}
        matrices = {name: rainflow_matrix(s.cycles, RAINFLOW_BINS) for name, s in spectra.items()}
        return SpectraView(response.history, response.fault_instant, spectra, matrices)
    return cached("spectra", case, compute, anti_slip)
