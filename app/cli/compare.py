"""``bogie compare``: a design variant beside its baseline from the command line.

    bogie compare BASE.toml VARIANT.toml --s0 0.005 --v 120 [--n0 N --bm B]
                  [--m0 M0 --f F --decay D --t-end T] [--json]

Each side: the stability limit s0*(v) at the speed, the largest real part, the counts of
unstable pairs and divergent real eigenvalues, the ten lowest complex pairs and the peak loads of
the short-circuit response (:mod:`model.studies.compare`).  ``--json`` prints ``{operating_point,
parameter_differences, base, variant, delta}``.  Without ``--n0``/``--bm`` each set uses its own
wheel force and motor slope.  Bad input: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse

from app.cli.options import (
    PARAMETER_FILE,
    UsageError,
    add_operating_point,
    add_short_circuit,
    add_time_grid,
    overrides_from,
    short_circuit_from,
)
from app.cli.output import emit


def register(subparsers) -> None:
    p = subparsers.add_parser("compare", help="a design variant beside its baseline (two TOML sets)")
    p.add_argument("base", type=PARAMETER_FILE, metavar="BASE.toml", help="baseline parameter file")
    p.add_argument("variant", type=PARAMETER_FILE, metavar="VARIANT.toml", help="variant parameter file")
    add_operating_point(p)
    # the comparison samples its response at a fixed 10 kHz (no --fs): f stays below that rate
    add_short_circuit(p, intervals={"f": "(0, 1e4)"}, phase=False)
    add_time_grid(p, "horizon of the response")
    p.set_defaults(func=cmd_compare)


def _fmt(value, spec: str) -> str:
    return "—" if value is None else format(value, spec)


def comparison_table(data: dict) -> str:
    """The human-readable form of :meth:`model.studies.compare.DesignComparison.as_dict`."""
    base, variant, delta = data["base"], data["variant"], data["delta"]
    point = data["operating_point"]["base"]
    lines = [f"operating point: s0 = {point['s0']:g}, v = {point['v_kmh']:g} km/h", "",
             "parameter differences (base -> variant):"]
    lines += [f"  {name}: {d['base']:g} -> {d['variant']:g} {d['unit']}"
              for name, d in data["parameter_differences"].items()] or ["  none"]
    lines += ["", f"{'':28}{'base':>14}{'variant':>14}{'delta':>14}",
              f"{'s0*(v) [-]':28}{_fmt(base['s0_limit'], '14.6f')}"
              f"{_fmt(variant['s0_limit'], '14.6f')}{_fmt(delta['s0_limit'], '+14.6f')}",
              f"{'largest Re [1/s]':28}{base['max_real_part']:14.4f}"
              f"{variant['max_real_part']:14.4f}{delta['max_real_part']:+14.4f}",
              f"{'flutter pairs':28}{base['flutter_pairs']:14d}{variant['flutter_pairs']:14d}"
              f"{delta['flutter_pairs']:+14d}",
              f"{'divergent real':28}{base['divergent_real']:14d}{variant['divergent_real']:14d}"
              f"{delta['divergent_real']:+14d}", "", "lowest complex pairs: Re [1/s] ± i Im [Hz]"]
    for nu, (a, b) in enumerate(zip(base["pairs"], variant["pairs"], strict=False), start=1):
        lines.append(f"  {nu:>2} {a['re']:+9.4f} ± i{a['im_hz']:8.3f}   "
                     f"{b['re']:+9.4f} ± i{b['im_hz']:8.3f}   Δ {b['re'] - a['re']:+.4f}, "
                     f"{b['im_hz'] - a['im_hz']:+.3f} Hz")
    lines += ["", "peak loads (signed total of largest magnitude) [N m / N]:"]
    for name, peak in base["peak_loads"].items():
        lines.append(f"  {name:28}{peak:14.0f}{variant['peak_loads'][name]:14.0f}"
                     f"{delta['peak_loads'][name]:+14.0f}")
    return "\n".join(lines)


def cmd_compare(args: argparse.Namespace) -> None:
    import sys

    from model.mechanics.parameters import load_parameters
    from model.studies.compare import compare_designs

    if args.params is not None:
        raise UsageError("give the two sets as BASE.toml VARIANT.toml, not --params")
    if args.s0 is None:
        raise UsageError("--s0 is required")
    # the operating point's quantities that change a set's values apply to both sets
    changes = overrides_from(args)
    base, variant = (load_parameters(path).replace(**changes)
                     for path in (args.base, args.variant))
    result = compare_designs(base, variant, args.s0, args.v, args.n0, args.bm,
                             short_circuit_from(args), args.t_end,
                             progress=lambda text: print(f"bogie compare: {text}",
                                                         file=sys.stderr, flush=True))
    data = result.as_dict()
    emit(args, data, comparison_table(data))
