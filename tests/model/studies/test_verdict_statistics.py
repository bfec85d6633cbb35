"""The statistics of the verdict under uncertainty on a stand-in whose Sobol indices are known in
closed form: a press fit's safety factor ``c δ μ / L``, the product of two sampled strength data
(interference δ and friction μ, uniform) over a sampled load scale L (log-uniform, the stand-in's
"dynamics").  For a product of independent factors g_i with means m_i and second moments s_i:
``V = Π s − Π m²``, ``V_i = (s_i − m_i²) Π_{j≠i} m_j²``, ``V_Ti = (s_i − m_i²) Π_{j≠i} s_j``, and the
closed index of the group {δ, μ} is ``m_L² (s_δ s_μ − m_δ² m_μ²) / V``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from model.studies.parameter_ranges import ParameterRange
from model.studies.verdict_statistics import (
    check_sample_count,
    prefix_quantiles,
    probability_below,
    quantile_interval,
    quantiles,
    saltelli_design,
    sobol_indices,
    sobol_samples,
)

LOAD = ParameterRange("rotor_inertia", 8.0, 18.0, "stand-in: the load scale L")
INTERFERENCE = ParameterRange("wheel_seat_interference_min", 1.28e-4, 2.36e-4, "stand-in: δ",
                              log=False)
FRICTION = ParameterRange("wheel_seat_friction_min", 0.08, 0.16, "stand-in: μ", log=False)
UNKNOWNS = (LOAD, INTERFERENCE, FRICTION)
SCALE = 1.5 * 12.0 / (1.9e-4 * 0.12)  # a factor of 1.5 at L = 12, δ = 0.19 mm, μ = 0.12
GROUPS = (("dynamics", (0,)), ("strength data", (1, 2)))
# Tolerance of an index at n = 1024: the spread of the estimators over independent scrambles of
# this stand-in is about 0.001 there (asserted below 0.003 by the test itself), so 0.01 is several
# standard deviations and still far finer than any conclusion a board draws from an index.
TOLERANCE = 0.01


def safety_factor(X: np.ndarray) -> np.ndarray:
    return SCALE * X[:, 1] * X[:, 2] / X[:, 0]


def _uniform_moments(low, high):
    return (low + high) / 2, (low * low + low * high + high * high) / 3


def analytic_indices():
    """(first, total) per unknown (L, δ, μ) and (closed first, total) of the two groups."""
    ln = math.log(LOAD.high / LOAD.low)
    m_L = (1 / LOAD.low - 1 / LOAD.high) / ln  # moments of 1/L, L log-uniform
    s_L = (1 / LOAD.low**2 - 1 / LOAD.high**2) / (2 * ln)
    m_d, s_d = _uniform_moments(INTERFERENCE.low, INTERFERENCE.high)
    m_u, s_u = _uniform_moments(FRICTION.low, FRICTION.high)
    m, s = np.array([m_L, m_d, m_u]), np.array([s_L, s_d, s_u])
    V = np.prod(s) - np.prod(m**2)
    first = np.array([(s[i] - m[i]**2) * np.prod(np.delete(m**2, i)) for i in range(3)]) / V
    total = np.array([(s[i] - m[i]**2) * np.prod(np.delete(s, i)) for i in range(3)]) / V
    strength_closed = m_L**2 * (s_d * s_u - m_d**2 * m_u**2) / V
    group_first = np.array([first[0], strength_closed])
    group_total = np.array([total[0], 1 - first[0]])  # a group's total: 1 − its complement's closed
    return first, total, group_first, group_total


def _indices(n: int, seed: int):
    design = saltelli_design([u.distribution() for u in UNKNOWNS], n, seed, GROUPS)
    f_A, f_B, f_AB, f_AG = design.split(safety_factor(design.rows))
    return (sobol_indices(f_A[0], f_B[0], f_AB[:, 0]),
            sobol_indices(f_A[0], f_B[0], f_AG[:, 0]))


def test_sobol_indices_of_the_stand_in_match_the_closed_form():
    """Per unknown and per group (dynamics {L}, strength data {δ, μ}), first order and total,
    over 8 independent scrambles at n = 1024: each estimate within TOLERANCE of the closed form,
    and the spread over the scrambles small enough for that tolerance to mean something."""
    first, total, group_first, group_total = analytic_indices()
    assert total.sum() > 1 > first.sum()  # the product interacts: the test sees interactions
    runs = [_indices(1024, seed) for seed in range(8)]
    estimates = {"first": (first, [r[0].first for r in runs]),
                 "total": (total, [r[0].total for r in runs]),
                 "group first": (group_first, [r[1].first for r in runs]),
                 "group total": (group_total, [r[1].total for r in runs])}
    for label, (exact, values) in estimates.items():
        values = np.array(values)
        assert np.abs(values - exact).max() <= TOLERANCE, label
        assert values.std(axis=0).max() < 0.3 * TOLERANCE, label


def test_the_estimators_are_scipys():
    """The same numbers as ``scipy.stats.sobol_indices`` on the same function values."""
    design = saltelli_design([u.distribution() for u in UNKNOWNS], 256, 5)
    f_A, f_B, f_AB, _ = design.split(safety_factor(design.rows))
    ours = sobol_indices(f_A[0], f_B[0], f_AB[:, 0])
    theirs = stats.sobol_indices(func={"f_A": f_A, "f_B": f_B, "f_AB": f_AB}, n=256)
    assert ours.first == pytest.approx(theirs.first_order, rel=1e-12, abs=1e-14)
    assert ours.total == pytest.approx(theirs.total_order, rel=1e-12, abs=1e-14)


def test_the_design_mixes_the_columns_of_A_and_B():
    design = saltelli_design([u.distribution() for u in UNKNOWNS], 8, 1, GROUPS)
    rows = design.rows.reshape(design.blocks, 8, 3)
    assert design.blocks == 2 + 3 + 2
    np.testing.assert_array_equal(rows[0], design.A)
    np.testing.assert_array_equal(rows[1], design.B)
    for i in range(3):
        expected = design.A.copy()
        expected[:, i] = design.B[:, i]
        np.testing.assert_array_equal(rows[2 + i], expected)
    np.testing.assert_array_equal(rows[5][:, 0], design.B[:, 0])  # the dynamics group from B
    np.testing.assert_array_equal(rows[5][:, 1:], design.A[:, 1:])
    np.testing.assert_array_equal(rows[6][:, 1:], design.B[:, 1:])  # the strength group from B
    for j, unknown in enumerate(UNKNOWNS):
        assert np.all((design.A[:, j] >= unknown.low) & (design.A[:, j] <= unknown.high))


def test_undefined_rows_are_left_out_and_a_constant_has_no_indices():
    design = saltelli_design([u.distribution() for u in UNKNOWNS], 64, 2)
    f_A, f_B, f_AB, _ = design.split(safety_factor(design.rows))
    f_A, f_AB = f_A[0].copy(), f_AB[:, 0].copy()
    f_A[3] = np.nan
    f_AB[1, 10] = np.nan
    with_gaps = sobol_indices(f_A, f_B[0], f_AB)
    keep = np.ones(64, dtype=bool)
    keep[[3, 10]] = False
    without = sobol_indices(f_A[keep], f_B[0][keep], f_AB[:, keep])
    assert with_gaps.rows == 62
    np.testing.assert_array_equal(with_gaps.first, without.first)
    constant = sobol_indices(np.ones(8), np.ones(8), np.ones((3, 8)))
    assert np.all(constant.first == 0)
    assert np.all(constant.total == 0)
    assert np.all(np.isnan(sobol_indices(np.full(4, np.nan), np.ones(4), np.ones((2, 4))).first))


def test_bootstrap_intervals_hold_their_estimate():
    design = saltelli_design([u.distribution() for u in UNKNOWNS], 256, 3)
    f_A, f_B, f_AB, _ = design.split(safety_factor(design.rows))
    result = sobol_indices(f_A[0], f_B[0], f_AB[:, 0], resamples=200, seed=1)
    low, high = result.total_interval
    assert np.all(low < high)
    assert np.all((low <= result.total) & (result.total <= high))


def test_probability_below_with_its_binomial_error_and_exact_interval():
    values = np.array([1.0, 2.0, 0.5, np.nan, 3.0, 1.2, np.inf, 0.9])
    p = probability_below(values, 1.1)  # 1.0, 0.5, 0.9 below; NaN left out; inf is not below
    assert (p.below, p.samples) == (3, 7)
    assert p.value == pytest.approx(3 / 7)
    assert p.standard_error == pytest.approx(math.sqrt(3 / 7 * 4 / 7 / 7))
    assert stats.binom.cdf(3, 7, p.interval[1]) == pytest.approx(0.025)  # Clopper-Pearson
    assert stats.binom.sf(2, 7, p.interval[0]) == pytest.approx(0.025)
    none = probability_below(np.full(20, 2.0), 1.5)
    assert (none.value, none.standard_error, none.interval[0]) == (0.0, 0.0, 0.0)
    assert none.interval[1] == pytest.approx(1 - 0.025 ** (1 / 20))  # k = 0: the exact bound


def test_quantile_intervals_cover_the_true_quantile():
    """For independent samples the order-statistic interval covers the true quantile at least as
    often as it says (here the 95 % quantile of a uniform variable, 1000 draws of 200)."""
    rng = np.random.default_rng(4)
    covered = sum(low <= 0.95 <= high for low, high in
                  (quantile_interval(rng.random(200), 95.0) for _ in range(1000)))
    assert covered >= 940
    assert np.isnan(quantile_interval(rng.random(10), 95.0)[1])  # 10 samples cannot bound it


def test_quantiles_and_their_convergence_over_leading_points():
    values = sobol_samples([FRICTION.distribution()], 64, 9)[:, 0]
    steps = prefix_quantiles([values], 95.0)
    assert [m for m, _ in steps] == [2, 4, 8, 16, 32, 64]
    assert steps[-1][1] == quantiles(values, [95.0])[0]
    halves = prefix_quantiles([values[:32], values[32:]], 50.0)
    assert [m for m, _ in halves] == [4, 8, 16, 32, 64]
    assert quantiles(np.array([np.nan, 1.0, 3.0]), [50.0])[0] == 2.0


@pytest.mark.parametrize("n", [0, 1, 3, 12, True, 2.0, "4"])
def test_sample_counts_are_powers_of_two(n):
    with pytest.raises(ValueError, match="power of 2"):
        check_sample_count(n)
