"""The dashboard's table frames: every column's type declared, also when the frame is empty (a
Tabulator takes its columns' formatters from its first frame)."""

from __future__ import annotations

from app.dashboard.layout import typed_frame
from app.dashboard.verdicts_view import COLUMNS


def test_an_empty_table_frame_keeps_its_text_columns_text():
    empty = typed_frame(COLUMNS, [])
    assert {name: str(empty[name].dtype) for name in COLUMNS} == COLUMNS
    row = {name: ("ID1 axle" if dtype == "object" else 1.5) for name, dtype in COLUMNS.items()}
    filled = typed_frame(COLUMNS, [row])
    assert list(filled.columns) == list(COLUMNS)
    assert filled["component"].tolist() == ["ID1 axle"]
    assert {name: str(filled[name].dtype) for name in COLUMNS} == COLUMNS
