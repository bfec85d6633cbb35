"""The numbers the pages quote agree with the results files the scripts write
(``scripts/docs_numbers.py``; regenerate with ``scripts/regenerate_docs_results.py``).

The count of disagreements is the measure (target 0); the other tests show that the check can
fail: a number rounded wrongly, a missing key, a results file of another parameter set, a block
that differs, and that ``--update`` rewrites a number in the digits it was quoted with."""

from __future__ import annotations

import json
import sys

import pytest
from conftest import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
import docs_numbers
from docs_numbers import Sources, check_pages, check_text, format_like, parse_quoted


def test_every_quoted_number_agrees_with_its_results_file():
    found, count = check_pages()
    assert count > 0
    assert [str(item) for item in found] == [], f"{len(found)} disagreements of {count} tags"


@pytest.mark.parametrize(("quoted", "value", "agrees"), [
    ("4.2·10¹⁵", 4.249e15, True), ("4.2·10¹⁵", 4.26e15, False),
    ("19 411", 19411.4, True), ("19 411", 19412.0, False),
    ("−0.065", -0.0649, True), ("−0.065", 0.065, False),
    ("+33.27", 33.266, True), ("5.4e-7", 5.43e-7, True), ("5.4e-7", 5.5e-7, False),
    ("10²²", 3.0e22, True), ("10²²", 4.0e23, False), ("±0.84", 0.8449, True),
    ("0.0082013", 0.00820128, True), ("1 138", 1138.47, True), ("41", 41.4, True),
])
def test_a_number_agrees_only_within_its_quoted_digits(quoted, value, agrees):
    parsed, _ = parse_quoted("at " + quoted)
    assert parsed.text == quoted
    assert parsed.agrees(value) is agrees


def test_bounds():
    parsed, _ = parse_quoted("within 0.05")
    assert parsed.agrees(0.0504, "max")
    assert not parsed.agrees(0.06, "max")
    assert parsed.agrees(0.9, "min")
    assert not parsed.agrees(0.04, "min")


@pytest.mark.parametrize(("quoted", "value", "written"), [
    ("4.2·10¹⁵", 1.432e32, "1.4·10³²"), ("19 411", 21_334.6, "21 335"), ("−0.065", -0.0721, "−0.072"),
    ("+33.27", 13.06, "+13.06"), ("10²²", 2e16, "10¹⁶"), ("5.4e-7", 1.8e-7, "1.8e-7"),
    ("9.96·10³", 9.996e3, "1.00·10⁴"), ("0.43", 0.4342, "0.43"), ("2.28·10⁴", -2.279e4, "−2.28·10⁴"),
])
def test_update_keeps_the_format(quoted, value, written):
    assert format_like(quoted, value) == written


@pytest.fixture
def results(tmp_path, monkeypatch):
    folder = tmp_path / "results"
    folder.mkdir()
    (folder / "x.json").write_text(json.dumps({
        "parameters_hash": "h", "peak": 19411.4, "cases": [{"t": 0.1808}], "table": "| a |\n|---|"}))
    return folder


def test_disagreements_are_found_and_updated(results):
    text = ("peak 19.4<!--=x/peak *1e-3--> kN m at 0.18<!--=x/cases/0/t--> s, wrong 19.5<!--=x/peak *1e-3-->,"
            " gone 1.0<!--=x/nothing-->, bound 0.2<!--=x/cases/0/t max-->\n<!--begin=x/table-->\n| b |\n<!--end-->\n")
    found, updated, count = check_text(text, "page.md", Sources(results), update=True)
    assert count == 6
    assert sorted(item.quoted for item in found) == ["(block)", "1.0", "19.5"]
    assert "wrong 19.4<!--=x/peak *1e-3-->" in updated
    assert "<!--begin=x/table-->\n| a |\n|---|\n<!--end-->" in updated
    again, _, _ = check_text(updated, "page.md", Sources(results))
    assert [item.quoted for item in again] == ["1.0"]  # a missing key is left to the author


def test_a_block_end_marker_must_start_a_line(results):
    """After a table's last row or a code fence the marker on the same line would glue to it (a
    fence would not close): such a block is a disagreement, and ``--update`` puts the marker on a
    line of its own."""
    glued = "<!--begin=x/table-->\n| a |\n|---|<!--end-->\n"
    found, updated, _ = check_text(glued, "page.md", Sources(results), update=True)
    assert len(found) == 1
    assert updated == "<!--begin=x/table-->\n| a |\n|---|\n<!--end-->\n"


def test_a_tag_without_a_number_before_it_is_a_disagreement(results):
    found, _, _ = check_text("the peak<!--=x/peak-->", "page.md", Sources(results))
    assert len(found) == 1
    assert "no number" in found[0].expected


def test_results_of_another_parameter_set_are_a_disagreement(tmp_path, results, monkeypatch):
    (tmp_path / "docs").mkdir()
    (tmp_path / "README.md").write_text("x 19 411<!--=x/peak-->\n")
    (tmp_path / "BENCHMARKS.md").write_text("")
    monkeypatch.setattr(docs_numbers, "parameters_hash", lambda: "another")
    found, count = check_pages(tmp_path, results=results)
    assert count == 1
    assert [item.page for item in found] == ["docs/results/x.json"]


def test_the_regeneration_command_runs_every_results_script():
    """Each results file names the script that wrote it, and that script is a step of
    ``scripts/regenerate_docs_results.py`` (one command regenerates them all)."""
    import regenerate_docs_results

    steps = {part for step in regenerate_docs_results.STEPS for command in step.commands
             for part in command if part.startswith("scripts/")}
    for path in sorted((ROOT / "docs" / "results").glob("*.json")):
        command = json.loads(path.read_text(encoding="utf-8"))["command"]
        assert command.split()[0] in steps, path.name


def test_no_tag_starts_a_line():
    """A line that starts with ``<!--`` is an HTML block on GitHub: the rest of the line would
    lose its markdown.  A tag follows its number, so it never starts a line."""
    for page in docs_numbers.pages():
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1):
            assert not line.startswith("<!--="), f"{page.name}:{number}"
