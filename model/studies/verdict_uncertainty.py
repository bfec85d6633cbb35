"""The verdict under uncertainty: how far the safety factors of the assessment move over the prior
ranges of the unpublished dynamics parameters and of the strength data, how likely a check falls
below its required factor, and which unknowns decide it.

    result = run_verdict_uncertainty(parameters, 16, seed=12)             # distributions only
    result = run_verdict_uncertainty(parameters, 16, indices=True)         # + Sobol indices
    result.governing.quantiles, result.governing.failure.value            # p5, p50, p95; P(fail)
    result.band("ID2 gear seat", "press_fit_slip", "short_circuit")       # one check's band
    save_parameters(sample_parameters(parameters, result, 3), "s3.toml")  # re-run sample 3

**What is sampled.**  The dynamics' priors (:data:`model.studies.uncertainty.UNCERTAIN_PARAMETERS`)
and the strength data's and ripple amplitudes' (:data:`model.studies.verdict_priors.
STRENGTH_PARAMETERS`), or the ranges given (:func:`model.studies.verdict_priors.load_ranges`,
:func:`~model.studies.verdict_priors.merge_ranges`), independent, each uniform or log-uniform over
its range, by scrambled Sobol' points (:mod:`model.studies.verdict_statistics`); every other
value is the set's.  Ranges the options make meaningless are left out and listed
(:func:`~model.studies.verdict_priors.relevant_ranges`).  Per sample the whole assessment of
:func:`model.studies.assessment.assess` with the given options (all four load cases by default):
every check's safety factor, and the governing check (least margin) with its factor.

**How it is computed.**  The load cases depend on the dynamics parameters only, and the ripple
case's loads scale linearly with the converters' amplitudes.  The rows of the design (the samples;
with indices Saltelli's matrices) are grouped by their dynamics values; one work item per group
(:func:`assess_rows`, on the study engine's ``map_unordered``) builds the model once
(:func:`model.studies.maps.cached_model`), computes the short-circuit, unstable-adhesion and
starting cases and the ripple case's responses at 1 N m per order (:func:`dynamics_cases`), and
then, for each of its rows, scales the ripple responses to the row's amplitudes and checks the
row's strength data against these loads (:func:`model.studies.assessment.assessment_of`).  A row
that changes only strength data or ripple amplitudes costs milliseconds.  The results equal
``assess`` on the row's parameter set (the scaling is exact: the responses are computed as
amplitude times |H|).  A dynamics sample that a load case refuses (a grid point unstable under its
creep law, a ripple point unstable) has no verdict: its rows are NaN, listed with the reason, and
left out of the statistics (quantiles and P(fail) over the samples with a verdict; the indices
over the rows of A, B and every AB defined).

**Reading it.**  P(fail) is the fraction of the prior's samples whose factor falls below the
required one: a probability over what is not known of this design, not a failure rate in service.
Its sampling uncertainty and the quantiles' intervals: :mod:`model.studies.verdict_statistics`.
Indices: of the governing check's safety factor (the check of least margin in each sample; where
checks of different required factors take turns, it jumps) and of every check's; per unknown and
per group (``"dynamics"``: better measurements of the bogie; ``"strength data"``: better data of
the parts and converters).  ``n (d + 2)`` assessments for d unknowns (Saltelli) and 2n for the
two groups' matrices, of which ``n (2 + d_dynamics)`` need dynamics runs.

**Stopping.**  ``progress(done, total, elapsed [s])`` before the first and after every finished
work item (a dynamics run), ``checkpoint()`` before the first and as every item finishes:
whatever either raises ends the study and reaches the caller; the engine cancels the items not
yet finished (in this process the next item does not start), nothing is kept.  Units: SI.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path

import numpy as np

from model.mechanics.operating_point import KMH
from model.mechanics.parameters import ALL_SCHEMA, Parameters, parameter_hash
from model.studies.assessment import (
    Assessment,
    AssessmentOptions,
    LoadCase,
    assessed_outputs,
    assessment_of,
    ripple_case_sweep,
    ripple_load_case,
    ripple_of,
    short_circuit_case,
    starting_case,
    unstable_adhesion_case,
)
from model.studies.parameter_ranges import ParameterRange
from model.studies.ripple_case import RippleSweep
from model.studies.verdict_priors import (
    GROUPS,
    VerdictUncertaintyError,
    check_ranges,
    default_ranges,
    group_of,
    relevant_ranges,
)
from model.studies.verdict_result import (
    GOVERNING,
    PERCENTS,
    FactorBand,
    SampleVerdict,
    VerdictUncertainty,
)
from model.studies.verdict_statistics import (
    BOOTSTRAP_RESAMPLES,
    check_sample_count,
    probability_below,
    quantile_interval,
    quantiles,
    saltelli_design,
    sobol_indices,
    sobol_samples,
)

CheckName = tuple[str, str, str]  # (component, kind, load case) of a check


@dataclass(frozen=True)
class RowVerdicts:
    """Every check's safety factor for rows of a design (plain data: what a work item returns)."""

    factors: np.ndarray  # rows x checks [-] (NaN: no verdict)
    governing: np.ndarray  # (rows,) index of the governing check (-1: no verdict)
    checks: tuple[CheckName, ...]  # () when no row has a verdict
    required: tuple[float, ...]  # per check [-]
    errors: tuple[str, ...]  # per row: why it has no verdict ("" where it has one)
    runs: int = 1  # dynamics runs behind these rows


