"""The parameter file's schema as the table of docs/own-bogie.md: every name, its unit, what it
is, the values the model accepts, the bundled default and, for the parameters ``bogie calibrate``
fits, the calibration's bounds — read from ``model/mechanics/parameters.py`` (``SCHEMA``, the
dynamics; ``ASSESSMENT_SCHEMA``, the strength data of ``bogie assess``) and
``model/studies/calibration_bounds.py`` (``FREE_PARAMETERS``).

    .venv/bin/python scripts/parameter_schema.py     # docs/results/parameters.json, prints the table

``tests/docs/test_own_bogie.py`` renders the table from the code and checks the page's copy.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

SECTIONS = {  # the first parameter of each group of the schema -> its heading
    "wheel_radius": "wheel, rail and contact", "polach_mu0": "creep law (Polach)",
    "wheelbase": "geometry", "car_body_mass": "masses and inertias",
    "driving_shaft_stiffness": "stiffnesses", "primary_damping_z": "damping and the motor",
    "wheel_seat_diameter": "strength data of the checks (`bogie assess`; not the dynamics)",
}


def _number(x: float) -> str:
    if 1e3 <= abs(x) < 1e6:
        return f"{x:,.0f}".replace(",", " ").replace("-", "−")
    if x == 0 or 1e-3 <= abs(x) < 1e3:
        return f"{x:.4g}".replace("-", "−")
    exponent = math.floor(math.log10(abs(x)))
    return f"{x / 10 ** exponent:.3g}·10" + str(exponent).translate(
        str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻"))


def _valid(low: float, high: float, low_allowed: bool) -> str:
    left = "≥" if low_allowed else ">"
    if math.isinf(high):
        return f"{left} {_number(low)}"
    return f"{_number(low)} {'≤' if low_allowed else '<'} x ≤ {_number(high)}"


def schema_table() -> str:
    """Markdown: one row per parameter of the schema, in its order."""
    from model.mechanics.parameters import ALL_SCHEMA, load_parameters
    from model.studies.calibration_bounds import FREE_PARAMETERS

    defaults = load_parameters()
    free = {f.name: f for f in FREE_PARAMETERS}
    lines = ["| name | unit | what it is | valid | default (calibrated set) | calibrated within |",
             "|---|---|---|---|---|---|"]
    for name, (unit, description, (low, high, low_allowed)) in ALL_SCHEMA.items():
        if name in SECTIONS:
            lines.append(f"| **{SECTIONS[name]}** | | | | | |")
        bounds = f"{_number(free[name].low)} … {_number(free[name].high)}" if name in free else "—"
        lines.append(f"| `{name}` | {unit} | {description.replace('|', '/')} | "
                     f"{_valid(low, high, low_allowed)} | {_number(defaults[name])} | {bounds} |")
    return "\n".join(lines)


EXAMPLE_NOTE = "30 % softer quill shaft (drawing 123)"


def example_output() -> str:
    """What ``bogie parameters --params my_bogie.toml`` prints for the worked example (the bundled
    set with the driving shaft 30 % softer, as scripts/model_facts.py's variant): the first line,
    the heading and its row."""
    import tempfile

    from model_facts import SOFTER

    from app.cli.parameters import parameter_table
    from model.mechanics.parameters import Parameters, load_parameters, save_parameters
    from model.studies.calibration_bounds import parameter_rows

    base = load_parameters()
    variant = base.replace(driving_shaft_stiffness=round(SOFTER * base["driving_shaft_stiffness"], -4))
    variant = Parameters(variant.values, {**base.notes, "driving_shaft_stiffness": EXAMPLE_NOTE})
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "my_bogie.toml"
        save_parameters(variant, path)
        table = parameter_table(parameter_rows(load_parameters(path)), "my_bogie.toml").splitlines()
    row = next(line for line in table if line.startswith("driving_shaft_stiffness"))
    return "\n".join(["```", "$ bogie parameters --params my_bogie.toml", table[0], "", table[2], "…",
                      row, "```"])


def main() -> None:
    from docs_numbers import write_results

    from model.mechanics.parameters import ALL_SCHEMA, ASSESSMENT_SCHEMA, SCHEMA
    from model.studies.calibration_bounds import FREE_PARAMETERS

    table = schema_table()
    print(table)
    data = {"blocks": {"schema": table, "example_output": example_output()},
            "count": len(ALL_SCHEMA), "dynamics": len(SCHEMA), "strength": len(ASSESSMENT_SCHEMA),
            "calibrated": len(FREE_PARAMETERS)}
    print(f"wrote {write_results('parameters', data, 'scripts/parameter_schema.py')}")


if __name__ == "__main__":
    main()
