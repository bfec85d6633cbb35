"""The Variant tab shows the calibration's bounds of the baseline's fitted parameters, the same
rows as ``bogie parameters --json`` (model.studies.calibration_bounds.parameter_rows)."""

from __future__ import annotations

import json

from bokeh.document import Document

from app.cli.main import main
from app.dashboard.dashboard import BogieDashboard


def test_variant_tab_shows_the_bounds_of_bogie_parameters(capsys):
    dashboard = BogieDashboard()
    doc = Document()
    doc.add_root(dashboard.layout.get_root(doc))
    view = dashboard.variant_view
    assert main(["parameters", "--json"]) == 0
    rows = {row["name"]: row for row in json.loads(capsys.readouterr().out)["parameters"]
            if row["lower"] is not None}
    assert view.bounds.keys() == rows.keys()
    table = next(o for o in view.__panel__().select(lambda o: "variant-bounds" in
                                                 (getattr(o, "css_classes", None) or [])))
    for name, row in rows.items():
        assert f"<td class='text'>{name}</td>" in table.object
        assert f"{row['lower']:.4g} … {row['upper']:.4g}" in table.object
        if name in view.inputs:
            widget = view.inputs[name]
            assert f"calibrated within {row['lower']:.4g} … {row['upper']:.4g}" in \
                widget.description
            assert ("(on a calibration bound)" in widget.label) == row["on_bound"]
