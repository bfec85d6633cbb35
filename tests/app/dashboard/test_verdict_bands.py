"""The verdict under uncertainty in the Verdicts tab, without a server: a result of ``bogie assess
--samples … --out`` in the server's studies folder, picked by name from the tab's list, puts each
check's 5–95 % safety-factor band beside its nominal value and the governing check's probability
of failure on the indicator's tooltip; a result of other strength data, a name not in the list or
a file that is not such a result: a notice says why, the previous bands are kept.

The result is a real (small) run of the model's study at the dashboard's own point and options,
written as the command line writes it (``VerdictUncertainty.as_dict``)."""

from __future__ import annotations

import json

import pytest
from conftest import dashboard_with_study_queue

from app.results import compute
from app.results.verdicts import band_words
from app.services.studies_folder import refusal
from model.studies.assessment import AssessmentOptions
from model.studies.verdict_uncertainty import run_verdict_uncertainty

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def dash(tmp_path_factory):
    for dashboard in dashboard_with_study_queue(tmp_path_factory.mktemp("studies")):
        dashboard.verdicts.on_shown(True)  # not served: computed when the tab opens
        yield dashboard


@pytest.fixture(scope="module")
def result(dash):
    """A verdict result of the dashboard's set and point (the dashboard's assessment options at
    a stable point: its creepage and speed as the short-circuit grid)."""
    case = dash.state()
    op = case.operating_point()
    options = AssessmentOptions(s0=(op.s0,), v=(op.v,), N0=op.N0, b_M=op.b_M,
                                excitation=case.short_circuit())
    return run_verdict_uncertainty(compute.parameters_for(case), 2, seed=5, options=options)


def _write(dash, name: str, data: dict) -> str:
    (dash.verdicts._folder().root / name).write_text(json.dumps(data), encoding="utf-8")
    dash.verdicts.refresh_results()
    return name


def test_a_result_of_the_folder_puts_its_bands_beside_the_checks(dash, result):
    view = dash.verdicts
    assert view.result is not None
    name = _write(dash, "verdict-a.json", result.as_dict())
    assert name in view.uncertainty_select.options
    view.open_uncertainty(name)
    assert not view.notice.visible
    for row, check in zip(view.rows, sorted(view.result.checks, key=lambda c: -c.utilisation),
                          strict=True):
        band = result.band(check.component, check.kind, check.load_case)
        assert row["band 5–95 %"] == band_words(result, check)
        assert f"{band.quantiles[0]:.3g}" in row["band 5–95 %"]
    assert "probability of the governing check below its required factor" in \
        view.indicator.object
    assert f"{result.governing.failure.value:.2f}" in view.indicator.object


def test_other_strength_data_or_a_bad_name_or_file_keep_the_previous_bands(dash, result):
    view = dash.verdicts
    view.open_uncertainty(_write(dash, "verdict-a.json", result.as_dict()))
    shown = [row["band 5–95 %"] for row in view.rows]
    assert all(shown)
    other = result.as_dict()
    other["set_hash"] = "0" * 64  # a result of another set or other strength data
    view.open_uncertainty(_write(dash, "verdict-other.json", other))
    assert view.notice.visible
    assert "another parameter set or other strength data" in view.notice.object
    assert view.uncertainty is result or view.uncertainty.set_hash == result.set_hash
    assert [row["band 5–95 %"] for row in view.rows] == shown
    view.open_uncertainty("../../etc/passwd.json")
    assert view.notice.object == refusal("verdict")
    (view._folder().root / "not-a-verdict.json").write_text(
        '{"format": "bogie-verdict-uncertainty-1", "n": "x"}', encoding="utf-8")
    view.refresh_results()
    view.open_uncertainty("not-a-verdict.json")
    assert view.notice.object == "that file is not a result of bogie assess --samples"
    assert [row["band 5–95 %"] for row in view.rows] == shown