def _reason(error: Exception) -> str:
    """One line: the error's class and the first line of its message."""
    lines = str(error).splitlines()
    return f"{type(error).__name__}: {lines[0]}" if lines else type(error).__name__


def _no_verdicts(rows: int, error: Exception) -> RowVerdicts:
    return RowVerdicts(np.full((rows, 0), np.nan), np.full(rows, -1), (), (),
                       (_reason(error),) * rows)


def verdict_rows(verdicts: Sequence[Assessment | Exception]) -> RowVerdicts:
    """The plain data of assessments (an exception: that row has no verdict)."""
    done = [v for v in verdicts if isinstance(v, Assessment)]
    checks = tuple((c.component, c.kind, c.load_case) for c in done[0].checks) if done else ()
    required = tuple(c.required for c in done[0].checks) if done else ()
    factors = np.full((len(verdicts), len(checks)), np.nan)
    governing = np.full(len(verdicts), -1)
    errors = []
    for r, verdict in enumerate(verdicts):
        if not isinstance(verdict, Assessment):
            errors.append(_reason(verdict))
            continue
        if tuple((c.component, c.kind, c.load_case) for c in verdict.checks) != checks:
            raise RuntimeError("the assessments of one work item have different checks")
        factors[r] = [c.safety_factor for c in verdict.checks]
        governing[r] = next(i for i, c in enumerate(verdict.checks) if c is verdict.governing)
        errors.append("")
    return RowVerdicts(factors, governing, checks, required, tuple(errors))


def dynamics_cases(parameters: Parameters, options: AssessmentOptions
                   ) -> tuple[dict[str, LoadCase], RippleSweep | None]:
    """What the set's dynamics give the assessment: the short-circuit, unstable-adhesion and
    starting cases of ``options.cases`` as :func:`~model.studies.assessment.assess` computes them
    (in this process), and for the ripple case its sweep at 1 N m per order of the options' or the
    set's ripple (:func:`scaled_sweep` gives any amplitudes).  Raises what the cases raise."""
    outputs = assessed_outputs(parameters)
    builders = {"short_circuit": short_circuit_case, "unstable_adhesion": unstable_adhesion_case,
                "starting": starting_case}
    cases = {name: builders[name](parameters, outputs, options)
             for name in options.cases if name in builders}
    if "ripple" not in options.cases:
        return cases, None
    unit = dict.fromkeys(ripple_of(parameters, options), 1.0)
    return cases, ripple_case_sweep(parameters, outputs, options, unit)


def scaled_sweep(unit: RippleSweep, ripple: dict) -> RippleSweep:
    """The sweep of unit amplitudes (1 N m per order) at the amplitudes ``ripple`` {order: [N m]}:
    the responses are amplitude times |H|, so this equals the sweep computed at them."""
    amplitudes = np.array([ripple[order] for order in unit.orders], dtype=float)
    return replace(unit, ripple=amplitudes,
                   by_motor=unit.by_motor * amplitudes[None, None, :, None, None])


def verdict_on_loads(parameters: Parameters, options: AssessmentOptions,
                     cases: dict[str, LoadCase], unit: RippleSweep | None) -> Assessment:
    """The assessment of ``parameters`` on loads its dynamics gave (:func:`dynamics_cases`): the
    ripple case scaled to the set's (or the options') amplitudes, every check of the set's data."""
    built = []
    for name in options.cases:
        if name == "ripple":
            built.append(ripple_load_case(scaled_sweep(unit, ripple_of(parameters, options)),
                                          parameters, options))
        else:
            built.append(cases[name])
    return assessment_of(parameters, built)


