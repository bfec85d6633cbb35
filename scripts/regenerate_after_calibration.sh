#!/usr/bin/env bash
# Everything numeric that follows the default parameter set, regenerated in dependency order
# after `bogie calibrate` has rewritten assets/parameters/calibrated.toml.
#
#     bash scripts/regenerate_after_calibration.sh            # all (≈ 25 min on 2 cores)
#     bash scripts/regenerate_after_calibration.sh --no-app   # without the screenshots
#
# Then read what changed: `git diff --stat`, the figures and screenshots (open the PNGs), and the
# numbers the scripts print against those quoted in docs/validation.md, docs/response.md,
# docs/nonlinear.md, docs/sensitivity.md, docs/design-loads.md and README.md
# (scripts/validation_table.py prints the tables of docs/validation.md; the worked example of
# docs/design-loads.md is printed to /tmp/regen_design_loads.md).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PY:-.venv/bin/python}
BOGIE=${BOGIE:-.venv/bin/bogie}
export OPENBLAS_NUM_THREADS=1
step() { echo; echo "=== $* ($(date -u +%H:%M:%S) UTC)"; }

step "golden data (tests/golden)"
$PY scripts/make_golden.py
$PY scripts/make_golden_nonlinear.py

step "stored uncertainty studies (assets/data), two at a time"
$BOGIE uncertainty --samples 16 --out assets/data/uncertainty_n16.json > /tmp/regen_u16.log &
$BOGIE uncertainty --samples 32 --no-indices --speeds 40,80,120,160,200,250 \
    --out assets/data/uncertainty_no-indices_n32.json > /tmp/regen_u32.log
$BOGIE uncertainty --samples 32 --posterior --speeds 40,80,120,160,200,250 \
    --out assets/data/uncertainty_posterior_n32.json > /tmp/regen_p32.log
wait

step "figures (assets/figures)"
$PY scripts/figures_response.py
$PY scripts/figures_nonlinear.py
$PY scripts/figures_sensitivity.py
if [[ "${1:-}" != "--no-app" ]]; then
    $PY scripts/figures_posterior.py --app   # + uncertainty_band_app.png (needs chromium)
    step "screenshots (assets/screenshots; needs chromium)"
    $PY scripts/bench_app.py --only-screenshots
    $PY scripts/screenshot_design_loads.py
else
    $PY scripts/figures_posterior.py
fi
step "the worked example of docs/design-loads.md (/tmp/regen_design_loads.md)"
$PY scripts/example_design_loads.py > /tmp/regen_design_loads.md
step "done"
