"""The statistics of the verdict under uncertainty on plain arrays: scrambled Sobol' samples of a
prior, Saltelli's design and the Sobol indices of any function sampled on it, quantiles, the
probability of falling below a required value, and their sampling uncertainty.  Nothing here knows
the bogie: the study (:mod:`model.studies.verdict_uncertainty`) and its tests' stand-ins use it
alike.

**Samples.**  ``n`` (a power of 2) points of a scrambled Sobol' sequence (``scipy.stats.qmc``),
mapped through each input's distribution (its ``ppf``).  For Sobol indices, two matrices A and B
of n rows each, the first and last d columns of a 2d-dimensional sequence (as
``scipy.stats.sobol_indices`` draws them), and Saltelli's design (:func:`saltelli_design`): A, B,
for every input i the matrix AB_i (A with column i from B), and for every group of inputs the
matrix AB_G (A with the group's columns from B): ``n (d + 2 + groups)`` rows.

**Sobol indices** (:func:`sobol_indices`): the estimators of ``scipy.stats.sobol_indices``,
first order ``S_i = mean(f_B (f_AB_i − f_A)) / V`` (Saltelli 2010) and total
``S_Ti = mean((f_A − f_AB_i)²) / (2 V)`` (Jansen 1999), V the variance of f over A and B, f
centred by its mean over A and B.  A group's AB_G gives the group's closed first-order and total
index the same way.  Rows where the function is undefined (NaN) in any matrix are left out for
that output; an output that does not vary has indices 0.  95 % intervals: a bootstrap over the
rows (percentile).

**Sampling uncertainty.**  The probability ``P = k / m`` (k of m defined samples below the
required value) comes with the binomial standard error ``sqrt(P (1 − P) / m)`` and the 95 %
Clopper–Pearson interval; a quantile with the distribution-free 95 % interval between two order
statistics (ranks from the binomial distribution).  Both are exact for m independent samples (plain
Monte Carlo).  The samples here are a scrambled Sobol' net: for a smooth function its error falls
faster than Monte Carlo's, for an indicator (a probability) and a quantile about as fast; the
binomial figures are then a stand-in for the net's own error, not a bound (Owen's bound for
scrambled nets allows a constant factor above Monte Carlo's variance).  The tests measure the
spread over independent scrambles of a stand-in against them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

CONFIDENCE = 0.95
BOOTSTRAP_RESAMPLES = 499


def check_sample_count(n: object) -> int:
    """``n`` as a power of 2 ≥ 2 (else ValueError): the balance of a Sobol' net."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 2 or n & (n - 1):
        raise ValueError(f"n = {n!r} is not allowed: must be a power of 2 >= 2 (the balance of "
                         "the Sobol' points)")
    return n


def sobol_samples(distributions: Sequence, n: int, seed: int) -> np.ndarray:
    """n x d values: n scrambled Sobol' points in (0, 1)^d through each distribution's ppf."""
    check_sample_count(n)
    d = len(distributions)
    points = stats.qmc.Sobol(d, scramble=True, rng=np.random.default_rng(seed)).random(n)
    return np.column_stack([dist.ppf(points[:, j]) for j, dist in enumerate(distributions)])