def assess_rows(rows: np.ndarray, base: dict[str, float], names: Sequence[str],
                dynamics: Sequence[str], options: AssessmentOptions) -> RowVerdicts:
    """The work item of the study: rows (m x len(names)) of values of ``names`` on top of the set
    ``base`` (name -> value), equal in their ``dynamics`` names; the load cases once, then every
    row's checks (module docstring).  Plain data in and out: picklable for any executor."""
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    column = {name: j for j, name in enumerate(names)}
    if any(np.any(rows[:, column[name]] != rows[0, column[name]]) for name in dynamics):
        raise ValueError("the rows of one work item must share their dynamics values")
    base_set = Parameters(dict(base))
    try:
        loads_set = base_set.replace(**{name: float(rows[0, column[name]]) for name in dynamics})
        cases, unit = dynamics_cases(loads_set, options)
    except ValueError as error:  # a case refuses these dynamics: no verdict for the rows
        return _no_verdicts(len(rows), error)
    verdicts: list[Assessment | Exception] = []
    for row in rows:
        try:
            row_set = base_set.replace(**dict(zip(names, map(float, row), strict=True)))
            verdicts.append(verdict_on_loads(row_set, options, cases, unit))
        except ValueError as error:
            verdicts.append(error)
    return verdict_rows(verdicts)


def evaluate_rows(work: Callable[[np.ndarray], RowVerdicts], rows: np.ndarray,
                  dynamics_columns: Sequence[int], map_unordered=None,
                  progress: Callable[[int, int, float], None] | None = None,
                  checkpoint: Callable[[], None] | None = None) -> RowVerdicts:
    """``work`` over the rows grouped by their values in ``dynamics_columns`` (one item per
    distinct dynamics, its rows in their order) on ``map_unordered`` (default: in this process);
    ``progress(done, total, elapsed [s])`` and ``checkpoint()`` before the first and after every
    finished item (either may raise to stop).  The rows' verdicts in the order of ``rows``."""
    from model.studies.engine import serial_map_unordered

    rows = np.asarray(rows, dtype=float)
    members: dict[tuple[float, ...], list[int]] = {}
    for r, row in enumerate(rows):
        members.setdefault(tuple(row[list(dynamics_columns)]), []).append(r)
    groups = list(members.values())
    start = time.monotonic()
    if checkpoint is not None:
        checkpoint()
    if progress is not None:
        progress(0, len(groups), 0.0)
    parts: dict[int, RowVerdicts] = {}
    for done, (index, part) in enumerate((map_unordered or serial_map_unordered)(
            work, [rows[g] for g in groups]), start=1):
        if checkpoint is not None:
            checkpoint()
        parts[index] = part
        if progress is not None:
            progress(done, len(groups), time.monotonic() - start)
    defined = [p for p in parts.values() if p.checks]
    checks = defined[0].checks if defined else ()
    required = defined[0].required if defined else ()
    if any(p.checks != checks for p in defined):
        raise RuntimeError("work items gave different checks")
    factors = np.full((len(rows), len(checks)), np.nan)
    governing = np.full(len(rows), -1)
    errors = [""] * len(rows)
    for index, g in enumerate(groups):
        part = parts[index]
        if part.checks:
            factors[g] = part.factors
        governing[g] = part.governing
        for r, error in zip(g, part.errors, strict=True):
            errors[r] = error
    return RowVerdicts(factors, governing, checks, required, tuple(errors), runs=len(groups))


def options_as_dict(options: AssessmentOptions) -> dict:
    """The assessment's options as plain data (SI; speeds in km/h), recorded with the result."""
    e = options.excitation
    anti_slip = options.anti_slip
    return {"cases": list(options.cases), "s0": list(options.s0),
            "v_kmh": [v / KMH for v in options.v], "N0": options.N0, "b_M": options.b_M,
            "M0": e.M0, "f": e.f, "D": e.D, "t_end": options.t_end, "fs": options.fs,
            "unstable_s0": options.unstable_s0, "unstable_v_kmh": options.unstable_v / KMH,
            "unstable_t_end": options.unstable_t_end,
            "anti_slip": None if anti_slip is None else {
                "enabled": anti_slip.enabled, "delay": anti_slip.delay,
                "threshold": anti_slip.threshold, "rate": anti_slip.rate,
                "floor": anti_slip.floor},
            "starting_v_kmh": options.starting_v / KMH,
            "ripple": None if options.ripple is None else {
                order.name: float(a) for order, a in options.ripple.items()},
            "ripple_v_kmh": [v / KMH for v in options.ripple_v],
            "ripple_drive": None if options.ripple_drive is None else {
                "pole_pairs": options.ripple_drive.pole_pairs,
                "pinion_teeth": options.ripple_drive.pinion_teeth}}


