"""Eigenvalues and stability of the linearized bogie (eqs. 21–22 in first-order form).

State ``u = [Δq; Δq̇]``, ``u̇ = A u`` with ``A = [[0, I], [−M⁻¹K, −M⁻¹B_total]]``; the massless
internal coordinates of the Maxwell elements (yaw dampers) are first order, their velocities are
not states (:mod:`model.analysis.linear_system`): ``u = [Δq; Δq̇_inertial]``.  The rigid-body
zero eigenvalues are *identified*, not guessed: every vector ``r`` with ``K r = 0`` (the rigid spin
of each whole drivetrain, the whole vehicle's translation and yaw, known from the kinematics and
checked against K) gives the exact
eigenpair ``(0, [r; 0])`` whatever the damping, and the invariant subspace they span is deflated
before the eigenvalues of the rest are computed (:mod:`model.analysis.linear_system`).  The decomposition
with vectors is shared with the short-circuit response through :func:`bogie_system`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Literal

import numpy as np

from model.analysis.linear_system import (
    LinearSystem,
    SystemCache,
    inertial_inverse_mass,
    massless_coordinates,
)
from model.mechanics.assembly import BogieModel
from model.mechanics.irregularity import irregularity_forces
from model.mechanics.operating_point import OperatingPoint, damping_matrix

# a real eigenvalue this close to zero (relative to the largest |λ|, ~3e5 1/s) is zero to
# rounding: at b_M = 0 the vehicle rolling freely (translation with every wheel rolling: no slip,
# no motor slope) has no damping at all, and its velocity's eigenvalue comes out as ±1e-12 1/s
NEUTRAL_RTOL = 1e-12


def non_neutral(eigenvalues: np.ndarray) -> np.ndarray:
    """Mask of the eigenvalues that are not zero to rounding (:data:`NEUTRAL_RTOL`).  A neutral
    eigenvalue is treated like the deflated rigid-body zeros: neither growth nor decay."""
    lam = np.asarray(eigenvalues)
    if lam.size == 0:
        return np.ones(0, dtype=bool)
    return np.abs(lam) > NEUTRAL_RTOL * np.abs(lam).max()


@dataclass
class StateSpace:
    """Constant pieces of the first-order form, computed once per model."""

    model: BogieModel

    @cached_property
    def inverse_mass(self) -> np.ndarray:
        """M⁻¹ on the inertial coordinates (the massless ones excluded) [1/kg, …]."""
        return inertial_inverse_mass(self.model.M)

    def system(self, B_total: np.ndarray) -> LinearSystem:
        """The first-order form with damping ``B_total`` (input: M_C, as :func:`bogie_system`)."""
        m = self.model
        return LinearSystem(m.M, B_total, m.K, m.short_circuit_force, m.rigid_body_modes,
                            self.inverse_mass, m.rolling_mode[:, None])

    def state_matrix(self, B_total: np.ndarray) -> np.ndarray:
        """A (N x N) with damping ``B_total`` [1/s and 1/s² blocks]."""
        return self.system(B_total).A


def state_space(model: BogieModel) -> StateSpace:
    """The (cached) first-order pieces of a model."""
    cache = model.__dict__.setdefault("_state_space", None)
    if cache is None:
        cache = StateSpace(model)
        model.__dict__["_state_space"] = cache
    return cache


def state_matrix(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """A (N x N, state [Δq; Δq̇_inertial]) at an operating point [1/s and 1/s² blocks]."""
    return state_space(model).state_matrix(damping_matrix(model, op))


@dataclass(frozen=True)
class EigenResult:
    """All eigenvalues at an operating point.  Re in 1/s; ``im_hz`` = Im/(2π) in Hz."""

    operating_point: OperatingPoint
    eigenvalues: np.ndarray  # the N − n_rigid non-rigid eigenvalues [1/s], unsorted
    vectors: np.ndarray | None  # state eigenvectors (N x len(eigenvalues)), [Δq; Δq̇_inertial]
    n_rigid: int  # identified rigid-body zero eigenvalues
    n_coordinates: int  # n: the first n rows of a state vector are Δq
    # where ``vectors`` is None: the state eigenvectors of the given indices, computed when a
    # mode's shape is asked (eigen_analysis(..., vectors="on_demand"); it keeps the decomposed
    # system alive while the result lives), and the shapes computed so far
    vectors_of: Callable[[np.ndarray], np.ndarray] | None = field(
        default=None, repr=False, compare=False)
    _shapes: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def complex_index(self) -> np.ndarray:
        """Indices of complex eigenvalues with Im > 0, by ascending Im."""
        idx = np.flatnonzero(self.eigenvalues.imag > 0)
        return idx[np.argsort(self.eigenvalues.imag[idx], kind="stable")]

    @property
    def real_index(self) -> np.ndarray:
        """Indices of real eigenvalues, from the largest down."""
        idx = np.flatnonzero(self.eigenvalues.imag == 0)
        return idx[np.argsort(-self.eigenvalues.real[idx], kind="stable")]

    @property
    def complex_pairs(self) -> np.ndarray:
        """Upper-half complex eigenvalues sorted by imaginary part [1/s]."""
        return self.eigenvalues[self.complex_index]

    @property
    def real_eigenvalues(self) -> np.ndarray:
        """Real eigenvalues from the largest down [1/s] (the real ones, not the real parts)."""
        return self.eigenvalues.real[self.real_index]

    @property
    def real(self) -> np.ndarray:
        """Deprecated name of :attr:`real_eigenvalues` (it is not the real parts, as numpy's
        ``.real`` would be); warns, and goes in the next release."""
        warnings.warn("EigenResult.real is deprecated: use EigenResult.real_eigenvalues (the real "
                      "eigenvalues, largest first)", DeprecationWarning, stacklevel=2)
        return self.real_eigenvalues

    @property
    def max_real_part(self) -> float:
        """Largest real part of the eigenvalues that are not neutral (:func:`non_neutral`)."""
        return float(self.eigenvalues[non_neutral(self.eigenvalues)].real.max())

    @property
    def flutter(self) -> int:
        """Number of unstable complex pairs."""
        return int(np.count_nonzero(self.complex_pairs.real > 0))

    @property
    def divergence(self) -> int:
        """Number of positive real eigenvalues (a real eigenvalue zero to rounding, |λ| <=
        :data:`NEUTRAL_RTOL` max|λ|, is neutral: a rigid-body motion's velocity without any
        damping, e.g. the vehicle rolling freely at b_M = 0)."""
        values = self.real_eigenvalues
        tolerance = NEUTRAL_RTOL * np.abs(self.eigenvalues).max()
        return int(np.count_nonzero(values > tolerance))

    @property
    def stable(self) -> bool:
        return self.max_real_part <= 0.0

    def mode_shape(self, index: int) -> np.ndarray:
        """Displacement part Δq of eigenvector ``index``, scaled to unit largest entry."""
        if self.vectors is not None:
            q = self.vectors[:self.n_coordinates, index]
        elif self.vectors_of is not None:
            index = int(index)
            if index not in self._shapes:
                self._shapes[index] = self.vectors_of(np.array([index]))[:self.n_coordinates, 0]
            q = self._shapes[index]
        else:
            raise ValueError("eigenvectors were not computed")
        return q / q[np.argmax(np.abs(q))]


def rigid_zero_count(model: BogieModel) -> int:
    """The exact zero eigenvalues of the bogie at every operating point: one per rigid-body mode
    (``K r = 0``) and one more for the velocity of the vehicle rolling without slip, which no
    damping meets (:attr:`model.mechanics.assembly.BogieModel.rolling_mode`)."""
    return model.rigid_body_modes.shape[1] + 1


def bogie_system(model: BogieModel, op: OperatingPoint, cached: bool = True) -> LinearSystem:
    """The bogie at ``op`` as a :class:`LinearSystem` (input: the short-circuit torque M_C on
    ID1's rotor and stator).  ``cached``: kept with the last few operating points of the model, so
    that the eigen-analysis and the response at one point share one eigendecomposition."""
    def build() -> LinearSystem:
        return state_space(model).system(damping_matrix(model, op))
    if not cached:
        return build()
    cache = model.__dict__.setdefault("_systems", SystemCache())
    return cache.get(op, build)


def running_system(model: BogieModel, op: OperatingPoint, cached: bool = True) -> LinearSystem:
    """The running system at ``op``: the bogie of :func:`bogie_system` with the wheel-force
    coupling (the creep force's share μ(s0) ΔN_j of the rims' vertical motion, non-symmetric;
    :mod:`model.mechanics.irregularity`), the system the rail–wheel irregularities drive.  The
    coupling has no rim-``z`` component along any rigid-body mode or the rolling velocity, so they
    stay exact eigenpairs.  ``cached``: kept beside :func:`bogie_system`'s systems."""
    def build() -> LinearSystem:
        forces = irregularity_forces(model, op)
        M = model.M + forces.M_c
        inertial = np.setdiff1d(np.arange(model.n), massless_coordinates(M))
        inverse = np.linalg.inv(M[np.ix_(inertial, inertial)])  # M + M_c is not symmetric
        return LinearSystem(M, damping_matrix(model, op) + forces.B_c, model.K + forces.K_c,
                            model.short_circuit_force, model.rigid_body_modes, inverse,
                            model.rolling_mode[:, None])
    if not cached:
        return build()
    cache = model.__dict__.setdefault("_running_systems", SystemCache())
    return cache.get(op, build)


def forget_systems(model: BogieModel) -> None:
    """Drop the cached per-operating-point systems of ``model`` (cold timings in benchmarks)."""
    model.__dict__.pop("_systems", None)
    model.__dict__.pop("_running_systems", None)


def eigen_analysis(model: BogieModel, op: OperatingPoint,
                   vectors: bool | Literal["on_demand"] = True) -> EigenResult:
    """All eigenvalues (and eigenvectors) at ``op`` with the rigid-body ones deflated.

    With ``vectors`` the decomposition is cached for the operating point (the response reuses
    it); without, a point already decomposed is not decomposed again, and a new one is not cached
    (root finding and sweeps would only evict the points the user is looking at).
    ``vectors="on_demand"``: decomposed and cached as with True, but the state eigenvectors are
    formed only for the modes whose shape is asked (:meth:`EigenResult.mode_shape`;
    ``vectors`` None): a table of ten modes does not pay for all of them.

    Example::

        >>> from model import build_model, default_operating_point, eigen_analysis, load_parameters
        >>> parameters = load_parameters()
        >>> model = build_model(parameters)
        >>> result = eigen_analysis(model, default_operating_point(parameters, s0=0.014))
        >>> result.stable, result.flutter > 0, result.divergence
        (False, True, 1)
        >>> bool(result.real_eigenvalues[0] > 0)        # the largest real eigenvalue [1/s]
        True
    """
    n_rigid = rigid_zero_count(model)
    if not vectors:
        cache = model.__dict__.get("_systems")
        system = cache.peek(op) if cache is not None else None
        if system is None:
            system = bogie_system(model, op, cached=False)
        return EigenResult(op, system.eigenvalues(), None, n_rigid, model.n)
    system = bogie_system(model, op)
    if vectors == "on_demand":
        return EigenResult(op, system.eigen[0], None, n_rigid, model.n,
                           vectors_of=system.state_vectors)
    return EigenResult(op, system.eigen[0], system.state_vectors(), n_rigid, model.n)
