"""Which parameter moves what: eigenvalue, stability-limit and peak-load sensitivities.

Eigenvalues.  For ``(λ²M + λB + K) x = 0`` with the left eigenvector ``yᴴ(λ²M + λB + K) = 0``
(Tisseur and Meerbergen, SIAM Review 43 (2001) 235–286)::

    dλ/dp = −yᴴ(λ²M′ + λB′ + K′) x / yᴴ(2λM + B) x

with ``B = B + b_M B_M + B_ad(s0, v, N0)`` the damping at the operating point.  The derivative
matrices are exact, never finite differences of eigenvalues:

* ``M′, B′, K′`` of the constant assembly by the **complex step** through the element functions
  (``p → p + i h``, ``X′ = Im X(p + i h)/h``, ``h = 10⁻²⁰ max(|p|, 1)``; exact to rounding, no
  subtractive cancellation).  They depend only on the parameter set and are cached per model
  (:func:`structural_derivatives`); only the coordinates a parameter touches are kept.
* ``B′`` of the operating-point blocks: ``∂(b_M B_M)/∂b_M = B_M``, and ``b_M ∂B_M/∂p`` for the
  gear ratio and the wheel radius (eq. 6 measures the rotor against the rolling p/r0 · ẋ of the
  vehicle); ``B_ad`` is linear in its four
  coefficients ``b11 = N0 μ′(s0, v)/v``, ``b22, b23, b33 = f_ij/v`` and quadratic in ``r0``:
  ``b11`` by the complex step through Polach's law (s0, v, N0 and the law's parameters), the
  Kalker coefficients ``f_ij`` by central differences with a relative step of 10⁻⁴ (they come from
  a root-find for the Hertz ellipse and an interpolation in Kalker's table, which the complex
  step cannot pass; truncation ≈ 10⁻⁸ relative, see the tests).

Eigenvectors: the right and left null vectors of ``λ²M + λB + K`` at each eigenvalue of the
eigen-analysis, by inverse iteration with one complex LU per mode (the eigenvalue is exact to
rounding: one step gives the right vector to working accuracy, two the left one, which differs
more from x̄ since B is not symmetric).

What is *not* returned as a number (and said instead):

* the rigid-body zero eigenvalues (the spins of the two drivetrains, the vehicle's translation
  and yaw, ``K r = 0`` for every parameter value, and the velocity of the vehicle rolling
  without slip, which no damping meets): they stay exactly zero, their sensitivity is zero by
  construction;
* near-repeated eigenvalues (the ID1/ID2 twins: nearly equal pairs of the two drives): where the
  relative gap to the nearest other eigenvalue is below :data:`NEAR_REPEATED` the derivative of a
  single member is not meaningful (the pair splits non-smoothly under a perturbation that breaks
  the twin symmetry); such modes are flagged and their derivatives are NaN.

Stability limit.  At ``s0*`` the critical eigenvalue has ``Re λc = 0``, so
``ds0*/dp = −Re(∂λc/∂p)/Re(∂λc/∂s0)``.  When the critical eigenvalue is the divergence of a
rigid-body motion's velocity — ID1's drivetrain spin together with the vehicle's longitudinal
translation (the slip of wheelset 1) — its crossing is where ``rᴴ B r = 0`` for that rigid
motion ``r``: only the longitudinal creep damping ``b11 ∝ ∂μ/∂s`` acts on it (all structural
damping is stiffness-proportional or acts between bodies, ``b_M`` acts on ID2 only, the lateral
creep on the yaw), so ``s0*`` is the creep maximum ``∂μ/∂s = 0`` and the formula is 0/0 there
(λc meets the rigid zero).  Then
``ds0*/dp = −(∂μ′/∂p)/(∂μ′/∂s)`` (implicit function theorem, complex step through Polach's law)
and is exactly zero for every structural parameter — reported as such, with the numbers.

Peak drive loads: central differences of the closed-form response at the peak's sample
(:mod:`model.analysis.peak_sensitivity`; envelope theorem: the peak is stationary in time).

Normalized sensitivities for ranking: ``p/λ · dλ/dp`` (complex), ``p · ∂Re λ/∂p`` [1/s] (the
change of the growth rate per relative change of p) and ``p/s0* · ds0*/dp``.
"""

from __future__ import annotations

import math
import threading
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from model.analysis.eigen import EigenResult, eigen_analysis
from model.analysis.modes import characterize
from model.analysis.stability import stability_limit
from model.contact.creep import PolachLaw, creep_block, kalker_creep_coefficients
from model.mechanics.assembly import (
    CONVERTER_FILTER,
    BogieModel,
    assembled_matrices,
    motor_speed_row,
)
from model.mechanics.operating_point import OperatingPoint, damping_matrix
from model.mechanics.parameters import SCHEMA, Parameters

