import sys, numpy as np
from model.parameters import load_parameters
from probe.common import analyse, cost, report, FREE
p = load_parameters(sys.argv[1])
for kv in sys.argv[2:]:
    k, v = kv.split('='); p = p.replace(**{k: float(v)})
a = analyse(p)
c, extra = cost(a)
print(report(a)); print('cost', round(c,3), 'extras<12.6:', len(extra), 'n_real', a['n_real'], 'n_complex', a['n_complex'], 'max_re', a['max_re'])
print('ranks ok:', list(a['matched']) == list(range(10)), 'op_err', np.round(a['op_err'], 5))
print('score matrix (rows T2#1..10, cols rank 1..):'); np.set_printoptions(precision=2, linewidth=200, suppress=True); print(a['score'][:, :16])
