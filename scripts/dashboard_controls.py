"""The dashboard's controls with their ranges, defaults and units, and the same quantity's name and
unit in a link, on the command line and in the files — the table of README.md, read from a
dashboard object (no server).

    .venv/bin/python scripts/dashboard_controls.py      # docs/results/dashboard.json, prints it

``tests/docs/test_readme.py`` builds a dashboard and checks that README.md's table is this one.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

# dashboard parameter -> (command-line option [unit], in files: name [unit])
ELSEWHERE = {
    "s0": ("`--s0` [-]", "`s0` [-]"),
    "v": ("`--v` [km/h]", "`v` [m/s], `v_kmh`"),
    "N0": ("`--n0` [N]", "`N0` [N], `wheel_force`"),
    "b_M": ("`--bm` [N m s/rad]", "`b_M` [N m s/rad], `motor_slope`"),
    "rail": ("`--rail` (`bogie envelope`, `report`, `study map`)", "`rail`"),
    "M0": ("`--m0` [N m]", "`M0` [N m]"),
    "f": ("`--f` [Hz]", "`f` [Hz]"),
    "D": ("`--decay` [-]", "`D` [-]"),
    "dt": ("`--phase` [s]", "`phase_s` [s]"),
    "t_end": ("`--t-end` [s]", "`t` [s]"),
    "creep": ("`--creep`", "`creep`"),
    "anti_slip": ("`--anti-slip`", "`anti_slip`"),
    "delay": ("`--anti-slip-delay` [s]", "`anti_slip_delay` [s]"),
    "threshold": ("`--anti-slip-threshold` [m/s]", "—"),
    "rate": ("`--anti-slip-rate` [1/s]", "—"),
}


def _number(x: float) -> str:
    return f"{x:,.6g}".replace(",", " ").replace("-", "−")


def controls_rows(dashboard) -> list[tuple]:
    """(CSS class, label, range, default, link name [unit], CLI option, files) of every control
    of the dashboard's controls column, in its order."""
    from app.dashboard.url_state import CHOICES, NUMBERS

    link = {target: f"`{name}` [{unit}]" for name, (target, _, unit) in NUMBERS.items()}
    link |= {target: f"`{name}`" for name, target in CHOICES.items()}
    sliders = dashboard.controls.sliders
    rows = []
    for name, widget in sliders.items():
        if name == "dt":  # after its switch, as in the column
            auto = dashboard.param["dt_auto"]
            rows.append(("ctl-dt_auto", "Δt automatic: the motor torque continuous at the fault",
                         "on / off", "on" if auto.default else "off", "`phase` absent",
                         "`--phase` absent", "—"))
        default = _number(widget.value) + (" (the set's)" if name in ("N0", "b_M") else "")
        rows.append((f"ctl-{name}", widget.label, f"{_number(widget.start)} … {_number(widget.end)} "
                     f"(step {_number(widget.step)})", default, link.get(name, "—"),
                     *ELSEWHERE[name]))
        if name == "b_M":
            rail = dashboard.param["rail"]
            rows.append(("ctl-rail", "rail condition (creep law)", " / ".join(rail.objects),
                         rail.default, link["rail"], *ELSEWHERE["rail"]))
    nonlinear = dashboard.nonlinear
    rows.append(("ctl-creep", "creep model", " / ".join(nonlinear.creep.options),
                 nonlinear.creep.value, "—", *ELSEWHERE["creep"]))
    rows.append(("ctl-antislip", nonlinear.anti_slip.label, "on / off",
                 "on" if nonlinear.anti_slip.value else "off", "—", *ELSEWHERE["anti_slip"]))
    for key, widget in (("delay", nonlinear.delay), ("threshold", nonlinear.threshold),
                        ("rate", nonlinear.rate)):
        css = next(c for c in widget.css_classes if c.startswith("ctl-"))
        bound = "≥ 0" if key == "delay" else "> 0"
        rows.append((css, widget.label, f"{bound} (step {_number(widget.step)})",
                     _number(widget.value), "—", *ELSEWHERE[key]))
    return rows


def controls_table(dashboard) -> str:
    lines = ["| control (CSS class) | dashboard: what [unit] | range | default | link | command line "
             "| files (JSON, Zarr, TOML; SI) |", "|---|---|---|---|---|---|---|"]
    lines += ["| " + " | ".join(f"`{row[0]}`" if i == 0 else row[i] for i in range(len(row))) + " |"
              for row in controls_rows(dashboard)]
    return "\n".join(lines)


def main() -> None:
    from docs_numbers import write_results

    from app.dashboard.dashboard import BogieDashboard

    table = controls_table(BogieDashboard(query={}))
    print(table)
    print(f"wrote {write_results('dashboard', {'blocks': {'controls': table}}, 'scripts/dashboard_controls.py')}")


if __name__ == "__main__":
    main()
