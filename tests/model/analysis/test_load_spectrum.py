"""Load spectra: rainflow cycles of known signals, the load collective, the
damage-equivalent range, and agreement with the ``rainflow`` package on the model's histories.

Tolerances: the known signals are sums of sines sampled where the sines take the values 0 and ±1
(cos(nπ/2) is 0 only to ≈ 6e-17), so their ranges are exact to rounding: 1e-12 relative.  Against
the ``rainflow`` package's own aggregation (``count_cycles``) the equivalent ranges agree within
1e-6 relative (the target; the two sum the same terms in another order, so they agree to
≈ 1e-15) and the cycle totals exactly.
"""

from __future__ import annotations

import numpy as np
import pytest
import rainflow

from model import build_model, default_operating_point, load_parameters
from model.analysis.load_spectrum import (
    N_REF,
    SpectrumError,
    cumulative_exceedance,
    equivalent_range,
    history_spectra,
    load_spectrum,
    rainflow_cycles,
    rainflow_matrix,
)


def two_sines(periods: int, A: float = 2.0, B: float = 1.5) -> np.ndarray:
    """A cos θ + B cos 2θ at θ = nπ/2, n = 0 … 4·periods: per period the reversals
    A+B, −B, B−A, −B (B > A/2): one small cycle (−B ↔ B−A) and the big swing A+B ↔ −B."""
    theta = np.arange(4 * periods + 1) * np.pi / 2
    return A * np.cos(theta) + B * np.cos(2 * theta)


def test_sum_of_two_sines_counted_exactly():
    periods, A, B = 7, 2.0, 1.5
    cycles = rainflow_cycles(two_sines(periods, A, B))
    small = cycles[np.isclose(cycles[:, 0], 2 * B - A, rtol=1e-12)]
    big = cycles[np.isclose(cycles[:, 0], A + 2 * B, rtol=1e-12)]
    assert len(small) + len(big) == len(cycles)  # no other range
    # the small cycle closes once per period: full cycles, mean (−B + B − A)/2
    assert len(small) == periods
    assert np.all(small[:, 2] == 1.0)
    np.testing.assert_allclose(small[:, 1], -A / 2, rtol=1e-12)
    # the big swings never close inside the history (ASTM 5.4.4: each counted as a half cycle
    # when it contains the starting point, and the residue as half cycles): 2 per period
    assert len(big) == 2 * periods
    assert np.all(big[:, 2] == 0.5)
    np.testing.assert_allclose(big[:, 1], (A + B - B) / 2, rtol=1e-12)
    spectrum = load_spectrum(two_sines(periods, A, B), slopes=(3.0, 5.0))
    assert spectrum.total_cycles == 2 * periods
    for m in (3.0, 5.0):
        expected = ((periods * (2 * B - A) ** m + periods * (A + 2 * B) ** m) / N_REF) ** (1 / m)
        assert spectrum.equivalent_range[m] == pytest.approx(expected, rel=1e-12)
    # the collective as a step function H(ΔM) (its ranges are distinct floats, so the rounding
    # of cos(nπ/2) splits each level into near-equal entries; H counts across them)
    ranges, counts = spectrum.exceedance_range, spectrum.exceedance_count
    assert np.all(np.diff(ranges) < 0)
    assert np.all(np.diff(counts) > 0)

    def H(level):  # cycles with a range ≥ level
        return counts[ranges >= level * (1 - 1e-12)][-1]

    assert H(A + 2 * B) == periods
    assert H(2 * B - A) == 2 * periods


