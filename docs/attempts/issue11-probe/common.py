"""Feasibility probe for issue 11: fewest complex pairs below 12.6 Hz within the patch's bounds."""
import math
import numpy as np
from scipy.optimize import linear_sum_assignment
from model import calibration as cal
from model.assembly import build_model
from model.eigen import eigen_analysis
from model.modes import characterize, wheelset_yaw_fraction

import os
RANK = int(os.environ.get('RANK', 0))
N_COMPLEX0 = 183
F_CUT = float(os.environ.get('F_CUT', 12.6))
T1 = np.array(cal.TABLE1_IM_HZ)
FREE = tuple(f for f in cal.SEARCH_PARAMETERS if f.name not in os.environ.get('FIX', '').split(','))
NAMES = [f.name for f in FREE]
LOW = np.log([f.low for f in FREE]); HIGH = np.log([f.high for f in FREE])


def analyse(p, fmax=16.0, describe=False):
    p = cal.fit_operating_data(cal.with_constraints(p))
    op_err = [row.error for row in cal.operating_rows(p)]
    m = build_model(p)
    r = eigen_analysis(m, cal._operating_point(p, cal.S0_STABLE))
    ci = r.complex_index
    f = r.eigenvalues[ci].imag / (2 * np.pi)
    n_cand = max(12, int(np.count_nonzero(f < fmax)))
    cand = ci[:n_cand]
    shapes = [r.mode_shape(i) for i in cand]
    chars = [characterize(m, r.eigenvalues[i], q) for i, q in zip(cand, shapes)]
    yaws = [wheelset_yaw_fraction(m, q) for q in shapes]
    score = np.array([[sig(c, y) for c, y in zip(chars, yaws)] for _, sig in cal.MODE_SIGNATURES])
    rows, cols = linear_sum_assignment(-score)
    matched = np.empty(10, dtype=int); matched[rows] = cols   # rank position (0-based) per Table-2 k
    mscore = score[rows, cols]
    # real eigenvalues of frame/motor body modes (overdamped pairs), not the slow secondary-suspension ones
    over = []
    for i in r.real_index:
        z = r.eigenvalues[i].real
        if -2000 < z < -0.5:
            c = characterize(m, r.eigenvalues[i], r.mode_shape(i))
            lead = max(c.kinetic, key=c.kinetic.get)
            if lead in ('BF', 'ID1.stator', 'ID2.stator'):
                over.append((z, c.kinetic[lead], c.description))
    return dict(over=over, p=p, op_err=op_err, ev=r.eigenvalues[cand], f=f[:n_cand], re=r.eigenvalues[cand].real,
                matched=matched, mscore=mscore, score=score, chars=chars,
                n_real=len(r.real_index), reals=r.real, max_re=r.max_real_part, n_complex=len(ci))


def cost(a, overdamp_ref=None, w_over=0.0):
    f, matched = a['f'], a['matched']
    extra = [j for j in range(len(f)) if f[j] < F_CUT and j not in set(matched)]
    c = sum(0.3 + 3.0 * (F_CUT - f[j]) / F_CUT for j in extra)
    for k in range(10):
        lr = math.log(f[matched[k]] / T1[k])
        c += (max(0.0, abs(lr) - 0.10) / 0.03) ** 2 + 0.2 * (lr / 0.10) ** 2
        c += 3.0 * max(0.0, 0.15 - a["mscore"][k]) / 0.15   # weak character match
    c += sum((e / 0.01) ** 2 for e in a['op_err'])
    if a['max_re'] > 0:
        c += 10 + 100 * a['max_re']
    if w_over:   # pairs lost to overdamping: fewer complex eigenvalues than the patch's set (183)
        c += w_over * max(0, N_COMPLEX0 - a['n_complex'])
    if RANK:     # the k-th pair by Im must have Table 2's k-th character, within 5 % of Table 1's k-th
        for k in range(10):
            lr = math.log(f[k] / T1[k])
            c += 0.5 * (max(0.0, abs(lr) - 0.045) / 0.02) ** 2 + (0.5 if matched[k] != k else 0.0)
    return c, extra


def report(a, fmax=14.0):
    f, matched = a['f'], a['matched']
    inv = {j: k for k, j in enumerate(matched)}
    lines = []
    for j in range(len(f)):
        if f[j] >= fmax:
            break
        tag = f"T2#{inv[j]+1:<2d} (score {a['mscore'][inv[j]]:.2f})" if j in inv else "EXTRA          "
        lines.append(f"{j+1:2d} {f[j]:7.3f} Hz  Re {a['re'][j]:8.3f}  {tag}  {a['chars'][j].description}")
    for z, body, d in a['over']:
        lines.append(f"   overdamped real {z:9.3f} 1/s (lead body kinetic share {body:.2f}): {d}")
    return "\n".join(lines)
