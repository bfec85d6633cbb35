"""Every sub-command of ``bogie`` with generated bad values for each of its options: the answer is
exit status 0 (the value is allowed) or 2 with ONE line on stderr naming the option the user
typed — never a traceback.

The sub-commands and their options are enumerated from the parser (:func:`app.cli.main.build_parser`),
so a new command or option is covered without editing this file.  The bad values are chosen per
the option's kind: a number (empty, negative, NaN, infinite, huge, not a number), a choice (empty,
unknown), an input file (empty, missing, a directory, unreadable, not TOML), an output (empty,
an unwritable place, a missing directory, an existing directory, a wrong extension) and any other
text (empty, lists and ranges broken in every way, a range of a billion values).

The commands run in-process through :func:`app.cli.main.main` with their real validation; what
computes after it (the eigen-analyses, the histories, the studies, the server) is replaced by a
stub that stops the command at once (:class:`Computed`: the value was accepted, exit status 0).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest
from conftest import bogie_parsers

from app.cli.main import main
from model.mechanics.parameters import CALIBRATED_FILE, ESTIMATE_FILE

# where the computation of each command starts: module, function (imported by the commands when
# they run, so replacing the module's attribute reaches them)
COMPUTING = (
    ("model.analysis.eigen", "eigen_analysis"),
    ("model.analysis.stability", "stability_limit"),
    ("model.analysis.locus", "root_locus"),
    ("model.analysis.export", "export_system"),
    ("model.analysis.antislip", "required_reaction_time"),
    ("model.analysis.response", "short_circuit_response"),
    ("model.analysis.nonlinear", "nonlinear_response"),
    ("model.analysis.fault_instant", "phase_families"),
    ("model.analysis.sensitivity", "eigen_sensitivities"),
    ("model.analysis.sensitivity", "limit_sensitivity"),
    ("model.analysis.campbell", "campbell"),
    ("model.analysis.campbell", "ripple_response"),
    ("model.analysis.frequency_response", "frequency_response"),
    ("model.analysis.wheel_excitation", "polygon_response"),
    ("model.analysis.track_spectrum", "random_response"),
    ("model.studies.assessment", "assess"),
    ("model.studies.life", "route_life"),
    ("model.studies.assessment", "short_circuit_points"),
    ("model.studies.verdict_uncertainty", "run_verdict_uncertainty"),
    ("model.studies.global_calibration", "global_search"),
    ("model.studies.global_calibration", "run_start"),
    ("model.studies.compare", "compare_designs"),
    ("model.studies.uncertainty", "run_uncertainty"),
    ("model.studies.store", "run_into_store"),
    ("model.studies.store", "run_in_memory"),
    ("model.studies.engine", "StudyEngine"),  # no cluster is started
    ("app.report.page", "build_report"),
    ("app.server.serve", "serve"),  # no server is started
)

# a good value of an option a command requires, so that the others can be tried
REQUIRED = {"s0": "0.005", "v": "120", "samples": "2", "ripple": "el:6=250",
            "route": str(Path(__file__).resolve().parents[3] / "assets" / "routes"
                         / "mixed_passenger_200.toml")}
# what a command refuses to run without though the parser does not require it (compare: its two
# parameter files, given before the options)
NEEDS = {"report": ["--s0", "0.005"], "locus": ["--s0-range", "0.001:0.01:3"],
         "ripple": ["--ripple", "el:6=250"],
         "calibrate": ["--out", "calibrated.toml"],
         "compare": [str(CALIBRATED_FILE), str(ESTIMATE_FILE), "--s0", "0.005"]}

NUMBER_VALUES = ("", "-1", "nan", "inf", "-inf", "1e999", "99999999999999999999", "abc", "0")
TEXT_VALUES = ("", " ", "-1", "nan", "abc", ",", "1,,x", "1:2", "1:2:0", "2:1:3", "1:2:x",
               "0:1:1000000000", "1e999", "-1e999,0")
CHOICE_VALUES = ("", "nonsense")


class Computed(Exception):
    """Raised where a command starts computing: every option value was accepted."""


def _stop(*_args, **_kwargs):
    raise Computed


def leaf_commands() -> list[tuple[list[str], argparse.ArgumentParser]]:
    """(words, parser) of every command of ``bogie`` that runs (``study map`` …)."""
    return [(words, parser) for words, parser in bogie_parsers()
            if not any(isinstance(a, argparse._SubParsersAction) for a in parser._actions)]


def _text(action: argparse.Action) -> str:
    return " ".join(str(x) for x in (action.metavar, action.help) if x)


def _is_output(action: argparse.Action) -> bool:
    return action.dest == "out" or bool(re.search(r"\bwrit", (action.help or "").lower()))


def _is_input_file(action: argparse.Action) -> bool:
    return action.metavar == "FILE" and not _is_output(action)


def _suffix(action: argparse.Action) -> str:
    found = re.search(r"\.(npz|html|zarr|json|csv|toml)\b", _text(action))
    return f".{found.group(1)}" if found else ".json"


def bad_values(action: argparse.Action, tmp_path) -> list[str | None]:
    """The bad values of an option (None: the flag alone)."""
    if action.nargs == 0:
        return [None]
    if action.choices:
        return list(CHOICE_VALUES)
    if action.type is not None:
        return list(NUMBER_VALUES)
    if _is_output(action):
        suffix = "" if "dir" in _text(action).lower() else _suffix(action)
        return ["", f"/proc/out{suffix}", f"/proc/no/such/out{suffix}",
                str(tmp_path / "missing" / f"out{suffix}"), str(tmp_path),
                str(tmp_path / "out.wrong-extension")]
    if _is_input_file(action):
        garbage = tmp_path / "garbage.toml"
        garbage.write_bytes(b"\x00\xff\xfe not = [toml\n")
        return ["", str(tmp_path / "missing.toml"), str(tmp_path), "/proc/self/mem",
                str(garbage)]
    return list(TEXT_VALUES)


def required_arguments(parser, tested: argparse.Action, tmp_path) -> list[str]:
    """Good values of the options the command requires, but the one under test."""
    arguments = []
    for action in parser._actions:
        if action.required and action.option_strings and action is not tested:
            good = (str(tmp_path / f"good-output{_suffix(action)}") if _is_output(action)
                    else REQUIRED[action.dest])
            arguments += [action.option_strings[0], good]
    return arguments


def cases():
    for words, parser in leaf_commands():
        for action in parser._actions:
            if not action.option_strings or action.dest == "help":
                continue
            yield pytest.param(words, action.option_strings[0],
                               id=f"{' '.join(words)} {action.option_strings[0]}")


@pytest.fixture
def stubbed(monkeypatch):
    """Every computing function replaced by :func:`_stop`; the model assembled once per set.

    Every module of ``model`` and ``app.cli`` is imported first: a module first imported while
    the stubs are in place would keep a stub it imports by name (``from … import f``) for the
    rest of the test session, and the other tests would meet it."""
    import importlib

    from model.mechanics import assembly
    from model.mechanics.parameters import parameter_hash

    for module in all_modules():
        importlib.import_module(module)
    for module, name in COMPUTING:
        monkeypatch.setattr(importlib.import_module(module), name, _stop)
    build, models = assembly.build_model, {}

    def cached(parameters):
        key = parameter_hash(parameters)
        if key not in models:
            models[key] = build(parameters)
        return models[key]

    monkeypatch.setattr(assembly, "build_model", cached)


def all_modules() -> list[str]:
    """The names of every module of the ``model`` and ``app.cli`` packages."""
    import pkgutil

    import app.cli
    import model

    return [info.name for package in (model, app.cli)
            for info in pkgutil.walk_packages(package.__path__, package.__name__ + ".")]


def run(argv, capsys):
    try:
        code = main(argv)
    except Computed:
        code = 0
    except SystemExit as exit_:
        code = exit_.code
    out, err = capsys.readouterr()
    return code, out, err


def test_every_command_is_enumerated():
    """The enumeration reaches the nested commands and finds options everywhere (a parser
    change that hid them would make the test below vacuous)."""
    names = [" ".join(words) for words, _ in leaf_commands()]
    assert {"eigen", "export", "envelope", "assess", "serve", "study map", "study limit",
            "study uncertainty"} <= set(names)
    assert len(list(cases())) > 200


@pytest.mark.slow
@pytest.mark.parametrize(("words", "option"), list(cases()))
def test_bad_values_give_one_line_naming_the_option(words, option, tmp_path, capsys, stubbed,
                                                    monkeypatch):
    monkeypatch.chdir(tmp_path)
    parser = dict((tuple(w), p) for w, p in leaf_commands())[tuple(words)]
    action = next(a for a in parser._actions if option in a.option_strings)
    for value in bad_values(action, tmp_path):
        typed = [option] if value is None else [option, value]
        argv = [*words, *NEEDS.get(words[0], []), *required_arguments(parser, action, tmp_path),
                *typed]
        code, _, err = run(argv, capsys)
        said = f"bogie {' '.join(argv)}"
        assert "Traceback" not in err, f"{said}:\n{err}"
        assert code in (0, 2), f"{said}: exit {code}\n{err}"
        if value is not None and _is_output(action) and (not value or value.startswith("/proc/")):
            assert code == 2, f"{said}: an output it cannot write was accepted"
        if code == 2:
            assert err.endswith("\n"), f"{said}: not one line:\n{err}"
            assert err.count("\n") == 1, f"{said}: not one line:\n{err}"
            assert option in err, f"{said}: the message does not name {option}: {err}"


@pytest.mark.parametrize(("argv", "option"), [
    (["export", "--out", "/proc/x.npz"], "--out"),
    (["assess", "--samples", "2", "--write-samples", "/proc/nope"], "--write-samples"),
    (["assess", "--samples", "2", "--out", "/proc/verdict.json"], "--out"),
    (["response", "--out", "/proc/r.csv"], "--out"),
    (["spectrum", "--out", "/proc/s.npz"], "--out"),
    (["envelope", "--serial", "--out", "/proc/e.zarr"], "--out"),
    (["study", "map", "--s0", "0.005", "--v", "120", "--serial", "--out", "/proc/m.zarr"], "--out"),
    (["study", "uncertainty", "--samples", "2", "--serial", "--out", "/proc/u.json"], "--out"),
    (["uncertainty", "--samples", "2", "--out", "/proc/u.json"], "--out"),
    (["report", "--s0", "0.005", "--out", "/proc/r.html"], "--out"),
    (["frf", "--csv", "/proc/h.csv"], "--csv"),
    (["calibrate", "--out", "/proc/c.toml"], "--out"),
])
def test_unwritable_outputs_are_refused_before_any_work(argv, option, capsys, stubbed):
    """An output the command cannot write (here in /proc, which refuses new files even to root)
    is one line naming the option, exit 2 — before anything is computed (the stubs would end
    the command with exit 0)."""
    code, out, err = run(argv, capsys)
    assert code == 2, err
    assert err.count("\n") == 1, err
    assert f"{option} '/proc/" in err
    assert "cannot write there" in err
    assert out == ""


def test_an_existing_output_file_is_not_changed_by_the_check(tmp_path, capsys, stubbed):
    """The writability check of an existing file appends nothing (a command that stops later
    leaves the user's file as it was) and leaves no probe file behind."""
    target = tmp_path / "history.csv"
    target.write_text("kept\n")
    code, _, err = run(["response", "--out", str(target), "--t-end", "0.1"], capsys)
    assert code == 0, err  # accepted: stopped at the (stubbed) computation
    assert target.read_text() == "kept\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["history.csv"]


def test_ripple_speeds_are_named_as_typed(capsys):
    code, _, err = run(["assess", "--ripple-v", "200:10:5"], capsys)
    assert code == 2
    assert err.count("\n") == 1
    assert "--ripple-v" in err
    assert "--v " not in err


@pytest.mark.parametrize(("argv", "option"), [
    (["uncertainty", "--samples", "2", "--seed", "-1"], "--seed"),  # numpy refuses it later
    (["study", "uncertainty", "--samples", "2", "--seed", "-1", "--out", "u.json"], "--seed"),
    (["assess", "--samples", "2", "--seed", "-1"], "--seed"),
    (["uncertainty", "--samples", str(2**40)], "--samples"),  # the points would not fit memory
    (["assess", "--samples", str(2**40)], "--samples"),
    (["envelope", "--workers", "100000"], "--workers"),  # as many processes
    (["serve", "--background-workers", "100000"], "--background-workers"),
    (["study", "limit", "--v", "120", "--out", "s.zarr", "--scheduler", "abc"], "--scheduler"),
    (["envelope", "--v", "0:1:1000000000"], "--v"),  # a billion values, made before the check
])
def test_values_the_computation_would_fail_on_are_refused_first(argv, option, capsys, stubbed,
                                                                tmp_path, monkeypatch):
    """Values the parser once accepted and the computation then failed on (a traceback, a
    process per worker, memory): one line naming the option, before any work."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run(argv, capsys)
    assert code == 2, err
    assert err.count("\n") == 1, err
    assert option in err
    assert out == ""
