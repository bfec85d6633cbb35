"""The dashboard's sensitivity tornado (app/dashboard/sensitivity_view.py) without a server.

Expectations come from model.analysis.sensitivity at the dashboard's point, never typed in.  Building a
dashboard computes the stability limit, a root locus and the derivative matrices (seconds), so
these tests are slow.
"""

from __future__ import annotations

import numpy as np
import pytest

from app.dashboard.sensitivity_view import BARS, ranked, sensitivity_data
from app.results import compute
from model.analysis.sensitivity import eigen_sensitivities


@pytest.fixture(scope="module")
def dash():
    from app.dashboard.dashboard import BogieDashboard

    return BogieDashboard()


@pytest.mark.slow
def test_tornado_shows_the_models_sensitivities_of_the_selected_mode(dash):
    view = dash.sensitivity
    assert view.data is not None, view.note.object
    assert view.data.key == dash.state().point()
    dash.mode = 3
    model = compute.model("", dash.rail)
    op = dash.state().operating_point()
    expected = eigen_sensitivities(model, op)
    growth = expected.values * expected.derivatives[:, 2].real
    largest = expected.names[int(np.argmax(np.abs(growth)))]
    shown = view.source.data
    assert len(shown["name"]) == BARS
    assert shown["name"][-1] == largest  # the largest bar on top
    assert list(view.figure.y_range.factors) == list(shown["name"])
    assert "ν = 3" in view.note.object


@pytest.mark.slow
def test_targets_and_a_new_point(dash):
    view = dash.sensitivity
    view.target.value = "limit"
    names = view.source.data["name"]
    # the limit is the creep maximum at 120 km/h: only creep-law quantities move it
    nonzero = [n for n, v in zip(names, view.source.data["value"], strict=True) if v != 0]
    assert nonzero
    assert all(n.startswith("polach_") or n in ("creep_slope", "v", "N0", "wheel_force")
               for n in nonzero)
    assert "creep maximum" in view.note.object
    view.target.value = "damping"
    assert view.figure.xaxis.axis_label == "p · ∂ζ/∂p [-]"
    dash.s0 = 0.014  # unserved: recomputed synchronously on the change
    assert view.data.key == dash.state().point()
    data = sensitivity_data(dash.state())
    names, values, _ = ranked(data, "damping", dash.mode)
    assert list(view.source.data["name"]) == names
    np.testing.assert_array_equal(view.source.data["value"], values)
    view.target.value = "growth"
