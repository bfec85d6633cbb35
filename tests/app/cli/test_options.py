"""The shared argument helpers of ``bogie`` (:mod:`app.cli.options`): intervals checked as they
are printed, the time grid's sample cap, and the bounds the report takes from the dashboard.
Parsing only: no command runs here.
"""

from __future__ import annotations

import argparse

import pytest

from app.cli.main import build_parser
from app.cli.options import MAX_SAMPLES, UsageError, bounded, check_samples
from model.mechanics.parameters import CALIBRATED_FILE, ESTIMATE_FILE


@pytest.mark.parametrize(("interval", "inside", "outside"), [
    ("(0, 60]", ["1e-9", "60"], ["0", "60.000001", "-1"]),
    ("[0.2, 5]", ["0.2", "5"], ["0.19999", "5.00001"]),
    ("(250, 1e6)", ["250.001", "999999"], ["250", "1e6"]),
    ("[-0.01, 0.01]", ["-0.01", "0", "0.01"], ["-0.0101", "0.0101"]),
])
def test_bounded_checks_the_interval_it_prints(interval, inside, outside):
    parse = bounded("--x (thing, s)", interval, "s")
    for text in inside:
        assert parse(text) == float(text)
    for text in [*outside, "nan", "inf"]:
        with pytest.raises(argparse.ArgumentTypeError) as error:
            parse(text)
        assert str(error.value) == f"--x (thing, s) = {text} is not allowed: must be in {interval} s"
    with pytest.raises(argparse.ArgumentTypeError, match="must be a number, got 'ten'"):
        parse("ten")


@pytest.mark.parametrize("interval", ["0, 1", "(0; 1)", "[0, 1", "(a, 1)"])
def test_a_malformed_interval_is_a_programming_error(interval):
    with pytest.raises(ValueError, match="is not written as"):
        bounded("--x", interval)


def test_the_sample_cap_is_inclusive():
    check_samples(argparse.Namespace(t_end=2.0, fs=MAX_SAMPLES / 2.0))
    with pytest.raises(UsageError, match=f"--t-end × --fs = 2000002 samples is too many: at most {MAX_SAMPLES}"):
        check_samples(argparse.Namespace(t_end=2.0, fs=MAX_SAMPLES / 2.0 + 1.0))


def _parses(argv: list[str]) -> bool:
    """True if the parser accepts ``argv``; False if it refuses it with exit status 2."""
    try:
        build_parser().parse_args(argv)
    except SystemExit as stop:
        code = stop.code
    else:
        return True
    if code != 2:
        raise AssertionError(f"exit status {code} for {argv}")
    return False


def test_report_bounds_are_the_dashboards_sliders(capsys):
    """``bogie report`` reproduces the dashboard, so it accepts exactly what the sliders allow
    (the dashboard in kN m and ms, the command line in N m and s)."""
    from app.dashboard.dashboard import BogieDashboard

    options = {"M0": ("--m0", 1e3), "f": ("--f", 1.0), "D": ("--decay", 1.0),
               "dt": ("--phase", 1e-3), "t_end": ("--t-end", 1.0)}
    for name, (option, scale) in options.items():
        low, high = BogieDashboard.param[name].bounds
        for value, accepted in ((low, True), (high, True), (low - 0.01 * (high - low), False),
                                (high + 0.01 * (high - low), False)):
            argv = ["report", "--out", "r.html", option, repr(value * scale)]
            assert _parses(argv) is accepted, (argv, capsys.readouterr().err)
    capsys.readouterr()


@pytest.mark.parametrize(("command", "options"), [
    ("response", ["--m0", "--f", "--decay", "--phase", "--t-end", "--fs"]),
    ("antislip", ["--t-end", "--fs"]),
    ("compare", ["--m0", "--f", "--decay", "--t-end"]),
    ("report", ["--m0", "--f", "--decay", "--phase", "--t-end"]),
])
def test_shared_option_blocks_have_the_same_labels(command, options, capsys):
    """Every command names a refused value of a shared option the same way."""
    labels = {"--m0": "--m0 (amplitude, N m)", "--f": "--f (frequency, Hz)", "--decay": "--decay (D)",
              "--phase": "--phase (Δt, s)", "--t-end": "--t-end (horizon, s)",
              "--fs": "--fs (sampling rate, Hz)"}
    positional = [str(CALIBRATED_FILE), str(ESTIMATE_FILE)] if command == "compare" else []
    for option in options:
        assert not _parses([command, *positional, option, "1e300"])
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        assert f"argument {option}: {labels[option]} = 1e300 is not allowed: must be in " in err
