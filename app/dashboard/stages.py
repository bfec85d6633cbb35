"""The computations of a dashboard's change.

The dashboard's state is a case record (:class:`app.results.case.Case`: the parameter set, the
operating point, the short circuit, the horizon; :meth:`BogieDashboard.state`) and the root
locus's swept quantity (a :class:`app.results.case.Sweep`).  Two stages per change:

* *fast* (:func:`fast`): the eigen-analysis of the operating point (status, creep, tables, mode
  shapes) and the short-circuit response (time histories, peaks);
* *slow* (:func:`slow`): the stability limit s0*(v) and the dense root locus, which only depend
  on part of the case and are usually kept.

Each computation is independent of the others; served, they run side by side on worker threads
(:mod:`app.dashboard.scheduler`), one BLAS thread each
(:func:`app.services.thread_pools.limit_blas_threads`).  A rejected parameter combination raises
one of :data:`MODEL_ERRORS`.
"""

from __future__ import annotations

import numpy as np

from app.results import compute
from app.results.case import CaseBase, Sweep
from model import NoStabilityLimit, OperatingPointError, ParameterError

MODEL_ERRORS = (OperatingPointError, ParameterError, NoStabilityLimit, ValueError,
                np.linalg.LinAlgError)


def point(case: CaseBase) -> compute.PointResult:
    """Eigenvalues, verdict and modes at the operating point."""
    return compute.point_result(case)


def response(case: CaseBase) -> compute.ResponseView:
    """The short-circuit response at the operating point."""
    return compute.response_result(case)


def limit(case: CaseBase, before_each=None) -> compute.LimitResult:
    """The stability limit s0*(v) at the case's speed (``before_each``: see
    :func:`app.results.compute.limit_result`)."""
    return compute.limit_result(case, before_each)


def coarse_locus(sweep: Sweep) -> compute.LocusResult:
    """The coarse root locus (shown first)."""
    return compute.locus_result(sweep)


def dense_locus(sweep: Sweep) -> compute.LocusResult:
    """The dense root locus (replaces the coarse one)."""
    return compute.dense_locus_result(sweep)


def fast(case: CaseBase) -> tuple[compute.PointResult, compute.ResponseView]:
    """(point result, response result): the first answer to a change."""
    return point(case), response(case)


def slow(case: CaseBase, sweep: Sweep) -> tuple[compute.LimitResult, compute.LocusResult]:
    """(stability limit, dense root locus)."""
    return limit(case), dense_locus(sweep)
