"""A design variant beside its baseline: stability, the lowest modes and the short-circuit loads
of two parameter sets at one operating point.

:func:`design_summary` computes one side (eigen-analysis, stability limit s0*(v) at the speed,
short-circuit response); :func:`compare_designs` both sides and their differences.  Used by
``bogie compare BASE.toml VARIANT.toml`` (:mod:`app.cli.compare`) and by the dashboard's
variant view.  Units: SI, except ``v_kmh`` [km/h] and ``im_hz`` [Hz].
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from model.analysis.eigen import eigen_analysis
from model.analysis.modes import mode_character
from model.analysis.response import ShortCircuit, short_circuit_response
from model.analysis.stability import NoStabilityLimit, stability_limit
from model.mechanics.assembly import build_model
from model.mechanics.operating_point import KMH, OperatingPoint
from model.mechanics.parameters import SCHEMA, Parameters

N_PAIRS = 10  # complex pairs compared (the lowest by frequency, Table 1)
LOAD_OUTPUTS = tuple(f"{drive}.{quantity}" for drive in ("ID1", "ID2") for quantity in (
    "driving_shaft.torque", "disc_clutch.torque", "disc_clutch.force_x", "disc_clutch.force_y",
    "disc_clutch.force_z"))
LIMIT_S0_LOW = 5e-4  # lower end of the s0*(v) search [-]
LIMIT_XTOL = 1e-6  # s0*(v) to this [-]


@dataclass(frozen=True)
class Pair:
    """One complex pair (upper eigenvalue) of the lowest ones."""

    re: float  # Re λ [1/s]
    im_hz: float  # Im λ / 2π [Hz]
    damping_ratio: float  # −Re λ / |λ| [-]
    description: str  # dominant motion (model.analysis.modes)


@dataclass(frozen=True)
class DesignSummary:
    """What a design review compares for one parameter set at one operating point."""

    s0_limit: float | None  # stability limit s0*(v) at the speed [-]; None: none in the range
    s0_limit_reason: str  # why there is none ("" otherwise)
    max_real_part: float  # largest real part of the eigenvalues [1/s]
    stable: bool
    flutter_pairs: int  # unstable complex pairs
    divergent_real: int  # positive real eigenvalues
    pairs: list[Pair]  # the N_PAIRS lowest complex pairs
    peak_loads: dict[str, float]  # LOAD_OUTPUTS -> signed total of largest magnitude [N m / N]
    peak_times: dict[str, float]  # [s]
    M_ad: float  # maximal adhesion moment 2 N0 r0 μ_max [N m]


@dataclass(frozen=True)
class DesignComparison:
    """Baseline, variant and variant − baseline."""

    operating_point: dict  # s0 [-], v_kmh, N0 [N] and b_M [N m s/rad] of each side
    parameter_differences: dict[str, tuple[float, float]]  # name -> (base, variant) [SI]
    base: DesignSummary
    variant: DesignSummary
    delta: dict  # variant − base of every number above (None where a side has no limit)

    def as_dict(self) -> dict:
        """Plain data for JSON: ``{operating_point, parameter_differences, base, variant,
        delta}``."""
        data = asdict(self)
        data["parameter_differences"] = {
            name: {"base": a, "variant": b, "unit": SCHEMA[name][0]}
            for name, (a, b) in self.parameter_differences.items()}
        return data


def design_summary(parameters: Parameters, s0: float, v_kmh: float, N0: float | None = None,
                   b_M: float | None = None, excitation: ShortCircuit | None = None,
                   t_end: float = 2.0, fs: float = 10_000.0) -> DesignSummary:
    """One side of a comparison.  ``N0`` [N] and ``b_M`` [N m s/rad] default to the set's
    ``wheel_force`` and ``motor_slope``; ``excitation`` to :class:`ShortCircuit`'s defaults."""
    model = build_model(parameters)
    N0 = parameters["wheel_force"] if N0 is None else N0
    b_M = parameters["motor_slope"] if b_M is None else b_M
    op = OperatingPoint.from_kmh(s0, v_kmh, N0, b_M)
    result = eigen_analysis(model, op)
    pairs = []
    for index in result.complex_index[:N_PAIRS]:
        character = mode_character(model, result, int(index))
        lam = complex(result.eigenvalues[index])
        pairs.append(Pair(lam.real, lam.imag / (2 * math.pi), character.damping_ratio,
                          character.description))
    try:
        limit = stability_limit(model, v_kmh * KMH, N0, b_M, s0_low=LIMIT_S0_LOW,
                                xtol=LIMIT_XTOL)
        s0_limit, reason = limit.s0_limit, ""
    except NoStabilityLimit as error:
        s0_limit, reason = None, str(error)
    response = short_circuit_response(model, op, excitation, t_end=t_end, fs=fs,
                                      outputs=list(LOAD_OUTPUTS))
    return DesignSummary(
        s0_limit=s0_limit, s0_limit_reason=reason, max_real_part=float(result.max_real_part),
        stable=bool(result.stable), flutter_pairs=int(result.flutter),
        divergent_real=int(result.divergence), pairs=pairs,
        peak_loads={name: float(response.peaks[name]) for name in LOAD_OUTPUTS},
        peak_times={name: float(response.peak_times[name]) for name in LOAD_OUTPUTS},
        M_ad=float(response.limits["M_ad"]))


def _difference(a, b):
    return None if a is None or b is None else b - a


def summary_delta(base: DesignSummary, variant: DesignSummary) -> dict:
    """variant − base: the limit, the largest real part, the counts, each of the lowest pairs
    (paired by rank: ν-th with ν-th) and each peak load."""
    return {
        "s0_limit": _difference(base.s0_limit, variant.s0_limit),
        "max_real_part": variant.max_real_part - base.max_real_part,
        "flutter_pairs": variant.flutter_pairs - base.flutter_pairs,
        "divergent_real": variant.divergent_real - base.divergent_real,
        "pairs": [{"re": b.re - a.re, "im_hz": b.im_hz - a.im_hz,
                   "damping_ratio": b.damping_ratio - a.damping_ratio}
                  for a, b in zip(base.pairs, variant.pairs, strict=False)],
        "peak_loads": {name: variant.peak_loads[name] - base.peak_loads[name]
                       for name in LOAD_OUTPUTS},
        "M_ad": variant.M_ad - base.M_ad,
    }


def compare_designs(base: Parameters, variant: Parameters, s0: float, v_kmh: float,
                    N0: float | None = None, b_M: float | None = None,
                    excitation: ShortCircuit | None = None, t_end: float = 2.0,
                    progress=None) -> DesignComparison:
    """Both sides at the same s0 and v (``N0``/``b_M`` given: the same for both; else each
    set's own), and the differences.  ``progress(text)`` is told when each side starts."""
    sides = []
    for label, parameters in (("base", base), ("variant", variant)):
        if progress is not None:
            progress(f"{label}: eigenvalues, s0*(v) and the short-circuit response…")
        sides.append(design_summary(parameters, s0, v_kmh, N0, b_M, excitation, t_end))
    differences = {name: (base.values[name], variant.values[name]) for name in SCHEMA
                   if base.values[name] != variant.values[name]}
    point = {label: {"s0": s0, "v_kmh": v_kmh,
                     "N0": p["wheel_force"] if N0 is None else N0,
                     "b_M": p["motor_slope"] if b_M is None else b_M}
             for label, p in (("base", base), ("variant", variant))}
    return DesignComparison(point, differences, sides[0], sides[1],
                            summary_delta(sides[0], sides[1]))
