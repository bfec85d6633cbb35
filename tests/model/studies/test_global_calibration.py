"""The global calibration's pieces (model/studies/global_calibration.py): the Sobol' starts, the
front, the spread and the search's bookkeeping with a stubbed least squares (the real starts:
tests/app/cli/test_cli_calibrate.py, slow)."""

from __future__ import annotations

import math

import pytest

from model.studies import global_calibration as gc
from model.studies.calibration_bounds import SEARCH_PARAMETERS
from model.studies.engine import serial_map_unordered


def test_start_k_is_the_same_point_whatever_the_number_of_starts():
    """Start 0 is the start file's own values (no value replaced); start k ≥ 1 is point k − 1
    of one scrambled Sobol' sequence (fast_forward): a start re-runs alone; the first points are
    the sequence's, inside every bound."""
    from scipy.stats import qmc

    first = qmc.Sobol(len(SEARCH_PARAMETERS), scramble=True, seed=gc.SOBOL_SEED).random(8)
    for k in range(8):
        assert gc.sobol_unit_point(k, len(SEARCH_PARAMETERS)) == pytest.approx(first[k], abs=0)
    assert gc.start_values(0) == {}
    for k in (1, 5, 17):
        values = gc.start_values(k)
        assert values == gc.start_values(k)
        for f in SEARCH_PARAMETERS:
            assert f.low <= values[f.name] <= f.high, f.name
    assert gc.start_values(1) != gc.start_values(2)
    with pytest.raises(ValueError, match="start index"):
        gc.sobol_unit_point(-1, 3)
    with pytest.raises(ValueError, match="start index"):
        gc.start_values(-1)


def test_log_parameters_are_spread_log_uniformly():
    u = gc.sobol_unit_point(3, len(SEARCH_PARAMETERS))
    values = gc.start_values(4)
    for f, ui in zip(SEARCH_PARAMETERS, u, strict=True):
        if f.log:
            assert math.log(values[f.name] / f.low) / math.log(f.high / f.low) == pytest.approx(ui)
        else:
            assert (values[f.name] - f.low) / (f.high - f.low) == pytest.approx(ui)


def _result(index, cost, frequency, divergence, values=None, ranks=0):
    return gc.StartResult(index, {}, values or {}, cost, frequency, ranks, 0, 7.0, divergence,
                          1.0)


def test_front_keeps_the_starts_no_other_beats_in_both_errors():
    results = [_result(0, 5.0, 0.10, 0.50), _result(1, 4.0, 0.30, 0.05), _result(2, 3.0, 0.20, 0.60),
               _result(3, 6.0, 0.10, 0.40), _result(4, 7.0, 0.05, 0.90)]
    # 0 is beaten by 3 (same frequency error, smaller divergence error); 2 by 0 and 3
    assert gc.front(results) == [1, 3, 4]


def test_spread_over_the_best_quarter_as_a_share_of_the_bounds():
    f = SEARCH_PARAMETERS[0]
    names = [g.name for g in SEARCH_PARAMETERS]
    base = {name: g.low for name, g in zip(names, SEARCH_PARAMETERS, strict=True)}
    middle = SEARCH_PARAMETERS[2]
    base[middle.name] = math.sqrt(middle.low * middle.high)  # the same, inside the bounds
    results = []
    for k in range(8):  # costs 0…7: the best quarter is 2 starts, at least MIN_BEST = 4
        values = dict(base)
        values[f.name] = f.low * (f.high / f.low) ** (0.1 * k)  # starts 0…3: 0 … 0.3 of the bounds
        results.append(_result(k, float(k), 0.1, 0.1, values))
    assert [r.index for r in gc.best_starts(results)] == [0, 1, 2, 3]
    rows = {row.name: row for row in gc.spread(results)}
    assert rows[f.name].share == pytest.approx(0.3)
    assert not rows[f.name].identified
    assert rows[names[1]].share == 0.0  # all on the lower bound: held there, not identified
    assert rows[names[1]].on_bound
    assert not rows[names[1]].identified
    assert rows[middle.name].share == 0.0
    assert rows[middle.name].identified
    assert not rows[middle.name].on_bound


def test_global_search_runs_every_start_and_ranks_them_by_the_rule(monkeypatch):
    """Stubbed least squares: the search maps every start, orders them by index and picks the
    best by the rule: the divergence within 10 % first, then the most ranks within 5 %, then the
    smaller largest frequency error, then the cost (start 3 has the lowest cost but misses the
    divergence; 1 and 2 tie in ranks, 2 has the smaller error); it reports the front and spread."""
    starts = {0: (3.0, 0.20, 0.05, 6), 1: (2.0, 0.10, 0.08, 8), 2: (2.5, 0.08, 0.02, 8),
              3: (1.0, 0.04, 0.50, 10)}  # cost, frequency error, divergence error, ranks
    values = {g.name: g.low for g in SEARCH_PARAMETERS}

    def fake(k, start_file=None, phases=None):
        cost, frequency, divergence, ranks = starts[k]
        return _result(k, cost, frequency, divergence, values, ranks)

    monkeypatch.setattr(gc, "run_start", fake)
    seen = []
    result = gc.global_search(3, serial_map_unordered, progress=lambda r: seen.append(r.index))
    assert seen == [0, 1, 2, 3]
    assert [r.index for r in result.results] == [0, 1, 2, 3]
    assert result.best == 2
    assert result.front == [2, 3]
    assert [r.index for r in gc.best_starts(result.results)] == [2, 1, 0, 3]
    assert len(result.spread) == len(SEARCH_PARAMETERS)
    data = result.as_dict()
    assert data["starts"] == 3  # the Sobol' starts 1 … 3 beside start 0, the start file's
    assert data["best"] == 2
    with pytest.raises(ValueError, match="starts"):
        gc.global_search(0, serial_map_unordered)


def test_a_start_the_model_cannot_analyse_is_reported_not_fatal(monkeypatch):
    """Start 8's creep shape leaves the creep law without a maximum below s = 1 for any (μ0,
    A, B, p) within their bounds: the start is reported as failed, and the search goes on
    without it (not in the front, the spread or the best)."""
    failed = gc.run_start(8, phases=((1, gc.PHASES[0][1]), (1, gc.PHASES[1][1])))
    assert "no maximum" in failed.failed
    assert math.isinf(failed.cost)
    assert failed.as_dict()["cost"] is None
    values = {g.name: g.low for g in SEARCH_PARAMETERS}

    def fake(k, start_file=None, phases=None):
        if k == 1:
            return failed
        return _result(k, float(k), 0.1 * k, 0.1 * k, values)

    monkeypatch.setattr(gc, "run_start", fake)
    result = gc.global_search(2, serial_map_unordered)
    assert result.best == 0
    assert result.front == [0]
    assert [r.index for r in gc.best_starts(result.results)] == [0, 2]