MODE_COUNT = 10  # the ten lowest complex pairs, as the rest of the tool reports them
COMPLEX_STEP = 1e-20  # relative imaginary step of the complex-step derivatives
KALKER_STEP = 1e-4  # relative central-difference step of Kalker's coefficients f_ij
NEAR_REPEATED = 1e-6  # relative gap |λ − λ_j|/|λ| below which a mode counts as a twin
RIGID_SPIN_MAC = 0.99  # a real mode this close to the rigid-body subspace is a rigid motion's velocity
# a limit this close to the creep maximum (relative), set by ID1's spin, *is* the creep maximum:
# root finders stop within their tolerance of it (the dashboard's 1e-6 absolute, Brent's 1e-7)
CREEP_MAXIMUM_RTOL = 1e-3
# operating-point quantities: name -> unit (SI; v in m/s)
OPERATING_PARAMETERS: dict[str, str] = {"s0": "1", "v": "m/s", "N0": "N", "b_M": "N m s/rad"}
# parameters an operating point takes by default (CLI, dashboard): their total derivative adds
# the operating quantity's when the caller says they are linked
LINKED = {"wheel_force": "N0", "motor_slope": "b_M"}
# parameters that do not enter the constant assembly (contact and motor only; checked by a test)
NOT_IN_ASSEMBLY = frozenset({"rail_head_radius", "wheel_force", "polach_mu0",
                             "polach_A", "polach_B", "polach_kA", "polach_kS", "creep_slope",
                             "motor_slope"})
# parameters of the vehicle's rolling that eq. 6 measures the healthy motor's speed against
# (B_M's entry p/r0 on CB.x; with a converter it is in the filter's row of the constant B)
MOTOR_SPEED_INPUTS = ("gear_ratio", "wheel_radius")
KALKER_INPUTS = ("wheel_radius", "rail_head_radius", "young_modulus", "poisson_ratio")
CREEP_LAW_INPUTS = ("polach_mu0", "polach_A", "polach_B", "polach_kA", "polach_kS",
                    "creep_slope", "wheel_force")
SUBSYSTEMS = ("ID1", "BFCB", "ID2")


class SensitivityError(ValueError):
    """Bad input for a sensitivity computation (one-line message)."""


# --- derivative matrices -------------------------------------------------------------------------

