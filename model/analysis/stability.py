"""Stability limit s0*(v): the smallest creepage at which the bogie becomes unstable.

Found by root finding (Brent) on the largest real part of the non-rigid eigenvalues, after an
expanding bracket search; not by scanning a grid.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from scipy.optimize import brentq

from model.analysis.eigen import eigen_analysis
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import OperatingPoint


class NoStabilityLimit(ValueError):
    """The bogie is stable (or unstable) over the whole searched creepage range."""


@dataclass(frozen=True)
class StabilityLimit:
    v: float  # speed [m/s]
    s0_limit: float  # critical creepage [-]
    evaluations: int  # eigen-analyses used


def max_real_part(model: BogieModel, op: OperatingPoint) -> float:
    """Largest real part of the non-rigid eigenvalues [1/s]."""
    return eigen_analysis(model, op, vectors=False).max_real_part


def stability_limit(model: BogieModel, v: float, N0: float, b_M: float, s0_low: float = 1e-4,
                    s0_high: float = 0.5, xtol: float = 1e-7,
                    bracket: tuple[float, float] | None = None,
                    before_each: Callable[[], None] | None = None) -> StabilityLimit:
    """Smallest s0 in (s0_low, s0_high) where the largest real part crosses zero at speed v [m/s].

    The bracket starts at ``s0_low`` (must be stable) and doubles an upper creepage until the bogie
    is unstable; Brent's method then finds the crossing to ``xtol``.

    ``bracket = (stable s0, unstable s0)`` [-] narrows the search when the caller knows where the
    first crossing is (e.g. the neighbouring points of a root locus over s0 where its branches turn
    unstable; the caller vouches that smaller creepages are stable).  Both ends are checked by a
    full eigen-analysis; if either does not hold, the bracket is ignored and the search above runs.

    ``before_each()`` is called before every eigen-analysis: a caller that no longer needs the
    limit (an interactive view whose speed has moved on) stops the search by raising there.

    Example::

        >>> from model import KMH, build_model, load_parameters, stability_limit
        >>> parameters = load_parameters()
        >>> limit = stability_limit(build_model(parameters), 120 * KMH, parameters["wheel_force"],
        ...                         parameters["motor_slope"])
        >>> round(limit.s0_limit, 4)                    # the study: 0.0082
        0.0082
    """
    count = 0

    def growth(s0: float) -> float:
        nonlocal count
        if before_each is not None:
            before_each()
        count += 1
        return max_real_part(model, OperatingPoint(s0, v, N0, b_M))

    def holds(low: float, high: float) -> bool:
        return s0_low <= low < high <= s0_high and growth(low) <= 0 < growth(high)

    if bracket is not None and holds(*map(float, bracket)):
        low, high = map(float, bracket)
    else:
        if growth(s0_low) > 0:
            raise NoStabilityLimit(f"already unstable at s0 = {s0_low:g}")
        low, high = s0_low, 2 * s0_low
        while growth(high) <= 0:
            low, high = high, 2 * high
            if high > s0_high:
                raise NoStabilityLimit(f"stable over the whole range s0 <= {s0_high:g}")
    s0 = brentq(growth, low, high, xtol=xtol, rtol=1e-10)
    return StabilityLimit(v, float(s0), count)