def set_hash(parameters: Parameters) -> str:
    """SHA-256 (hex) of every value of the set, strength data too (names in schema order, each
    value's ``repr``): which set a result of the verdict belongs to."""
    canonical = json.dumps([[name, repr(float(parameters.values[name]))] for name in ALL_SCHEMA],
                           separators=(",", ":"))
    return hashlib.sha256(canonical.encode("utf-8")).hexdigest()


def _band(values: np.ndarray, required: float, nominal: float, key: CheckName,
          compare_to_one: np.ndarray | None = None) -> FactorBand:
    """Quantiles, their intervals and P(fail) of one factor over the listed samples (for the
    governing check ``compare_to_one``: each sample's factor over its own required factor)."""
    failure = (probability_below(values, required) if compare_to_one is None
               else probability_below(compare_to_one, 1.0))
    return FactorBand(*key, required, nominal, tuple(float(q) for q in quantiles(values, PERCENTS)),
                      tuple(quantile_interval(values, p) for p in PERCENTS), failure)


def _with_indices(band: FactorBand, design, f_A, f_B, f_AB, f_AG, resamples: int, seed: int
                  ) -> FactorBand:
    """The band with the Sobol indices of its factor (per unknown, per group in GROUPS order)."""
    per_unknown = sobol_indices(f_A, f_B, f_AB, resamples, seed)
    per_group = sobol_indices(f_A, f_B, f_AG, resamples, seed)
    position = {name: k for k, (name, _) in enumerate(design.groups)}

    def by_group(values):
        return tuple(float(values[position[g]]) if g in position else math.nan for g in GROUPS)

    def pairs(interval):
        return tuple((float(lo), float(hi)) for lo, hi in zip(*interval, strict=True))

    extra = {}
    if resamples:
        extra = {"first_order_interval": pairs(per_unknown.first_interval),
                 "total_order_interval": pairs(per_unknown.total_interval),
                 "group_first_order_interval": tuple(zip(by_group(per_group.first_interval[0]),
                                                         by_group(per_group.first_interval[1]),
                                                         strict=True)),
                 "group_total_order_interval": tuple(zip(by_group(per_group.total_interval[0]),
                                                         by_group(per_group.total_interval[1]),
                                                         strict=True))}
    return replace(band, first_order=tuple(map(float, per_unknown.first)),
                   total_order=tuple(map(float, per_unknown.total)),
                   group_first_order=by_group(per_group.first),
                   group_total_order=by_group(per_group.total), **extra)


