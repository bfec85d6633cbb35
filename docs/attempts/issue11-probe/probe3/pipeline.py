"""Deterministic issue-11 calibration chain (replaces the manual chains of probe/ and probe2/).

  stage 1  patch calibration: stage A + B1 + B2 (model.calibration.calibrate) from the estimate
  stage 2  lead values frame_inertia_x=1800, stator_inertia_y=180, silent_block_stiffness_x=8.8e6
  stage 3  compass search on the probe/ objective (RANK=0, F_CUT=12.6, no overdamping term)
  stage 4  compass search on the probe/ objective (RANK=1, overdamping penalised, W_OVER)
  stage 5  compass search on the probe2/ objective (default weights RANK_W=CHAR_W=20, RANK_TOL=0.045, NPOS_W=2)

Every search has a fixed evaluation budget (no wall-time limit) and a fixed move order (the
parameters cyclically in SEARCH_PARAMETERS order, +step before -step; after an accepted move the
sweep continues with the next parameter); no random numbers.  Each stage writes probe3/stageN.toml
(stage 5 also probe3/final.toml) and one summary line to stdout.

usage: pipeline.py [--scale X] [--out DIR] [--from-stage N] [--char4 W] [--wide5]
  --scale X       multiply every budget by X (e.g. 0.05 for a quick determinism check)
  --out DIR       output directory (default probe3)
  --from-stage N  start at stage N from DIR/stage{N-1}.toml (re-run a stage to check determinism)
"""
import argparse, math, os, sys, time

# the probe objectives read options from the environment at import: pin them
for k in ('RANK', 'F_CUT', 'FIX', 'RANK_TOL', 'RANK_W', 'CHAR_W', 'NPOS_W', 'SEED'):
    os.environ.pop(k, None)

import numpy as np
from model.parameters import load_parameters, save_parameters, Parameters
from model import calibration as cal
import probe.common as pc
import probe2.common as p2c

ESTIMATE = 'assets/parameters/estimate.toml'
LEAD = dict(frame_inertia_x=1800.0, stator_inertia_y=180.0, silent_block_stiffness_x=8.8e6)
BUDGET = {1: 2400, 3: 1000, 4: 1500, 5: 3000}    # evaluations per stage (stage 1: calibrate's)
W_OVER = 1.0                                     # stage 4: per complex pair lost to overdamping
N_REAL0 = 18


def clip(p):
    p = cal.with_constraints(p)
    for f in cal.SEARCH_PARAMETERS:
        p = p.replace(**{f.name: float(min(max(p[f.name], f.low), f.high))})
    return cal.with_constraints(p)


def compass(start, cost, budget, steps, log, label):
    """Deterministic compass search in log space within cal.SEARCH_PARAMETERS' bounds."""
    free = cal.SEARCH_PARAMETERS
    best = start
    best_c, best_a = cost(best)
    n = 1
    log(f"  {label}: start cost {best_c:.6g}")
    for cycle in range(20):
        c_cycle = best_c
        for step in steps:
            i, since = 0, 0          # since = moves tried since the last improvement
            while n < budget and since < 2 * len(free):
                f = free[i % len(free)]; i += 1
                for d in (1, -1):
                    since += 1
                    x = math.log(best[f.name])
                    xn = min(max(x + d * step, math.log(f.low)), math.log(f.high))
                    if abs(xn - x) < 1e-9 or n >= budget:
                        continue
                    q = cal.with_constraints(best.replace(**{f.name: float(math.exp(xn))}))
                    c, a = cost(q); n += 1
                    if c < best_c - 1e-4 * max(1, best_c):
                        best, best_c, best_a, since = q, c, a, 0
                        log(f"  {label}: [{n}] step {step} {f.name} -> {math.exp(xn):.5g} cost {c:.6g}")
                        break
            log(f"  {label}: step {step} done, {n} evaluations, cost {best_c:.6g}")
        if best_c > c_cycle * (1 - 1e-3) or n >= budget:
            break
    return best, best_c, best_a, n


def probe_cost(rank, w_over, w_char=0.0):
    def J(q):
        pc.RANK = rank
        try:
            a = pc.analyse(q)
        except Exception:  # noqa: BLE001 - a failed trial is just a bad trial
            return math.inf, None
        extra = w_char * sum(int(a['matched'][k] != k) for k in range(10))   # wrong character by rank
        return pc.cost(a, N_REAL0, w_over)[0] + extra, a
    return J


