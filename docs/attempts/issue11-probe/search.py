"""Compass search on log-parameters (patch bounds) minimising extra complex pairs below 12.6 Hz.
usage: search.py START.toml OUT.toml MAX_EVALS [W_OVER] [name=value ...]"""
import math, sys, time
import numpy as np
from model.parameters import load_parameters, save_parameters, Parameters
from model import calibration as cal
from probe.common import analyse, cost, report, FREE, NAMES, LOW, HIGH

start_file, out_file, max_evals = sys.argv[1], sys.argv[2], int(sys.argv[3])
w_over = float(sys.argv[4]) if len(sys.argv) > 4 else 0.0
p = load_parameters(start_file)
for kv in sys.argv[5:]:
    k, v = kv.split('='); p = p.replace(**{k: float(v)})
p = cal.with_constraints(p)
for f in FREE:   # clip into the bounds
    p = p.replace(**{f.name: float(min(max(p[f.name], f.low), f.high))})
a0 = analyse(p); N_REAL0 = 18   # real eigenvalues of the patch's calibrated set

def J(q):
    try:
        a = analyse(q)
    except Exception as exc:  # noqa
        return math.inf, None
    return cost(a, N_REAL0, w_over)[0], a

best = p; best_c, best_a = J(p); n = 1; t0 = time.time()
print(f"start cost {best_c:.4f}", flush=True)
for cycle in range(6):
    c_cycle = best_c
    for step in (0.4, 0.15, 0.05, 0.015):
        improved = True
        while improved and n < max_evals:
            improved = False
            order = np.random.default_rng(n).permutation(len(FREE))
            for i in order:
                f = FREE[i]
                for d in (1, -1):
                    x = math.log(best[f.name])
                    xn = min(max(x + d * step, LOW[i]), HIGH[i])
                    if abs(xn - x) < 1e-9:
                        continue
                    q = cal.with_constraints(best.replace(**{f.name: float(math.exp(xn))}))
                    c, a = J(q); n += 1
                    if c < best_c - 1e-4 * max(1, best_c):
                        best, best_c, best_a, improved = q, c, a, True
                        print(f"[{n} {time.time()-t0:.0f}s] step {step} {f.name} -> {math.exp(xn):.4g} cost {c:.4f}", flush=True)
                        break
                if improved or n >= max_evals:
                    break
    if best_c > c_cycle - 1e-3 or n >= max_evals:
        break
best = cal.fit_operating_data(best)
save_parameters(Parameters(dict(best.values), dict(best.notes), "probe"), out_file,
                f"issue-11 feasibility probe (probe/search.py), cost {best_c:.4f}")
a = analyse(best)
c, extra = cost(a, N_REAL0, w_over)
print(report(a)); print(f"cost {c:.4f} extras<12.6 {len(extra)} n_real {a['n_real']} (start {a0['n_real']}) n_complex {a['n_complex']} max_re {a['max_re']:.4f}")
print("ranks ok:", list(a['matched']) == list(range(10)))
for f in FREE:
    v = best[f.name]; tag = " LOW" if v <= f.low * 1.001 else (" HIGH" if v >= f.high * 0.999 else "")
    print(f"  {f.name:34s} {v:12.5g}  [{f.low:g}, {f.high:g}]{tag}")
print("evals", n, "time", round(time.time() - t0))
