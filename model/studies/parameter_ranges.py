"""A range of values an unpublished parameter may take, with the source of its ends.

Two studies declare such ranges: the calibration searches within its **bounds** (what the part can
be, :mod:`model.studies.calibration_bounds`) and the uncertainty study samples its **prior**
(what is still plausible around the calibrated value, :mod:`model.studies.uncertainty`).  Both
use this one class, and a prior of a calibrated parameter lies within its calibration bounds
(:func:`outside`, checked by the tests), so that no study samples a value the calibration rules
out.  Plain data and arithmetic.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

BOUND_TOLERANCE = 1e-3  # a value this close to an end sits on it (relative; of the range if linear)


@dataclass(frozen=True)
class ParameterRange:
    """``low`` … ``high`` [the parameter's schema unit] for the parameter ``name``; ``reason``
    says why the ends are where they are; ``log``: a scale parameter, searched on its logarithm
    and sampled log-uniformly (False: on its value, uniformly, e.g. a height); ``source``: the
    published data on real vehicles the ends come from, or that the range is an engineering
    estimate for want of such data (empty where the range is not a hardware range, e.g. a prior
    around a calibrated value)."""

    name: str
    low: float
    high: float
    reason: str
    log: bool = True
    source: str = ""

    @property
    def bounds_source(self) -> str:
        """The reason for the ends and, where declared, the data they come from."""
        return f"{self.reason} [{self.source}]" if self.source else self.reason

    def on_bound(self, value: float) -> bool:
        """Whether ``value`` sits on one of the ends: within 0.1 % of it (log ranges), or within
        0.1 % of the range (the others)."""
        if self.log:
            return min(abs(math.log(value / self.low)), abs(math.log(value / self.high))) \
                <= BOUND_TOLERANCE
        return min(abs(value - self.low), abs(value - self.high)) \
            <= BOUND_TOLERANCE * (self.high - self.low)

    def distribution(self):
        """The frozen ``scipy.stats`` distribution over the range: log-uniform or uniform."""
        from scipy import stats  # not needed by the parameter table (``bogie parameters``)

        if self.log:
            return stats.loguniform(self.low, self.high)
        return stats.uniform(self.low, self.high - self.low)


def outside(inner: Iterable[ParameterRange], outer: Iterable[ParameterRange]) -> list[str]:
    """The names whose range in ``inner`` reaches beyond their range in ``outer`` (parameters
    that ``outer`` does not declare are not compared), each as ``"name: a … b not within c … d"``."""
    bounds = {r.name: r for r in outer}
    return [f"{r.name}: {r.low:g} … {r.high:g} not within {bounds[r.name].low:g} … "
            f"{bounds[r.name].high:g}"
            for r in inner if r.name in bounds
            and not bounds[r.name].low <= r.low <= r.high <= bounds[r.name].high]
