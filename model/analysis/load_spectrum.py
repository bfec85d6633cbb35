"""Load spectra for fatigue: rainflow cycles, the cumulative exceedance diagram (the load
collective) and damage-equivalent ranges of a load history.

API::

    from model.analysis.load_spectrum import load_spectrum, history_spectra
    spectrum = load_spectrum(result.outputs["ID1.driving_shaft.torque"], "…", "N m")
    spectrum.cycles                      # k x 3: range, mean, count (1 or ½) [unit, unit, -]
    spectrum.exceedance_range, spectrum.exceedance_count   # the load collective
    spectrum.equivalent_range[3.0]       # ΔM_eq for Wöhler slope m = 3 [unit]

**Counting.**  Rainflow counting after ASTM E1049-85 (2011), section 5.4.4, by the maintained
``rainflow`` package (PyPI, pure Python, 3.x): the series is reduced to its reversals (the first
and last samples count as reversals), and the **residue** — the ranges left unclosed at the end —
is counted as **half cycles**, as the standard's section 5.4.4 does.  Each cycle is reported as
(range, mean, count) with count 1 for a full cycle and 0.5 for a half cycle.  No gate (hysteresis
filter) is applied: every reversal of the sampled series counts, down to rounding-level wiggles,
which add cycles but no damage worth speaking of.

**Cumulative exceedance (load collective).**  ``H(ΔM) = Σ nᵢ over the cycles with ΔMᵢ ≥ ΔM``: the
number of cycles whose range reaches ΔM, plotted with H on a logarithmic axis — the form drive
designers read (a *Lastkollektiv* of ranges).  Given as the distinct ranges, largest first, with H
at each.

**Damage-equivalent range.**  For a Wöhler (S–N) curve ``N(ΔM) = N_ref (ΔM_eq/ΔM)^m`` and
Palmgren–Miner's linear damage sum, the constant range that does the same damage in ``N_ref``
cycles: ``ΔM_eq = (Σ nᵢ ΔMᵢ^m / N_ref)^(1/m)``, default m = 3 and 5 and N_ref = 10⁷ (evaluated as
``ΔM_max (Σ nᵢ (ΔMᵢ/ΔM_max)^m / N_ref)^(1/m)``, which cannot overflow).  It is a property of the
history alone: no stress concentration, no real shaft's S–N curve, no mean-stress correction
(docs/design-loads.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

DEFAULT_SLOPES = (3.0, 5.0)  # Wöhler exponents m [-]
N_REF = 1e7  # reference cycle count of the equivalent range [-]


class SpectrumError(ValueError):
    """Bad input for a load spectrum (one-line message)."""


def rainflow_cycles(series) -> np.ndarray:
    """Rainflow cycles of ``series`` (ASTM E1049-85, residue as half cycles; the ``rainflow``
    package) as a k x 3 array: range, mean [unit of the series], count (1 or 0.5), in the order
    the count closes them."""
    import rainflow

    values = np.asarray(series, dtype=float)
    if values.ndim != 1:
        raise SpectrumError("a load history must be one-dimensional")
    if not np.all(np.isfinite(values)):
        raise SpectrumError("a load history must be finite")
    cycles = [(rng, mean, count) for rng, mean, count, _, _ in rainflow.extract_cycles(values)]
    return np.array(cycles, dtype=float).reshape(-1, 3)


def cumulative_exceedance(cycles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(distinct ranges, largest first [unit]; H: cycles with a range at least as large [-])."""
    cycles = np.asarray(cycles, dtype=float).reshape(-1, 3)
    if len(cycles) == 0:
        return np.zeros(0), np.zeros(0)
    ranges, inverse = np.unique(cycles[:, 0], return_inverse=True)  # ascending
    counts = np.bincount(inverse, weights=cycles[:, 2], minlength=len(ranges))
    return ranges[::-1].copy(), np.cumsum(counts[::-1])


