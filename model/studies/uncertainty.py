"""Uncertainty of the verdicts from the unpublished parameters: quasi-Monte-Carlo and Sobol indices.

Every parameter in :data:`UNCERTAIN_PARAMETERS` is an estimate (nothing about it was published);
each gets a documented **prior range** (a :class:`~model.studies.parameter_ranges.ParameterRange`,
the reason next to it; for a parameter the calibration fits, within its calibration bounds),
sampled log-uniformly (uniform for the loss time) by a scrambled Sobol' sequence (``scipy.stats.qmc`` through
``scipy.stats.sobol_indices``, Saltelli 2010 estimators, bootstrap confidence intervals).  The
other parameters stay at the calibrated set's values.

Prior or posterior (``method``).  The calibration constrains some of these parameters (the disc
clutch and driving shaft stiffnesses by the 2.7 Hz and 298 Hz modes, the creep law by the
operating data and the creep maximum at 0.0082).  Sampling the prior ranges answers "how much
could the verdict move given what we did not know before fitting": it is wider than the spread
left after the fit.  The linearized posterior (:mod:`model.studies.posterior`: Gaussian in ln p with
covariance ``(Jᵀ W J + Σ_prior⁻¹)⁻¹`` from the Jacobian of the calibration's residuals) answers
"how much is still unknown given the published numbers"; its inputs are correlated, so it gives
distributions only (Sobol indices assume independent inputs).

Outputs per model run (:func:`output_names`; :data:`OUTPUT_NAMES` for the default speeds):
s0* at the study's speeds (default 120 and 200 km/h; more speeds give the s0*(v) band); the
imaginary part [Hz] and damping ratio of the ten Table-1 modes (matched by character at s0 = 0.005, 120 km/h,
:func:`model.studies.calibration_targets.match_table1_modes`, so that modes do not swap between samples); the peak
totals of ID1's and ID2's disc-clutch and driving-shaft torques after the short circuit (default
excitation, 0.5 s at 5 kHz: the oscillating part has died out after 0.2 s).

The stability limit uses that ``s0* ≤ s_max(v)`` always (ID1's drivetrain spin diverges beyond the
creep maximum, see :mod:`model.analysis.sensitivity`): if the bogie is stable at ``s_max/2`` and at
``(1 − 10⁻³) s_max``, ``s0* = s_max``; otherwise Brent's method below ``s_max``
(:func:`model.analysis.stability.stability_limit`).

Execution: :func:`run_uncertainty` takes a ``map``-like executor (default: the builtin ``map``,
serial) and evaluates chunks of samples (:func:`evaluate_chunk`, a module-level function of plain
data, so that a process pool or a Dask client's ``map`` can run it).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy import stats

from model.analysis.sensitivity import MODE_COUNT
from model.mechanics.parameters import ParameterError, Parameters
from model.studies.parameter_ranges import ParameterRange

V_SPEEDS_KMH = (120.0, 200.0)
S0_MODES = 0.005  # creepage of the mode table and the short circuit [-]
V_MODES_KMH = 120.0
PEAK_OUTPUTS = ("ID1.disc_clutch.torque", "ID2.disc_clutch.torque",
                "ID1.driving_shaft.torque", "ID2.driving_shaft.torque")
RESPONSE_T_END, RESPONSE_FS = 0.5, 5_000.0  # [s], [Hz]
OUTPUT_NAMES = ("s0_limit_120", "s0_limit_200",
                *(f"mode{k}_im_hz" for k in range(1, MODE_COUNT + 1)),
                *(f"mode{k}_damping_ratio" for k in range(1, MODE_COUNT + 1)),
                *(f"peak.{name}" for name in PEAK_OUTPUTS))
OUTPUT_UNITS = ("1", "1", *("Hz",) * MODE_COUNT, *("1",) * MODE_COUNT, *("N m",) * len(PEAK_OUTPUTS))
METHODS = ("prior", "posterior")
RESULT_FORMAT = "bogie-uncertainty-2"  # results that carry their parameter set and conditions


def output_names(speeds_kmh: Sequence[float] = V_SPEEDS_KMH) -> tuple[str, ...]:
    """Output names with the stability limit at each speed (``s0_limit_120`` for 120 km/h)."""
    return (*(f"s0_limit_{v:g}" for v in speeds_kmh), *OUTPUT_NAMES[2:])


def output_units(speeds_kmh: Sequence[float] = V_SPEEDS_KMH) -> tuple[str, ...]:
    return (*("1",) * len(speeds_kmh), *OUTPUT_UNITS[2:])


class UncertaintyError(ValueError):
    """Bad input for an uncertainty study (one-line message)."""


UNCERTAIN_PARAMETERS: tuple[ParameterRange, ...] = (
    # the creep shape within ÷ 1.2 … × 1.2 (Polach's A ÷ 1.1 … × 1.1) of the fit: over this box
    # the creep maximum at 120 km/h — the stability limit, which stage A fits to the published
    # 0.0082 — stays within 0.0058 … 0.013 (a wider box puts it below the operating creepage
    # 0.005 in a third of the samples, where no verdict exists); a grid of 7 values each of
    # slope, A and B, geometric, has a creep maximum below s = 1 everywhere at 40–250 km/h
    ParameterRange("creep_slope", 800.0, 1155.0, "the calibrated creep shape (kA 0.38, kS "
                   "0.27) needs ~960 (docs/validation.md); Hertz+Kalker would give ~130; "
                   "÷ 1.2 … × 1.2 around the fit"),
    ParameterRange("polach_A", 0.73, 0.88, "Polach's presets 0.4; calibrated 0.80: ÷ 1.1 … × 1.1"),
    ParameterRange("polach_B", 0.76, 1.09, "Polach's presets 0.2–0.6 s/m; calibrated 0.91: "
                   "÷ 1.2 … × 1.2"),
    ParameterRange("motor_slope", 1000.0, 12000.0, "torque falls 12.8 kN m over 0.5–6 % of "
                   "213 rad/s (converter control unknown); calibrated 1 210"),
    ParameterRange("rubber_loss_time", 1e-4, 4e-4, "rubber loss factor 0.05–0.2 at ~80 Hz",
                   log=False),
    ParameterRange("disc_clutch_torsional_stiffness", 3.5e4, 1e5, "rubber disc clutch; "
                   "calibrated 4.0e4 from the 2.7 Hz mode"),
    ParameterRange("driving_shaft_stiffness", 6e6, 1.2e7, "quill shaft; calibrated 7.5e6 "
                   "from the 298 Hz mode"),
    ParameterRange("rotor_inertia", 6.0, 18.0, "550 kg rotor, radius of gyration 0.10–0.18 m; "
                   "calibrated 7.5"),
    ParameterRange("silent_block_stiffness_x", 7.5e6, 2.4e7, "rubber-metal block, "
                   "calibrated 1.5e7 (÷ 2 … the calibration's bound 2.4e7)"),
    ParameterRange("primary_stiffness_x", 1.7e6, 6.0e6, "longitudinal guide, calibrated "
                   "3.0e6 (the calibration's bound 1.7e6 … × 2)"),
    ParameterRange("yaw_damping", 2.4e5, 9.6e5, "yaw damper, calibrated 4.8e5: ÷ 2 … × 2"),
    ParameterRange("yaw_damper_series_stiffness", 1.2e7, 3e7, "the yaw dampers' end bushes, "
                   "calibrated 2.43e7: ÷ 2 … the calibration's bound 3e7"),
    ParameterRange("gear_mesh_stiffness", 7.5e8, 3e9, "~7–30 N/(µm mm) × 100 mm face width"),
)


def sample_outputs(values: Mapping[str, float],
                   speeds_kmh: Sequence[float] = V_SPEEDS_KMH) -> np.ndarray:
    """All :func:`output_names` (s0* at ``speeds_kmh`` [km/h], the modes, the peaks) for one full
    parameter set (name -> value, SI) (NaN where a quantity could not be computed, e.g. no
    stability limit in the searched range)."""
    from model.analysis.eigen import eigen_analysis
    from model.analysis.response import short_circuit_response
    from model.analysis.stability import NoStabilityLimit, max_real_part, stability_limit
    from model.mechanics.assembly import build_model
    from model.mechanics.operating_point import KMH, OperatingPoint, creep_law
    from model.studies.calibration_targets import match_table1_modes

    parameters = Parameters(dict(values))
    model = build_model(parameters)
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    out = np.full(len(speeds_kmh) + len(OUTPUT_NAMES) - 2, np.nan)
    for k, v_kmh in enumerate(speeds_kmh):
        v = v_kmh * KMH
        try:
            s_max, _ = creep_law(parameters, N0).maximum(v)
        except ValueError:  # no creep maximum below s = 1: the full search
            s_max = None
        if s_max is not None and all(max_real_part(model, OperatingPoint(s, v, N0, b_M)) <= 0.0
                                     for s in (0.5 * s_max, (1 - 1e-3) * s_max)):
            out[k] = s_max
        else:
            try:
                out[k] = stability_limit(model, v, N0, b_M,
                                         s0_high=0.5 if s_max is None else s_max).s0_limit
            except NoStabilityLimit:
                pass  # NaN: stable (or unstable) over the whole searched range
    op = OperatingPoint(S0_MODES, V_MODES_KMH * KMH, N0, b_M)
    result = eigen_analysis(model, op)
    matched, _ = match_table1_modes(model, result)
    lam = result.eigenvalues[matched]
    first = len(speeds_kmh)
    out[first:first + MODE_COUNT] = lam.imag / (2 * np.pi)
    out[first + MODE_COUNT:first + 2 * MODE_COUNT] = -lam.real / np.abs(lam)
    response = short_circuit_response(model, op, t_end=RESPONSE_T_END, fs=RESPONSE_FS,
                                      outputs=list(PEAK_OUTPUTS))
    out[first + 2 * MODE_COUNT:] = [response.peaks[name] for name in PEAK_OUTPUTS]
    return out


def evaluate_chunk(samples: np.ndarray, base: Mapping[str, float], names: Sequence[str],
                   speeds_kmh: Sequence[float] = V_SPEEDS_KMH) -> np.ndarray:
    """Outputs (len(samples) x len(output_names(speeds_kmh))) for rows of sample values of
    ``names`` on top of the base set ``base`` (plain data in and out: picklable for any
    executor)."""
    from threadpoolctl import threadpool_limits

    rows = []
    with threadpool_limits(1):
        for sample in np.atleast_2d(samples):
            values = dict(base)
            values.update(zip(names, map(float, sample), strict=True))
            rows.append(sample_outputs(values, speeds_kmh))
    return np.array(rows).reshape(len(np.atleast_2d(samples)), len(OUTPUT_NAMES) - 2 + len(speeds_kmh))


@dataclass(frozen=True)
class UncertaintyResult:
    """Distributions and Sobol indices (plain data).  With indices: the samples are the prior QMC
    samples A and B (2n runs); the indices use all n (d + 2) runs.  Without (``indices`` False:
    a posterior, or a prior sampled for its distributions only): n QMC samples, n runs, the
    index arrays NaN.  What the result belongs to: the parameter set's hash
    (:func:`model.mechanics.parameters.parameter_hash`), the wheel force N0 [N], the motor slope b_M
    [N m s/rad] (its nominal value: it is sampled when ``motor_slope`` is among ``names``), the
    rail condition (the set's own creep law: ``calibrated``) and the speeds of s0* [km/h]."""

    names: tuple[str, ...]  # uncertain parameters
    ranges: tuple[tuple[float, float], ...]  # their prior ranges [schema unit]
    outputs: tuple[str, ...]  # OUTPUT_NAMES
    units: tuple[str, ...]
    base_samples: int  # n (power of 2)
    runs: int  # n (d + 2) model runs
    samples: np.ndarray  # 2n x d parameter values
    values: np.ndarray  # 2n x len(outputs)
    first_order: np.ndarray  # len(outputs) x d
    total_order: np.ndarray  # len(outputs) x d
    first_order_ci: np.ndarray  # 2 x len(outputs) x d (low, high), 95 % bootstrap
    total_order_ci: np.ndarray  # 2 x len(outputs) x d
    seed: int
    nominal: np.ndarray  # outputs of the base set
    method: str = "prior"  # "prior" (documented ranges) or "posterior" (linearized, model.studies.posterior)
    indices: bool = True  # Sobol indices computed
    speeds_kmh: tuple[float, ...] = V_SPEEDS_KMH  # speeds of the s0* outputs [km/h]
    parameters_hash: str = ""
    wheel_force: float = math.nan  # N0 [N]
    motor_slope: float = math.nan  # nominal b_M [N m s/rad]
    rail: str = "calibrated"
    clipped: int = 0  # posterior coordinates clipped to the documented ranges
    posterior: dict | None = None  # LinearizedPosterior.as_dict()

    def percentiles(self, q=(5, 50, 95)) -> np.ndarray:
        """len(q) x len(outputs) percentiles of the sample distribution (NaN ignored)."""
        return np.nanpercentile(self.values, q, axis=0)

    def as_dict(self) -> dict:
        def clean(a):
            return [None if not math.isfinite(float(x)) else float(x) for x in np.ravel(a)]

        p5, p50, p95 = self.percentiles()
        if self.method == "posterior":
            sampling = ("linearized posterior (model/studies/posterior.py): scrambled Sobol' QMC, normal "
                        "ppf, Cholesky factor, clipped to the documented ranges; no Sobol indices "
                        "(correlated inputs)")
        elif self.indices:
            sampling = ("prior ranges (log-uniform), scrambled Sobol' QMC, Saltelli 2010 "
                        "(scipy.stats.sobol_indices), 95 % bootstrap confidence intervals")
        else:
            sampling = "prior ranges (log-uniform), scrambled Sobol' QMC, distributions only"
        return {
            "format": RESULT_FORMAT, "method": self.method, "sampling": sampling,
            "indices": self.indices, "parameters_hash": self.parameters_hash,
            "conditions": {"wheel_force_N": clean([self.wheel_force])[0],
                           "motor_slope_Nms_per_rad": clean([self.motor_slope])[0],
                           "motor_slope_sampled": "motor_slope" in self.names,
                           "rail": self.rail},
            "speeds_kmh": [float(v) for v in self.speeds_kmh],
            "clipped_coordinates": self.clipped, "posterior": self.posterior,
            "base_samples": self.base_samples, "runs": self.runs, "seed": self.seed,
            "parameters": [{"name": n, "low": lo, "high": hi}
                           for n, (lo, hi) in zip(self.names, self.ranges, strict=True)],
            "outputs": [{"name": name, "unit": unit, "nominal": clean([self.nominal[j]])[0],
                         "p5": clean([p5[j]])[0], "p50": clean([p50[j]])[0],
                         "p95": clean([p95[j]])[0],
                         "first_order": clean(self.first_order[j]),
                         "total_order": clean(self.total_order[j]),
                         "first_order_ci": [clean(self.first_order_ci[0, j]),
                                            clean(self.first_order_ci[1, j])],
                         "total_order_ci": [clean(self.total_order_ci[0, j]),
                                            clean(self.total_order_ci[1, j])]}
                        for j, (name, unit) in enumerate(zip(self.outputs, self.units, strict=True))],
            "samples": [clean(row) for row in self.samples],  # 2n x d (A and B)
            "values": [clean(row) for row in self.values],  # 2n x outputs
        }

    def summary(self) -> str:
        p5, p50, p95 = self.percentiles()
        lines = [f"uncertainty: {len(self.names)} parameters ({self.method}), n = "
                 f"{self.base_samples}, {self.runs} model runs"
                 + (f", {self.clipped} coordinates clipped to the ranges" if self.clipped else ""),
                 "", f"{'output':<34} {'nominal':>11} {'p5':>11} {'p50':>11} {'p95':>11}"
                 + ("  leading S_T" if self.indices else "")]
        for j, name in enumerate(self.outputs):
            if not self.indices:
                lines.append(f"{name:<34} {self.nominal[j]:>11.5g} {p5[j]:>11.5g} "
                             f"{p50[j]:>11.5g} {p95[j]:>11.5g}")
                continue
            lead = int(np.nanargmax(self.total_order[j])) if np.any(np.isfinite(self.total_order[j])) else 0
            width = self.total_order_ci[1, j, lead] - self.total_order_ci[0, j, lead]
            lines.append(f"{name:<34} {self.nominal[j]:>11.5g} {p5[j]:>11.5g} {p50[j]:>11.5g} "
                         f"{p95[j]:>11.5g}  {self.names[lead]} {self.total_order[j, lead]:.2f} "
                         f"(CI width {width:.2f})")
        return "\n".join(lines)


def _chunks(X: np.ndarray, size: int) -> list[np.ndarray]:
    return [X[i:i + size] for i in range(0, len(X), size)]


def sobol_study(evaluate: Callable[[np.ndarray], np.ndarray], distributions: Sequence, n: int,
                seed: int = 12, map_fn: Callable = map, chunk_size: int = 4,
                progress: Callable[[int, int], None] | None = None, n_resamples: int = 999):
    """First and total Sobol indices of a vector function by ``scipy.stats.sobol_indices``
    (scrambled Sobol' samples of ``distributions``, Saltelli 2010), with 95 % bootstrap intervals.

    ``evaluate(chunk)``: outputs (rows x s) for a chunk of samples (rows x d); run through
    ``map_fn`` over chunks of ``chunk_size`` rows.  Returns (runs, samples 2n x d of A and B,
    their outputs 2n x s, first s x d, total s x d, first_ci 2 x s x d, total_ci 2 x s x d)."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 2 or n & (n - 1):
        raise UncertaintyError(f"n = {n!r} is not allowed: must be a power of 2 >= 2")
    runs = n * (len(distributions) + 2)
    done = 0
    recorded: list[tuple[np.ndarray, np.ndarray]] = []

    def func(x: np.ndarray) -> np.ndarray:
        nonlocal done
        X = np.asarray(x).T  # samples x d
        parts = []
        for part in map_fn(evaluate, _chunks(X, chunk_size)):
            parts.append(np.atleast_2d(np.asarray(part)))
            done += len(parts[-1])
            if progress is not None:
                progress(done, runs)
        Y = np.vstack(parts)
        recorded.append((X.copy(), Y))
        return Y.T.copy()  # scipy centres the outputs in place: keep the recorded ones

    sobol = stats.sobol_indices(func=func, n=n, dists=list(distributions),
                                rng=np.random.default_rng(seed))
    with warnings.catch_warnings():  # degenerate bootstrap distributions (small n, an output
        # that does not vary): their intervals come out NaN, which the result shows as such
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", stats.DegenerateDataWarning)
        boot = sobol.bootstrap(confidence_level=0.95, n_resamples=n_resamples)
    samples = np.vstack([recorded[0][0], recorded[1][0]])
    values = np.vstack([recorded[0][1], recorded[1][1]])
    first = np.atleast_2d(sobol.first_order)
    total = np.atleast_2d(sobol.total_order)
    first_ci = np.array([np.atleast_2d(boot.first_order.confidence_interval.low),
                         np.atleast_2d(boot.first_order.confidence_interval.high)])
    total_ci = np.array([np.atleast_2d(boot.total_order.confidence_interval.low),
                         np.atleast_2d(boot.total_order.confidence_interval.high)])
    return runs, samples, values, first, total, first_ci, total_ci


def qmc_study(evaluate: Callable[[np.ndarray], np.ndarray], transform: Callable, d: int, n: int,
              seed: int = 12, map_fn: Callable = map, chunk_size: int = 4,
              progress: Callable[[int, int], None] | None = None):
    """Distributions only: n scrambled Sobol' points in (0, 1)^d, ``transform(u)`` -> (samples
    n x d, clipped count), evaluated through ``map_fn`` in chunks.  Returns (samples, outputs
    n x s, clipped)."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 2 or n & (n - 1):
        raise UncertaintyError(f"n = {n!r} is not allowed: must be a power of 2 >= 2")
    u = stats.qmc.Sobol(d, scramble=True, rng=np.random.default_rng(seed)).random(n)
    samples, clipped = transform(u)
    parts, done = [], 0
    for part in map_fn(evaluate, _chunks(samples, chunk_size)):
        parts.append(np.atleast_2d(np.asarray(part)))
        done += len(parts[-1])
        if progress is not None:
            progress(done, n)
    return samples, np.vstack(parts), clipped


