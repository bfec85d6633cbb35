"""README.md for a newcomer: its two commands, a Python block that runs as written, the glossary,
the dashboard's controls as the dashboard has them, a Limitations section; LICENSE and
CITATION.cff."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")
sys.path.insert(0, str(ROOT / "scripts"))


def _section(title: str) -> str:
    start = README.index(f"## {title}\n")
    end = README.find("\n## ", start + 3)
    return README[start:end if end > 0 else None]


def test_the_two_commands():
    assert "bash run.sh app     # 1. the dashboard" in README
    assert "bash run.sh test    # 2. the whole test suite" in README


def test_the_python_block_runs_as_written():
    """The block of "Use it from Python", unchanged, in a fresh interpreter of the environment
    (what a newcomer does after ``pip install -e .``)."""
    block = re.search(r"```python\n(.*?)```", _section("Use it from Python"), re.S).group(1)
    assert 4 <= len(block.strip().splitlines()) <= 8
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    run = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True, timeout=300,
                         cwd="/", env=env)  # not the checkout: the installed package
    assert run.returncode == 0, run.stderr[-2000:]
    stable, peak = run.stdout.split()
    assert stable == "True"
    assert float(peak) > 1e4  # N m


@pytest.mark.parametrize("term", ["ID1", "ID2", "BF", "CB", "DC", "HS", "TM", "M_ad", "b_M", "s0",
                                  "N0"])
def test_the_glossary_has(term):
    assert f"**{term}**" in _section("Words and abbreviations")


def test_limitations_gathered():
    limitations = _section("Limitations")
    for page in ("docs/validation.md", "docs/nonlinear.md", "docs/response.md", "docs/resonance.md",
                 "docs/design-loads.md", "docs/sensitivity.md"):
        assert page in limitations


@pytest.mark.slow
def test_the_controls_table_is_the_dashboards():
    """The table of "Controls and units" rendered from a dashboard object (ranges, steps and
    defaults of its widgets, the link's and the command line's names); the block must equal it."""
    from dashboard_controls import controls_table

    from app.dashboard.dashboard import BogieDashboard

    block = re.search(r"<!--begin=dashboard/blocks/controls-->\n(.*?)\n?<!--end-->", README, re.S)
    assert block.group(1).strip() == controls_table(BogieDashboard(query={})).strip()


def test_the_command_line_options_of_the_controls_table_exist():
    from app.cli.main import build_parser

    options = set(re.findall(r"`(--[a-z-]+)`", _section("Controls and units")))
    known: set[str] = set()
    parsers = list(build_parser()._subparsers._group_actions[0].choices.values())
    while parsers:  # every command and sub-command (bogie study map, …)
        parser = parsers.pop()
        for action in parser._actions:
            known |= set(action.option_strings)
            if isinstance(action.choices, dict):
                parsers += [c for c in action.choices.values() if hasattr(c, "_actions")]
    assert options
    assert options <= known


def test_license_and_citation():
    import yaml

    assert "MIT License" in (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert "the bogie-drive-dynamics authors" in (ROOT / "LICENSE").read_text(encoding="utf-8")
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert citation["cff-version"] == "1.2.0"
    assert citation["license"] == "MIT"
    study = citation["references"][0]
    assert study["title"].startswith("Dynamic wheelset drive load of the railway vehicle")
    assert [a["family-names"] for a in study["authors"]] == ["Zeman", "Hlaváč"]
    assert study["journal"] == "Applied and Computational Mechanics"