def sample_verdicts(work: Callable[[np.ndarray], RowVerdicts], unknowns: Sequence[ParameterRange],
                    n: int, seed: int = 12, indices: bool = False,
                    groups: Sequence[str] | None = None, nominal_row: np.ndarray | None = None,
                    map_unordered=None, progress: Callable[[int, int, float], None] | None = None,
                    checkpoint: Callable[[], None] | None = None,
                    resamples: int = BOOTSTRAP_RESAMPLES, fixed: Sequence[tuple[str, str]] = (),
                    parameters_hash: str = "", set_hash: str = "", options: dict | None = None
                    ) -> VerdictUncertainty:
    """The study on any ``work`` (:func:`assess_rows` for the bogie, a stand-in in the tests):
    scrambled Sobol' samples of ``unknowns`` (with ``indices`` Saltelli's design), the rows
    grouped by their dynamics values (``groups``: per unknown, default :func:`~model.studies.
    verdict_priors.group_of`) and evaluated by :func:`evaluate_rows`, ``nominal_row`` (the set's
    own values, optional) with them; then the bands (module docstring).  ``fixed``,
    ``parameters_hash``, ``set_hash``, ``options``: recorded with the result."""
    unknowns = tuple(unknowns)
    try:
        check_sample_count(n)
    except ValueError as error:
        raise VerdictUncertaintyError(str(error)) from None
    groups = tuple(group_of(u.name) for u in unknowns) if groups is None else tuple(groups)
    distributions = [u.distribution() for u in unknowns]
    dynamics_columns = [j for j, g in enumerate(groups) if g == GROUPS[0]]
    design = None
    if indices:
        design = saltelli_design(distributions, n, seed, [
            (g, [j for j, h in enumerate(groups) if h == g]) for g in GROUPS])
        rows = design.rows
        listed = np.arange(2 * n)
    else:
        rows = sobol_samples(distributions, n, seed)
        listed = np.arange(n)
    design_rows = len(rows)
    if nominal_row is not None:
        rows = np.vstack([rows, np.asarray(nominal_row, dtype=float)[None, :]])
    verdicts = evaluate_rows(work, rows, dynamics_columns, map_unordered, progress, checkpoint)
    if not verdicts.checks:
        raise VerdictUncertaintyError(f"no sample has a verdict: {verdicts.errors[0]}")
    checks, required = verdicts.checks, np.array(verdicts.required)
    has_verdict = verdicts.governing >= 0
    pick = np.where(has_verdict, verdicts.governing, 0)
    governing_factor = np.where(has_verdict, verdicts.factors[np.arange(len(rows)), pick], np.nan)
    reserve = governing_factor / required[pick]
    nominal = (verdicts.factors[-1] if nominal_row is not None
               else np.full(len(checks), np.nan))
    nominal_check = int(verdicts.governing[-1]) if nominal_row is not None else -1
    governing_nominal = nominal[nominal_check] if nominal_check >= 0 else math.nan
    bands = [_band(verdicts.factors[listed, c], float(required[c]), float(nominal[c]), key)
             for c, key in enumerate(checks)]
    governing_band = _band(governing_factor[listed], math.nan, float(governing_nominal),
                           (GOVERNING, "", ""), compare_to_one=reserve[listed])
    if design is not None:
        outputs = np.column_stack([governing_factor[:design_rows],
                                   verdicts.factors[:design_rows]])
        f_A, f_B, f_AB, f_AG = design.split(outputs)
        governing_band = _with_indices(governing_band, design, f_A[0], f_B[0], f_AB[:, 0],
                                       f_AG[:, 0], resamples, seed)
        bands = [_with_indices(band, design, f_A[c + 1], f_B[c + 1], f_AB[:, c + 1],
                               f_AG[:, c + 1], 0, seed) for c, band in enumerate(bands)]
    counts = np.bincount(verdicts.governing[listed][has_verdict[listed]], minlength=len(checks))
    samples = tuple(SampleVerdict(tuple(map(float, rows[r])), int(verdicts.governing[r]),
                                  float(governing_factor[r]), verdicts.errors[r]) for r in listed)
    return VerdictUncertainty(
        unknowns, groups, tuple(fixed), n, seed, indices, verdicts.runs, len(rows), tuple(bands),
        governing_band, tuple(int(c) for c in counts), samples, nominal_check, parameters_hash,
        set_hash, dict(options or {}))


def run_verdict_uncertainty(parameters: Parameters, n: int, seed: int = 12, indices: bool = False,
                            options: AssessmentOptions | None = None,
                            ranges: Iterable[ParameterRange] | None = None, map_unordered=None,
                            progress: Callable[[int, int, float], None] | None = None,
                            checkpoint: Callable[[], None] | None = None, nominal: bool = True,
                            resamples: int = BOOTSTRAP_RESAMPLES) -> VerdictUncertainty:
    """The verdict under uncertainty of ``parameters`` (module docstring).

    ``n``: samples (a power of 2 ≥ 2); with ``indices`` the base count of Saltelli's design
    (2n listed samples, n (d + 4) assessments).  ``options``: the assessment's (default
    :class:`~model.studies.assessment.AssessmentOptions`).  ``ranges``: every prior to sample
    (default :func:`~model.studies.verdict_priors.default_ranges`; a file's through
    :func:`~model.studies.verdict_priors.merge_ranges`), checked by
    :func:`~model.studies.verdict_priors.check_ranges` (:class:`~model.studies.verdict_priors.
    PriorRangeError`, one line naming the datum).  ``map_unordered``: the study engine's (default:
    in this process); ``progress``, ``checkpoint``: see the module docstring.  ``nominal``: also
    assess the set itself (one more dynamics run; each band's ``nominal``).  ``resamples``: of
    the bootstrap intervals of the governing check's indices."""
    options = AssessmentOptions() if options is None else options
    kept, fixed = relevant_ranges(default_ranges() if ranges is None else ranges, options)
    if not kept:
        raise VerdictUncertaintyError("no unknowns to sample under these options")
    check_ranges(parameters, kept)
    names = tuple(item.name for item in kept)
    dynamics = tuple(name for name in names if group_of(name) == GROUPS[0])
    work = partial(assess_rows, base=dict(parameters.values), names=names, dynamics=dynamics,
                   options=options)
    nominal_row = np.array([parameters[name] for name in names]) if nominal else None
    return sample_verdicts(work, kept, n, seed, indices, nominal_row=nominal_row,
                           map_unordered=map_unordered, progress=progress, checkpoint=checkpoint,
                           resamples=resamples, fixed=tuple(fixed.items()),
                           parameters_hash=parameter_hash(parameters),
                           set_hash=set_hash(parameters), options=options_as_dict(options))


