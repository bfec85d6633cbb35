"""The reduced model of a sweep: the bogie projected on a basis of mode shapes, with the creep
damping affine in its four coefficients (:func:`creep_patterns`), so that every point of a root
locus or of a study's s0-line costs one small eigen-solve (:mod:`model.analysis.locus`,
:mod:`model.studies.s0_line`)."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from model.analysis.linear_system import Deflation, first_order_matrix, massless_coordinates
from model.contact.creep import creep_block
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import OperatingPoint, creep_coefficients


def creep_patterns(model: BogieModel) -> list[np.ndarray]:
    """The four n x n patterns P11, P22, P23, P33 of B_ad (coefficient 1 each)."""
    r0 = model.parameters["wheel_radius"]
    patterns = []
    for unit in np.eye(4):
        block = creep_block(*unit, r0=r0)
        P = np.zeros((model.n, model.n))
        for index in model.rims.values():
            P[np.ix_(index, index)] += block
        patterns.append(P)
    return patterns


def pattern_coefficients(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """(b11, b22, b23, b33) at ``op``: the coefficients of the four creep patterns of
    :func:`creep_patterns` (B_ad = Σ b_k P_k)."""
    cc = creep_coefficients(model.parameters, op)
    return np.array([cc.b11, cc.b22, cc.b23, cc.b33])


class Reduced:
    """Projected matrices of the sweep on a basis Φ.

    The massless coordinates (the Maxwell elements' internal coordinates,
    :mod:`model.analysis.linear_system`) are kept exactly: Φ = [Φ_i, E_m] with Φ_i an orthonormal basis
    of the inertial parts of the given vectors and E_m the unit vectors of the massless
    coordinates, so the reduced model has the full model's first-order structure (its reduced
    mass is ``diag(I, 0)`` in the mass-normalized coordinates) and an eigenvector whose inertial
    part lies in span(Φ_i) is reproduced exactly."""

    def __init__(self, model: BogieModel, op: OperatingPoint, patterns, vectors: list[np.ndarray]):
        massless = massless_coordinates(model.M)
        stacked = np.hstack(vectors)
        stacked[massless] = 0.0
        U, s, _ = np.linalg.svd(stacked, full_matrices=False)
        Phi_i = U[:, s > 1e-12 * s[0]]
        E_m = np.zeros((model.n, len(massless)))
        E_m[massless, np.arange(len(massless))] = 1.0
        Phi = np.hstack([Phi_i, E_m])
        r_i = Phi_i.shape[1]
        self.Phi = Phi
        self.inertial = np.arange(r_i)  # reduced coordinates with mass
        self.massless = np.arange(r_i, Phi.shape[1])  # the massless coordinates, kept
        self.M_Phi = model.M @ Phi
        self.K_Phi = model.K @ Phi
        self.b_M = op.b_M  # the motor slope of C0 [N m s/rad]
        C0 = model.B + op.b_M * model.motor_pattern
        self.C0_Phi = C0 @ Phi
        self.motor_Phi = model.motor_pattern @ Phi  # B_M Φ (b_M = 1)
        self.P_Phi = [P @ Phi for P in patterns]
        if any(np.any(P[massless]) or np.any(P[:, massless]) for P in patterns):
            raise ValueError("a creep pattern acts on a massless coordinate")
        # mass-normalize the inertial reduced coordinates: Φ_iᵀ M Φ_i = L Lᵀ (Linv: block
        # diagonal with the identity on the massless ones)
        L = np.linalg.cholesky(Phi_i.T @ self.M_Phi[:, :r_i])
        self.Linv = np.eye(Phi.shape[1])
        self.Linv[:r_i, :r_i] = sla.solve_triangular(L, np.eye(r_i), lower=True)
        project = lambda X: self.Linv @ (Phi.T @ X) @ self.Linv.T  # noqa: E731
        self.K_r = project(self.K_Phi)
        self.C0_r = project(self.C0_Phi)
        self.motor_r = project(self.motor_Phi)
        self.P_r = [project(P) for P in self.P_Phi]
        # The reduced model's exact zeros, deflated as in the full model
        # (model.analysis.linear_system): the basis holds the rigid-body modes, whose reduced
        # coordinates y_R = Lᵀ Φᵀ R give the eigenpairs (0, [y_R; 0]) whatever the damping, and
        # the free rolling velocity [0; y_roll] maps onto them (a Jordan chain).  Left in, the
        # chain's double zero comes out as a pair ≈ ±1e-5 1/s (the square root of the rounding),
        # and where a drivetrain spin's eigenvalue passes through 0 (the creep maximum) closer
        # than that, dropping the Ritz values nearest to zero left a spurious one in the spin's
        # place.  (Mass-normalized coordinates put every velocity on one footing: the
        # orthogonal Deflation loses no digits here.)
        rigid, rolling = (sla.solve_triangular(self.Linv.T, Phi.T @ vectors, lower=False,
                                               check_finite=False)
                          for vectors in (model.rigid_body_modes, model.rolling_mode[:, None]))
        self.deflation = Deflation(np.block([
            [rigid, np.zeros((Phi.shape[1], 1))],
            [np.zeros((r_i, rigid.shape[1])), rolling[self.inertial]]]))
        self.zero_count = rigid.shape[1] + 1  # deflated zeros: rigid_zero_count(model)

    @property
    def size(self) -> int:
        return self.Phi.shape[1]

    @property
    def mass_diagonal(self) -> np.ndarray:
        """The reduced (mass-normalized) mass matrix's diagonal: 1 inertial, 0 massless."""
        d = np.zeros(self.size)
        d[self.inertial] = 1.0
        return d

    def first_order(self, K: np.ndarray, C: np.ndarray) -> np.ndarray:
        """The reduced state matrix (state: reduced coordinates, velocities of the inertial
        ones; :func:`model.analysis.linear_system.first_order_matrix`)."""
        return first_order_matrix(np.eye(len(self.inertial)), C, K, self.inertial, self.massless)

    def solve(self, c: np.ndarray, b_M: float | None = None):
        """The non-rigid Ritz values and their displacement vectors (Φ coordinates, unit norm)
        at coefficients c (``b_M`` [N m s/rad]: another motor slope than the sweep's); the exact
        zeros are deflated (:attr:`zero_count` of them).

        With ``Qᵀ A Q = [[N, A12], [0, A22]]`` (N nilpotent, N² = 0) an eigenvector y of A22 gives
        the eigenvector ``Q [(λ − N)⁻¹ A12 y; y]`` of A, ``(λ − N)⁻¹ = (λ + N)/λ²``: scaled by
        λ², ``Q [(λ + N) A12 y; λ² y]``, which stays finite for a λ at zero (a spin at the creep
        maximum: its vector is a rigid one's)."""
        r, k = self.size, self.zero_count
        C = self.C0_r + sum(ck * Pk for ck, Pk in zip(c, self.P_r, strict=True))
        if b_M is not None and b_M != self.b_M:
            C = C + (b_M - self.b_M) * self.motor_r
        P = self.deflation.project(self.first_order(self.K_r, C))
        lam, Y = np.linalg.eig(P[k:, k:])  # numpy releases the GIL: points run on several threads
        W = P[:k, k:] @ Y
        Z = self.deflation.apply(np.vstack([W * lam + P[:k, :k] @ W, Y * lam**2]))
        X = self.Linv.T @ Z[:r]  # back from mass-normalized to Φ coordinates
        X /= np.linalg.norm(X, axis=0)
        return lam, X

    def damping_Phi(self, c: np.ndarray, b_M: float | None = None) -> np.ndarray:
        """C(c) Φ: the full damping matrix at creep coefficients c (and motor slope ``b_M``
        [N m s/rad], None: the sweep's) times the basis [N s/m]."""
        C_Phi = self.C0_Phi + sum(ck * P for ck, P in zip(c, self.P_Phi, strict=True))
        if b_M is not None and b_M != self.b_M:
            C_Phi = C_Phi + (b_M - self.b_M) * self.motor_Phi
        return C_Phi

    def error_estimate(self, c: np.ndarray, lam: np.ndarray, X: np.ndarray,
                       C_Phi: np.ndarray | None = None, floor: float = 1e-300) -> np.ndarray:
        """First-order eigenvalue error from the full-model residual, relative to
        max(|λ|, ``floor`` [1/s]) (``C_Phi``: :meth:`damping_Phi` at c, if already formed)."""
        if C_Phi is None:
            C_Phi = self.damping_Phi(c)
        CX = C_Phi @ X
        MX = self.M_Phi @ X
        residual = lam**2 * MX + lam * CX + self.K_Phi @ X
        derivative = 2 * lam * MX + CX
        return (np.linalg.norm(residual, axis=0) / np.linalg.norm(derivative, axis=0)
                / np.maximum(np.abs(lam), floor))
