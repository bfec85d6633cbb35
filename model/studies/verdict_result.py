"""What the verdict under uncertainty gives (:mod:`model.studies.verdict_uncertainty`): per check
and for the governing check the band of the safety factor, the probability of falling below the
required factor, the Sobol indices of the unknowns, and every listed sample with its governing
check; plain data, JSON through :meth:`VerdictUncertainty.as_dict` and back through
:meth:`VerdictUncertainty.from_dict` (a stored result the dashboard picks by name).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from model.analysis.assessment import KIND_NAMES
from model.studies.parameter_ranges import ParameterRange
from model.studies.verdict_priors import GROUPS, VerdictUncertaintyError
from model.studies.verdict_statistics import Probability, prefix_quantiles

RESULT_FORMAT = "bogie-verdict-uncertainty-1"
PERCENTS = (5.0, 50.0, 95.0)  # the quantiles of every band [%]
GOVERNING = "governing"  # the band's component name for the governing check of each sample


def _number(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def _float(value) -> float:
    return math.nan if value is None else float(value)


def _pairs(values) -> list[list[float | None]]:
    return [[_number(low), _number(high)] for low, high in values]


@dataclass(frozen=True)
class FactorBand:
    """One check's safety factor over the prior (or the governing check's: ``component`` is
    :data:`GOVERNING`, the check of least margin in each sample): its quantiles, the probability
    of falling below the required factor (for the governing check: of failing the verdict), and
    with indices the first-order and total Sobol indices of each unknown and of each group."""

    component: str
    kind: str  # model.analysis.assessment.KINDS ("" for the governing check)
    load_case: str  # ("" for the governing check)
    required: float  # required safety factor [-] (NaN for the governing: each sample's own)
    nominal: float  # the set's own safety factor [-] (NaN: not computed)
    quantiles: tuple[float, ...]  # at PERCENTS [-]
    quantile_intervals: tuple[tuple[float, float], ...]  # 95 % of each, NaN: unbounded [-]
    failure: Probability  # of a factor below the required one
    first_order: tuple[float, ...] = ()  # per unknown (empty without indices)
    total_order: tuple[float, ...] = ()
    first_order_interval: tuple[tuple[float, float], ...] = ()  # 95 % bootstrap (the governing)
    total_order_interval: tuple[tuple[float, float], ...] = ()
    group_first_order: tuple[float, ...] = ()  # per GROUPS entry (NaN: nothing of it sampled)
    group_total_order: tuple[float, ...] = ()
    group_first_order_interval: tuple[tuple[float, float], ...] = ()
    group_total_order_interval: tuple[tuple[float, float], ...] = ()

    @property
    def label(self) -> str:
        if self.component == GOVERNING:
            return "governing check"
        return f"{self.component}, {KIND_NAMES.get(self.kind, self.kind)}, {self.load_case}"

    def as_dict(self, names: tuple[str, ...]) -> dict:
        data = {"component": self.component, "kind": self.kind, "load_case": self.load_case,
                "required": _number(self.required), "nominal": _number(self.nominal),
                **{f"p{p:g}": _number(q) for p, q in zip(PERCENTS, self.quantiles, strict=True)},
                "quantile_intervals": {f"p{p:g}": [_number(lo), _number(hi)] for p, (lo, hi)
                                       in zip(PERCENTS, self.quantile_intervals, strict=True)},
                "p_fail": self.failure.as_dict(), "indices": None}
        if self.first_order:
            def named(values):
                return {name: _number(v) for name, v in zip(names, values, strict=True)}

            def grouped(values):
                return {group: _number(v) for group, v in zip(GROUPS, values, strict=True)}

            data["indices"] = {
                "first_order": named(self.first_order), "total_order": named(self.total_order),
                "first_order_interval": dict(zip(names, _pairs(self.first_order_interval),
                                                 strict=False)),
                "total_order_interval": dict(zip(names, _pairs(self.total_order_interval),
                                                 strict=False)),
                "groups": {group: {"first_order": _number(self.group_first_order[g]),
                                   "total_order": _number(self.group_total_order[g]),
                                   "first_order_interval": _pairs(
                                       self.group_first_order_interval)[g]
                                   if self.group_first_order_interval else None,
                                   "total_order_interval": _pairs(
                                       self.group_total_order_interval)[g]
                                   if self.group_total_order_interval else None}
                           for g, group in enumerate(GROUPS)}}
        return data

    @classmethod
    def from_dict(cls, data: Mapping, names: tuple[str, ...]) -> FactorBand:
        p = data["p_fail"]
        failure = Probability(_float(p["value"]), _float(p["standard_error"]),
                              tuple(_float(x) for x in p["interval"]), int(p["below"]),
                              int(p["samples"]))
        indices = data.get("indices") or {}

        def per_name(key):
            return tuple(_float(indices[key][name]) for name in names) if indices else ()

        def per_name_pairs(key):
            table = indices.get(key) or {}
            return tuple((_float(table[n][0]), _float(table[n][1])) for n in names if n in table)

        def per_group(key):
            return tuple(_float(indices["groups"][g][key]) for g in GROUPS) if indices else ()

        def per_group_pairs(key):
            if not indices or indices["groups"][GROUPS[0]][key] is None:
                return ()
            return tuple((_float(indices["groups"][g][key][0]), _float(indices["groups"][g][key][1]))
                         for g in GROUPS)

        return cls(str(data["component"]), str(data["kind"]), str(data["load_case"]),
                   _float(data["required"]), _float(data["nominal"]),
                   tuple(_float(data[f"p{p:g}"]) for p in PERCENTS),
                   tuple((_float(data["quantile_intervals"][f"p{p:g}"][0]),
                          _float(data["quantile_intervals"][f"p{p:g}"][1])) for p in PERCENTS),
                   failure, per_name("first_order"), per_name("total_order"),
                   per_name_pairs("first_order_interval"), per_name_pairs("total_order_interval"),
                   per_group("first_order"), per_group("total_order"),
                   per_group_pairs("first_order_interval"), per_group_pairs("total_order_interval"))


@dataclass(frozen=True)
class SampleVerdict:
    """One listed sample: the values of the unknowns it drew and its governing check."""

    values: tuple[float, ...]  # per unknown, in the order of the result's names [schema units]
    check: int  # index of the governing check in the result's checks (-1: no verdict)
    safety_factor: float  # the governing check's [-] (NaN: no verdict)
    error: str = ""  # why the sample has no verdict (one line)


@dataclass(frozen=True)
class VerdictUncertainty:
    """The verdict under uncertainty (plain data).  ``samples``: the listed samples — with
    indices the rows of Saltelli's A then B (2n), without the n points of the sequence; the
    other rows of the design (A with columns from B) enter the indices only.  ``runs``: the
    dynamics runs (models built, load cases computed), ``evaluations``: the assessments from
    them (one per row of the design, plus the set itself when ``nominal_check`` >= 0).  What the
    result belongs to: the dynamics' hash (:func:`model.mechanics.parameters.parameter_hash`),
    the whole set's hash (strength data too) and the assessment's options."""

    unknowns: tuple[ParameterRange, ...]  # the sampled priors
    groups: tuple[str, ...]  # per unknown: "dynamics" or "strength data"
    fixed: tuple[tuple[str, str], ...]  # (name, why) of default ranges the options leave out
    n: int  # base sample count (power of 2)
    seed: int
    indices: bool
    runs: int
    evaluations: int
    checks: tuple[FactorBand, ...]  # in the assessment's order
    governing: FactorBand
    governing_counts: tuple[int, ...]  # per check: the listed samples it governs
    samples: tuple[SampleVerdict, ...]
    nominal_check: int  # the set's own governing check (-1: not computed)
    parameters_hash: str
    set_hash: str
    options: dict  # the assessment's options (options_as_dict)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(item.name for item in self.unknowns)

    @property
    def undefined(self) -> int:
        """Listed samples without a verdict (a load case refused their dynamics)."""
        return sum(1 for s in self.samples if s.check < 0)

    def band(self, component: str, kind: str, load_case: str) -> FactorBand:
        """The band of one check (KeyError when the result has no such check)."""
        for band in self.checks:
            if (band.component, band.kind, band.load_case) == (component, kind, load_case):
                return band
        raise KeyError(f"no check {component!r}, {kind!r}, {load_case!r} in the result")

    def convergence(self, percent: float = 95.0) -> list[tuple[int, float]]:
        """(samples, the governing safety factor's ``percent`` quantile over them) for growing
        power-of-2 leading parts of the listed samples (of A and of B together with indices)."""
        factors = [s.safety_factor for s in self.samples]
        parts = [factors[:self.n], factors[self.n:]] if self.indices else [factors]
        return prefix_quantiles(parts, percent)

    def as_dict(self) -> dict:
        names = self.names
        sampling = ("prior ranges, scrambled Sobol' points (scipy.stats.qmc); "
                    + ("Saltelli's design A, B, AB_i, AB_group: first-order indices Saltelli "
                       "2010, total Jansen 1999, 95 % bootstrap intervals (governing check)"
                       if self.indices else "distributions only")
                    + "; P(fail): the fraction of the samples below the required factor with the "
                    "binomial standard error and the 95 % Clopper-Pearson interval (exact for "
                    "independent samples, a stand-in for the Sobol' points' own error); quantile "
                    "intervals: distribution-free, from order statistics")
        samples = []
        for index, sample in enumerate(self.samples):
            governing = None
            if sample.check >= 0:
                band = self.checks[sample.check]
                governing = {"component": band.component, "kind": band.kind,
                             "load_case": band.load_case,
                             "safety_factor": _number(sample.safety_factor),
                             "required": _number(band.required)}
            samples.append({"index": index,
                            "values": dict(zip(names, map(float, sample.values), strict=True)),
                            "governing": governing, "error": sample.error})
        return {
            "format": RESULT_FORMAT, "sampling": sampling, "n": self.n, "seed": self.seed,
            "indices": self.indices, "runs": self.runs, "evaluations": self.evaluations,
            "parameters_hash": self.parameters_hash, "set_hash": self.set_hash,
            "options": self.options, "groups": list(GROUPS),
            "unknowns": [{"name": r.name, "group": g, "low": r.low, "high": r.high, "log": r.log,
                          "reason": r.reason}
                         for r, g in zip(self.unknowns, self.groups, strict=True)],
            "fixed": [{"name": name, "why": why} for name, why in self.fixed],
            "nominal_check": self.nominal_check,
            "governing": {**self.governing.as_dict(names),
                          "counts": [{"component": b.component, "kind": b.kind,
                                      "load_case": b.load_case, "samples": count}
                                     for b, count in zip(self.checks, self.governing_counts,
                                                         strict=True) if count]},
            "checks": [band.as_dict(names) for band in self.checks],
            "samples": samples,
            "undefined": self.undefined,
        }

    @classmethod
    def from_dict(cls, data: Mapping) -> VerdictUncertainty:
        """The result of :meth:`as_dict` (a stored file's JSON); :class:`VerdictUncertaintyError`
        for another format."""
        if not isinstance(data, Mapping) or data.get("format") != RESULT_FORMAT:
            raise VerdictUncertaintyError(f"not a result of the verdict under uncertainty "
                                          f"(format {RESULT_FORMAT})")
        try:
            unknowns = tuple(ParameterRange(u["name"], float(u["low"]), float(u["high"]),
                                            str(u["reason"]), log=bool(u["log"]))
                             for u in data["unknowns"])
            names = tuple(u.name for u in unknowns)
            checks = tuple(FactorBand.from_dict(c, names) for c in data["checks"])
            keys = [(c.component, c.kind, c.load_case) for c in checks]
            counts = [0] * len(checks)
            for entry in data["governing"]["counts"]:
                counts[keys.index((entry["component"], entry["kind"], entry["load_case"]))] = \
                    int(entry["samples"])
            samples = []
            for s in data["samples"]:
                g = s["governing"]
                check = -1 if g is None else keys.index((g["component"], g["kind"],
                                                         g["load_case"]))
                samples.append(SampleVerdict(tuple(float(s["values"][n]) for n in names), check,
                                             math.nan if g is None else _float(g["safety_factor"]),
                                             str(s.get("error", ""))))
            return cls(unknowns, tuple(str(u["group"]) for u in data["unknowns"]),
                       tuple((f["name"], f["why"]) for f in data["fixed"]), int(data["n"]),
                       int(data["seed"]), bool(data["indices"]), int(data["runs"]),
                       int(data["evaluations"]), checks,
                       FactorBand.from_dict(data["governing"], names), tuple(counts),
                       tuple(samples), int(data["nominal_check"]), str(data["parameters_hash"]),
                       str(data["set_hash"]), dict(data["options"]))
        except (KeyError, TypeError, ValueError, IndexError) as error:
            raise VerdictUncertaintyError(f"a malformed result of the verdict under uncertainty: "
                                          f"{type(error).__name__} {error}") from None

    def summary(self, rows: int = 8) -> str:
        """A text table: the governing check, then the ``rows`` checks of least median margin,
        each with its band and P(fail); with indices the leading unknowns of the governing."""
        def line(band: FactorBand) -> str:
            p = band.failure
            return (f"{band.label:<52} {band.nominal:>8.3g} {band.quantiles[0]:>8.3g} "
                    f"{band.quantiles[1]:>8.3g} {band.quantiles[2]:>8.3g} "
                    f"{p.value:>8.3f} ± {p.standard_error:.3f}")

        head = (f"verdict under uncertainty: {len(self.unknowns)} unknowns "
                f"({self.groups.count(GROUPS[0])} dynamics, {self.groups.count(GROUPS[1])} "
                f"strength data), n = {self.n}, {len(self.samples)} samples, {self.runs} "
                f"dynamics runs, {self.evaluations} assessments"
                + (f"; {self.undefined} samples without a verdict" if self.undefined else ""))
        lines = [head, "", f"{'check':<52} {'nominal':>8} {'p5':>8} {'p50':>8} {'p95':>8} "
                 f"{'P(fail)':>8}", line(self.governing)]
        order = sorted(range(len(self.checks)), key=lambda i: (
            self.checks[i].quantiles[1] / self.checks[i].required
            if math.isfinite(self.checks[i].quantiles[1]) else math.inf))
        lines += [line(self.checks[i]) for i in order[:rows]]
        if self.governing.total_order:
            lead = sorted(range(len(self.unknowns)), key=lambda j: -_sortable(
                self.governing.total_order[j]))[:5]
            lines += ["", "governing safety factor, total indices: " + ", ".join(
                f"{self.names[j]} {self.governing.total_order[j]:.2f}" for j in lead),
                "by group (first order / total): " + ", ".join(
                f"{g} {self.governing.group_first_order[k]:.2f} / "
                f"{self.governing.group_total_order[k]:.2f}" for k, g in enumerate(GROUPS))]
        return "\n".join(lines)


def _sortable(value: float) -> float:
    return value if math.isfinite(value) else -math.inf
