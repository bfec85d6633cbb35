"""issue-11 probe 2: Re / driving-shaft / divergence targets while keeping Table 1 by rank."""
import math, os
import numpy as np
from model import calibration as cal

T1 = np.array(cal.TABLE1_IM_HZ)
RANK_TOL = float(os.environ.get('RANK_TOL', 0.045))   # penalty-free band (log) of the by-rank Im
RANK_W = float(os.environ.get('RANK_W', 20.0))
CHAR_W = float(os.environ.get('CHAR_W', 20.0))
NPOS_W = float(os.environ.get('NPOS_W', 2.0))          # per positive real beyond two at 0.014
# optional extra weights on the original cost's terms (1 = cal.search_cost as is)
FREE = cal.SEARCH_PARAMETERS
NAMES = [f.name for f in FREE]


def analyse(p):
    p = cal.fit_operating_data(cal.with_constraints(p))
    operating = sum(cal._soft(row.error / 0.01) for row in cal.operating_rows(p))
    e = cal.evaluate_by_rank(p)
    base = operating + cal.rank_cost(e)
    f = e.stable.imag / (2 * np.pi)
    lr = np.log(f / T1)
    pen_rank = sum(RANK_W * (max(0.0, abs(x) - RANK_TOL) / 0.01) ** 2 for x in lr)
    pen_char = CHAR_W * int(np.count_nonzero(~e.character_ok))
    npos = int(np.count_nonzero(e.unstable_real > 0))
    pen_pos = NPOS_W * max(0, npos - 2)
    return dict(p=p, e=e, base=base, pen_rank=pen_rank, pen_char=pen_char, pen_pos=pen_pos,
                cost=base + pen_rank + pen_char + pen_pos, lr=lr, npos=npos,
                re=[e.matched[k - 1].real for k in cal.RE_MODES],
                ds=e.driving_shaft.imag / (2 * np.pi), pos=e.unstable_real[:3].copy())


def brief(a):
    return (f"cost {a['cost']:.3f} (base {a['base']:.3f} rank {a['pen_rank']:.2f} char {a['pen_char']:.0f} pos {a['pen_pos']:.0f}) "
            f"maxdf {100*np.max(np.abs(a['lr'])):.2f}% Re(1,3,4,8,9,10) " + " ".join(f"{x:.3g}" for x in a['re'])
            + f" ds {a['ds']:.1f} reals014 " + " ".join(f"{x:.3g}" for x in a['pos']))