def run_uncertainty(parameters: Parameters, n: int, uncertain: Iterable[ParameterRange] = UNCERTAIN_PARAMETERS,
                    seed: int = 12, map_fn: Callable = map, chunk_size: int = 4,
                    progress: Callable[[int, int], None] | None = None,
                    n_resamples: int = 999, method: str = "prior", indices: bool | None = None,
                    speeds_kmh: Sequence[float] = V_SPEEDS_KMH, rail: str = "calibrated",
                    posterior=None) -> UncertaintyResult:
    """Distributions (and, for the prior, Sobol indices) of :func:`output_names`.

    ``n``: base sample count (power of 2, ≥ 2).  ``method``: ``"prior"`` samples the documented
    ranges (independent; with ``indices`` (default) Saltelli's design, ``n (d + 2)`` runs; with
    ``indices=False`` n runs, distributions only); ``"posterior"`` samples the linearized
    posterior (:mod:`model.studies.posterior`, computed here unless given; n runs, no indices: the
    inputs are correlated).  ``speeds_kmh``: the speeds of s0* [km/h] (the s0*(v) band).
    ``rail``: the creep law ``parameters`` carry (recorded with the result, not applied here).
    ``map_fn(func, chunks)`` evaluates :func:`evaluate_chunk` over chunks of ``chunk_size``
    samples (builtin ``map``: serial; a Dask client's or a process pool's ``map`` runs them in
    parallel — results are collected in order).  ``progress(done, total)`` after every chunk."""
    from model.mechanics.parameters import parameter_hash

    uncertain = tuple(uncertain)
    if method not in METHODS:
        raise UncertaintyError(f"method '{method}' is not allowed: use one of {', '.join(METHODS)}")
    if indices is None:
        indices = method == "prior"
    if indices and method == "posterior":
        raise UncertaintyError("Sobol indices need independent inputs: not for the posterior")
    if not uncertain:
        raise UncertaintyError("no uncertain parameters given")
    if chunk_size < 1:
        raise UncertaintyError(f"chunk_size = {chunk_size} is not allowed: must be >= 1")
    speeds_kmh = tuple(float(v) for v in speeds_kmh)
    if not speeds_kmh or any(not (math.isfinite(v) and 1.0 <= v <= 500.0) for v in speeds_kmh):
        raise UncertaintyError(f"speeds {speeds_kmh} are not allowed: at least one, each in "
                               "[1, 500] km/h")
    if len(set(speeds_kmh)) != len(speeds_kmh):
        raise UncertaintyError("speeds must be distinct")
    for item in uncertain:
        if item.name not in parameters.values:
            raise UncertaintyError(f"unknown parameter '{item.name}'")
        if not 0 < item.low < item.high:
            raise UncertaintyError(f"range of '{item.name}' must satisfy 0 < low < high")
        try:
            parameters.replace(**{item.name: item.low}).replace(**{item.name: item.high})
        except ParameterError as error:
            raise UncertaintyError(f"range of '{item.name}': {error}") from None
    names = tuple(item.name for item in uncertain)
    base = dict(parameters.values)
    evaluate = partial(evaluate_chunk, base=base, names=names, speeds_kmh=speeds_kmh)
    outputs = output_names(speeds_kmh)
    blank = np.full((len(outputs), len(names)), np.nan)
    clipped, posterior_data = 0, None
    if indices:
        study = sobol_study(evaluate, [item.distribution() for item in uncertain], n, seed=seed,
                            map_fn=map_fn, chunk_size=chunk_size, progress=progress,
                            n_resamples=n_resamples)
        runs, samples, values, first, total, first_ci, total_ci = study
    else:
        if method == "posterior":
            from model.studies.posterior import PosteriorError, linearized_posterior

            if posterior is None:
                try:
                    posterior = linearized_posterior(parameters, uncertain)
                except (PosteriorError, ValueError) as error:
                    raise UncertaintyError(f"linearized posterior: {error}") from None
            if posterior.names != names:
                raise UncertaintyError("the posterior belongs to other parameters")
            transform = posterior.transform
            posterior_data = posterior.as_dict()
        else:
            distributions = [item.distribution() for item in uncertain]

            def transform(u):
                return np.column_stack([dist.ppf(u[:, j]) for j, dist in
                                        enumerate(distributions)]), 0
        samples, values, clipped = qmc_study(evaluate, transform, len(names), n, seed=seed,
                                             map_fn=map_fn, chunk_size=chunk_size,
                                             progress=progress)
        runs, first, total = n, blank, blank
        first_ci = total_ci = np.array([blank, blank])
    nominal = evaluate_chunk(np.array([[base[name] for name in names]]), base, names, speeds_kmh)[0]
    return UncertaintyResult(names, tuple((item.low, item.high) for item in uncertain), outputs,
                             output_units(speeds_kmh), n, runs, samples, values, first, total,
                             first_ci, total_ci, seed, nominal, method=method, indices=indices,
                             speeds_kmh=speeds_kmh, parameters_hash=parameter_hash(parameters),
                             wheel_force=float(parameters["wheel_force"]),
                             motor_slope=float(parameters["motor_slope"]), rail=rail,
                             clipped=clipped, posterior=posterior_data)


