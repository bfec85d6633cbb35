"""Peaks and limit crossings of load histories: one function for the linear
(:mod:`model.analysis.response`) and the nonlinear (:mod:`model.analysis.nonlinear`) response, so that a table of
peaks describes whichever history is on screen by the same rules.

    from model.analysis.load_peaks import history_peaks_and_crossings
    found = history_peaks_and_crossings(t, totals, steady, limits)
    found.peaks, found.peak_times, found.perturbation_peaks, found.limit_crossings
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# (output name suffix, limit name): the totals checked against each limit
LIMITED = (("disc_clutch.torque", "M_ad"), ("claw_clutch.torque", "M_ad"),
           ("wheelset.adhesion_moment", "M_ad"), ("driving_shaft.torque", "M_ad/p"),
           ("creep_force", "mu_max N0"))
# A total crosses its limit when |total| > limit (1 + LIMIT_TOLERANCE): a load that sits on its
# limit to rounding (a creep force saturated at μ_max N0 by the nonlinear law) is not a crossing.
LIMIT_TOLERANCE = 1e-12


@dataclass(frozen=True)
class LimitCrossing:
    """A total load that passed a physical limit."""

    output: str  # output name
    limit_name: str  # e.g. "M_ad"
    limit: float  # limit magnitude [unit of the output]
    time: float  # first time |total| > limit [s]
    value: float  # total value at that time [unit of the output]


@dataclass(frozen=True)
class PeaksAndCrossings:
    """Peaks of each history and the limit crossings (plain data)."""

    peaks: dict[str, float]  # name -> signed total of largest magnitude [unit]
    peak_times: dict[str, float]  # name -> its time [s]
    perturbation_peaks: dict[str, float]  # name -> signed Δy of largest magnitude [unit]
    perturbation_peak_times: dict[str, float]  # name -> its time [s]
    limit_crossings: list[LimitCrossing]  # first crossing of each (output, limit), by time


def history_peaks_and_crossings(t: np.ndarray, totals: dict[str, np.ndarray],
                                steady: dict[str, float], limits: dict[str, float],
                                checks=LIMITED) -> PeaksAndCrossings:
    """Peaks (largest magnitude, first on ties) of the totals and of their perturbations
    ``total − steady[name]``, and the first time each total's magnitude passes a limit
    (``checks``: (name suffix, limit name) pairs; ``limits``: limit name -> magnitude)."""
    peaks, peak_times, perturbation_peaks, perturbation_times = {}, {}, {}, {}
    crossings = []
    for name, y in totals.items():
        k = int(np.argmax(np.abs(y)))
        peaks[name], peak_times[name] = float(y[k]), float(t[k])
        d = y - steady[name]
        k = int(np.argmax(np.abs(d)))
        perturbation_peaks[name], perturbation_times[name] = float(d[k]), float(t[k])
        for suffix, limit_name in checks:
            if name.endswith(suffix) and limit_name in limits:
                limit = limits[limit_name]
                over = np.flatnonzero(np.abs(y) > limit * (1 + LIMIT_TOLERANCE))
                if len(over):
                    k = int(over[0])
                    crossings.append(LimitCrossing(name, limit_name, limit, float(t[k]),
                                                   float(y[k])))
    crossings.sort(key=lambda c: c.time)
    return PeaksAndCrossings(peaks, peak_times, perturbation_peaks, perturbation_times, crossings)
