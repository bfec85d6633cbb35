"""What a dashboard computation depends on, and the computations of a change.

:class:`State` is a snapshot of the dashboard's parameters as primitives (the cache keys of
:mod:`app.results.compute`, rounded: no float noise in the keys).  Two stages per change:

* *fast* (:func:`fast`): the eigen-analysis of the operating point (status, creep, tables, mode
  shapes) and the short-circuit response (time histories, peaks);
* *slow* (:func:`slow`): the stability limit s0*(v) and the dense root locus, which only depend
  on part of the parameters and are usually cached.

Each computation is independent of the others; served, they run side by side on worker threads
(:mod:`app.dashboard.scheduler`), one BLAS thread each
(:func:`app.services.thread_pools.limit_blas_threads`).  A rejected parameter combination raises
one of :data:`MODEL_ERRORS`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from app.results import compute
from model import NoStabilityLimit, OperatingPointError, ParameterError

MODEL_ERRORS = (OperatingPointError, ParameterError, NoStabilityLimit, ValueError,
                np.linalg.LinAlgError)
# decimals of each operating-point quantity in the cache keys (no float noise in the keys)
KEY_DIGITS = {"s0": 7, "v": 3, "N0": 3, "b_M": 3}


def key_value(name: str, value: float) -> float:
    """``value`` of the operating-point quantity ``name`` as the cache keys hold it."""
    return float(round(value, KEY_DIGITS[name]))


@dataclass(frozen=True)
class State:
    """The primitives a computation depends on (a snapshot of the parameters)."""

    params_path: str  # the parameter set (app.results.variants: a bundled file or a variant)
    rail: str
    s0: float  # [-]
    v: float  # [km/h]
    N0: float  # [kN]
    b_M: float  # [N m s/rad]
    M0: float  # [kN m]
    f: float  # [Hz]
    D: float  # [-]
    dt: float | None  # [ms]; None: automatic (continuous motor torque)
    t_end: float  # [s]
    locus: str  # the root locus's swept parameter: "s0" or "v"

    @property
    def point(self) -> tuple:
        return (self.params_path, self.rail, self.s0, self.v, self.N0, self.b_M)

    @property
    def locus_key(self) -> tuple:
        """What the root locus depends on: (set, rail, swept parameter, fixed value, N0, b_M)."""
        fixed = self.v if self.locus == "s0" else self.s0
        return (self.params_path, self.rail, self.locus, fixed, self.N0, self.b_M)

    @property
    def limit_key(self) -> tuple:
        """What s0*(v) depends on besides the set: (rail, v, N0, b_M)."""
        return (self.rail, self.v, self.N0, self.b_M)


def point(state: State) -> compute.PointResult:
    """Eigenvalues, verdict and modes at the operating point."""
    return compute.point_result(*state.point)


def response(state: State) -> compute.ResponseView:
    """The short-circuit response at the operating point."""
    return compute.response_result(*state.point, state.M0, state.f, state.D, state.dt,
                                   state.t_end)


def limit(state: State) -> compute.LimitResult:
    """The stability limit s0*(v) at the state's speed."""
    return compute.limit_result(state.params_path, state.rail, state.v, state.N0, state.b_M)


def coarse_locus(state: State) -> compute.LocusResult:
    """The coarse root locus (shown first)."""
    return compute.locus_result(*state.locus_key)


def dense_locus(state: State) -> compute.LocusResult:
    """The dense root locus (replaces the coarse one)."""
    return compute.dense_locus_result(*state.locus_key)


def fast(state: State) -> tuple[compute.PointResult, compute.ResponseView]:
    """(point result, response result): the first answer to a change."""
    return point(state), response(state)


def slow(state: State) -> tuple[compute.LimitResult, compute.LocusResult]:
    """(stability limit, dense root locus)."""
    return limit(state), dense_locus(state)
