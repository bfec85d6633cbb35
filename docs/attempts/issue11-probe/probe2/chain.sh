#!/bin/bash
# homotopy: from probe2/s1.toml move the creep shape in steps toward the soft shape of s2, a short
# search (creep shape fixed) after each step so that the ranks and characters are tracked; then a free search
cd /work/wt11
export PYTHONPATH=/work/wt11 OPENBLAS_NUM_THREADS=1
PY=/work/main/.venv/bin/python
prev=probe2/s1.toml; i=0
for shape in "0.47 0.25 400" "0.46 0.27 480" "0.45 0.29 550" "0.45 0.30 600"; do
  set -- $shape; i=$((i+1))
  FIX=polach_kA,polach_kS,creep_slope $PY probe2/search.py $prev probe2/h$i.toml 130 polach_kA=$1 polach_kS=$2 creep_slope=$3 > probe2/h$i.log 2>&1
  grep final probe2/h$i.log
  prev=probe2/h$i.toml
done
$PY probe2/search.py $prev probe2/h5.toml 150 > probe2/h5.log 2>&1; grep final probe2/h5.log
