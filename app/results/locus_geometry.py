"""The root locus as drawn: where a sweep's grid is refined, and where a branch's line is broken.

Pure geometry of tracked eigenvalue branches (numpy only), in plot units: Re [1/s], Im [Hz].
"""

from __future__ import annotations

import math

import numpy as np

LOCUS_UNIFORM_SHARE = 0.3  # share of the dense points spread evenly (the rest follow the motion)
LOCUS_JUMP_FACTOR = 2.5  # a step this many times as fast as both neighbouring steps is a jump
LOCUS_JUMP_MIN = 0.5  # ... and longer than this in plot units (Re [1/s], Im [Hz]): line broken
LOCUS_JUMP_LONG = 0.04  # a step longer than this share of the plot (Re and Im spans of the
LOCUS_JUMP_SIDE = 1.5  # sweep) is a jump already when it is this many times as fast as one
# neighbouring step: a branch accelerating into a collision of eigenvalues (steps 10, 16, 50,
# then 5 [1/s]) is not resolved by any grid


def _step_lengths(eigenvalues: np.ndarray, re_unit: float, im_unit: float) -> np.ndarray:
    """(n_points - 1, n_branches) step lengths of the branches, Re counted in ``re_unit`` and
    Im in ``im_unit`` [1/s]."""
    steps = np.diff(eigenvalues, axis=0)
    return np.hypot(steps.real / re_unit, steps.imag / im_unit)


def _plot_shares(eigenvalues: np.ndarray) -> np.ndarray:
    """Step lengths as shares of the plot: Re and Im divided by the sweep's spans of Re and Im
    (the axes' extent when the whole sweep is shown)."""
    finite = eigenvalues[np.isfinite(eigenvalues)]
    spans = [np.ptp(part) if finite.size and np.ptp(part) > 0 else 1.0
             for part in (finite.real, finite.imag)]
    return _step_lengths(eigenvalues, *spans)


def _plot_steps(eigenvalues: np.ndarray) -> np.ndarray:
    """Step lengths in plot units (Re [1/s], Im [Hz])."""
    return _step_lengths(eigenvalues, 1.0, 2 * math.pi)


def refine_grid(values: np.ndarray, eigenvalues: np.ndarray, n_points: int) -> np.ndarray:
    """``n_points`` parameter values from values[0] to values[-1], denser where the branches of
    a coarse sweep (``eigenvalues`` at ``values``) move fast: each coarse interval gets a share
    LOCUS_UNIFORM_SHARE / intervals of the points plus a share of the rest proportional to the
    largest distance any branch travels across it on the plot (Re [1/s], Im [Hz])."""
    values = np.asarray(values, dtype=float)
    intervals = len(values) - 1
    motion = np.nan_to_num(_plot_steps(eigenvalues).max(axis=1)) if eigenvalues.size else \
        np.zeros(intervals)
    weight = np.full(intervals, LOCUS_UNIFORM_SHARE / intervals)
    if motion.sum() > 0:
        weight += (1.0 - LOCUS_UNIFORM_SHARE) * motion / motion.sum()
    else:
        weight = np.full(intervals, 1.0 / intervals)
    steps = np.maximum(1, np.floor(weight / weight.sum() * (n_points - 1)).astype(int))
    while steps.sum() < n_points - 1:  # hand the rounding remainder to the busiest intervals
        steps[np.argmax(weight / steps)] += 1
    pieces = [np.linspace(values[i], values[i + 1], steps[i] + 1)[:-1] for i in range(intervals)]
    return np.concatenate([*pieces, values[-1:]])


def locus_jumps(values: np.ndarray, eigenvalues: np.ndarray) -> np.ndarray:
    """Steps that are jumps (a branch meeting another one and turning, or moving faster than the
    grid resolves): per unit of the swept parameter, more than LOCUS_JUMP_FACTOR times as fast
    as in both neighbouring steps of the same branch, and longer than LOCUS_JUMP_MIN plot units
    (Re [1/s], Im [Hz]); or longer than LOCUS_JUMP_LONG of the plot (Re and Im measured in
    shares of the sweep's spans, as they appear on the plot) and more than LOCUS_JUMP_SIDE times
    as fast as one of its neighbouring steps (a branch accelerating into a collision with
    another one grows its steps geometrically, 10, 16, 50 [1/s], and no grid resolves the last
    ones).  The plots break the line there instead of drawing a straight segment across the
    plane; the points themselves stay."""
    steps = _plot_steps(eigenvalues)
    if len(steps) < 3:
        return np.zeros(steps.shape, dtype=bool)
    rate = steps / np.diff(np.asarray(values, dtype=float))[:, None]
    before = np.vstack([rate[1:2], rate[:-1]])  # the first / last step: their only neighbour
    after = np.vstack([rate[1:], rate[-2:-1]])
    both = (rate > LOCUS_JUMP_FACTOR * np.maximum(before, after)) & (steps > LOCUS_JUMP_MIN)
    one = (rate > LOCUS_JUMP_SIDE * np.minimum(before, after)) & \
        (_plot_shares(eigenvalues) > LOCUS_JUMP_LONG)
    return both | one


def broken_columns(series: np.ndarray, jumps: np.ndarray | None) -> list[np.ndarray]:
    """One float array per branch (column of ``series``, (n_points, n_branches) real) with NaN
    inserted at its jumps: Bokeh breaks a line at NaN."""
    out = []
    for b in range(series.shape[1]):
        y = np.asarray(series[:, b], dtype=float)
        if jumps is not None and jumps[:, b].any():
            y = np.insert(y, np.flatnonzero(jumps[:, b]) + 1, np.nan)
        out.append(np.ascontiguousarray(y))
    return out
