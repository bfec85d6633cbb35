"""What several commands run alike (app.cli.runs) and the exit contract of app.cli.main: Ctrl-C
while a study's engine starts or runs exits with status 130 and no traceback, the engine closed;
only the project's input errors are "bad input" (exit 2), a programming error shows itself."""

from __future__ import annotations

import pytest

from app.cli.main import main
from app.cli.options import EXIT_INTERRUPTED


@pytest.mark.parametrize("command", [
    pytest.param(["study", "map", "--s0", "0.004:0.006:2", "--v", "100:120:2"], id="study map"),
    pytest.param(["study", "limit", "--v", "100:120:2"], id="study limit"),
    pytest.param(["envelope", "--s0", "0.005", "--v", "120", "--t-end", "0.2"], id="envelope"),
])
def test_ctrl_c_while_the_engine_starts_exits_130(command, tmp_path, monkeypatch, capsys):
    from model.studies.engine import StudyEngine

    closed = []

    def start(_engine) -> None:
        raise KeyboardInterrupt  # Ctrl-C while the cluster starts

    monkeypatch.setattr(StudyEngine, "start", start)
    monkeypatch.setattr(StudyEngine, "close", lambda engine: closed.append(engine))
    out = ["--out", str(tmp_path / "x.zarr")] if command[0] == "study" else []
    with pytest.raises(SystemExit) as stop:
        main([*command, *out])
    assert stop.value.code == EXIT_INTERRUPTED
    err = capsys.readouterr().err
    assert "interrupted" in err
    assert "Traceback" not in err
    assert len(closed) == 1  # the engine that was starting is stopped


def test_a_programming_error_is_not_bad_input(monkeypatch, capsys):
    """A KeyError or ValueError that no input caused propagates (its traceback shows where),
    instead of one line "bad input" with exit status 2."""
    from app.cli import analysis

    def broken(_args):
        return {}["missing"]

    monkeypatch.setattr(analysis, "cmd_eigen", broken)
    with pytest.raises(KeyError):
        main(["eigen"])
    assert capsys.readouterr().err == ""


def test_a_bad_value_of_the_model_is_bad_input(capsys):
    """An input error the model finds (an output it does not know) is one line, exit 2."""
    code = main(["response", "--s0", "0.005", "--t-end", "0.1", "--outputs", "ID1.no.torque"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("bogie response: error:")
    assert err.count("\n") == 1
