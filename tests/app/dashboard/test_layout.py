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


def test_an_opened_tab_brings_its_missed_rows_with_its_models(monkeypatch):
    """The rows a hidden tab's table missed are in its models when the browser first gets them,
    not in a change sent after them (which a Tabulator that is still building drops)."""
    import pandas as pd
    import panel as pn
    from bokeh.document import Document
    from bokeh.models import ColumnDataSource

    from app.dashboard import layout

    doc = Document()
    monkeypatch.setattr(layout, "served_document", lambda: doc)  # hidden views wait, as served
    table = pn.widgets.Tabulator(pd.DataFrame({"nu": []}, dtype="int64"))
    view_tabs = layout.ViewTabs(("First", pn.pane.Markdown("first")), ("Table", table))
    view_tabs.on_opening(lambda: view_tabs.flush(view_tabs.shown))
    doc.add_root(view_tabs.tabs.get_root(doc))

    def show_rows(count):
        table.value = pd.DataFrame({"nu": list(range(1, count + 1))})

    view_tabs.when_shown("table", show_rows, 3)
    assert table.value.empty  # hidden: the update waits
    data_changes = []
    doc.on_change(lambda event: data_changes.append(event)
                  if isinstance(getattr(event, "model", None), ColumnDataSource) else None)
    view_tabs.tabs.active = 1
    assert len(table.value) == 3
    sources = [model for model in doc.models if isinstance(model, ColumnDataSource)]
    assert [list(source.data["nu"]) for source in sources] == [[1, 2, 3]]
    assert data_changes == []
