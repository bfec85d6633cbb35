"""The dashboard's downloads: what is on screen as files (CSV, JSON, TOML, the HTML report).

Each file is made when its button is pressed, from the dashboard's last valid results and its
current parameters; the CSV keeps the full 10 kHz histories (the plots show decimated ones).  The
CSV and the report describe the history of the peak table: the linear one, or the nonlinear one
when the nonlinear creep model is on.
"""

from __future__ import annotations

import io
import json

import numpy as np
import panel as pn

from app.report.page import ReportHistory, build_report
from app.results import compute
from model.mechanics.parameters import dumps_parameters


class Downloads:
    """The download buttons of one dashboard (``widgets``) and the files behind them.

    ``dashboard``: its ``point`` (last valid result), ``described_history()``, ``history_key``
    and ``state()``."""

    def __init__(self, dashboard):
        self.dashboard = dashboard
        self.widgets = [
            pn.widgets.FileDownload(callback=self.time_histories_csv, filename="time_histories.csv",
                                    label="time histories (CSV)", css_classes=["dl-csv"],
                                    sizing_mode="stretch_width"),
            pn.widgets.FileDownload(callback=self.eigenvalues_json, filename="eigenvalues.json",
                                    label="eigenvalues (JSON)", css_classes=["dl-json"],
                                    sizing_mode="stretch_width"),
            pn.widgets.FileDownload(callback=self.parameters_toml, filename="parameters.toml",
                                    label="parameter set (TOML)", css_classes=["dl-toml"],
                                    sizing_mode="stretch_width"),
            pn.widgets.FileDownload(callback=self.report_html, filename="bogie-report.html",
                                    label="report (HTML, opens offline)",
                                    css_classes=["dl-report"], sizing_mode="stretch_width"),
        ]

    def describe(self, history: compute.ResponseView | None) -> None:
        """The CSV's file name says which history it holds (``time_histories.csv``: the linear
        one; ``time_histories_nonlinear.csv``: the nonlinear creep model's)."""
        nonlinear = history is not None and history.nonlinear
        self.widgets[0].filename = ("time_histories_nonlinear.csv" if nonlinear
                                    else "time_histories.csv")

    def time_histories_csv(self) -> io.StringIO:
        """Time [s] and every output of the history the peak table describes (linear, or
        nonlinear with nonlinear creep on; units in the header), the motor torque M_C [N m]
        last."""
        r = self.dashboard.described_history()
        names = list(r.outputs)
        header = "t [s]," + ",".join(f"{n} [{r.units[n]}]" for n in names) + ",M_C [N m]"
        data = np.column_stack([r.t, *r.outputs.values(), r.M_C])
        buffer = io.StringIO()
        np.savetxt(buffer, data, delimiter=",", header=header, comments="", fmt="%.8g")
        buffer.seek(0)
        return buffer

    def eigenvalues_json(self) -> io.StringIO:
        """Operating point (SI, v in km/h), verdict, modes and every eigenvalue [1/s]."""
        p = self.dashboard.point
        lam = p.eigenvalues
        order = np.lexsort((lam.real, lam.imag))
        # the point's quantities by their file keys, in the files' units (SI, v in km/h)
        point = {key: value for key, value in p.case.files().items() if value is not None}
        data = {"operating_point": point,
                "stable": p.stable, "max_real_part": p.max_real_part, "flutter_pairs": p.flutter,
                "divergent_real": p.divergence, "rigid_body": p.n_rigid,
                "modes": [{"nu": m.number, "re": m.eigenvalue.real, "im_hz": m.im_hz,
                           "damping_ratio": m.damping_ratio, "description": m.description}
                          for m in p.modes],
                "eigenvalues": [{"re": float(x.real), "im": float(x.imag)} for x in lam[order]]}
        return io.StringIO(json.dumps(data, indent=1))

    def parameters_toml(self) -> io.StringIO:
        """The parameter set in use (variant applied, rail condition's creep law), as TOML."""
        state = self.dashboard.state()
        p = compute.parameters_for(state)
        point = ", ".join(q.said(getattr(state, q.name)) for q in state.of_role("point"))
        header = (f"parameter set in use by the dashboard (rail condition: {state.rail})\n"
                  f"operating point: {point}")
        return io.StringIO(dumps_parameters(p, header))

    def report_html(self) -> io.StringIO:
        """The self-contained HTML report of the current state (:mod:`app.report.page`)."""
        state = self.dashboard.state()
        key = self.dashboard.history_key
        history = ReportHistory(None if key is None else key.anti_slip,  # None: linear creep
                                self.dashboard.nonlinear.valid)
        return io.StringIO(build_report(state, history))
