"""``bogie assess`` at the default set against one ``bogie envelope --phase all`` call at a single
(s0, v) point, in the same run (the target: at most 10x); the assessment's four transient and
ripple load cases against the same without the ripple case (the target: at most 3x); and what the
running case adds (``bogie assess --serial`` against ``--no-running``).

    .venv/bin/python scripts/bench_assess.py [--runs 3] [--json FILE]

Each command runs as its own process (as a user runs it, imports included), alternated; the
medians and their ratios are printed.  Both commands are timed twice: as run by default (their
short-circuit grid on a local Dask cluster) and with ``--serial`` (in the command's process); the
ratios compare like with like.  The ripple case's cost: the serial assessment of the four load
cases against the serial assessment of the other three (``AssessmentOptions.cases``), both as a
process running :func:`model.studies.assessment.assess` on the default set.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

BOGIE = str(Path(sys.executable).with_name("bogie"))
COMMANDS = {
    "assess": [BOGIE, "assess", "--json"],
    "assess --serial": [BOGIE, "assess", "--serial", "--json"],
    "assess --serial --no-running": [BOGIE, "assess", "--serial", "--no-running", "--json"],
    "envelope": [BOGIE, "envelope", "--s0", "0.005", "--v", "120", "--phase", "all", "--json"],
    "envelope --serial": [BOGIE, "envelope", "--s0", "0.005", "--v", "120", "--phase", "all",
                          "--serial", "--json"],
    "assess() four cases": [sys.executable, "-c",
                            "from model import load_parameters; "
                            "from model.studies.assessment import assess; "
                            "assess(load_parameters())"],
    "assess() without ripple": [sys.executable, "-c",
                                "from model import load_parameters; "
                                "from model.studies.assessment import AssessmentOptions, assess; "
                                "assess(load_parameters(), AssessmentOptions(cases=("
                                "'short_circuit', 'unstable_adhesion', 'starting')))"],
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    for _ in range(args.runs):
        for name, command in COMMANDS.items():
            start = time.perf_counter()
            subprocess.run(command, check=True, env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            times[name].append(time.perf_counter() - start)
    medians = {name: statistics.median(values) for name, values in times.items()}
    result = {"runs": args.runs, "times_s": times, "median_s": medians,
              "ratio_to_envelope": medians["assess"] / medians["envelope"],
              "ratio_serial": medians["assess --serial"] / medians["envelope --serial"],
              "ratio_with_ripple": (medians["assess() four cases"]
                                    / medians["assess() without ripple"]),
              "running_case_s": (medians["assess --serial"]
                                 - medians["assess --serial --no-running"])}
    for name, value in medians.items():
        print(f"{name:<20} median {value:6.2f} s  ({', '.join(f'{x:.2f}' for x in times[name])})")
    print(f"assess / envelope = {result['ratio_to_envelope']:.2f}x, with --serial both "
          f"{result['ratio_serial']:.2f}x (target <= 10x)")
    print(f"four load cases / without the ripple case = {result['ratio_with_ripple']:.2f}x "
          "(target <= 3x)")
    print(f"the running case (assess --serial against --no-running): "
          f"{result['running_case_s']:.1f} s")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
