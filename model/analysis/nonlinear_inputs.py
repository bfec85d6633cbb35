"""The inputs of the nonlinear response (:mod:`model.analysis.nonlinear`) besides the short circuit:
the anti-slip protection's settings (:class:`AntiSlip`) and the rail–wheel surface deviations of the
four wheels as time histories (:class:`IrregularityHistory`), each checked on construction with a
one-line :class:`NonlinearError`.

An irregularity history gives, for the four inputs of
:func:`model.mechanics.irregularity.irregularity_inputs` (``IDk.rimNN.irregularity``, ID1's rims 12
and 14, then ID2's), the deviation Δ_j(t) [m] and its first two time derivatives Δ̇_j [m/s] and
Δ̈_j [m/s²], which the irregularity's generalized force ``k_R Δ + b_R Δ̇ + m_R Δ̈`` and the wheel
force need (:mod:`model.mechanics.irregularity`).  Two kinds:

* **harmonic** (:meth:`IrregularityHistory.harmonic`): ``Δ_j = a_j cos(2π f_j t + φ_j)`` per
  wheel, what a wheel polygon of order k gives at f = k v / (2π r0) or a periodic rail defect at
  f = v / wavelength.  Derivatives exact; the nonlinear response steps its force exactly
  (exponential inputs, like the short-circuit torque's oscillation).
* **sampled** (:meth:`IrregularityHistory.sampled`): Δ_j at given times, interpolated by a cubic
  spline (scipy's ``CubicSpline``, not-a-knot ends), whose first and second derivatives are Δ̇
  and Δ̈: Δ̈ is then continuous and piecewise linear, which the response's first-order hold of
  the force follows.  Samples must cover the run, 0 … t_end.

Both start from the pre-fault state (Δq = 0) at t = 0: an input that is not zero there (a cosine
with cos φ ≠ 0) starts with a jump of the wheel force, and its start transient is part of the
response.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from model.analysis.response import ResponseError
from model.mechanics.assembly import DRIVES, RIM_NODES
from model.mechanics.irregularity import SUFFIX

# the four inputs in the order of ``irregularity_inputs(model)`` (``model.rims``)
WHEELS = tuple(f"{drive}.rim{node}{SUFFIX}" for drive in DRIVES for node in RIM_NODES)
MIN_SAMPLES = 4  # a cubic spline with not-a-knot ends needs four samples


class NonlinearError(ResponseError):
    """Bad input for a nonlinear response (one-line message)."""


# --- anti-slip protection -----------------------------------------------------------------------------

@dataclass(frozen=True)
class AntiSlip:
    """Anti-slip protection of the healthy drive ID2 (see docs/nonlinear.md for the sources).

    Defaults (assumptions, said as such in the docs):

    * ``threshold = 0.3 m/s``: ≈ 1 km/h of extra slip speed of the wheelset, the order of the
      slip-speed thresholds of wheel-slip detection in traction control (a few tenths of a m/s to a
      few km/h); the pre-fault slip speed s0·v (0.17 m/s at s0 = 0.005, 0.47 m/s at 0.014,
      120 km/h) is not counted.
    * ``delay = 0.1 s``: the reaction time under study (the study: "within about 0.35 s").
    * ``rate = 10 1/s``: the converter takes the full torque (characteristic) away in 0.1 s.
    * ``floor = 0``: the torque is taken away completely (with ID1 failed, traction on that bogie is
      cut) and held there for the rest of the run.
    """

    enabled: bool = True
    delay: float = 0.1  # reaction delay τ after detection [s], ≥ 0
    threshold: float = 0.3  # |Δ slip velocity| of ID2's wheelset that trips it [m/s], > 0
    rate: float = 10.0  # torque reduction rate [fraction of M(s0, v) per s], > 0
    floor: float = 0.0  # torque kept after the reduction [fraction of M(s0, v)], 0 ≤ floor < 1

    def __post_init__(self) -> None:
        checks = (("anti-slip delay (s)", self.delay, 0.0, 60.0, True, "in [0, 60] s"),
                  ("anti-slip threshold (m/s)", self.threshold, 0.0, 100.0, False,
                   "> 0 and at most 100 m/s"),
                  ("anti-slip rate (1/s)", self.rate, 0.0, 1e6, False, "> 0 and at most 1e6 1/s"),
                  ("anti-slip floor", self.floor, 0.0, 1.0, True, "in [0, 1)"))
        for label, value, low, high, closed_low, allowed in checks:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise NonlinearError(f"{label} must be a number, got {value!r}")
            ok = (low <= value if closed_low else low < value) and value <= high
            if label.endswith("floor") and value >= 1.0:
                ok = False
            if not math.isfinite(value) or not ok:
                raise NonlinearError(f"{label} = {value} is not allowed: must be {allowed}")


# --- rail–wheel surface deviations ---------------------------------------------------------------------

def _per_wheel(value, label: str, unit: str, default: float = 0.0) -> np.ndarray:
    """``value`` as one float per wheel (4, in :data:`WHEELS` order): a number (every wheel), four
    numbers, or a mapping ``IDk.rimNN.irregularity`` -> number (the others ``default``)."""
    if isinstance(value, Mapping):
        unknown = [name for name in value if name not in WHEELS]
        if unknown:
            raise NonlinearError(f"unknown irregularity input '{unknown[0]}': use "
                                 f"{', '.join(WHEELS)}")
        out = np.full(len(WHEELS), float(default))
        for name, number in value.items():
            out[WHEELS.index(name)] = _number(number, f"{label} of {name}", unit)
        return out
    if isinstance(value, int | float) and not isinstance(value, bool):
        return np.full(len(WHEELS), _number(value, label, unit))
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise NonlinearError(f"{label} must be numbers [{unit}], got {value!r}") from None
    if array.shape != (len(WHEELS),):
        raise NonlinearError(f"{label} must be one number or one per wheel ({len(WHEELS)}), "
                             f"got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise NonlinearError(f"{label} must be finite [{unit}]")
    return array


def _number(value, label: str, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise NonlinearError(f"{label} must be a finite number [{unit}], got {value!r}")
    return float(value)


@dataclass(frozen=True, eq=False)
class IrregularityHistory:
    """Rail–wheel surface deviations Δ_j(t) of the four wheels (module docstring); build with
    :meth:`harmonic` or :meth:`sampled`.

    Example::

        >>> from model.analysis.nonlinear_inputs import IrregularityHistory
        >>> d = IrregularityHistory.harmonic(frequency=20.0,
        ...                                  amplitude={"ID1.rim12.irregularity": 1e-4})
        >>> delta, rate, acceleration = d.values([0.0])
        >>> float(delta[0, 0]), float(acceleration[0, 0]) < 0      # [m], [m/s²]
        (0.0001, True)
    """

    names: tuple[str, ...]  # the inputs, IDk.rimNN.irregularity (:data:`WHEELS`)
    frequency: np.ndarray | None = None  # harmonic: f_j [Hz] (4)
    amplitude: np.ndarray | None = None  # harmonic: â_j = a_j e^(iφ_j) [m] (4, complex)
    times: np.ndarray | None = None  # sampled: the sample times [s] (K)
    samples: np.ndarray | None = None  # sampled: Δ_j at them [m] (K x 4)
    _spline: CubicSpline | None = field(default=None, repr=False)

    @classmethod
    def harmonic(cls, frequency, amplitude, phase=0.0) -> IrregularityHistory:
        """``Δ_j(t) = a_j cos(2π f_j t + φ_j)``: ``frequency`` f_j [Hz] ≥ 0, ``amplitude`` a_j [m]
        and ``phase`` φ_j [deg], each a number (every wheel), four numbers (:data:`WHEELS`
        order) or a mapping ``IDk.rimNN.irregularity`` -> number (the wheels not named: amplitude
        and phase 0, frequency 0)."""
        f = _per_wheel(frequency, "irregularity frequency", "Hz")
        a = _per_wheel(amplitude, "irregularity amplitude", "m")
        phi = _per_wheel(phase, "irregularity phase", "deg")
        if np.any(f < 0):
            raise NonlinearError("irregularity frequency must be ≥ 0 Hz")
        return cls(names=WHEELS, frequency=f, amplitude=a * np.exp(1j * np.radians(phi)))

    @classmethod
    def sampled(cls, times, deviations) -> IrregularityHistory:
        """Δ_j at ``times`` [s] (strictly increasing, at least four): ``deviations`` [m] as an
        array (len(times) x 4, :data:`WHEELS` order) or a mapping ``IDk.rimNN.irregularity`` ->
        array (len(times); the wheels not named: 0)."""
        try:
            t = np.asarray(times, dtype=float)
        except (TypeError, ValueError):
            raise NonlinearError("irregularity times must be numbers [s]") from None
        if t.ndim != 1 or len(t) < MIN_SAMPLES:
            raise NonlinearError(f"irregularity times must be one row of at least {MIN_SAMPLES} "
                                 f"values [s], got shape {t.shape}")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
            raise NonlinearError("irregularity times must be finite and strictly increasing [s]")
        if isinstance(deviations, Mapping):
            unknown = [name for name in deviations if name not in WHEELS]
            if unknown:
                raise NonlinearError(f"unknown irregularity input '{unknown[0]}': use "
                                     f"{', '.join(WHEELS)}")
            values = np.zeros((len(t), len(WHEELS)))
            for name, column in deviations.items():
                values[:, WHEELS.index(name)] = _column(column, len(t), name)
        else:
            try:
                values = np.array(deviations, dtype=float)
            except (TypeError, ValueError):
                raise NonlinearError("irregularity deviations must be numbers [m]") from None
            if values.shape != (len(t), len(WHEELS)):
                raise NonlinearError(f"irregularity deviations must be {len(t)} x {len(WHEELS)} "
                                     f"(times x wheels) [m], got shape {values.shape}")
        if not np.all(np.isfinite(values)):
            raise NonlinearError("irregularity deviations must be finite [m]")
        return cls(names=WHEELS, times=t, samples=values, _spline=CubicSpline(t, values, axis=0))

    @property
    def is_harmonic(self) -> bool:
        return self.frequency is not None

    @property
    def span(self) -> tuple[float, float]:
        """The times the history covers [s] (a harmonic: all)."""
        if self.is_harmonic:
            return -math.inf, math.inf
        return float(self.times[0]), float(self.times[-1])

    def values(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Δ [m], Δ̇ [m/s], Δ̈ [m/s²]) at the times ``t`` [s], each len(t) x 4."""
        t = np.asarray(t, dtype=float)
        if self.is_harmonic:
            s = 2j * np.pi * self.frequency
            phasor = self.amplitude[None, :] * np.exp(t[:, None] * s[None, :])
            return phasor.real, (s * phasor).real, (s * s * phasor).real
        spline = self._spline
        return spline(t), spline(t, 1), spline(t, 2)


def _column(values, count: int, name: str) -> np.ndarray:
    try:
        column = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise NonlinearError(f"irregularity deviations of {name} must be numbers [m]") from None
    if column.shape != (count,):
        raise NonlinearError(f"irregularity deviations of {name} must be {count} values (one per "
                             f"time) [m], got shape {column.shape}")
    return column
