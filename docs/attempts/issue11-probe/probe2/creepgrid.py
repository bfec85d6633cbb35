"""dmu/ds at 0.005 and 0.014 after stage A for a grid of the creep shape (kA, kS, creep_slope)."""
import sys, itertools
import numpy as np
from model.parameters import load_parameters
from model import calibration as cal
from model.operating_point import creep_law
p0 = load_parameters(sys.argv[1])
V = cal.V_REF
for kA, kS, c in itertools.product((0.3, 0.45, 0.7, 1.0), (0.1, 0.2, 0.3, 0.4), (130, 200, 339, 600, 1200, 3000)):
    if kS > kA: continue
    p = cal.fit_operating_data(p0.replace(polach_kA=kA, polach_kS=kS, creep_slope=c))
    err = max(abs(r.error) for r in cal.operating_rows(p))
    law = creep_law(p)
    print(f"kA {kA:.2f} kS {kS:.2f} slope {c:5.0f}  dmu(0.005) {law.dmu_ds(0.005, V):7.3f} dmu(0.014) {law.dmu_ds(0.014, V):7.3f}  mu0 {p['polach_mu0']:.3f} A {p['polach_A']:.3f} B {p['polach_B']:.3f} p {p['gear_ratio']:.3f} opErr {100*err:.2f}%", flush=True)
