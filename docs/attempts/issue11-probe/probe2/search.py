"""Compass search on log-parameters within cal.SEARCH_PARAMETERS' bounds; objective =
cal.search_cost (stage A re-solved per trial) + RANK_W*((|ln f_k/T1_k|-RANK_TOL)/0.01)^2 per rank
outside RANK_TOL + CHAR_W per rank with a wrong character + NPOS_W per positive real beyond two at 0.014.
usage: search.py START.toml OUT.toml MAX_SECONDS [name=value ...]   (env: RANK_W CHAR_W RANK_TOL NPOS_W FIX=a,b SEED)"""
import math, os, sys, time
import numpy as np
from model.parameters import load_parameters, save_parameters, Parameters
from model import calibration as cal
from probe2.common import analyse, brief, FREE

print("command: " + " ".join(f"{k}={os.environ[k]}" for k in ("RANK_W", "CHAR_W", "RANK_TOL", "NPOS_W", "FIX", "SEED") if k in os.environ)
      + " python " + " ".join(sys.argv), flush=True)
start_file, out_file, max_s = sys.argv[1], sys.argv[2], float(sys.argv[3])
fixed = set(os.environ.get('FIX', '').split(','))
free = [f for f in FREE if f.name not in fixed]
p = load_parameters(start_file)
for kv in sys.argv[4:]:
    k, v = kv.split('='); p = p.replace(**{k: float(v)})
p = cal.with_constraints(p)
for f in FREE:
    p = p.replace(**{f.name: float(min(max(p[f.name], f.low), f.high))})


def J(q):
    try:
        a = analyse(q)
    except Exception as exc:  # noqa
        return math.inf, None
    return a['cost'], a


def save(best, a, tag):
    save_parameters(Parameters(dict(a['p'].values), dict(best.notes), "probe2"), out_file,
                    f"issue-11 probe 2 (probe2/search.py {' '.join(sys.argv[1:])}), {tag}\n{brief(a)}")


best = p; best_c, best_a = J(p); n = 1; t0 = time.time()
print("start", brief(best_a), flush=True)
rng = np.random.default_rng(int(os.environ.get('SEED', 1)))
steps = (0.3, 0.1, 0.03, 0.01)
last_save = time.time()
for cycle in range(20):
    c_cycle = best_c
    for step in steps:
        improved = True
        while improved and time.time() - t0 < max_s:
            improved = False
            for i in rng.permutation(len(free)):
                f = free[i]
                for d in rng.permutation([1, -1]):
                    x = math.log(best[f.name])
                    xn = min(max(x + d * step, math.log(f.low)), math.log(f.high))
                    if abs(xn - x) < 1e-9:
                        continue
                    q = cal.with_constraints(best.replace(**{f.name: float(math.exp(xn))}))
                    c, a = J(q); n += 1
                    if c < best_c - 1e-4 * max(1, best_c):
                        best, best_c, best_a, improved = q, c, a, True
                        print(f"[{n} {time.time()-t0:.0f}s] step {step} {f.name} -> {math.exp(xn):.4g}  {brief(a)}", flush=True)
                        break
                if improved or time.time() - t0 >= max_s:
                    break
            if time.time() - last_save > 120:
                save(best, best_a, f"checkpoint after {n} evaluations"); last_save = time.time()
        print(f"  step {step} done: {n} evals {time.time()-t0:.0f}s cost {best_c:.4f}", flush=True)
    if best_c > c_cycle * (1 - 1e-3) or time.time() - t0 >= max_s:
        break
save(best, best_a, f"final after {n} evaluations")
print("final", brief(best_a))
print(cal.format_table(cal.evaluate(best_a['p'])))
for f in FREE:
    v = best_a['p'][f.name]; tag = " LOW" if v <= f.low * 1.001 else (" HIGH" if v >= f.high * 0.999 else "")
    print(f"  {f.name:34s} {v:12.5g}  [{f.low:g}, {f.high:g}]{tag}")
print("evals", n, "time", round(time.time() - t0))