def planned_size(n: int, indices: bool, groups: Sequence[str], nominal: bool = True
                 ) -> tuple[int, int]:
    """(dynamics runs, assessments) of a study of ``n`` samples over unknowns of ``groups`` (one
    entry per unknown, as :func:`run_verdict_uncertainty` keeps them) before it runs: what a
    queue's limits compare.  Rows share a dynamics run when their dynamics values are equal: all
    of them without a dynamics unknown, A's rows with the strength data's AB, B's with AB of
    the only dynamics unknown or of the dynamics group."""
    d = len(groups)
    d_dynamics = sum(1 for g in groups if g == GROUPS[0])
    if indices:
        evaluations = n * (d + 2 + len({g for g in groups}))
        runs = 1 if d_dynamics == 0 else 2 * n if d_dynamics == 1 else n * (2 + d_dynamics)
    else:
        evaluations, runs = n, (1 if d_dynamics == 0 else n)
    extra = 1 if nominal else 0
    return runs + (extra if d_dynamics else 0), evaluations + extra


def sample_parameters(parameters: Parameters, result: VerdictUncertainty, index: int) -> Parameters:
    """The complete parameter set of listed sample ``index`` of ``result`` (computed on
    ``parameters``, else :class:`VerdictUncertaintyError`): the set with the sample's values, each
    noted with its sample and prior.  ``assess`` on it with the result's options gives the
    sample's verdict."""
    if set_hash(parameters) != result.set_hash:
        raise VerdictUncertaintyError("the result belongs to another parameter set")
    if not 0 <= index < len(result.samples):
        raise VerdictUncertaintyError(f"sample {index} is not listed: the result lists "
                                      f"{len(result.samples)} samples (0 … "
                                      f"{len(result.samples) - 1})")
    sample = result.samples[index]
    values = dict(zip(result.names, sample.values, strict=True))
    notes = dict(parameters.notes)
    for item in result.unknowns:
        unit = ALL_SCHEMA[item.name][0]
        notes[item.name] = (f"sample {index} of the verdict under uncertainty (n = {result.n}, "
                            f"seed {result.seed}): drawn from {item.low:g} … {item.high:g} {unit} "
                            f"({'log-uniform' if item.log else 'uniform'}; {item.reason}); the "
                            f"set's value {parameters[item.name]:g} {unit}")
    sampled = parameters.replace(**values)
    return Parameters(sampled.values, notes, f"{parameters.source} (sample {index})")


def save_sample_parameters(parameters: Parameters, result: VerdictUncertainty,
                           directory: str | Path) -> list[Path]:
    """Write every listed sample's complete set (:func:`sample_parameters`) as
    ``sample_0000.toml`` … into ``directory`` (made if missing), each headed by its sample, seed
    and governing check; the paths written."""
    from model.mechanics.parameters import save_parameters

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    width = max(4, len(str(len(result.samples) - 1)))
    paths = []
    for index, sample in enumerate(result.samples):
        if sample.check >= 0:
            band = result.checks[sample.check]
            verdict = (f"governing check: {band.component}, {band.kind}, {band.load_case}, "
                       f"safety factor {sample.safety_factor!r} (required {band.required:g})")
        else:
            verdict = f"no verdict: {sample.error}"
        header = (f"sample {index} of the verdict under uncertainty: n = {result.n}, seed "
                  f"{result.seed}, {len(result.unknowns)} unknowns sampled\n{verdict}\n"
                  "re-run: bogie assess --params <this file>, with the study's options")
        path = directory / f"sample_{index:0{width}d}.toml"
        save_parameters(sample_parameters(parameters, result, index), path, header)
        paths.append(path)
    return paths
