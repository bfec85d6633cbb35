"""The stability verdict at an operating point from what is known already: the preview a dragged
slider shows before its release computes the full answer.

Sources, in this order (the first that decides gives the verdict; the eigenvalues shown come
from the best source that has them):

Everything is looked up in the one results cache (:mod:`app.results.cache`) the full answers
fill:

1. the point computed before (:func:`app.results.compute.known_point`): exact;
2. the stability limit s0*(v) at the point's speed, wheel force and motor slope
   (:func:`app.results.compute.known_limit`): stable below it, exactly (it is the smallest
   unstable creepage found by the eigen-analysis);
3. a root locus through the point (over s0 at its speed, or over v at its creepage;
   :func:`app.results.compute.known_locus`): the tracked branches interpolated linearly between
   the two neighbouring sweep points; the verdict where both neighbours agree, else the
   interpolated leading eigenvalue's sign;
4. the reduced model of the session's root locus (:func:`app.results.compute.reduced_estimate`:
   one small eigenproblem, never a dense one), where its error estimates decide the verdict.

Where none decides, the preview says so (``stable`` None) instead of guessing.  Nothing here
runs a dense eigen-analysis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from app.results import compute
from app.results.case import Case, CaseBase, Sweep
from model import creep_law

# the sliders that preview while dragged: the operating point's (a quantity that changes the
# model, role "override", needs the model rebuilt: it is computed on release)
PREVIEWED = Case.names("point")
EXACT = "computed at this point"
BELOW_LIMIT = "s0 below s0*(v), exact"
ABOVE_LIMIT = "s0 at or above s0*(v)"
LOCUS = "root locus, both neighbouring points"
INTERPOLATED = "root locus, interpolated"
REDUCED = "reduced model"
NOT_COVERED = "not computed yet"


@dataclass(frozen=True)
class Preview:
    """What is known at one operating point without computing it."""

    point: Case  # the point (a record's point(): s0 [-], v [km/h], N0 [kN], b_M …)
    stable: bool | None  # None: nothing known decides it
    source: str  # where the verdict comes from (one of the names above)
    s0_limit: float | None  # s0*(v) at the point's speed, N0, b_M, if known [-]
    eigenvalues: np.ndarray  # upper-half-plane eigenvalues for the locus marker [1/s]
    leading: complex | None  # the eigenvalue with the largest real part [1/s]
    leading_source: str  # where it comes from (EXACT, INTERPOLATED, REDUCED or "")
    leading_error: float | None  # its estimated absolute error [1/s] (reduced model), else None
    mu0: float  # μ(s0, v) at the point [-] (the creep plot's marker)

    @property
    def s0(self) -> float:
        return self.point.s0

    @property
    def v_kmh(self) -> float:
        return self.point.v


def along(locus: compute.LocusResult, x: float):
    """The locus's branches at ``x`` (its parameter's display units, inside its range):
    (upper eigenvalues interpolated linearly between the neighbouring points [1/s], the
    neighbours' parameter values, the neighbours' stability (bool, bool)).  A branch that jumps
    between the neighbours takes the nearer point's value (the line is broken there)."""
    values = np.asarray(locus.values, dtype=float)
    i = int(np.clip(np.searchsorted(values, x, side="right") - 1, 0, len(values) - 2))
    fraction = float(np.clip((x - values[i]) / (values[i + 1] - values[i]), 0.0, 1.0))
    low, high = locus.eigenvalues[i], locus.eigenvalues[i + 1]
    lam = low + fraction * (high - low)
    if locus.jumps is not None:
        nearer = high if fraction > 0.5 else low
        lam = np.where(locus.jumps[i], nearer, lam)
    return lam, (float(values[i]), float(values[i + 1])), (bool(locus.stable[i]),
                                                            bool(locus.stable[i + 1]))


def _covering_locus(point: CaseBase, first: str):
    """(locus, x) of a known root locus through the point, the sweep over ``first`` tried first;
    (None, None) if none is known."""
    for parameter in (first, *(p for p in ("s0", "v") if p != first)):
        x = getattr(point, parameter)
        locus = compute.known_locus(point.sweep(parameter))
        if locus is not None and locus.values[0] <= x <= locus.values[-1]:
            return locus, x
    return None, None


def _leading(lam: np.ndarray) -> complex | None:
    finite = lam[np.isfinite(lam)]
    return complex(finite[np.argmax(finite.real)]) if finite.size else None


