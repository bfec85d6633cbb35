"""docs/own-bogie.md: the parameter file's schema as the code has it (names, units, meanings,
valid values, defaults, the calibration's bounds), and the worked example's output."""

from __future__ import annotations

import re
import sys

from conftest import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
import parameter_schema

PAGE = (ROOT / "docs" / "own-bogie.md").read_text(encoding="utf-8")


def _block(name: str) -> str:
    return re.search(rf"<!--begin=parameters/blocks/{name}-->\n(.*?)\n?<!--end-->", PAGE, re.S).group(1).strip()


def test_the_schema_table_is_the_codes():
    assert _block("schema") == parameter_schema.schema_table().strip()


def test_every_parameter_has_a_row():
    from model.mechanics.parameters import ALL_SCHEMA

    rows = re.findall(r"^\| `(\w+)` \|", _block("schema"), re.M)
    assert rows == list(ALL_SCHEMA)


def test_the_worked_example_output_is_the_commands():
    assert _block("example_output") == parameter_schema.example_output().strip()
