"""Linearized posterior of the unpublished parameters from the calibration's targets.

The calibration (:mod:`model.calibration`) fits the structural parameters to the published
frequencies and the creep law to the operating data.  Sampling the prior ranges of
:data:`model.uncertainty.UNCERTAIN_PARAMETERS` ignores that: a sample with a disc clutch twice
as stiff moves the 2.7 Hz mode far off its published value.  The linearized (Laplace) posterior
keeps what the published numbers say, at the cost of one Jacobian (no re-calibration per sample):

* coordinates: θ = ln p of the d uncertain parameters (all positive scale parameters);
* prior: Gaussian in θ, centred at the calibrated set's value, standard deviation
  ``(ln high − ln low) / 4`` (the documented range taken as ±2σ, ≈ 95 %);
* data: the calibration's targets (:func:`model.calibration.frequency_rows` and
  :func:`model.calibration.operating_rows`) as whitened log residuals
  ``r_i = ln(achieved_i / target_i) / σ_i`` with the tolerances the calibration states:
  σ = 0.03 for the eleven frequencies (its 3 % acceptance scale, ``LOSS_SCALE``); for the
  operating data, which it fits exactly, the rounding of the published numbers (half a unit of
  the last digit): 12 800 N m → 50 N m (0.39 %), M_ad = 0.52·10⁵ N m → 500 N m (0.96 %), the
  creep maximum 0.0082 → 0.00005 (0.61 %);
* Jacobian ``J = ∂r/∂θ`` by central differences of exactly those residuals (the modes matched
  by character, as in the fit) with a step of ``JACOBIAN_STEP`` = 10⁻³ in ln p: the truncation
  error is O(h²) ≈ 10⁻⁶ relative, the eigenvalues and the creep maximum are computed to ≈ 10⁻¹²
  (rounding error ≈ 10⁻⁹), and a 0.1 % step moves no mode far enough to change its character
  match (checked against the analytic eigenvalue sensitivities in tests/test_posterior.py);
  cost 2 d evaluations (one eigen-analysis with vectors and the character matching each);
* posterior: Gaussian in θ, mean at the calibrated values (the fit's point; no Gauss–Newton
  step is taken: the set on screen is the calibrated one), covariance
  ``Σ = (Jᵀ J + Σ_prior⁻¹)⁻¹``.

Sampling (:meth:`LinearizedPosterior.transform`): scrambled Sobol' points u in (0, 1)^d →
z = Φ⁻¹(u) (standard normal ppf) → θ = μ + L z (L: Cholesky factor of Σ) → **clipped** to the
documented ranges [ln low, ln high] per coordinate (clipping keeps the QMC point set balanced,
rejection would not; the clipped coordinates are counted and reported).  The inputs are
correlated, so Sobol indices (which assume independent inputs) are not computed for posterior
samples: only the distributions.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
from scipy import stats

from .parameters import Parameters

JACOBIAN_STEP = 1e-3  # central-difference step in ln p [-]
FREQUENCY_SIGMA = 0.03  # relative tolerance of the published frequencies (calibration.LOSS_SCALE)
# operating data: half a unit of the last published digit, relative
OPERATING_SIGMA = {"M(s0=0.005) motor torque": 50.0 / 12_800.0,
                   "M(s0=0.014) motor torque": 50.0 / 12_800.0,
                   "M_ad adhesion moment": 500.0 / 52_000.0,
                   "creep maximum s (stability-limit proxy)": 0.00005 / 0.0082}


class PosteriorError(ValueError):
    """The posterior cannot be formed (one-line message)."""


@dataclass(frozen=True)
class LinearizedPosterior:
    """Gaussian posterior of θ = ln p of the uncertain parameters (plain data)."""

    names: tuple[str, ...]
    lows: np.ndarray  # documented ranges [schema unit]
    highs: np.ndarray
    mean_log: np.ndarray  # (d,) ln of the calibrated values
    prior_sd_log: np.ndarray  # (d,)
    targets: tuple[str, ...]  # calibration targets (rows of J)
    sigmas: np.ndarray  # (m,) relative tolerances
    residuals: np.ndarray  # (m,) whitened residuals at the calibrated set
    jacobian: np.ndarray  # (m, d) ∂r/∂θ, whitened
    covariance_log: np.ndarray  # (d, d) posterior covariance of θ

    @property
    def sd_log(self) -> np.ndarray:
        """Posterior standard deviations of ln p (≈ relative standard deviations of p)."""
        return np.sqrt(np.diag(self.covariance_log))

    @property
    def correlation(self) -> np.ndarray:
        sd = self.sd_log
        return self.covariance_log / np.outer(sd, sd)

    def transform(self, u: np.ndarray) -> tuple[np.ndarray, int]:
        """Parameter values (n x d, schema units) for points u (n x d) in (0, 1)^d, and the number
        of coordinates clipped to the documented ranges."""
        u = np.clip(np.atleast_2d(u), 1e-12, 1 - 1e-12)
        z = stats.norm.ppf(u)
        theta = self.mean_log + z @ np.linalg.cholesky(self.covariance_log).T
        low, high = np.log(self.lows), np.log(self.highs)
        clipped = int(np.count_nonzero((theta < low) | (theta > high)))
        return np.exp(np.clip(theta, low, high)), clipped

    def as_dict(self) -> dict:
        return {"coordinates": "ln p", "jacobian_step": JACOBIAN_STEP,
                "parameters": [{"name": n, "value": float(math.exp(m)), "low": float(lo),
                                "high": float(hi), "prior_sd_log": float(s0),
                                "posterior_sd_log": float(s)}
                               for n, m, lo, hi, s0, s in zip(self.names, self.mean_log, self.lows,
                                                              self.highs, self.prior_sd_log,
                                                              self.sd_log, strict=True)],
                "targets": [{"name": t, "sigma_relative": float(s), "residual": float(r)}
                            for t, s, r in zip(self.targets, self.sigmas, self.residuals,
                                               strict=True)],
                "correlation": [[float(x) for x in row] for row in self.correlation]}


def calibration_residuals(parameters: Parameters) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """(target names, whitened log residuals, relative tolerances) of the calibration's targets
    (the eleven matched frequencies and the four operating data) for a parameter set."""
    from .calibration import frequency_rows, operating_rows

    rows = [*frequency_rows(parameters), *operating_rows(parameters)]
    for row in rows:
        if row.unit != "Hz" and row.name not in OPERATING_SIGMA:
            raise PosteriorError(f"no tolerance for the calibration target '{row.name}'")
    sigmas = np.array([FREQUENCY_SIGMA if row.unit == "Hz" else OPERATING_SIGMA[row.name]
                       for row in rows])
    r = np.array([math.log(row.achieved / row.target) for row in rows]) / sigmas
    return tuple(row.name for row in rows), r, sigmas


def linearized_posterior(parameters: Parameters, uncertain: Iterable,
                         progress: Callable[[int, int], None] | None = None) -> LinearizedPosterior:
    """The linearized posterior of the ``uncertain`` parameters (items with ``name``, ``low``,
    ``high``) around ``parameters`` (the calibrated set).  2 d + 1 residual evaluations."""
    uncertain = tuple(uncertain)
    names = tuple(item.name for item in uncertain)
    lows = np.array([item.low for item in uncertain], dtype=float)
    highs = np.array([item.high for item in uncertain], dtype=float)
    values = np.array([parameters[name] for name in names], dtype=float)
    outside = [f"{n} = {x:g} outside [{lo:g}, {hi:g}]" for n, x, lo, hi
               in zip(names, values, lows, highs, strict=True) if not lo <= x <= hi]
    if outside:
        raise PosteriorError("the set's value lies outside its documented range: "
                             + "; ".join(outside))
    targets, r0, sigmas = calibration_residuals(parameters)
    jacobian = np.empty((len(r0), len(names)))
    total = 2 * len(names)
    for j, name in enumerate(names):
        plus = calibration_residuals(parameters.replace(
            **{name: float(values[j] * math.exp(JACOBIAN_STEP))}))[1]
        minus = calibration_residuals(parameters.replace(
            **{name: float(values[j] * math.exp(-JACOBIAN_STEP))}))[1]
        jacobian[:, j] = (plus - minus) / (2 * JACOBIAN_STEP)
        if progress is not None:
            progress(2 * j + 2, total)
    prior_sd = (np.log(highs) - np.log(lows)) / 4.0
    precision = jacobian.T @ jacobian + np.diag(1.0 / prior_sd**2)
    covariance = np.linalg.inv(precision)
    covariance = 0.5 * (covariance + covariance.T)
    return LinearizedPosterior(names, lows, highs, np.log(values), prior_sd, targets, sigmas, r0,
                               jacobian, covariance)
