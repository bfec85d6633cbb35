"""Benchmark of the calibration (stages A and J): ``bogie calibrate`` against one eigen-analysis call.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_calibration.py [--repeats 3]
        [--reference assets/parameters/calibrated.toml] [--json FILE]

In one run, as separate processes (what a user runs; the interpreter's start-up counted in both):

* reference: ``bogie eigen --s0 0.005 --json`` (the calibrated set; median of ``--repeats``);
* the bundled set's command, ``bogie calibrate --from assets/parameters/calibration_start.toml
  --divergence-weight 10 --out TMP`` (once: it takes a minute or two), wall time;
* the ratio of the two (the target: at most 150);
* reproduction: whether the written set equals ``--reference`` byte for byte, and if not the
  largest relative difference of a value (the bundled set
  is the output of this very command).

Wall clock; the machine may be shared, so the ratio is taken within one run.
"""

from __future__ import annotations

import argparse
import filecmp
import json
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BOGIE = [sys.executable, "-m", "app"]
# the command the bundled set's header names (docs/validation.md, "The bundled set")
BUNDLED_COMMAND = ["--from", "assets/parameters/calibration_start.toml", "--divergence-weight", "10"]


def timed(argv: list[str]) -> float:
    began = time.perf_counter()
    subprocess.run([*BOGIE, *argv], check=True, cwd=ROOT, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, env={"OPENBLAS_NUM_THREADS": "1", "PATH": ""})
    return time.perf_counter() - began


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--reference", default=str(ROOT / "assets/parameters/calibrated.toml"))
    parser.add_argument("--json", default=None, help="write the numbers to this file")
    args = parser.parse_args()
    eigen = statistics.median(timed(["eigen", "--s0", "0.005", "--json"])
                              for _ in range(args.repeats))
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "calibrated.toml"
        calibrate = timed(["calibrate", *BUNDLED_COMMAND, "--out", str(out)])
        same = filecmp.cmp(out, args.reference, shallow=False)
        written = tomllib.loads(out.read_text(encoding="utf-8"))
    bundled = tomllib.loads(Path(args.reference).read_text(encoding="utf-8"))
    difference = max(abs(written[k]["value"] / bundled[k]["value"] - 1) if bundled[k]["value"] else
                     abs(written[k]["value"]) for k in bundled)
    result = {"eigen_call_s": eigen, "calibrate_s": calibrate, "ratio": calibrate / eigen,
              "reproduces_reference": same, "largest_relative_difference": difference,
              "reference": args.reference}
    print(f"bogie eigen --s0 0.005 --json: {eigen:.2f} s (median of {args.repeats})")
    print(f"bogie calibrate:               {calibrate:.1f} s")
    print(f"ratio: {calibrate / eigen:.0f} (target <= 150)")
    print(f"written set equals {args.reference}: "
          + ("yes" if same else f"NO (largest relative difference of a value {difference:.2g})"))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