def preview(case: CaseBase, sweep: Sweep | None, dragged: str = "s0") -> Preview:
    """The preview at the case's point; ``sweep``: the root locus on screen (its reduced model
    is the last source), ``dragged``: the slider moved (its sweep is tried first).  Costs at
    most one reduced eigenproblem; raises what the model raises for an invalid point."""
    point = case.point()
    s0 = point.s0
    m = compute.model_for(point)
    op = point.operating_point()  # validates the point (OperatingPointError)
    mu0 = float(creep_law(m.parameters, op.N0).mu(op.s0, op.v))
    limit = compute.known_limit(point)
    s0_limit = limit.s0_limit if limit is not None else None
    stable, source = None, NOT_COVERED
    lam, leading, leading_source, leading_error = np.zeros(0, complex), None, "", None

    exact = compute.known_point(point)
    if exact is not None:
        stable, source = exact.stable, EXACT
        lam = np.array([mode.eigenvalue for mode in exact.modes], dtype=complex)
        upper = exact.eigenvalues[exact.eigenvalues.imag >= 0]
        leading, leading_source, leading_error = _leading(upper), EXACT, 0.0
        return Preview(point, stable, source, s0_limit, lam, leading, leading_source,
                       leading_error, mu0)

    if s0_limit is not None and s0 < s0_limit:
        stable, source = True, BELOW_LIMIT
    locus, x = _covering_locus(point, "v" if dragged == "v" else "s0")
    if locus is not None:
        lam, between, neighbours = along(locus, x)
        leading, leading_source = _leading(lam), INTERPOLATED
        if stable is None:
            if s0_limit is not None and locus.parameter == "s0" and between[0] <= s0_limit:
                # s0* ≤ s0 < the next sweep point: unstable from s0* on, whatever the sweep's
                # points (the limit is exact, the sweep's points are not there)
                stable, source = False, ABOVE_LIMIT
            elif neighbours[0] == neighbours[1]:
                stable, source = neighbours[0], LOCUS
            elif leading is not None:
                stable, source = leading.real <= 0.0, INTERPOLATED
    elif stable is None and s0_limit is not None:
        stable, source = False, ABOVE_LIMIT
    if stable is not None and leading is not None:
        return Preview(point, stable, source, s0_limit, lam, leading, leading_source, None, mu0)

    estimate = None
    if sweep is not None:
        estimate = compute.reduced_estimate(sweep, point)
    if estimate is not None and estimate.eigenvalues.size:
        i = estimate.leading
        lam = estimate.eigenvalues[estimate.eigenvalues.imag >= 0]
        leading, leading_source = complex(estimate.eigenvalues[i]), REDUCED
        leading_error = float(estimate.absolute_error[i])
        if stable is None and estimate.stable is not None:
            stable, source = estimate.stable, REDUCED
    return Preview(point, stable, source, s0_limit, lam, leading, leading_source, leading_error,
                   mu0)


def describe(result: Preview, dragged: str) -> list[str]:
    """The preview's lines of text (HTML-free, units given): the dragged value and the margin to
    the limit, the leading eigenvalue and where the verdict comes from."""
    point = result.point
    s0, v_kmh = point.s0, point.v
    value = (f"s0 = {s0:.4f}" if dragged == "s0"
             else point.quantity(dragged).said(getattr(point, dragged)))
    if result.s0_limit is not None:
        limit = (f"limit s0* = {result.s0_limit:.4f} at {v_kmh:g} km/h "
                 f"(margin s0* − s0 = {result.s0_limit - s0:+.4f})")
        if dragged != "s0":
            limit = f"s0 = {s0:.4f}, {limit}"
    else:
        limit = f"limit s0* at {v_kmh:g} km/h not computed yet"
    lines = [f"{value}, {limit}"]
    if result.leading is not None:
        lam = result.leading
        error = (f" ± {result.leading_error:.1e}" if result.leading_error else "")
        kind = (f"{abs(lam.imag) / (2 * math.pi):.2f} Hz" if abs(lam.imag) > 1e-9 else "real")
        lines.append(f"leading λ: Re = {lam.real:+.4f}{error} 1/s, {kind} "
                     f"({result.leading_source})")
    if result.stable is None:
        lines.append("verdict: no computed result covers this point yet — release for the full "
                     "answer")
    else:
        lines.append(f"verdict from: {result.source}")
    return lines