@dataclass(frozen=True)
class MatrixDerivative:
    """∂M/∂p, ∂B/∂p, ∂K/∂p restricted to the coordinates ``index`` they touch (None: zero)."""

    index: np.ndarray  # global coordinate indices
    M: np.ndarray | None  # [kg/unit …]
    B: np.ndarray | None  # [N s/m/unit …]
    K: np.ndarray | None  # [N/m/unit …]

    def quadratic(self, lam: np.ndarray, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
        """``yᴴ(λ²M′ + λB′ + K′)x`` for the columns of X, Y (n x k) and eigenvalues lam (k)."""
        x, y = X[self.index], Y[self.index].conj()
        total = np.zeros(len(lam), dtype=complex)
        for matrix, factor in ((self.M, lam * lam), (self.B, lam), (self.K, None)):
            if matrix is None:
                continue
            term = np.einsum("ik,ik->k", y, matrix @ x)
            total += term if factor is None else factor * term
        return total


def _restrict(dM: np.ndarray, dB: np.ndarray, dK: np.ndarray) -> MatrixDerivative | None:
    touched = np.zeros(dM.shape[0], dtype=bool)
    for matrix in (dM, dB, dK):
        touched |= np.any(matrix != 0, axis=0) | np.any(matrix != 0, axis=1)
    index = np.flatnonzero(touched)
    if len(index) == 0:
        return None
    sub = lambda X: X[np.ix_(index, index)].copy() if np.any(X != 0) else None  # noqa: E731
    return MatrixDerivative(index, sub(dM), sub(dB), sub(dK))


def complex_step_parameters(parameters: Parameters, name: str, step: float) -> Parameters:
    """The set with ``name`` moved by ``i·step`` (not validated: complex values only feed the
    element functions, which carry them, see :mod:`model.mechanics.bodies`)."""
    values = dict(parameters.values)
    values[name] = values[name] + 1j * step
    return Parameters(values, parameters.notes, parameters.source)


def _step(value: float) -> float:
    return COMPLEX_STEP * max(abs(value), 1.0)


_derivative_lock = threading.Lock()


def structural_derivatives(model: BogieModel, progress=None,
                           names: Iterable[str] | None = None) -> dict[str, MatrixDerivative]:
    """∂(M, B, K)/∂p of the constant assembly for every parameter that enters it (complex step
    through :func:`model.mechanics.assembly.build_model`; one complex assembly per parameter), or for those
    of ``names`` only (the calibration's free parameters).  Cached on the model per parameter:
    they depend on the parameter set only.  ``progress(done, total)`` if given.  A parameter
    that does not enter the assembly has no entry."""
    with _derivative_lock:
        cache = model.__dict__.setdefault("_structural_derivatives", {})
        done_names = model.__dict__.setdefault("_structural_derivatives_done", set())
        p = model.parameters
        wanted = [name for name in (SCHEMA if names is None else names)
                  if name not in NOT_IN_ASSEMBLY]
        missing = [name for name in wanted if name not in done_names]
        for done, name in enumerate(missing):
            h = _step(p[name])
            M, B, K = assembled_matrices(complex_step_parameters(p, name, h))
            derivative = _restrict(M.imag / h, B.imag / h, K.imag / h)
            if derivative is not None:
                cache[name] = derivative
            done_names.add(name)
            if progress is not None:
                progress(done + 1, len(missing))
        return {name: cache[name] for name in wanted if name in cache}


def _law(values: Mapping, N0) -> PolachLaw:
    slope = values["creep_slope"] * (N0 / values["wheel_force"]) ** (-1.0 / 3.0)
    return PolachLaw(values["polach_mu0"], values["polach_A"], values["polach_B"],
                     values["polach_kA"], values["polach_kS"], slope)


def _kalker(values: Mapping, N0: float) -> np.ndarray:
    k = kalker_creep_coefficients(N0, values["wheel_radius"], values["rail_head_radius"],
                                  values["young_modulus"], values["poisson_ratio"])
    return np.array([k.f22, k.f23, k.f33])


def _creep_inputs(parameters: Parameters, op: OperatingPoint) -> dict:
    values = dict(parameters.values)
    values.update(s0=op.s0, v=op.v, N0=op.N0, b_M=op.b_M)
    return values


def _b11(values: Mapping) -> complex:
    law = _law(values, values["N0"])
    return values["N0"] * law.dmu_ds(values["s0"], values["v"]) / values["v"]


_kalker_cache: dict = {}
_kalker_lock = threading.Lock()


def _kalker_derivative(parameters: Parameters, N0: float, name: str) -> np.ndarray:
    """d(f22, f23, f33)/dp by central differences (relative step :data:`KALKER_STEP`); they do
    not depend on s0 or v, so they are kept per (parameter set, N0, name)."""
    key = (id(parameters), N0, name)
    with _kalker_lock:
        cached = _kalker_cache.get(key)
    if cached is not None and cached[0] is parameters:
        return cached[1]
    values = dict(parameters.values)
    values["N0"] = N0
    h = KALKER_STEP * abs(values[name])
    up, down = dict(values), dict(values)
    up[name], down[name] = values[name] + h, values[name] - h
    derivative = (_kalker(up, up["N0"]) - _kalker(down, down["N0"])) / (2 * h)
    with _kalker_lock:
        if len(_kalker_cache) > 512:
            _kalker_cache.clear()
        _kalker_cache[key] = (parameters, derivative)
    return derivative


def creep_coefficient_derivatives(parameters: Parameters, op: OperatingPoint,
                                  name: str) -> np.ndarray:
    """d(b11, b22, b23, b33, r0)/dp at ``op`` for a parameter or operating quantity ``name``
    [unit of each coefficient per unit of p]; zeros if it does not enter B_ad."""
    values = _creep_inputs(parameters, op)
    out = np.zeros(5)
    if name in CREEP_LAW_INPUTS or name in ("s0", "v", "N0"):
        h = _step(values[name])
        stepped = dict(values)
        stepped[name] = values[name] + 1j * h
        out[0] = float(np.imag(_b11(stepped))) / h
    if name in KALKER_INPUTS or name == "N0":
        out[1:4] = _kalker_derivative(parameters, op.N0, name) / op.v
    if name == "v":
        out[1:4] = -_kalker(values, op.N0) / op.v**2
    if name == "wheel_radius":
        out[4] = 1.0
    return out


def motor_pattern_derivative(model: BogieModel, op: OperatingPoint,
                             name: str) -> MatrixDerivative | None:
    """b_M ∂B_M/∂p for a parameter of the rolling reference of eq. 6 (:data:`MOTOR_SPEED_INPUTS`;
    None otherwise, at b_M = 0, or with a converter, whose filter row is in the constant B)."""
    if name not in MOTOR_SPEED_INPUTS or op.b_M == 0.0 or CONVERTER_FILTER in model.dofs.names:
        return None
    h = _step(model.parameters[name])
    stepped = complex_step_parameters(model.parameters, name, h)
    d_speed = motor_speed_row(stepped, model.dofs).imag / h
    force = model.motor_pattern[:, model.dofs.index("ID2.rotor.ry")]  # B_M = force ⊗ speed row
    zero = np.zeros((model.n, model.n))
    return _restrict(zero, op.b_M * np.outer(force, d_speed), zero)


def operating_derivative(model: BogieModel, op: OperatingPoint, name: str) -> MatrixDerivative | None:
    """∂B/∂p of the operating-point damping ``b_M B_M + B_ad`` (None if p does not enter)."""
    if name == "b_M":
        pattern = model.motor_pattern
        index = np.flatnonzero(np.any(pattern != 0, axis=0) | np.any(pattern != 0, axis=1))
        return MatrixDerivative(index, None, pattern[np.ix_(index, index)].copy(), None)
    d = creep_coefficient_derivatives(model.parameters, op, name)
    if not np.any(d):
        return None
    values = _creep_inputs(model.parameters, op)
    b11 = float(np.real(_b11(values)))
    f = _kalker(values, op.N0) / op.v
    r0 = model.parameters["wheel_radius"]
    block = creep_block(d[0], d[1], d[2], d[3], r0)  # linear in the four coefficients
    if d[4]:
        h = _step(r0)
        block = block + d[4] * creep_block(b11, f[0], f[1], f[2], r0 + 1j * h).imag / h
    index = np.concatenate(list(model.rims.values()))
    blocks = np.kron(np.eye(len(model.rims)), block)  # the same block on every rim
    return MatrixDerivative(index, None, blocks, None)


# --- eigenvalue sensitivities ----------------------------------------------------------------------

@dataclass(frozen=True)
class EigenSensitivities:
    """dλ/dp of selected eigenvalues at one operating point (plain data).

    Rows of ``derivatives`` follow ``names``: every parameter of the set (schema order, names as
    in the parameter file), then the operating quantities s0, v [m/s], N0, b_M.  A parameter's row
    is its partial derivative at the fixed operating point, plus the linked operating quantity's
    when ``linked`` names it (the CLI links ``wheel_force`` → N0 and ``motor_slope`` → b_M when the
    operating point takes them from the set)."""

    operating_point: OperatingPoint
    eigenvalues: np.ndarray  # k selected eigenvalues [1/s]
    indices: np.ndarray  # their indices in the eigen-analysis
    descriptions: tuple[str, ...]  # Table-2-style description of each mode
    names: tuple[str, ...]  # parameter names, then s0, v, N0, b_M
    units: tuple[str, ...]  # SI unit of each
    values: np.ndarray  # their values [unit]
    derivatives: np.ndarray  # len(names) x k, dλ/dp [1/s per unit]; NaN where not reliable
    condition: np.ndarray  # k eigenvalue condition numbers ‖x‖‖y‖‖[λ²M, λB, K]‖/(|λ| |yᴴQ′x|) [-]
    gap: np.ndarray  # k relative gaps |λ − λ_j|/|λ| to the nearest other eigenvalue [-]
    reliable: np.ndarray  # k booleans (False: near-repeated, see notes)
    notes: tuple[str, ...]  # what was detected (rigid-body zeros, twins)
    participation: tuple[dict[str, float], ...]  # per mode: subsystem -> participation share [-]
    kinetic: tuple[dict[str, float], ...]  # per mode: component -> kinetic-energy share [-]
    strain: tuple[dict[str, float], ...]  # per mode: element group -> strain-energy share [-]
    linked: tuple[str, ...]  # parameters whose row includes the linked operating quantity
    n_rigid: int  # rigid-body zero eigenvalues (sensitivity 0 by construction)

    @property
    def d_re(self) -> np.ndarray:
        """∂Re λ/∂p [1/s per unit]."""
        return self.derivatives.real

    @property
    def d_im_hz(self) -> np.ndarray:
        """∂(Im λ/2π)/∂p [Hz per unit]."""
        return self.derivatives.imag / (2 * np.pi)

    @property
    def d_damping_ratio(self) -> np.ndarray:
        """∂ζ/∂p with ζ = −Re λ/|λ| [1 per unit]."""
        lam = self.eigenvalues[None, :]
        a = np.abs(lam)
        return -(self.derivatives.real * a**2 - lam.real * np.real(lam.conj() * self.derivatives)) / a**3

    @property
    def normalized(self) -> np.ndarray:
        """p/λ · dλ/dp [-] (complex; Re: relative change of the modulus-scaled eigenvalue)."""
        return self.values[:, None] / self.eigenvalues[None, :] * self.derivatives

    @property
    def growth_per_relative_change(self) -> np.ndarray:
        """p · ∂Re λ/∂p [1/s]: change of the growth rate per relative change of p (for ranking
        where Re λ is near zero)."""
        return self.values[:, None] * self.derivatives.real

    def row(self, name: str) -> np.ndarray:
        try:
            return self.derivatives[self.names.index(name)]
        except ValueError:
            raise SensitivityError(f"unknown parameter '{name}'") from None


def _lu_for_inverse_iteration(matrix: np.ndarray):
    """LU factors of a matrix that is singular up to rounding at the shift (the point of inverse
    iteration): an exactly zero pivot (the shift is an exact eigenvalue) is replaced by
    eps·max|matrix|, so the solve amplifies that direction instead of failing."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sla.LinAlgWarning)
        lu, piv = sla.lu_factor(matrix, check_finite=False)
    tiny = np.finfo(float).eps * np.abs(matrix).max()
    small = np.flatnonzero(np.abs(np.diagonal(lu)) < tiny)
    lu[small, small] = tiny
    return lu, piv


def null_vectors(model: BogieModel, B_total: np.ndarray, lam: complex,
                 guess: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Right and left null vectors (x, y) of ``λ²M + λB + K`` by inverse iteration (unit
    2-norm).  ``guess``: the eigen-analysis' displacement vector (start for x; its conjugate
    starts y).  x takes one step; y two, since B is not symmetric (the creep blocks, the motor
    slope measured against the vehicle's speed) and the left vector differs from x̄."""
    lu, piv = _lu_for_inverse_iteration(lam * lam * model.M + lam * B_total + model.K)
    x = sla.lu_solve((lu, piv), model.M @ guess, check_finite=False)
    y = model.M @ guess.conj()
    for _ in range(2):
        y = sla.lu_solve((lu, piv), y / np.linalg.norm(y), trans=2, check_finite=False)
    return x / np.linalg.norm(x), y / np.linalg.norm(y)


def _real_eigenvalue_nearest_zero(model: BogieModel, op: OperatingPoint, iterations: int = 12,
                                  block: int = 3) -> float | None:
    """The eigenvalue nearest to 0 [1/s] of the state matrix at ``op`` with the rigid-body zeros
    deflated, by block inverse iteration on it (one real LU; ``block`` vectors, so that two
    eigenvalues at 0 — at the creep maximum both drivetrains' spins — do not stall it, as they
    stalled a single vector) and the Ritz values of the block; None unless the Ritz pair nearest
    to 0 is real with a residual at the rounding level of the matrix (or no convergence)."""
    from model.analysis.eigen import bogie_system

    A22 = bogie_system(model, op).reduced[1]
    lu, piv = _lu_for_inverse_iteration(A22)
    X, _ = np.linalg.qr(np.random.default_rng(1).standard_normal((len(A22), block)))
    # converged when the Ritz pair's residual is at the rounding level of A22 (whose 1-norm is
    # ≈ 7e11 1/s with the massless coordinates eliminated: eigenvalues within ≈ 1e-4 1/s of 0
    # are equal to working precision, the full analysis' included)
    tolerance = np.finfo(float).eps * np.abs(A22).sum(axis=0).max()
    for _ in range(iterations):
        X, _ = np.linalg.qr(sla.lu_solve((lu, piv), X, check_finite=False))
        AX = A22 @ X
        ritz, W = np.linalg.eig(X.T @ AX)
        k = int(np.argmin(np.abs(ritz)))
        if ritz[k].imag != 0.0:
            continue
        w = W[:, k].real
        residual = np.linalg.norm(AX @ w - ritz[k].real * (X @ w)) / np.linalg.norm(w)
        if residual <= tolerance:
            return float(ritz[k].real)
    return None


def _subsystem_of(model: BogieModel) -> np.ndarray:
    names = model.dofs.names
    return np.array([0 if n.startswith("ID1.") else 2 if n.startswith("ID2.") else 1 for n in names])


def eigen_sensitivities(model: BogieModel, op: OperatingPoint, indices: Iterable[int] | None = None,
                        linked: Iterable[str] = (), parameters: Iterable[str] | None = None,
                        result: EigenResult | None = None, describe: bool = True) -> EigenSensitivities:
    """dλ/dp at ``op`` for the eigenvalues ``indices`` of the eigen-analysis (default: the ten
    lowest complex pairs), every parameter (or those named in ``parameters``) and s0, v, N0, b_M.

    ``linked``: parameter names of :data:`LINKED` whose rows add the operating quantity's
    derivative (the operating point took them from the set).  ``describe=False`` skips the
    energy shares and descriptions of the modes (empty; the caller has them already).
    Example:
        >>> from model import build_model, default_operating_point, eigen_sensitivities, load_parameters
        >>> p = load_parameters(); s = eigen_sensitivities(build_model(p), default_operating_point(p), indices=[0])
        >>> "disc_clutch_torsional_stiffness" in s.names
        True
    """
    linked = tuple(linked)
    for name in linked:
        if name not in LINKED:
            raise SensitivityError(f"'{name}' cannot be linked; allowed: {', '.join(LINKED)}")
    wanted = list(SCHEMA) if parameters is None else list(parameters)
    for name in wanted:
        if name not in SCHEMA:
            raise SensitivityError(f"unknown parameter '{name}'; names as in the parameter file "
                                   "(model/mechanics/parameters.py SCHEMA)")
    result = eigen_analysis(model, op) if result is None else result
    indices = result.complex_index[:MODE_COUNT] if indices is None else np.asarray(list(indices), int)
    lam = result.eigenvalues[indices]
    B_total = damping_matrix(model, op)
    n = model.n
    X = np.empty((n, len(lam)), dtype=complex)
    Y = np.empty((n, len(lam)), dtype=complex)
    generic = np.random.default_rng(0).standard_normal(n)  # start vector without eigenvectors
    for k, (i, value) in enumerate(zip(indices, lam, strict=True)):
        guess = generic if result.vectors is None else result.vectors[:n, i]
        X[:, k], Y[:, k] = null_vectors(model, B_total, value, guess)
    denominator = np.einsum("ik,ik->k", Y.conj(), (2 * lam[None, :]) * (model.M @ X) + B_total @ X)

    # near-repeated eigenvalues and conditioning
    others = result.eigenvalues
    gap = np.empty(len(lam))
    for k, i in enumerate(indices):
        distance = np.abs(np.delete(others, i) - lam[k])
        gap[k] = distance.min() / abs(lam[k]) if len(distance) else math.inf
    scale = np.array([abs(v) ** 2 * np.abs(model.M).max() + abs(v) * np.abs(B_total).max()
                      + np.abs(model.K).max() for v in lam])
    condition = scale / (np.abs(lam) * np.abs(denominator))
    reliable = gap >= NEAR_REPEATED
    notes = [f"{result.n_rigid} rigid-body zero eigenvalues (the spins of the drivetrains, the "
             "vehicle's translation and yaw, K r = 0 for every parameter value, and the rolling "
             "velocity no damping meets): not computed, their sensitivity is zero by construction"]
    for k in np.flatnonzero(~reliable):
        j = int(np.argmin(np.abs(np.delete(others, indices[k]) - lam[k])))
        partner = np.delete(others, indices[k])[j]
        notes.append(f"mode at {lam[k].imag / (2 * np.pi):.4f} Hz is near-repeated (partner "
                     f"{partner.real:.5g}{partner.imag:+.5g}i 1/s, relative gap {gap[k]:.1e} < "
                     f"{NEAR_REPEATED:g}): a twin of the two drives; its derivatives are not "
                     "meaningful and are NaN")

    structural = structural_derivatives(model, names=wanted)
    names = tuple(wanted) + tuple(OPERATING_PARAMETERS)
    units = tuple(SCHEMA[name][0] for name in wanted) + tuple(OPERATING_PARAMETERS.values())
    values = np.array([model.parameters[name] for name in wanted]
                      + [op.s0, op.v, op.N0, op.b_M])
    operating_rows: dict[str, np.ndarray] = {}

    def sensitivity(derivative: MatrixDerivative | None) -> np.ndarray:
        if derivative is None:
            return np.zeros(len(lam), dtype=complex)
        return -derivative.quadratic(lam, X, Y) / denominator

    for name in OPERATING_PARAMETERS:
        operating_rows[name] = sensitivity(operating_derivative(model, op, name))
    rows = []
    for name in wanted:
        row = sensitivity(structural.get(name))
        if name in CREEP_LAW_INPUTS or name in KALKER_INPUTS:
            row = row + sensitivity(operating_derivative(model, op, name))
        if name in MOTOR_SPEED_INPUTS:
            row = row + sensitivity(motor_pattern_derivative(model, op, name))
        if name in linked:
            row = row + operating_rows[LINKED[name]]
        rows.append(row)
    rows += [operating_rows[name] for name in OPERATING_PARAMETERS]
    derivatives = np.array(rows)
    derivatives[:, ~reliable] = np.nan

    # participation per subsystem: p_j = ȳ_j [(2λM + B) x]_j / yᴴ(2λM + B)x, summed per subsystem
    weights = Y.conj() * ((2 * lam[None, :]) * (model.M @ X) + B_total @ X) / denominator[None, :]
    subsystem = _subsystem_of(model)
    participation = tuple({name: float(np.real(weights[subsystem == s, k].sum()))
                           for s, name in enumerate(SUBSYSTEMS)} for k in range(len(lam)))
    characters = [characterize(model, lam[k], X[:, k]) for k in range(len(lam))] if describe else []
    return EigenSensitivities(
        operating_point=op, eigenvalues=lam, indices=np.asarray(indices),
        descriptions=tuple(c.description for c in characters) if describe else ("",) * len(lam),
        names=names, units=units,
        values=values, derivatives=derivatives, condition=condition, gap=gap, reliable=reliable,
        notes=tuple(notes), participation=participation,
        kinetic=tuple(c.kinetic for c in characters) if describe else ({},) * len(lam),
        strain=tuple(c.strain for c in characters) if describe else ({},) * len(lam),
        linked=linked, n_rigid=result.n_rigid)


# --- stability limit -------------------------------------------------------------------------------

@dataclass(frozen=True)
class LimitSensitivity:
    """ds0*/dp at one speed (plain data).  ``names``, ``units``, ``values`` as in
    :class:`EigenSensitivities` (the s0 row is omitted: s0* does not depend on s0)."""

    v: float  # speed [m/s]
    N0: float  # [N]
    b_M: float  # [N m s/rad]
    s0_limit: float  # s0* [-]
    mechanism: str  # "creep maximum" (a rigid-body velocity: ID1's spin, the translation),
    # "flutter" or "divergence"
    critical_eigenvalue: complex  # λc at s0* [1/s]
    creep_maximum: float  # creepage of the creep maximum at v [-]
    dmu_ds_at_limit: float  # ∂μ/∂s at s0* [-]
    names: tuple[str, ...]
    units: tuple[str, ...]
    values: np.ndarray
    derivatives: np.ndarray  # ds0*/dp [1 per unit]
    note: str

    @property
    def normalized(self) -> np.ndarray:
        """p/s0* · ds0*/dp [-]."""
        return self.values * self.derivatives / self.s0_limit


def _rigid_spin_mac(model: BogieModel, q: np.ndarray) -> np.ndarray:
    """MAC of a displacement vector with each rigid-body mode (the drivetrains' spins, the
    vehicle's translation and yaw) [-]."""
    R = model.rigid_body_modes.real
    return np.abs(R.T @ q) ** 2 / (np.sum(R * R, axis=0) * np.real(np.vdot(q, q)))


def _rigid_subspace_share(model: BogieModel, q: np.ndarray) -> float:
    """‖P_R q‖² / ‖q‖² with P_R the orthogonal projector onto the rigid-body modes [-]: 1 for a
    velocity mode of the rigid-body motions (e.g. ID1's spin together with the vehicle's
    translation, the slip of wheelset 1 that crosses zero at the creep maximum)."""
    Q, _ = np.linalg.qr(model.rigid_body_modes.real)
    projection = Q.T @ q
    return float(np.real(np.vdot(projection, projection)) / np.real(np.vdot(q, q)))


def limit_sensitivity(model: BogieModel, v: float, N0: float, b_M: float,
                      linked: Iterable[str] = (), s0_limit: float | None = None,
                      parameters: Iterable[str] | None = None) -> LimitSensitivity:
    """ds0*/dp at speed ``v`` [m/s] for every parameter (or those named) and v, N0, b_M.

    ``s0_limit``: the limit if already known (else :func:`model.analysis.stability.stability_limit`).
    Example:
        >>> from model import KMH, build_model, limit_sensitivity, load_parameters
        >>> p = load_parameters()
        >>> round(limit_sensitivity(build_model(p), 120 * KMH, p["wheel_force"], p["motor_slope"]).s0_limit, 4)
        0.0082
    """
    linked = tuple(linked)
    wanted = list(SCHEMA) if parameters is None else list(parameters)
    for name in wanted:
        if name not in SCHEMA:
            raise SensitivityError(f"unknown parameter '{name}'; names as in the parameter file")
    if s0_limit is None:
        s0_limit = stability_limit(model, v, N0, b_M).s0_limit
    op = OperatingPoint(s0_limit, v, N0, b_M)
    law = _law(model.parameters.values, N0)
    s_max, _ = law.maximum(v)
    dmu = float(law.dmu_ds(s0_limit, v))
    at_maximum = abs(s0_limit - s_max) <= CREEP_MAXIMUM_RTOL * s_max
    B_total = damping_matrix(model, op)
    guess = np.random.default_rng(0).standard_normal(model.n)
    # at the creep maximum the critical eigenvalue is expected to be the real one crossing 0 (a
    # drivetrain's spin): found by shift-invert iteration at 0, without the full analysis; the
    # full analysis decides when it is not that (checked below by its mode shape)
    nearest = _real_eigenvalue_nearest_zero(model, op) if at_maximum else None
    result = None
    if nearest is None:
        result = eigen_analysis(model, op, vectors=False)  # the critical vector: inverse iteration
        critical = int(np.argmax(result.eigenvalues.real))
        lam_c = complex(result.eigenvalues[critical])
    else:
        lam_c = complex(nearest)
    q, _ = null_vectors(model, B_total, lam_c, guess)
    spin = lam_c.imag == 0 and _rigid_subspace_share(model, q) > RIGID_SPIN_MAC
    if not (spin and at_maximum) and result is None:
        result = eigen_analysis(model, op, vectors=False)
        critical = int(np.argmax(result.eigenvalues.real))
        lam_c = complex(result.eigenvalues[critical])
        q, _ = null_vectors(model, B_total, lam_c, guess)
        spin = lam_c.imag == 0 and _rigid_subspace_share(model, q) > RIGID_SPIN_MAC
    names = (*tuple(wanted), "v", "N0", "b_M")
    units = (*tuple(SCHEMA[name][0] for name in wanted), "m/s", "N", "N m s/rad")
    values = np.array([model.parameters[name] for name in wanted] + [v, N0, b_M])
    if spin and at_maximum:
        # s0* is the creep maximum: d/dp [∂μ/∂s (s*, p)] = 0  =>  ds*/dp = −μ′_p/μ′_s
        base = _creep_inputs(model.parameters, OperatingPoint(s_max, v, N0, b_M))

        def dmu_ds(name: str) -> float:
            h = _step(base[name])
            stepped = dict(base)
            stepped[name] = base[name] + 1j * h
            return float(np.imag(_law(stepped, stepped["N0"]).dmu_ds(stepped["s0"], stepped["v"]))) / h

        curvature = dmu_ds("s0")
        partial = {name: (-dmu_ds(name) / curvature if name in (*CREEP_LAW_INPUTS, "v", "N0") else 0.0)
                   for name in [*list(wanted), "v", "N0", "b_M"]}
        derivatives = np.array([partial[name] + (partial[LINKED[name]] if name in linked else 0.0)
                                for name in wanted] + [partial["v"], partial["N0"], partial["b_M"]])
        note = (f"s0* = {s0_limit:.7f} is the creep maximum (s_max = {s_max:.7f}, ∂μ/∂s(s0*) = "
                f"{dmu:.2e}): the critical eigenvalue λc = {lam_c.real:.1e} 1/s (0 to working "
                f"precision) is the divergence "
                f"of a rigid-body motion's velocity (ID1's drivetrain spin with the vehicle's "
                f"translation: MAC with the rigid-body modes "
                f"{', '.join(f'{x:.3f}' for x in _rigid_spin_mac(model, q))}, share of their "
                f"span {_rigid_subspace_share(model, q):.4f}); only the creep law moves it, "
                "ds0*/dp = −(∂μ′/∂p)/(∂μ′/∂s); every structural parameter: exactly 0")
        return LimitSensitivity(v, N0, b_M, s0_limit, "creep maximum", lam_c, s_max, dmu, names,
                                units, values, derivatives, note)
    sens = eigen_sensitivities(model, op, indices=[critical], linked=linked, parameters=wanted,
                               result=result, describe=False)
    d = sens.derivatives[:, 0].real
    d_s0 = d[sens.names.index("s0")]
    keep = [i for i, name in enumerate(sens.names) if name != "s0"]
    derivatives = -d[keep] / d_s0
    mechanism = "divergence" if lam_c.imag == 0 else "flutter"
    description = characterize(model, lam_c, q).description
    note = (f"s0* = {s0_limit:.7f} set by {mechanism} of '{description}' "
            f"(λc = {lam_c.real:.2e}{lam_c.imag:+.4g}i 1/s, ∂Re λc/∂s0 = {d_s0:.4g} 1/s); "
            "ds0*/dp = −Re(∂λc/∂p)/Re(∂λc/∂s0)")
    return LimitSensitivity(v, N0, b_M, s0_limit, mechanism, lam_c, s_max, dmu, names, units,
                            values, derivatives, note)
