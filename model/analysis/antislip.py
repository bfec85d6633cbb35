"""Required reaction time of the anti-slip protection: how late may it act?

    from model.analysis.antislip import required_reaction_time
    r = required_reaction_time(model, op)          # default limit M_ad, delays 0 … 0.5 s
    r.required_delay, r.reason, r.delays, r.peak_torque

``peak(τ)`` is the largest magnitude over the run of the *limited torques*, each referred to the
wheelset: the disc clutch torque as it is, the driving shaft torque times the gear ratio p (the
motor-side torque the wheel side sees), of the drives in ``drives``.  The required reaction time
is the largest delay τ (after detection, :class:`model.analysis.nonlinear.AntiSlip`) with
``peak(τ) ≤ limit``: the curve is evaluated on the delay grid, the first grid delay whose peak
passes the limit brackets the answer with its predecessor, and Brent's method finds the crossing
inside (xtol 1 ms).  None when no delay of the grid suffices (``reason = "no delay suffices"``:
already ``peak(0) > limit``) or every one does (``"every delay suffices"``).

What the limit means.  Default ``limit = M_ad = 2 N0 r0 μ_max(v)``, the most the wheelset can pass
in steady adhesion, applied to the totals of the *healthy* drive ID2, the one the protection acts
on: a self-excited oscillation should not load it beyond what adhesion can ever deliver.  Before
the fault ID2's disc clutch already carries p·M(s0, v) = 2 μ(s0) N0 r0 (0.98 M_ad at s0 = 0.014,
120 km/h), so the margin is small, and the answer is about the oscillation's growth, not the
pre-load.  ID1's loads are not limited by default: its motor short-circuited, its torques are the
fault's own transient (its driving shaft carries the short-circuit torque, 1.4 M_ad referred to
the wheel at the calibrated set, a few milliseconds after the fault), which no reaction of ID2's
protection changes; ``drives=("ID1", "ID2")`` limits both (then typically no delay suffices) and
``ResponseResult``-style peaks of ID1 are returned in ``fault_drive_peaks`` either way.  A design
strength of the parts is given as ``limit`` [N m] (wheel-side torque).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from model.analysis.nonlinear import AntiSlip, NonlinearError, nonlinear_response
from model.analysis.response import ShortCircuit
from model.mechanics.assembly import DRIVES, BogieModel
from model.mechanics.operating_point import OperatingPoint, adhesion_moment

LIMITED_PARTS = ("disc_clutch.torque", "driving_shaft.torque")
DEFAULT_DELAYS = np.linspace(0.0, 0.5, 26)  # [s]


@dataclass(frozen=True)
class ReactionTime:
    """Outcome of :func:`required_reaction_time` (plain data)."""

    required_delay: float | None  # largest delay with peak ≤ limit [s]; None: see reason
    reason: str  # "found", "no delay suffices" or "every delay suffices"
    limit: float  # [N m] (wheel-side torque)
    limit_name: str  # "M_ad" or "strength"
    delays: np.ndarray  # delays of the curve [s]
    peak_torque: np.ndarray  # peak(τ) of the limited torques (wheel side) [N m]
    peak_output: tuple[str, ...]  # which output carries each peak
    unprotected_peak: float  # peak without protection [N m]
    detection_time: float | None  # when the protection detects the slip [s] (None: never)
    limited_outputs: tuple[str, ...]
    fault_drive_peaks: dict[str, float]  # ID1's limited torques' peaks (wheel side) [N m]
    anti_slip: AntiSlip  # the protection (its delay varied)
    operating_point: OperatingPoint
    evaluations: int  # nonlinear runs

    @property
    def reaction_after_fault(self) -> float | None:
        """Detection time + required delay: when the protection must act, after the fault [s]."""
        if self.required_delay is None or self.detection_time is None:
            return None
        return self.detection_time + self.required_delay


def limited_peak(result, outputs: tuple[str, ...], gear_ratio: float) -> tuple[float, str]:
    """(largest |total| of ``outputs`` referred to the wheel side [N m], which output)."""
    best, which = -1.0, ""
    for name in outputs:
        factor = gear_ratio if name.endswith("driving_shaft.torque") else 1.0
        value = abs(result.peaks[name]) * factor
        if value > best:
            best, which = value, name
    return best, which


def required_reaction_time(model: BogieModel, op: OperatingPoint,
                           excitation: ShortCircuit | None = None, limit: float | None = None,
                           anti_slip: AntiSlip | None = None,
                           delays: np.ndarray | None = None, drives: tuple[str, ...] = ("ID2",),
                           t_end: float = 2.0, fs: float = 10_000.0,
                           progress: Callable[[str], None] | None = None,
                           checkpoint: Callable[[], None] | None = None) -> ReactionTime:
    """The required reaction time of the protection and the curve peak(τ) (module docstring).

    ``limit`` [N m] wheel-side torque (default M_ad); ``anti_slip`` the protection whose delay is
    varied (default :class:`AntiSlip()`); ``delays`` [s] increasing, ≥ 0 (default 0 … 0.5 s in
    20 ms); ``drives`` whose disc clutch and driving shaft torques are limited; ``progress``
    gets a line after each delay of the grid; ``checkpoint`` is handed to every run
    (:func:`model.analysis.nonlinear.nonlinear_response`: what it raises ends the search).

    Example::

        >>> import numpy as np
        >>> from model import (build_model, default_operating_point, load_parameters,
        ...                    required_reaction_time)
        >>> parameters = load_parameters()
        >>> model = build_model(parameters)
        >>> result = required_reaction_time(model, default_operating_point(parameters, s0=0.014),
        ...                                 delays=np.array([0.0, 0.5]), fs=2000.0)
        >>> result.reason in ("found", "no delay suffices", "every delay suffices")
        True
    """
    excitation = ShortCircuit() if excitation is None else excitation
    base = AntiSlip() if anti_slip is None else anti_slip
    if not isinstance(base, AntiSlip) or not base.enabled:
        raise NonlinearError("the required reaction time needs an enabled anti-slip protection")
    delays = DEFAULT_DELAYS if delays is None else np.asarray(delays, dtype=float)
    if delays.ndim != 1 or len(delays) < 2 or not np.all(np.isfinite(delays)) \
            or delays[0] < 0 or np.any(np.diff(delays) <= 0):
        raise NonlinearError("delays must be at least two increasing, finite values ≥ 0 [s]")
    if not drives or any(d not in DRIVES for d in drives):
        raise NonlinearError(f"drives must be among {', '.join(DRIVES)}, got {drives!r}")
    p = model.parameters
    if limit is None:
        limit, limit_name = adhesion_moment(p, op.v, op.N0), "M_ad"
    else:
        if isinstance(limit, bool) or not isinstance(limit, int | float) \
                or not math.isfinite(limit) or limit <= 0:
            raise NonlinearError(f"limit = {limit!r} is not allowed: must be a positive torque "
                                 "[N m]")
        limit, limit_name = float(limit), "strength"
    gear = p["gear_ratio"]
    limited = tuple(f"{d}.{part}" for d in drives for part in LIMITED_PARTS)
    fault_outputs = tuple(f"ID1.{part}" for part in LIMITED_PARTS)
    outputs = sorted(set(limited + fault_outputs))
    evaluations = 0

    def run(protection: AntiSlip | None):
        nonlocal evaluations
        evaluations += 1
        return nonlinear_response(model, op, excitation, t_end, fs, anti_slip=protection,
                                  outputs=outputs, checkpoint=checkpoint)

    def peak(delay: float) -> tuple[float, str, float | None]:
        result = run(AntiSlip(True, float(delay), base.threshold, base.rate, base.floor))
        value, which = limited_peak(result, limited, gear)
        return value, which, result.detection_time

    unprotected = run(None)
    unprotected_peak, _ = limited_peak(unprotected, limited, gear)
    fault_peaks = {name: abs(unprotected.peaks[name]) * (gear if "driving_shaft" in name else 1.0)
                   for name in fault_outputs}
    values, which, detection = [], [], None
    for i, delay in enumerate(delays):
        value, name, detection = peak(delay)
        values.append(value)
        which.append(name)
        if progress is not None:
            progress(f"delay {delay:.3f} s: peak {value:.6g} N m ({i + 1}/{len(delays)})")
    values = np.array(values)
    over = np.flatnonzero(values > limit)
    if len(over) == 0:
        required, reason = None, "every delay suffices"
    elif over[0] == 0:
        required, reason = None, "no delay suffices"
    else:
        lo, hi = float(delays[over[0] - 1]), float(delays[over[0]])
        required = brentq(lambda d: peak(d)[0] - limit, lo, hi, xtol=1e-3)
        reason = "found"
    return ReactionTime(required, reason, float(limit), limit_name, delays, values, tuple(which),
                        float(unprotected_peak), detection, limited, fault_peaks, base, op,
                        evaluations)
