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

# in the files: name [unit] of each quantity (the case's quantities take their command-line
# option from their declaration, app.results.case) and of the creep model's controls
FILES = {"s0": "`s0` [-]", "v": "`v` [m/s], `v_kmh`", "N0": "`N0` [N], `wheel_force`",
         "b_M": "`b_M` [N m s/rad], `motor_slope`",
         "rail": "`rail`", "M0": "`M0` [N m]",
         "f": "`f` [Hz]", "D": "`D` [-]", "dt": "`phase_s` [s]", "t_end": "`t` [s]"}
# the commands a choice's option belongs to (a number's: every command with the operating point)
COMMANDS = {"rail": " (`bogie envelope`, `report`, `study map`)"}
CREEP = {  # the creep model's controls: (command-line option [unit], in files: name [unit])
    "creep": ("`--creep`", "`creep`"),
    "anti_slip": ("`--anti-slip`", "`anti_slip`"),
    "delay": ("`--anti-slip-delay` [s]", "`anti_slip_delay` [s]"),
    "threshold": ("`--anti-slip-threshold` [m/s]", "—"),
    "rate": ("`--anti-slip-rate` [1/s]", "—"),
}


def elsewhere(q) -> tuple[str, str]:
    """(command-line option [unit], in files) of a quantity."""
    option = f"`{q.option}`" + (COMMANDS.get(q.name, "") if q.choice else f" [{q.outer_unit}]")
    # a quantity not listed in FILES: its declared file keys in the files' (the outer) unit
    files = FILES.get(q.name) or ", ".join(
        f"`{key}`" + ("" if q.choice or k else f" [{q.outer_unit}]") for k, key in enumerate(q.files))
    return option, files or "—"


def _number(x: float) -> str:
    return f"{x:,.6g}".replace(",", " ").replace("-", "−")


def controls_rows(dashboard) -> list[tuple]:
    """(CSS class, label, range, default, link name [unit], CLI option, files) of every control
    of the dashboard's controls column, in its order."""
    from app.dashboard.url_state import choices, numbers

    quantities = dashboard.case_type.quantities
    link = {q.name: f"`{name}` [{q.outer_unit}]" for name, q in numbers(quantities).items()}
    link |= {target: f"`{name}`" for name, target in choices(quantities).items()}
    sliders = dashboard.controls.sliders
    rows = []
    for name, widget in sliders.items():
        q = dashboard.case_type.quantity(name)
        if q.automatic:  # after its switch, as in the column
            auto = dashboard.param[f"{name}_auto"]
            rows.append((f"ctl-{name}_auto", f"{q.symbol} automatic: the motor torque continuous "
                         "at the fault", "on / off", "on" if auto.default else "off",
                         f"`{q.link}` absent", f"`{q.option}` absent", "—"))
        default = _number(widget.value) + (" (the set's)" if q.from_set else "")
        rows.append((f"ctl-{name}", widget.label, f"{_number(widget.start)} … {_number(widget.end)} "
                     f"(step {_number(widget.step)})", default, link.get(name, "—"),
                     *elsewhere(q)))
        if name == "b_M":
            rail = dashboard.case_type.quantity("rail")
            rows.append(("ctl-rail", rail.label, " / ".join(rail.choices), rail.default,
                         link["rail"], *elsewhere(rail)))
    nonlinear = dashboard.nonlinear
    rows.append(("ctl-creep", "creep model", " / ".join(nonlinear.creep.options),
                 nonlinear.creep.value, "—", *CREEP["creep"]))
    rows.append(("ctl-antislip", nonlinear.anti_slip.label, "on / off",
                 "on" if nonlinear.anti_slip.value else "off", "—", *CREEP["anti_slip"]))
    for key, widget in (("delay", nonlinear.delay), ("threshold", nonlinear.threshold),
                        ("rate", nonlinear.rate)):
        css = next(c for c in widget.css_classes if c.startswith("ctl-"))
        bound = "≥ 0" if key == "delay" else "> 0"
        rows.append((css, widget.label, f"{bound} (step {_number(widget.step)})",
                     _number(widget.value), "—", *CREEP[key]))
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