def creep_maximum_chunk(samples: np.ndarray, base: Mapping[str, float], names: Sequence[str],
                        speeds_kmh: Sequence[float] = V_SPEEDS_KMH) -> np.ndarray:
    """The creep maximum s_max(v) [-] at each speed for rows of sample values (NaN: no maximum)."""
    from model.mechanics.operating_point import KMH, creep_law

    rows = []
    for sample in np.atleast_2d(samples):
        values = dict(base)
        values.update(zip(names, map(float, sample), strict=True))
        law = creep_law(Parameters(values))
        row = []
        for v in speeds_kmh:
            try:
                row.append(law.maximum(v * KMH)[0])
            except ValueError:
                row.append(np.nan)
        rows.append(row)
    return np.array(rows)


def creep_maximum_study(parameters: Parameters, n: int,
                        uncertain: Iterable[ParameterRange] = UNCERTAIN_PARAMETERS,
                        seed: int = 12, n_resamples: int = 999):
    """Sobol indices of the creep maximum s_max(v) at :data:`V_SPEEDS_KMH` over the same prior
    (the creep law only: milliseconds per sample).  Where the full study finds s0* = s_max for
    every sample (the ID1 spin sets the limit), these are the indices of s0* at a sample count
    the full model cannot afford.  Returns :func:`sobol_study`'s tuple."""
    uncertain = tuple(uncertain)
    names = tuple(item.name for item in uncertain)
    return sobol_study(partial(creep_maximum_chunk, base=dict(parameters.values), names=names),
                       [item.distribution() for item in uncertain], n, seed=seed,
                       chunk_size=256, n_resamples=n_resamples)
