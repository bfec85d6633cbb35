#!/bin/bash
# one-at-a-time moves from probe2/best.toml toward the missed targets (look.py prints ranks, characters, Re, reals)
cd /work/wt11; export PYTHONPATH=/work/wt11 OPENBLAS_NUM_THREADS=1; PY=/work/main/.venv/bin/python
for a in "" "yaw_damper_height=0.35" "yaw_damper_height=0.15" "yaw_damping=3e5" "yaw_damping=1.5e5" \
         "creep_slope=480 polach_kS=0.27 polach_kA=0.46" "creep_slope=600 polach_kS=0.3 polach_kA=0.45" "creep_slope=1200 polach_kS=0.3 polach_kA=0.45" \
         "motor_slope=3000" "motor_slope=1000" "motor_slope=300" "motor_slope=60" "rotor_inertia=12" "rotor_inertia=24"; do
  echo "== ${a:-best}"; $PY probe2/look.py probe2/best.toml $a
done
