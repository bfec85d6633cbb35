"""The rail–wheel surface deviations in the nonlinear response's step loop
(:mod:`model.analysis.nonlinear`, :mod:`model.analysis.block_stepper`): their modal forcing per
step and the contacts' wheel-force changes ΔN_j.

The linear part is the running system (:func:`model.analysis.eigen.running_system`), driven by
the irregularity's generalized force ``G_q Δ + G_v Δ̇ + G_a Δ̈`` (n x 4 each,
:func:`model.mechanics.irregularity.irregularity_forces`).  Its modal increments over a step:

* harmonic history (:meth:`IrregularityHistory.harmonic`): exact.  ``Δ_j = Re(â_j e^(iω_j t))``
  gives the force ``Re(F̂_j e^(iω_j t))``, ``F̂_j = (G_q + iω G_v − ω² G_a)_j â_j``; each of its two
  exponentials e^(±iω t) adds ``β e^(s t_k) e^(λh) h φ1((s − λ) h)`` per step (as the
  short-circuit torque's damped oscillation does);
* sampled history: first-order hold of the force between the step's ends, modal weights
  ``h(φ1 − φ2)`` and ``h φ2`` (error O((ωh)²) at the history's frequencies ω).

The wheel-force change at each step's end is linear in the modal state, the step's remainders
and the known inputs:

    ΔN_j = −(m_R z̈_j + b_R ż_j + k_R z_j) + k_R Δ_j + b_R Δ̇_j + m_R Δ̈_j
         = Re(W_n ζ) + D_n r + (known part of Δ, Δ̇, Δ̈, M_C) + d_m2 ΔM_2

with z̈_j = (A x + b u) at the rim's vertical velocity state: the direct feed ``D_n`` of the
inputs acting at the step's end (on the bogie the creep forces and the motor torques do not act
on a rim's vertical acceleration directly — the mass matrix does not couple them — and these
direct terms come out zero; the irregularity's own force does, through the track mass m_R).
The rigid-body modes and the rolling velocity have no vertical rim motion, so the modal state
ζ (rigid coordinates deflated) holds all of ΔN's state part.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.analysis.block_stepper import hold_weights
from model.analysis.linear_system import LinearSystem
from model.analysis.nonlinear_inputs import IrregularityHistory
from model.mechanics.assembly import BogieModel
from model.mechanics.irregularity import irregularity_forces
from model.mechanics.operating_point import OperatingPoint


@dataclass(frozen=True, eq=False)
class IrregularityLoop:
    """What the step loop takes for the irregularities (:class:`model.analysis.block_stepper.
    StepInputs`' ``irregularity``), built once per run by :func:`irregularity_loop`."""

    history: IrregularityHistory
    h: float  # integration step [s]
    W: np.ndarray  # contacts x m: ΔN's state part = Re(W ζ) [N]
    D: np.ndarray  # contacts x channels: direct feed of the remainders into ΔN [N per N, N m]
    d_m2: np.ndarray  # contacts: direct feed of ID2's motor torque change ΔM_2 [N per N m]
    d_mc: np.ndarray  # contacts: direct feed of the short-circuit torque M_C [N per N m]
    torque: object  # M_C(t) [N m] of the run (t [s]), scaled as the run's excitation
    known_map: np.ndarray  # 12 x contacts: ΔN from (Δ, Δ̇, Δ̈) [N/m, N s/m, kg]
    beta: np.ndarray  # m x 12: modal inputs of G_q, G_v, G_a (the four wheels each)
    w0: np.ndarray  # m: hold weight of a step's start h(φ1 − φ2) [s]
    w1: np.ndarray  # m: of its end h φ2 [s]
    exponents: np.ndarray  # e: s [1/s] of the harmonic history's exponentials (none: sampled)
    weights: np.ndarray  # e x m: their exact modal increments per step (at t_k = 0)

    def forcing(self, k: int, L: int) -> np.ndarray:
        """Modal increments (L x m, complex) of the irregularity's force over the steps k … k+L−1
        (step i from t_i = i h to t_(i+1))."""
        if self.history.is_harmonic:
            t = (k + np.arange(L)) * self.h
            return np.exp(t[:, None] * self.exponents[None, :]) @ self.weights
        g = self.inputs((k + np.arange(L + 1)) * self.h) @ self.beta.T  # (L+1) x m
        return self.w0[None, :] * g[:-1] + self.w1[None, :] * g[1:]

    def known(self, k: int, L: int) -> np.ndarray:
        """ΔN's part (L x contacts) [N] at the ends of the steps k … k+L−1 that comes neither from
        the modal state nor from the remainders or ΔM_2: the deviations' own terms and their
        force's (and M_C's) direct feed."""
        return self.at((k + 1 + np.arange(L)) * self.h)

    def at(self, t: np.ndarray) -> np.ndarray:
        """That part at the times ``t`` [s] (len(t) x contacts) [N]."""
        out = self.inputs(t) @ self.known_map
        if np.any(self.d_mc):
            out += np.asarray(self.torque(t))[:, None] * self.d_mc[None, :]
        return out

    def inputs(self, t: np.ndarray) -> np.ndarray:
        """[Δ, Δ̇, Δ̈] at the times t (len(t) x 12) [m, m/s, m/s²]: the inputs of the force
        columns ``[G_q, G_v, G_a]`` (:func:`force_columns`)."""
        return np.hstack(self.history.values(t))


def force_columns(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """[G_q, G_v, G_a] (n x 12): the generalized force of (Δ, Δ̇, Δ̈) of the four wheels."""
    forces = irregularity_forces(model, op)
    return np.hstack([forces.G_q, forces.G_v, forces.G_a])


def wheel_force_rows(model: BogieModel, system: LinearSystem) -> tuple[np.ndarray, np.ndarray]:
    """(C_n, acceleration rows): ΔN's state part ``−(m_R z̈ + b_R ż + k_R z)`` of each contact as
    rows on the state (contacts x N, without the inputs' direct feed) and the state rows of the
    rims' vertical velocities (whose rates are z̈)."""
    p = model.parameters
    k_R, b_R, m_R = p["track_stiffness"], p["track_damping"], p["track_mass"]
    vertical = np.array([index[2] for index in model.rims.values()])  # [x, y, z, rx, ry, rz]
    velocity = model.n + np.searchsorted(system.inertial, vertical)
    C = -m_R * system.A[velocity]
    C[np.arange(len(vertical)), vertical] -= k_R
    C[np.arange(len(vertical)), velocity] -= b_R
    return C, velocity


def irregularity_loop(model: BogieModel, op: OperatingPoint, system: LinearSystem,
                      history: IrregularityHistory, h: float, modal_to_state: np.ndarray,
                      E: np.ndarray, channel_forces: np.ndarray, mc_force: np.ndarray,
                      torque) -> IrregularityLoop:
    """The :class:`IrregularityLoop` of a run on the running system ``system`` at step ``h`` [s]:
    ``modal_to_state`` (N x m, x = Re(X ζ)) and ``E`` = e^(λh) of the kept modes, the
    channels' generalized forces (n x channels: the four creep forces, ID2's motor torque),
    M_C's force and M_C(t) [N m] as the run steps them."""
    p = model.parameters
    k_R, b_R, m_R = p["track_stiffness"], p["track_damping"], p["track_mass"]
    lam_all, _, _, _, scale = system.modal
    keep = lam_all.imag >= 0
    lam = lam_all[keep]
    r = system.rigid_count
    columns = force_columns(model, op)
    rhs = system.deflation.to_deflated(system.input_map(columns))[r:] / scale[:, None]
    beta = system.solve_eigenvectors(rhs)[keep]  # m x 12
    C, velocity = wheel_force_rows(model, system)

    def direct(F: np.ndarray) -> np.ndarray:  # ΔN's direct feed of generalized forces F (n x k)
        return -m_R * system.input_map(F)[velocity]

    D = direct(channel_forces)
    wheels = C.shape[0]
    own = np.vstack([k_R * np.eye(wheels), b_R * np.eye(wheels), m_R * np.eye(wheels)])
    phi1, phi2 = hold_weights(lam * h)
    w1 = h * phi2
    exponents, weights = np.zeros(0, dtype=complex), np.zeros((0, len(lam)), dtype=complex)
    if history.is_harmonic:
        exps, rows = [], []
        for j in np.flatnonzero(history.amplitude != 0):
            omega = 2 * np.pi * history.frequency[j]
            for s, amplitude in ((1j * omega, history.amplitude[j]),
                                 (-1j * omega, np.conj(history.amplitude[j]))):
                b = beta[:, j] + s * beta[:, wheels + j] + s * s * beta[:, 2 * wheels + j]
                phi, _ = hold_weights((s - lam) * h)
                exps.append(s)
                rows.append(b * 0.5 * amplitude * E * h * phi)
        if exps:
            exponents, weights = np.array(exps), np.array(rows)
    return IrregularityLoop(
        history=history, h=h, W=np.ascontiguousarray(C @ modal_to_state), D=D,
        d_m2=D[:, -1].copy(), d_mc=direct(mc_force), torque=torque,
        known_map=own + direct(columns).T, beta=beta, w0=h * phi1 - w1, w1=w1,
        exponents=exponents, weights=weights)
