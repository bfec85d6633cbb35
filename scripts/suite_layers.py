"""What each layer of the test suite costs: the test time [s] of every test of a run, summed by
layer, from the log of a run with ``--durations=0``.

    bash run.sh test --durations=0 2>&1 | tee suite.log
    .venv/bin/python scripts/suite_layers.py suite.log

Layers (the markers of pyproject.toml): ``fast`` (not slow; ``bash run.sh test -m "not slow"``),
``slow`` without a browser or the image, ``browser`` (headless Chromium against a served app),
``docker`` (the image built with buildah).  A test's time is its setup, call and teardown as
pytest reports them: on two workers the wall time of the run is about half their sum, plus the
collection.  The tests each layer holds come from pytest's collection (``-m``), so the script
needs the project's venv and its tests.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LAYERS = {  # name -> pytest marker expression; every test is in exactly one
    "fast": "not slow",
    "slow": "slow and not browser and not docker",
    "browser": "slow and browser and not docker",
    "docker": "slow and docker",
}
DURATION = re.compile(r"^\s*([\d.]+)s (setup|call|teardown)\s+(\S+)")
TOTAL = re.compile(r"=+ .*?(\d+) passed.* in ([\d.]+)s")


def collected(expression: str) -> set[str]:
    """The test ids the marker expression selects."""
    out = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:xdist", "--collect-only", "-q",
                          "-m", expression], cwd=ROOT, capture_output=True, text=True, check=True)
    return {line.strip() for line in out.stdout.splitlines() if "::" in line}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("log", type=Path, help="the output of a run with --durations=0")
    args = parser.parse_args()
    times: Counter[str] = Counter()
    wall = None
    for line in args.log.read_text(errors="replace").splitlines():
        match = DURATION.match(line)
        if match:
            times[match.group(3)] += float(match.group(1))
        total = TOTAL.search(line)
        if total:
            wall = float(total.group(2))
    if not times:
        raise SystemExit(f"suite_layers: no durations in {args.log} (run pytest with --durations=0)")
    print(f"{'layer':8} {'tests':>6} {'test time [s]':>14}")
    count = 0
    for name, expression in LAYERS.items():
        tests = collected(expression)
        count += len(tests)
        print(f"{name:8} {len(tests):6d} {sum(times[t] for t in tests):14.0f}")
    print(f"{'all':8} {count:6d} {sum(times.values()):14.0f}")
    if wall is not None:
        print(f"pytest wall time {wall:.0f} s")


if __name__ == "__main__":
    main()