def test_constant_amplitude_block_counted_exactly():
    """A sin θ at its extremes (±A, K reversals): every range 2A, mean 0, K − 1 half cycles
    (ASTM: a range containing the starting point, and the residue, count half)."""
    K, A = 41, 3.0e4
    series = A * np.sin(np.pi / 2 + np.arange(K) * np.pi)
    cycles = rainflow_cycles(series)
    np.testing.assert_allclose(cycles[:, 0], 2 * A, rtol=1e-12)
    np.testing.assert_allclose(cycles[:, 1], 0.0, atol=1e-12 * A)
    assert cycles[:, 2].sum() == (K - 1) / 2
    for m in (3.0, 5.0, 8.0):
        assert equivalent_range(cycles, m) == pytest.approx(
            ((K - 1) / 2 * (2 * A) ** m / N_REF) ** (1 / m), rel=1e-12)
    # a block that starts and ends at zero adds two half cycles of range A
    block = np.concatenate([[0.0], series, [0.0]])
    cycles = rainflow_cycles(block)
    assert cycles[:, 2].sum() == (K - 1) / 2 + 1.0
    assert sorted(cycles[np.isclose(cycles[:, 0], A), 2]) == [0.5, 0.5]


def test_exceedance_and_equivalent_range_of_given_cycles():
    cycles = np.array([[10.0, 0.0, 1.0], [4.0, 1.0, 0.5], [10.0, 2.0, 0.5], [1.0, 0.0, 1.0]])
    ranges, counts = cumulative_exceedance(cycles)
    np.testing.assert_array_equal(ranges, [10.0, 4.0, 1.0])
    np.testing.assert_array_equal(counts, [1.5, 2.0, 3.0])
    assert equivalent_range(cycles, 3.0, n_ref=1.0) == pytest.approx(
        (1.5 * 1000 + 0.5 * 64 + 1) ** (1 / 3), rel=1e-14)
    # no overflow for huge ranges (a linear blow-up reaches 1e16 N m and more)
    assert equivalent_range(cycles * [1e60, 1, 1], 5.0) == pytest.approx(
        1e60 * equivalent_range(cycles, 5.0), rel=1e-12)
    assert equivalent_range(np.zeros((0, 3)), 3.0) == 0.0


@pytest.mark.parametrize("slope", [0.0, -3.0, float("nan"), True])
def test_bad_slope(slope):
    with pytest.raises(SpectrumError, match="slope"):
        load_spectrum(np.arange(5.0), slopes=(slope,))


def test_bad_series():
    with pytest.raises(SpectrumError, match="finite"):
        rainflow_cycles([0.0, np.inf, 1.0])
    with pytest.raises(SpectrumError, match="one-dimensional"):
        rainflow_cycles(np.zeros((3, 2)))


def test_rainflow_matrix_holds_every_cycle():
    cycles = rainflow_cycles(two_sines(5))
    counts, range_edges, mean_edges = rainflow_matrix(cycles, bins=8)
    assert counts.shape == (8, 8)
    assert counts.sum() == pytest.approx(cycles[:, 2].sum())
    assert range_edges[0] == 0.0
    assert range_edges[-1] == cycles[:, 0].max()
    assert mean_edges[0] <= cycles[:, 1].min()
    assert mean_edges[-1] >= cycles[:, 1].max()


@pytest.fixture(scope="module")
def histories():
    from model.analysis.nonlinear import nonlinear_response
    from model.analysis.response import short_circuit_response

    parameters = load_parameters()
    model = build_model(parameters)
    linear = short_circuit_response(model, default_operating_point(parameters, 0.005), None,
                                    2.0, 10_000.0)
    nonlinear = nonlinear_response(model, default_operating_point(parameters, 0.014), None,
                                   1.0, 5_000.0)
    return linear, nonlinear


@pytest.mark.parametrize("which", [0, 1])
def test_spectra_agree_with_the_rainflow_package(histories, which):
    result = histories[which]
    slopes = (3.0, 5.0)
    spectra = history_spectra(result, slopes)
    assert [s.name for s in spectra] == list(result.outputs)
    for s in spectra:
        counted = rainflow.count_cycles(result.outputs[s.name])  # [(range, count)], aggregated
        assert s.total_cycles == sum(n for _, n in counted)
        for m in slopes:
            reference = (sum(n * r**m for r, n in counted) / N_REF) ** (1 / m)
            assert s.equivalent_range[m] == pytest.approx(reference, rel=1e-6), (s.name, m)
        assert s.unit == result.units[s.name]
        assert s.exceedance_count[-1] == s.total_cycles
