"""Stage B2 of the by-rank calibration (the patch's `calibration.search_cost`, compass search
over SEARCH_PARAMETERS) from a given set.  usage: stage_b2.py START.toml OUT.toml MAX_EVALS"""
import sys
import time

from model import calibration as cal
from model.parameters import load_parameters, save_parameters

start = load_parameters(sys.argv[1])
began = time.time()
p = cal._pattern_search(cal.fit_operating_data(cal.with_constraints(start)),
                        cal.SEARCH_PARAMETERS, cal.search_cost, int(sys.argv[3]), print, "B2")
p = cal.fit_operating_data(p)
print(cal.format_table(cal.evaluate(p)))
print("time", time.time() - began)
save_parameters(p, sys.argv[2])
