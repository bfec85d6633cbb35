"""Parameter ranges: one class for the calibration's bounds and the uncertainty study's priors,
and a prior that never reaches beyond the bounds of a parameter the calibration fits."""

from __future__ import annotations

import numpy as np
import pytest

from model.mechanics.parameters import SCHEMA
from model.studies.calibration_bounds import FREE_PARAMETERS
from model.studies.parameter_ranges import ParameterRange, outside
from model.studies.uncertainty import UNCERTAIN_PARAMETERS


def test_on_bound_within_a_tenth_of_a_percent():
    f = ParameterRange("x", 2.0, 8.0, "test")
    assert f.on_bound(2.0)
    assert f.on_bound(8.0 * (1 - 5e-4))
    assert not f.on_bound(2.0 * 1.002)
    linear = ParameterRange("h", -0.4, 0.6, "test", log=False)
    assert linear.on_bound(0.5995)
    assert not linear.on_bound(0.0)


def test_distribution_covers_exactly_the_range():
    for r in (ParameterRange("x", 2.0, 8.0, "test"), ParameterRange("h", -0.4, 0.6, "t", log=False)):
        d = r.distribution()
        assert d.ppf(0.0) == pytest.approx(r.low, rel=1e-12, abs=1e-12)
        assert d.ppf(1.0) == pytest.approx(r.high, rel=1e-12)
    # log-uniform: the geometric mean is the median; uniform: the arithmetic mean
    assert ParameterRange("x", 2.0, 8.0, "t").distribution().median() == pytest.approx(4.0)
    assert ParameterRange("h", -0.4, 0.6, "t", log=False).distribution().median() == pytest.approx(0.1)


def test_outside_names_the_ranges_that_reach_beyond():
    bounds = (ParameterRange("a", 1.0, 10.0, "bounds"), ParameterRange("b", 1.0, 10.0, "bounds"))
    inner = (ParameterRange("a", 2.0, 10.0, "inside, up to the bound"),
             ParameterRange("b", 0.5, 5.0, "below the lower bound"),
             ParameterRange("c", 0.0, 1e9, "not calibrated: not compared"))
    assert outside(inner, bounds) == ["b: 0.5 … 5 not within 1 … 10"]


def test_every_prior_lies_within_the_calibration_bounds():
    """A sample of the uncertainty study never takes a value the calibration rules out (the two
    declarations drifted apart once: the priors of polach_B and of the yaw dampers reached up to
    1.33x, 1.7x and 1.2x beyond the calibration's upper bounds)."""
    assert outside(UNCERTAIN_PARAMETERS, FREE_PARAMETERS) == []
    calibrated = {f.name for f in FREE_PARAMETERS}
    assert len(calibrated & {p.name for p in UNCERTAIN_PARAMETERS}) >= 10  # the check compares


def test_declared_ranges_are_well_formed():
    for r in (*FREE_PARAMETERS, *UNCERTAIN_PARAMETERS):
        assert r.name in SCHEMA, r.name
        assert np.isfinite([r.low, r.high]).all(), r.name
        assert r.low < r.high, r.name
        assert r.low > 0 or not r.log, r.name
        assert r.reason, r.name
    for group in (FREE_PARAMETERS, UNCERTAIN_PARAMETERS):
        names = [r.name for r in group]
        assert len(names) == len(set(names))
