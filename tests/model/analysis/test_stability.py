"""The stability limit's search (:func:`model.analysis.stability.stability_limit`): its hook before
each eigen-analysis sees every evaluation, and a caller stops the search by raising there."""

from __future__ import annotations

import pytest

from model import KMH, build_model, load_parameters
from model.analysis.stability import stability_limit


class Stop(Exception):
    pass


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    return build_model(parameters), parameters["wheel_force"], parameters["motor_slope"]


def test_the_hook_runs_before_every_eigen_analysis_and_leaves_the_limit_unchanged(setup):
    model, N0, b_M = setup
    calls = []
    hooked = stability_limit(model, 120 * KMH, N0, b_M, bracket=(0.007, 0.009),
                             before_each=lambda: calls.append(1))
    plain = stability_limit(model, 120 * KMH, N0, b_M, bracket=(0.007, 0.009))
    assert len(calls) == hooked.evaluations > 2
    assert hooked.s0_limit == plain.s0_limit


def test_raising_in_the_hook_stops_the_search_at_once(setup):
    model, N0, b_M = setup
    calls = []

    def stop_at_the_third() -> None:
        calls.append(1)
        if len(calls) == 3:
            raise Stop

    with pytest.raises(Stop):
        stability_limit(model, 120 * KMH, N0, b_M, bracket=(0.007, 0.009),
                        before_each=stop_at_the_third)
    assert len(calls) == 3