def equivalent_range(cycles: np.ndarray, slope: float, n_ref: float = N_REF) -> float:
    """Damage-equivalent range ``(Σ nᵢ ΔMᵢ^m / N_ref)^(1/m)`` [unit] for Wöhler slope ``slope``
    = m > 0 and ``n_ref`` cycles (0 for a history without cycles)."""
    check_slope(slope)
    if not (math.isfinite(n_ref) and n_ref > 0):
        raise SpectrumError(f"N_ref = {n_ref!r} is not allowed: must be a positive number")
    cycles = np.asarray(cycles, dtype=float).reshape(-1, 3)
    largest = cycles[:, 0].max(initial=0.0)
    if largest == 0.0:
        return 0.0
    damage = float(np.sum(cycles[:, 2] * (cycles[:, 0] / largest) ** slope))
    return float(largest * (damage / n_ref) ** (1.0 / slope))


def check_slope(slope) -> float:
    """A Wöhler slope m: a finite number > 0 (else :class:`SpectrumError`)."""
    if isinstance(slope, bool) or not isinstance(slope, int | float) or not math.isfinite(slope) \
            or slope <= 0:
        raise SpectrumError(f"Wöhler slope m = {slope!r} is not allowed: must be a number > 0")
    return float(slope)


@dataclass(frozen=True)
class LoadSpectrum:
    """The load spectrum of one history (plain data; module docstring)."""

    name: str  # output name
    unit: str  # its SI unit
    cycles: np.ndarray  # k x 3: range [unit], mean [unit], count [-] (1 or 0.5)
    exceedance_range: np.ndarray  # distinct ranges, largest first [unit]
    exceedance_count: np.ndarray  # cycles with a range ≥ each [-]
    equivalent_range: dict[float, float]  # Wöhler slope m -> ΔM_eq [unit]
    n_ref: float  # reference cycles of ΔM_eq [-]

    @property
    def total_cycles(self) -> float:
        """Σ nᵢ (half cycles count ½) [-]."""
        return float(self.cycles[:, 2].sum())

    @property
    def largest_range(self) -> float:
        """Largest cycle range [unit] (0 without cycles)."""
        return float(self.cycles[:, 0].max(initial=0.0))


def load_spectrum(series, name: str = "", unit: str = "", slopes=DEFAULT_SLOPES,
                  n_ref: float = N_REF) -> LoadSpectrum:
    """Rainflow cycles, cumulative exceedance and equivalent ranges of ``series``."""
    slopes = [check_slope(m) for m in slopes]
    if not slopes:
        raise SpectrumError("give at least one Wöhler slope")
    cycles = rainflow_cycles(series)
    ranges, counts = cumulative_exceedance(cycles)
    return LoadSpectrum(name, unit, cycles, ranges, counts,
                        {m: equivalent_range(cycles, m, n_ref) for m in slopes}, float(n_ref))


def history_spectra(result, slopes=DEFAULT_SLOPES, n_ref: float = N_REF) -> list[LoadSpectrum]:
    """:func:`load_spectrum` of every output (totals) of a linear or nonlinear response result."""
    return [load_spectrum(values, name, result.units[name], slopes, n_ref)
            for name, values in result.outputs.items()]


def rainflow_matrix(cycles: np.ndarray, bins: int = 32) -> tuple[np.ndarray, np.ndarray,
                                                                   np.ndarray]:
    """The rainflow matrix: counts (bins x bins, rows by range, columns by mean), the range edges
    and the mean edges [unit] (equal widths over the cycles' extent)."""
    cycles = np.asarray(cycles, dtype=float).reshape(-1, 3)
    if isinstance(bins, bool) or not isinstance(bins, int) or bins < 1:
        raise SpectrumError(f"bins = {bins!r} is not allowed: a whole number >= 1")
    if len(cycles) == 0:
        return np.zeros((bins, bins)), np.linspace(0.0, 1.0, bins + 1), \
            np.linspace(-0.5, 0.5, bins + 1)
    r_top = cycles[:, 0].max() or 1.0
    m_low, m_high = cycles[:, 1].min(), cycles[:, 1].max()
    if m_high == m_low:
        m_low, m_high = m_low - 0.5 * r_top, m_high + 0.5 * r_top
    counts, range_edges, mean_edges = np.histogram2d(
        cycles[:, 0], cycles[:, 1], bins=bins, range=[[0.0, r_top], [m_low, m_high]],
        weights=cycles[:, 2])
    return counts, range_edges, mean_edges