def probe2_cost(q):
    try:
        a = p2c.analyse(q)
    except Exception:  # noqa: BLE001
        return math.inf, None
    return a['cost'], a


def rank_summary(p):
    e = cal.evaluate_by_rank(p)
    f = e.stable.imag / (2 * np.pi)
    err = 100 * (f / np.array(cal.TABLE1_IM_HZ) - 1)
    ok = int(np.count_nonzero((np.abs(err) <= 5) & e.character_ok))
    return (f"ranks within 5 % with character {ok}/10, max |err| {np.max(np.abs(err)):.2f} %, "
            f"chars ok {int(np.count_nonzero(e.character_ok))}/10")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--scale', type=float, default=1.0)
    ap.add_argument('--out', default='probe3')
    ap.add_argument('--from-stage', type=int, default=1)
    ap.add_argument('--char4', type=float, default=0.0,
                    help='stage 4: extra cost per rank whose matched character is not its own')
    ap.add_argument('--wide5', action='store_true', help='stage 5: steps 1.0 and 0.6 before 0.3 ...')
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    budget = {k: max(8, int(round(v * args.scale))) for k, v in BUDGET.items()}

    def log(msg):
        print(msg, flush=True)

    def save(p, n, header):
        path = os.path.join(args.out, f'stage{n}.toml')
        save_parameters(Parameters(dict(p.values), dict(p.notes), f'probe3-stage{n}'), path,
                        f"probe3/pipeline.py stage {n} (scale {args.scale}): {header}")
        return path

    def summary(n, t0, extra, p):
        log(f"STAGE {n} done in {time.time() - t0:.0f} s: {extra}; {rank_summary(p)}")

    log(f"pipeline: budgets {budget}, out {args.out}, from stage {args.from_stage}")
    s = args.from_stage
    p = load_parameters(ESTIMATE) if s == 1 else load_parameters(os.path.join(args.out, f'stage{s - 1}.toml'))

    if s <= 1:
        t0 = time.time()
        p, _rows = cal.calibrate(p, max_evaluations=budget[1], progress=log)
        c = cal.search_cost(p)
        save(p, 1, f"calibrate(estimate, max_evaluations={budget[1]}), search_cost {c:.6g}")
        summary(1, t0, f"calibrate {budget[1]} evaluations, search_cost {c:.6g}", p)
    if s <= 2:
        t0 = time.time()
        p = clip(p.replace(**LEAD))
        p = cal.fit_operating_data(p)
        save(p, 2, f"lead values {LEAD}")
        summary(2, t0, f"lead values {LEAD}", p)
    if s <= 3:
        t0 = time.time()
        p, c, a, n = compass(clip(p), probe_cost(0, 0.0), budget[3], (0.4, 0.15, 0.05, 0.015), log, 'stage 3')
        p = cal.fit_operating_data(p)
        save(p, 3, f"probe objective RANK=0 W_OVER=0, {n} evaluations, cost {c:.6g}")
        summary(3, t0, f"probe objective RANK=0, {n} evaluations, cost {c:.6g}", p)
    if s <= 4:
        t0 = time.time()
        c4 = f" char4={args.char4}" if args.char4 else ""
        p, c, a, n = compass(clip(p), probe_cost(1, W_OVER, args.char4), budget[4], (0.4, 0.15, 0.05, 0.015), log, 'stage 4')
        p = cal.fit_operating_data(p)
        save(p, 4, f"probe objective RANK=1 W_OVER={W_OVER}{c4}, {n} evaluations, cost {c:.6g}")
        summary(4, t0, f"probe objective RANK=1 W_OVER={W_OVER}{c4}, {n} evaluations, cost {c:.6g}", p)
    if s <= 5:
        t0 = time.time()
        p, c, a, n = compass(clip(p), probe2_cost, budget[5],
                             ((1.0, 0.6) if args.wide5 else ()) + (0.3, 0.1, 0.03, 0.01), log, 'stage 5')
        p = a['p']   # stage A re-solved (as probe2/search.py saves it)
        path = save(p, 5, f"probe2 objective, {n} evaluations\n{p2c.brief(a)}")
        with open(path, 'rb') as src, open(os.path.join(args.out, 'final.toml'), 'wb') as dst:
            dst.write(src.read())
        summary(5, t0, f"probe2 objective, {n} evaluations, {p2c.brief(a)}", p)


if __name__ == '__main__':
    main()
