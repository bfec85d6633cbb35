"""The calibration's targets (model/studies/calibration_targets.py): the eigen-analyses by rank
that the calibration and the literature tests compare (the numbers themselves are
tests/literature/test_table1.py)."""

from __future__ import annotations

import numpy as np

from model import load_parameters
from model.studies.calibration_targets import evaluate_by_rank


def test_evaluation_by_rank_of_the_calibrated_set():
    """The k-th entry is the k-th pair by Im; the character flags agree with the matching."""
    e = evaluate_by_rank(load_parameters())
    assert np.all(np.diff(e.stable.imag) >= 0)
    assert e.unstable is not None
    assert len(e.unstable) == 10
    assert np.all(np.diff(e.unstable_real) <= 0)
    assert e.max_real_stable < 0
    assert e.max_real_below_limit < 0
