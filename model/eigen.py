"""Eigenvalues and stability of the linearized bogie (eqs. 21–22 in first-order form).

State ``u = [Δq; Δq̇]``, ``u̇ = A u`` with ``A = [[0, I], [−M⁻¹K, −M⁻¹B_total]]``.  The rigid-body
zero eigenvalues are *identified*, not guessed: every vector ``r`` with ``K r = 0`` (the rigid spin
of each whole drivetrain, known from the kinematics and checked against K) gives the exact
eigenpair ``(0, [r; 0])`` whatever the damping, and the invariant subspace they span is deflated
before the eigenvalues of the rest are computed.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from .assembly import BogieModel
from .operating_point import OperatingPoint, damping_matrix


@dataclass
class StateSpace:
    """Constant pieces of the first-order form, computed once per model."""

    model: BogieModel

    @cached_property
    def inverse_mass(self) -> np.ndarray:
        n = self.model.n
        return sla.cho_solve(sla.cho_factor(self.model.M), np.eye(n))

    @cached_property
    def minus_Minv_K(self) -> np.ndarray:
        return -self.inverse_mass @ self.model.K

    @cached_property
    def deflation(self) -> tuple[np.ndarray, np.ndarray]:
        """Orthonormal bases (Q1 of the rigid-body subspace [r; 0], Q2 of its complement)."""
        rigid = np.vstack([self.model.rigid_body_modes, np.zeros_like(self.model.rigid_body_modes)])
        Q, _ = np.linalg.qr(rigid, mode="complete")
        r = rigid.shape[1]
        return Q[:, :r], Q[:, r:]

    def state_matrix(self, B_total: np.ndarray) -> np.ndarray:
        n = self.model.n
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = self.minus_Minv_K
        A[n:, n:] = -self.inverse_mass @ B_total
        return A


def state_space(model: BogieModel) -> StateSpace:
    """The (cached) first-order pieces of a model."""
    cache = model.__dict__.setdefault("_state_space", None)
    if cache is None:
        cache = StateSpace(model)
        model.__dict__["_state_space"] = cache
    return cache


def state_matrix(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """A (2n x 2n) at an operating point [1/s and 1/s² blocks]."""
    return state_space(model).state_matrix(damping_matrix(model, op))


@dataclass(frozen=True)
class EigenResult:
    """All eigenvalues at an operating point.  Re in 1/s; ``im_hz`` = Im/(2π) in Hz."""

    operating_point: OperatingPoint
    eigenvalues: np.ndarray  # the 2n − n_rigid non-rigid eigenvalues [1/s], unsorted
    vectors: np.ndarray | None  # state eigenvectors (2n x len(eigenvalues)), [Δq; Δq̇]
    n_rigid: int  # identified rigid-body zero eigenvalues

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
    def real(self) -> np.ndarray:
        """Real eigenvalues from the largest down [1/s]."""
        return self.eigenvalues.real[self.real_index]

    @property
    def max_real_part(self) -> float:
        return float(self.eigenvalues.real.max())

    @property
    def flutter(self) -> int:
        """Number of unstable complex pairs."""
        return int(np.count_nonzero(self.complex_pairs.real > 0))

    @property
    def divergence(self) -> int:
        """Number of positive real eigenvalues."""
        return int(np.count_nonzero(self.real > 0))

    @property
    def stable(self) -> bool:
        return self.max_real_part <= 0.0

    def mode_shape(self, index: int) -> np.ndarray:
        """Displacement part Δq of eigenvector ``index``, scaled to unit largest entry."""
        if self.vectors is None:
            raise ValueError("eigenvectors were not computed")
        n = self.vectors.shape[0] // 2
        q = self.vectors[:n, index]
        return q / q[np.argmax(np.abs(q))]


def eigen_analysis(model: BogieModel, op: OperatingPoint, vectors: bool = True) -> EigenResult:
    """All eigenvalues (and eigenvectors) at ``op`` with the rigid-body ones deflated."""
    ss = state_space(model)
    A = ss.state_matrix(damping_matrix(model, op))
    Q1, Q2 = ss.deflation
    A22 = Q2.T @ A @ Q2
    if not vectors:
        return EigenResult(op, sla.eigvals(A22, overwrite_a=True, check_finite=False), None,
                           Q1.shape[1])
    lam, Y = sla.eig(A22, overwrite_a=False, check_finite=False)
    # back to the full state: A [Q1 Q2] = [Q1 Q2] [[0, A12], [0, A22]]  =>  x = Q2 y + Q1 A12 y / λ
    A12 = Q1.T @ A @ Q2
    X = Q2 @ Y + Q1 @ ((A12 @ Y) / lam)
    X /= np.linalg.norm(X, axis=0)
    return EigenResult(op, lam, X, Q1.shape[1])