def sobol_pair(distributions: Sequence, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(A, B), n x d each: the first and last d columns of n scrambled Sobol' points in
    (0, 1)^2d through each distribution's ppf."""
    check_sample_count(n)
    d = len(distributions)
    points = stats.qmc.Sobol(2 * d, scramble=True, rng=np.random.default_rng(seed)).random(n)
    values = np.column_stack([dist.ppf(points[:, j])
                              for j, dist in enumerate([*distributions, *distributions])])
    return values[:, :d], values[:, d:]


@dataclass(frozen=True)
class SaltelliDesign:
    """The rows of Saltelli's design (module docstring) and where each matrix lies in them."""

    A: np.ndarray  # n x d
    B: np.ndarray  # n x d
    groups: tuple[tuple[str, tuple[int, ...]], ...]  # (group name, its columns), non-empty groups

    @property
    def n(self) -> int:
        return len(self.A)

    @property
    def blocks(self) -> int:
        """Matrices in :attr:`rows`: A, B, one AB_i per input, one AB_G per group."""
        return 2 + self.A.shape[1] + len(self.groups)

    @property
    def rows(self) -> np.ndarray:
        """n (d + 2 + groups) x d: A, B, AB_1 … AB_d, AB_G1 … (each n rows, in this order)."""
        d = self.A.shape[1]
        matrices = [self.A, self.B]
        for i in range(d):
            mixed = self.A.copy()
            mixed[:, i] = self.B[:, i]
            matrices.append(mixed)
        for _, columns in self.groups:
            mixed = self.A.copy()
            mixed[:, list(columns)] = self.B[:, list(columns)]
            matrices.append(mixed)
        return np.vstack(matrices)

    def split(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(f_A, f_B, f_AB, f_AG) of values over :attr:`rows` (rows x outputs, or rows): f_A and
        f_B outputs x n, f_AB d x outputs x n, f_AG groups x outputs x n."""
        values = np.asarray(values, dtype=float)
        values = values.reshape(self.blocks, self.n, -1)  # block, row, output
        values = np.moveaxis(values, -1, 1)  # block, output, row
        d = self.A.shape[1]
        return values[0], values[1], values[2:2 + d], values[2 + d:]


def saltelli_design(distributions: Sequence, n: int, seed: int,
                    groups: Sequence[tuple[str, Sequence[int]]] = ()) -> SaltelliDesign:
    """Saltelli's design over ``distributions`` (A and B by :func:`sobol_pair`) with a matrix
    AB_G for every non-empty group (name, columns)."""
    A, B = sobol_pair(distributions, n, seed)
    return SaltelliDesign(A, B, tuple((name, tuple(int(c) for c in columns))
                                      for name, columns in groups if len(columns)))


@dataclass(frozen=True)
class SobolIndices:
    """First-order and total indices of one output (NaN: not estimable) with 95 % bootstrap
    intervals (NaN when not asked for), over the inputs or the groups of a design."""

    first: np.ndarray  # (k,)
    total: np.ndarray  # (k,)
    first_interval: np.ndarray  # (2, k) low, high
    total_interval: np.ndarray  # (2, k)
    rows: int  # the rows of the design that entered (those where the output is defined)


def _estimates(f_A: np.ndarray, f_B: np.ndarray, f_AB: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, total) over the pages of f_AB (k x m) for rows f_A, f_B (m,); scipy's estimators."""
    mean = np.mean(np.concatenate([f_A, f_B]))
    f_A, f_B, f_AB = f_A - mean, f_B - mean, f_AB - mean
    variance = np.var(np.concatenate([f_A, f_B]))
    if not variance > 0:
        return np.zeros(len(f_AB)), np.zeros(len(f_AB))
    first = np.mean(f_B * (f_AB - f_A), axis=-1) / variance
    total = 0.5 * np.mean((f_A - f_AB) ** 2, axis=-1) / variance
    return first, total


def sobol_indices(f_A: np.ndarray, f_B: np.ndarray, f_AB: np.ndarray, resamples: int = 0,
                  seed: int = 0) -> SobolIndices:
    """Indices of one output from its values on A, B (n,) and on the AB pages (k x n) of a
    design (module docstring); ``resamples`` > 0: 95 % bootstrap intervals from that many
    resamples of the defined rows (a generator seeded with ``seed``)."""
    f_A, f_B, f_AB = (np.asarray(x, dtype=float) for x in (f_A, f_B, f_AB))
    k = len(f_AB)
    defined = np.isfinite(f_A) & np.isfinite(f_B) & np.all(np.isfinite(f_AB), axis=0)
    blank = np.full(k, np.nan)
    m = int(defined.sum())
    if m < 2:
        return SobolIndices(blank, blank, np.array([blank, blank]), np.array([blank, blank]), m)
    a, b, ab = f_A[defined], f_B[defined], f_AB[:, defined]
    first, total = _estimates(a, b, ab)
    first_interval = total_interval = np.array([blank, blank])
    if resamples > 0:
        rng = np.random.default_rng(seed)
        draws = np.empty((resamples, 2, k))
        for r in range(resamples):
            pick = rng.integers(0, m, m)
            draws[r] = _estimates(a[pick], b[pick], ab[:, pick])
        low, high = 50 * (1 - CONFIDENCE), 50 * (1 + CONFIDENCE)
        first_interval = np.percentile(draws[:, 0], [low, high], axis=0)
        total_interval = np.percentile(draws[:, 1], [low, high], axis=0)
    return SobolIndices(first, total, first_interval, total_interval, m)


@dataclass(frozen=True)
class Probability:
    """The fraction of the defined samples below a required value, with its sampling uncertainty
    (module docstring)."""

    value: float  # k / m [-] (NaN: no defined sample)
    standard_error: float  # sqrt(P (1 - P) / m) [-]
    interval: tuple[float, float]  # 95 % Clopper-Pearson [-]
    below: int  # k
    samples: int  # m

    def as_dict(self) -> dict:
        return {"value": _finite(self.value), "standard_error": _finite(self.standard_error),
                "interval": [_finite(x) for x in self.interval], "below": self.below,
                "samples": self.samples}


def probability_below(values: np.ndarray, required: float) -> Probability:
    """The probability that a value falls below ``required`` over the defined (non-NaN) values."""
    values = np.asarray(values, dtype=float)
    defined = values[~np.isnan(values)]
    m = len(defined)
    if m == 0:
        return Probability(math.nan, math.nan, (math.nan, math.nan), 0, 0)
    k = int(np.sum(defined < required))
    p = k / m
    interval = stats.binomtest(k, m).proportion_ci(CONFIDENCE, method="exact")
    return Probability(p, math.sqrt(p * (1 - p) / m), (float(interval.low), float(interval.high)),
                       k, m)


def quantiles(values: np.ndarray, percents: Sequence[float]) -> np.ndarray:
    """The ``percents`` [%] quantiles of the defined (non-NaN) values (linear interpolation between
    order statistics; NaN without a defined value)."""
    values = np.sort(np.asarray(values, dtype=float)[~np.isnan(values)])
    if len(values) == 0:
        return np.full(len(percents), np.nan)
    with np.errstate(invalid="ignore"):  # inf - inf between two unloaded checks' factors
        return np.quantile(values, np.asarray(percents, dtype=float) / 100.0)


def quantile_interval(values: np.ndarray, percent: float) -> tuple[float, float]:
    """The distribution-free 95 % interval of the ``percent`` [%] quantile: the order statistics
    of ranks ``binom.ppf(0.025, m, q)`` and ``binom.ppf(0.975, m, q) + 1`` of the m defined values
    (NaN for an end the sample cannot bound)."""
    values = np.sort(np.asarray(values, dtype=float)[~np.isnan(values)])
    m, q = len(values), percent / 100.0
    if m == 0:
        return math.nan, math.nan
    tail = (1 - CONFIDENCE) / 2
    lower = int(stats.binom.ppf(tail, m, q))  # 1-based rank
    upper = int(stats.binom.ppf(1 - tail, m, q)) + 1
    return (float(values[lower - 1]) if lower >= 1 else math.nan,
            float(values[upper - 1]) if upper <= m else math.nan)


def prefix_quantiles(parts: Sequence[np.ndarray], percent: float) -> list[tuple[int, float]]:
    """(count, the ``percent`` [%] quantile of the first m values of every part together) for
    m = 2, 4, … up to the shortest part: a quantile's convergence over the leading points of
    Sobol' sequences (``parts``: the values of each sequence in its order, e.g. those on A and on
    B; every power-of-2 prefix of a scrambled Sobol' sequence is a balanced net of its own)."""
    parts = [np.asarray(part, dtype=float) for part in parts]
    steps, m = [], 2
    while m <= min(len(part) for part in parts):
        leading = np.concatenate([part[:m] for part in parts])
        steps.append((len(leading), float(quantiles(leading, [percent])[0])))
        m *= 2
    return steps


def _finite(value: float) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None
