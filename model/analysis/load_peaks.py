"""Peaks and limit crossings of load histories: one function for the linear
(:mod:`model.analysis.response`) and the nonlinear (:mod:`model.analysis.nonlinear`) response, so that a table of
peaks describes whichever history is on screen by the same rules.

    from model.analysis.load_peaks import history_peaks_and_crossings
    found = history_peaks_and_crossings(t, totals, steady, limits)
    found.peaks, found.peak_times, found.perturbation_peaks, found.limit_crossings

**Peaks a reviewer can read** (:class:`LoadPeaks`, :func:`load_peaks`): the largest magnitude of
a total is often the value before the fault (ID1's disc clutch carries its motor's torque until
the short circuit) and the value at the end of a window is often a slow drift still settling to
the static response of the vehicle's deceleration.  So per output: the maximum, the minimum
and the swing from the pre-fault value, each with its time, and the swing split into its
quasi-static part (the static response to the lost torque and the slow modes,
:func:`model.analysis.response.quasi_static_response`) and its dynamic part (the oscillation
about it); for a linear history that grows without bound (an unstable point) the growth rate and
when each output passes its limit instead of peaks no shaft ever sees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# (output name suffix, limit name): the totals checked against each limit
LIMITED = (("disc_clutch.torque", "M_ad"), ("claw_clutch.torque", "M_ad"),
           ("wheelset.adhesion_moment", "M_ad"), ("driving_shaft.torque", "M_ad/p"),
           ("creep_force", "mu_max N0"))
# A total crosses its limit when |total| > limit (1 + LIMIT_TOLERANCE): a load that sits on its
# limit to rounding (a creep force saturated at μ_max N0 by the nonlinear law) is not a crossing.
LIMIT_TOLERANCE = 1e-12
# a linear history grows without bound when the system has an eigenvalue with a larger real part
GROWTH_RATE = 1e-6  # [1/s]


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


@dataclass(frozen=True)
class OutputExtremes:
    """One output's history as a reviewer reads it (the output's unit; times [s] after the
    fault; the first sample on ties)."""

    pre_fault: float  # the value before the fault
    maximum: float
    time_of_maximum: float
    minimum: float
    time_of_minimum: float
    swing: float  # total − pre-fault value of largest magnitude, signed
    time_of_swing: float
    # the swing at its time = quasi-static part + dynamic part (NaN: not split)
    quasi_static: float = math.nan
    dynamic: float = math.nan
    quasi_static_at_end: float = math.nan  # the quasi-static part at the history's end
    quasi_static_final: float = math.nan  # ... and long after, t → ∞ (NaN: not known)


def output_extremes(t: np.ndarray, total: np.ndarray, pre_fault: float,
                    quasi_static: np.ndarray | None = None,
                    quasi_static_final: float = math.nan) -> OutputExtremes:
    """The extremes of one history ``total`` on the times ``t`` [s], its swing from
    ``pre_fault`` and, given the quasi-static part of the perturbation (``quasi_static``, same
    samples as ``total``; ``quasi_static_final`` its value long after), the swing's split."""
    total = np.asarray(total, dtype=float)
    k_max, k_min = int(np.argmax(total)), int(np.argmin(total))
    swing = total - pre_fault
    k = int(np.argmax(np.abs(swing)))
    split = {}
    if quasi_static is not None:
        part = float(quasi_static[k])
        split = {"quasi_static": part, "dynamic": float(swing[k]) - part,
                 "quasi_static_at_end": float(quasi_static[-1]),
                 "quasi_static_final": float(quasi_static_final)}
    return OutputExtremes(float(pre_fault), float(total[k_max]), float(t[k_max]),
                          float(total[k_min]), float(t[k_min]), float(swing[k]), float(t[k]),
                          **split)


@dataclass(frozen=True)
class LoadPeaks:
    """The peaks a reviewer reads of one history (plain data; see the module docstring)."""

    creep: str  # "linear" or "nonlinear": which creep model the history has
    t_end: float  # the history's last time [s]
    units: dict[str, str]  # name -> unit
    extremes: dict[str, OutputExtremes]  # name -> its extremes (also of an unbounded history)
    growth_rate: float  # largest Re λ of the linear system [1/s] (NaN: nonlinear creep)
    # name -> the first time its total passed its limit (LIMITED; absent: none passed)
    crossings: dict[str, LimitCrossing] = field(default_factory=dict)
    split_note: str = ""  # why the swings are not split ("" when they are)

    @property
    def bounded(self) -> bool:
        """False for a linear history that grows without bound (an unstable point)."""
        return not (self.creep == "linear" and self.growth_rate > GROWTH_RATE)


def load_peaks(t: np.ndarray, totals: dict[str, np.ndarray], steady: dict[str, float],
               units: dict[str, str], limit_crossings: list[LimitCrossing], creep: str,
               growth_rate: float = math.nan,
               quasi_static: dict[str, np.ndarray] | None = None,
               quasi_static_final: dict[str, float] | None = None,
               split_note: str = "") -> LoadPeaks:
    """:class:`LoadPeaks` of the histories ``totals`` (name -> total values on ``t`` [s]) with
    their pre-fault values ``steady`` and first limit crossings (as
    :func:`history_peaks_and_crossings` finds them); ``quasi_static`` (name -> the quasi-static
    part of the perturbation on ``t``) and ``quasi_static_final`` (name -> its value long after)
    split the swings; ``growth_rate`` [1/s] is the linear system's largest Re λ."""
    if creep not in ("linear", "nonlinear"):
        raise ValueError(f"creep '{creep}': linear or nonlinear")
    extremes = {}
    for name, y in totals.items():
        part = None if quasi_static is None else quasi_static[name]
        final = math.nan if quasi_static_final is None else quasi_static_final[name]
        extremes[name] = output_extremes(t, y, steady[name], part, final)
    crossings = {}
    for crossing in sorted(limit_crossings, key=lambda c: c.time):
        crossings.setdefault(crossing.output, crossing)
    if quasi_static is None and not split_note:
        split_note = "not split"
    return LoadPeaks(creep, float(t[-1]), dict(units), extremes, float(growth_rate), crossings,
                     "" if quasi_static is not None else split_note)
