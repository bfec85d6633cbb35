"""Log-sensitivities d ln f / d ln p of the extra modes (frame roll, motors' opposite longitudinal,
frame yaw) and of the car-body bounce at a parameter set, for every free parameter (central difference
±5 %, one-sided at a bound)."""
import sys, math, numpy as np
from model.parameters import load_parameters
from model import calibration as cal
from model.assembly import build_model
from model.eigen import eigen_analysis
from model.modes import characterize
from probe.common import FREE

def extras(p):
    p = cal.fit_operating_data(cal.with_constraints(p))
    m = build_model(p); r = eigen_analysis(m, cal._operating_point(p, 0.005))
    best = {}
    for i in r.complex_index:
        z = r.eigenvalues[i]; f = z.imag / 2 / np.pi
        if f > 18: break
        c = characterize(m, z, r.mode_shape(i)); d = c.directions
        s = {"car body": c.kinetic.get("CB", 0) * d["CB"].get("z", 0)}
        if f > 7:
            s.update({"frame roll": c.kinetic.get("BF", 0) * d["BF"].get("rx", 0),
                 "TMs opp.long": sum(c.kinetic.get(t, 0) * (d[t].get("x", 0) + d[t].get("ry", 0)) for t in ("ID1.stator", "ID2.stator")) * 0.5 * (1 - c.phase_cosine("ID1.stator", "ID2.stator", "x")),
                 "frame yaw": c.kinetic.get("BF", 0) * d["BF"].get("rz", 0)})
        for k, v in s.items():
            if v > best.get(k, (0,))[0]:
                best[k] = (v, f, z.real)
    return {k: v[1:] for k, v in best.items()}

def main():
    p = load_parameters(sys.argv[1])
    base = extras(p)
    keys = list(base)
    print("at set:", {k: (round(f, 3), round(re, 2)) for k, (f, re) in base.items()})
    print(f"{'parameter':32s} {'value':>10s} bound " + " ".join(f"{k:>13s}" for k in keys))
    for fp in FREE:
        v = p[fp.name]
        up, dn = min(v * 1.05, fp.high), max(v / 1.05, fp.low)
        a, b = extras(p.replace(**{fp.name: up})), extras(p.replace(**{fp.name: dn}))
        tag = "LOW " if v <= fp.low * 1.001 else ("HIGH" if v >= fp.high * 0.999 else "    ")
        sens = [math.log(a[k][0] / b[k][0]) / math.log(up / dn) for k in keys]
        print(f"{fp.name:32s} {v:10.4g} {tag} " + " ".join(f"{s:13.3f}" for s in sens))

if __name__ == "__main__":
    main()
