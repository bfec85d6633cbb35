"""The benchmark commands that BENCHMARKS.md records still run on the present model, in a size
that takes seconds (smoke test: exit status 0 and the table they print; the timings themselves
are measured by running the scripts, never asserted here).  bench_response and bench_nonlinear
once stopped working unnoticed when the model gained massless coordinates."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from conftest import ROOT

pytestmark = pytest.mark.slow
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


@pytest.mark.parametrize(("script", "arguments", "expected"), [
    pytest.param("bench_locus.py", ["--points", "6", "--repeat", "1"],
                 "`root_locus` (reduced, error-controlled)", id="locus"),
    pytest.param("bench_response.py", ["--t-end", "0.05", "--skip-radau"],
                 "closed form, solve only (warm)", id="response"),
    pytest.param("bench_nonlinear.py", ["--t-end", "0.02", "--radau-budget", "2",
                                        "--reference-t-end", "0.001", "--reference-budget", "2"],
                 "scipy.integrate Radau rtol 1e-8 (nonlinear)", id="nonlinear"),
    pytest.param("bench_design_loads.py", ["--t-end", "0.05", "--fs", "2000", "--parts", "1,2"],
                 "scipy.signal.lsim of the linear system", id="design-loads"),
    pytest.param("bench_sensitivity.py", ["--repeats", "1", "--timed-runs", "1",
                                          "--creep-n", "16"],
                 "ds0*/dp at known s0*", id="sensitivity"),
    pytest.param("bench_resonance.py", ["--speeds", "12", "--points", "200", "--repeat", "1"],
                 "Campbell diagram, 12 speeds", id="resonance"),
    pytest.param("bench_preview.py", ["--quick"], "| b_M (reduced model) |", id="preview"),
])
def test_benchmark_script_runs(script, arguments, expected):
    run = subprocess.run([sys.executable, str(ROOT / "scripts" / script), *arguments], cwd=ROOT,
                         env=ENV, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert expected in run.stdout
