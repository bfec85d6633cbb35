"""The calibration's free parameters (model/studies/calibration_bounds.py): the estimate inside
every parameter's bounds, the physical constraints between them and their repair."""

from __future__ import annotations

import numpy as np

from model import load_parameters
from model.mechanics.parameters import ESTIMATE_FILE
from model.studies.calibration_bounds import FREE_PARAMETERS, constraint_values, with_constraints


def test_constraints_keep_inertias_and_polach_factors_consistent():
    """A rigid body's principal inertias obey |I_x − I_y| <= I_z <= I_x + I_y; Polach's
    kS <= kA.  constraint_values is <= 0 exactly when they hold; with_constraints restores
    them."""
    p = load_parameters(ESTIMATE_FILE).replace(frame_inertia_x=1000.0, frame_inertia_y=2000.0,
                                               frame_inertia_z=5000.0, polach_kA=0.35,
                                               polach_kS=0.4)
    assert np.count_nonzero(constraint_values(p) > 0) == 2
    fixed = with_constraints(p)
    assert fixed["frame_inertia_z"] == 3000.0
    assert fixed["polach_kS"] == 0.35
    assert np.all(constraint_values(fixed) <= 0)
    too_small = with_constraints(p.replace(frame_inertia_z=500.0))
    assert too_small["frame_inertia_z"] == 1000.0  # I_y − I_x
    untouched = load_parameters(ESTIMATE_FILE)
    assert with_constraints(untouched) is untouched
    assert np.all(constraint_values(untouched) <= 0)


def test_every_free_parameter_has_bounds_around_its_estimate():
    """The estimate lies inside its calibration bounds (the search starts there), each bound
    with its reason."""
    estimate = load_parameters(ESTIMATE_FILE)
    for f in FREE_PARAMETERS:
        assert f.low < f.high
        assert f.reason
        assert f.low <= estimate[f.name] <= f.high, f.name
        if f.log:
            assert f.low > 0, f.name
