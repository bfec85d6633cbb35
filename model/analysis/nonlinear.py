"""Nonlinear short-circuit response (spec §6): the longitudinal creep forces are the creep law
itself, with an anti-slip protection on the healthy drive's motor torque.

API::

    from model.analysis.nonlinear import AntiSlip, IrregularityHistory, nonlinear_response
    r = nonlinear_response(model, op, ShortCircuit(), t_end=2.0, fs=10_000.0,
                           creep="nonlinear", anti_slip=AntiSlip(delay=0.1),
                           irregularity=IrregularityHistory.harmonic(80.0, 1e-4))  # or None
    r.outputs["ID2.disc_clutch.torque"]   # totals, the same names as the linear response [N m]
    r.creepage["ID2.rim12"], r.slip_velocity[...], r.utilisation[...]   # per wheel
    r.motor_torques["ID2.motor.torque"]    # after protection [N m]
    r.wheel_force["ID2.rim12"]             # N_j with irregularities [N]

Equations.  With the creepage formed from the state (eq. 14), ``Δs_i v = H_i Δq̇`` (H: contacts
x n, :func:`creep_velocity_map`), the longitudinal creep force at contact i is
``T_i = N0 μ(s0 + Δs_i, v)`` and

    M Δq̈ + B_nl Δq̇ + K Δq = f_mc M_C(t) + f_m2 ΔM_2(t) + G N0 [μ(s0 + H Δq̇/v) − μ(s0)]

``B_nl`` = ``B + b_M B_M + B_ad`` without eq. 19's b11 terms (:func:`damping_without_longitudinal_
creep`), ``G`` = ``−Hᵀ`` (n x contacts, :func:`creep_force_map`) puts a unit creep force on a rim
(``e_x − r0 e_ry``), ``f_m2`` a unit driving torque of ID2's motor (rotor, stator reaction) and
``ΔM_2(t)`` the anti-slip reduction of that torque.  With μ replaced by its tangent at s0 this is
eq. 20 again: ``B + b_M B_M + B_ad = B_nl − G diag(N0 μ'(s0)/v) H``.  Kept linear as in the study:
the lateral and spin creep forces (Kalker, eq. 9–10), the vertical wheel forces (N = N0 in the
creep law unless irregularities are given, below; the track's m_R, b_R, k_R stay in M, B, K), the
healthy motor's slope b_M.

Method (exact linear part, implicit remainder). The equation is split at the tangent:

    M Δq̈ + B_total Δq̇ + K Δq = f_mc M_C + f_m2 ΔM_2 + G r(H Δq̇),
    r_i(z) = N0 [μ(s0 + z/v) − μ(s0)] − N0 μ'(s0) z/v        (zero with zero slope at z = 0)

The linear part is the closed form's system (:func:`model.analysis.eigen.bogie_system`, the *same* cached
eigendecomposition, rigid spins deflated) in its eigenbasis ``ζ``, stepped exactly: each mode by
``e^(λh)``, the step and the damped sinusoid of M_C by their exact integrals over the step. The
four remainder forces and ΔM_2 enter as piecewise-linear inputs (first-order hold; exact modal
weights ``h(φ1 − φ2)``, ``h φ2``), and the remainder at the end of each step is solved implicitly
from the four contact velocities ``z = H Δq̇`` by a Newton iteration (5 x 5 with the anti-slip
channel below; the creep feedback is stiff: ``N0 μ'/v`` reaches 10⁶ N s/m on a rim of ≈ 200 kg).
Why split at the tangent and not at ``B_nl``: without the b11 terms the drivetrain spins lose their
only damping (a double zero eigenvalue, a Jordan block the modal basis cannot hold), the linear
part would need its own eigendecomposition, and the whole creep feedback would carry the hold
error; at the tangent the linear part is exact, the remainder is O(Δs²), and ``creep="tangent"`` (μ
replaced by its tangent in the *same* loop: the remainder evaluates to rounding) reproduces the
closed form to rounding. The loop is numpy and scipy (:mod:`model.analysis.block_stepper`): the
remainders of a block of 32 steps are solved together by Newton with a triangular Jacobian (the
creep law on all of the block's contact values at once), the block's forced modal states by a
vectorised doubling scan, its outputs from them and the remainders by a Toeplitz matrix product
(the modal states inside a block are never formed, only the last one, carried on). Every step
the anti-slip logic sees the contact velocities (a block is cut where a reduction starts).

Anti-slip protection (:class:`AntiSlip`): detection when the slip velocity of ID2's wheelset
(mean of its two wheels) departs from its pre-fault value by more than ``threshold``, action
``delay`` seconds later; then ID2's motor torque — the pre-fault M(s0, v) *and* its slope part
``−b_M Δω`` (eq. 6), i.e. the whole characteristic — is scaled by ρ(t), which ramps from 1 at
``rate`` (per second) down to ``floor``.  The slope part depends on the state, so ρ·(−b_M Δω) is
solved with the creep forces in the same Newton iteration (a fifth channel).  ID1's motor is the
one that short-circuited: its torque is the fault torque M_C(t) of its machine, which no converter
controls, so the protection cannot act on it.

Rail–wheel irregularities (``irregularity``: an :class:`IrregularityHistory` of the four wheels'
Δ_j(t) [m]).  The wheel force varies, ``N_j = N0 + ΔN_j``, ``ΔN_j = −(m_R z̈_j + b_R ż_j + k_R z_j)
+ k_R Δ_j + b_R Δ̇_j + m_R Δ̈_j`` (z_j: the rim's ``z``, :mod:`model.mechanics.irregularity`), and
the creep force is ``T_j = N_j μ(s_j, v)`` — it saturates at μ_max N_j as a wheel unloads:

    (M + M_c) Δq̈ + (B_total + B_c) Δq̇ + (K + K_c) Δq = f_mc M_C + f_m2 ΔM_2
        + G_q Δ + G_v Δ̇ + G_a Δ̈ + G [r(H Δq̇) + ΔN ∘ (μ(s) − μ(s0))]

The linear part is then the running system (:func:`model.analysis.eigen.running_system`, its own
cached eigendecomposition: M + M_c is not symmetric), stepped exactly like the bogie; it holds
μ(s0) ΔN_j, whose state part is stiff (k_R μ(s0) on the longitudinal pattern) and would carry the
hold error in the remainder.  The deviations' force enters by exact modal increments (harmonic)
or first-order hold (sampled).  Only the product ΔN_j (μ(s_j) − μ(s0)) joins the remainder; ΔN is
not lagged but solved with it at each step's end, as further rows of the block solve (state,
remainders and the inputs' direct feed into z̈; :mod:`model.analysis.nonlinear_irregularity`),
held in Newton's Jacobian only, so the scheme keeps its order.  ``creep="tangent"`` gives
``T = N (μ0 + μ0' Δs)``, whose small-amplitude limit is the running system's frequency response.
The short circuit alone moves the rims vertically (its torque reaction loads ID1's wheels and
unloads ID2's by tens of per cent of N0), which a run with irregularities — Δ = 0 included —
takes into account and one without (N = N0, the bogie's system, the computation above) does not.
Not modelled: a wheel lifting off (N_j ≤ 0 ends the run), the Hertzian contact's own stiffness,
μ's own dependence on N (the law stays that of N0), the lateral and spin creep forces' on N.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from model.analysis.block_stepper import StepInputs, hold_weights, march, step_matrices
from model.analysis.eigen import bogie_system, running_system
from model.analysis.linear_system import LinearSystem
from model.analysis.load_peaks import LIMITED, LimitCrossing, history_peaks_and_crossings
from model.analysis.nonlinear_inputs import AntiSlip, IrregularityHistory, NonlinearError
from model.analysis.nonlinear_irregularity import IrregularityLoop, force_columns, irregularity_loop
from model.analysis.response import (
    MAX_POINTS,
    ShortCircuit,
    time_grid_points,
)
from model.contact.creep import PolachLaw
from model.mechanics.assembly import DRIVES, RIM_NODES, BogieModel
from model.mechanics.irregularity import irregularity_inputs
from model.mechanics.operating_point import (
    OperatingPoint,
    adhesion_moment,
    creep_coefficients,
    creep_law,
    longitudinal_creep_pattern,
    motor_torque,
)
from model.mechanics.outputs import OutputMatrices, output_matrices
from model.mechanics.parameters import Parameters

CREEP_MODELS = ("nonlinear", "tangent")
BLOCK_STEPS = 2048  # steps per compiled block (modal states of a block: ≈ 6 MB)
NEWTON_TOL = 1e-12  # relative change of the contact velocities at which Newton stops
NEWTON_MAX = 60


# --- maps between the state and the contacts -------------------------------------------------------

def creep_force_map(model: BogieModel) -> np.ndarray:
    """G (n x contacts): generalized force of a unit longitudinal creep force (+x on the wheel at
    the contact point) at each rim, in ``model.rims`` order [1 for x, m for ry]."""
    return longitudinal_creep_pattern(model)


def creep_velocity_map(model: BogieModel) -> np.ndarray:
    """H (contacts x n): ``Δs_i v = H_i Δq̇``, the rim's slip velocity ``r0 ṙy − ẋ`` [m/s per unit
    velocity]."""
    return -longitudinal_creep_pattern(model).T


def damping_without_longitudinal_creep(model: BogieModel, op: OperatingPoint) -> np.ndarray:
    """B_nl = B + b_M B_M + B_ad without the b11 terms of eq. 19 (n x n) [N s/m, …]."""
    from model.mechanics.operating_point import damping_matrix

    G = creep_force_map(model)
    b11 = creep_coefficients(model.parameters, op).b11
    return damping_matrix(model, op) - b11 * (G @ G.T)


def contact_names(model: BogieModel) -> list[str]:
    """Names of the contacts (rims) in the order of G's columns and H's rows."""
    return list(model.rims)


# --- result ---------------------------------------------------------------------------------------------

@dataclass
class NonlinearResult:
    """Nonlinear short-circuit time histories (plain data; module docstring)."""

    t: np.ndarray  # time points [s]
    outputs: dict[str, np.ndarray]  # name -> total (the linear response's names) [units]
    units: dict[str, str]  # name -> SI unit
    steady: dict[str, float]  # name -> pre-fault value [units]
    M_C: np.ndarray  # short-circuit torque of ID1 M_C(t) (eq. 23) [N m]
    motor_torques: dict[str, np.ndarray]  # "ID1.motor.torque", "ID2.motor.torque": totals [N m]
    creepage: dict[str, np.ndarray]  # rim -> total creepage s0 + Δs [-]
    slip_velocity: dict[str, np.ndarray]  # rim -> s·v [m/s]
    utilisation: dict[str, np.ndarray]  # rim -> μ(s, v)/μ_max(v) [-] (signed)
    peaks: dict[str, float]  # name -> signed total of largest magnitude [units]
    peak_times: dict[str, float]  # name -> its time [s]
    perturbation_peaks: dict[str, float]  # name -> signed Δy of largest magnitude [units]
    perturbation_peak_times: dict[str, float]  # name -> its time [s]
    limit_crossings: list[LimitCrossing]  # totals beyond the limits, by time
    limits: dict[str, float]  # "M_ad", "M_ad/p" [N m], "mu_max N0" [N], "strength" if given
    operating_point: OperatingPoint
    excitation: ShortCircuit
    creep_model: str  # "nonlinear" or "tangent"
    anti_slip: AntiSlip | None
    detection_time: float | None  # when the protection detected the slip [s] (None: never)
    action_time: float | None  # detection + delay [s] (None: never)
    motor_torque: float  # M(s0, v) before the fault [N m]
    mu_max: float  # μ_max(v) [-]
    newton_iterations: float  # mean Newton iterations per step
    torque_reduction: np.ndarray  # change of ID2's motor torque by the protection [N m]
    contact_velocity: np.ndarray | None = None  # N x contacts: H Δq̇ [m/s] (for checks)
    remainder_force: np.ndarray | None = None  # N x contacts: r(H Δq̇) [N]
    states: np.ndarray | None = None  # samples x N: [Δq; Δq̇_inertial] without the rigid-body
    # positions (the rolling velocity included), if asked
    irregularity: IrregularityHistory | None = None  # the rail–wheel deviations, if given
    wheel_force: dict[str, np.ndarray] | None = None  # rim -> vertical wheel force N_j [N]
    # (with irregularities; without, N_j = N0 throughout)

    def perturbation(self, name: str) -> np.ndarray:
        """Δy(t) = total − pre-fault value [unit of the output]."""
        return self.outputs[name] - self.steady[name]


# --- the computation --------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Setup:
    """Per (model, operating point, step) pieces of the stepping (built once, cached)."""

    E: np.ndarray  # e^(λh) per kept mode
    w0: np.ndarray  # first-order-hold weights h(φ1 − φ2) per mode
    w1: np.ndarray  # h φ2
    beta_mc: np.ndarray  # modal input of M_C
    P0: np.ndarray  # m x channels: β_c w0
    P1: np.ndarray  # m x channels: β_c w1
    p0_2: np.ndarray  # m: β_2 w0 (ID2 motor torque)
    p1_2: np.ndarray
    W: np.ndarray  # channels x m: [H; slope row] Δq̇ = Re(W ζ) (4 contacts + ID2's slope torque)
    D1: np.ndarray  # channels x channels: Re(W P1)
    lam: np.ndarray  # kept eigenvalues [1/s]
    modal_to_state: np.ndarray  # N x m: x = Re(X ζ) (rigid angles left out)


def _setup(model: BogieModel, op: OperatingPoint, h: float, system: LinearSystem) -> _Setup:
    """The modal pieces of the stepping at step ``h`` [s] (:class:`_Setup`) of ``system`` (the
    bogie, :func:`bogie_system`, or the running system, :func:`running_system`), built once per
    (model, operating point, h) and kept in the cached system."""
    key = ("nonlinear_setup", h)
    cached = system._cache.get(key)
    if cached is not None:
        return cached
    lam, Y, _, _, scale = system.modal
    deflation = system.deflation
    r = system.rigid_count
    keep = lam.imag >= 0
    weight = np.where(lam.imag > 0, 2.0, 1.0)[keep]
    G = creep_force_map(model)
    f_m2 = motor2_force(model)
    # inputs: M_C, ΔM_2, the creep remainders, ID2's motor torque again (the channel through
    # which the protection scales the motor's slope torque b_M Δω)
    inputs = system.input_map(np.column_stack([model.short_circuit_force, f_m2, G, f_m2]))
    rhs = deflation.to_deflated(inputs)[r:] / scale[:, None]
    beta = system.solve_eigenvectors(rhs)[keep]  # m x (2 + contacts)
    lam_k = lam[keep]
    E = np.exp(lam_k * h)
    phi1, phi2 = hold_weights(lam_k * h)
    w1 = h * phi2
    w0 = h * phi1 - w1
    # modal state -> full state (rigid angles left out: loads and velocities do not see them)
    Xc = deflation.apply(np.vstack([np.zeros((r, keep.sum())), (Y[:, keep] * scale[:, None])]))
    X = Xc * weight[None, :]
    H = creep_velocity_map(model)
    rotor2 = model.dofs.index("ID2.rotor.ry")
    slope_row = op.b_M * model.motor_pattern[rotor2]  # ID2's slope torque change = row · Δq̇
    W = np.vstack([H, slope_row]) @ (system.velocity_map @ X)
    P1 = beta[:, 2:] * w1[:, None]
    setup = _Setup(E=E, w0=w0, w1=w1, beta_mc=beta[:, 0], P0=beta[:, 2:] * w0[:, None], P1=P1,
                   p0_2=beta[:, 1] * w0, p1_2=beta[:, 1] * w1, W=np.ascontiguousarray(W),
                   D1=np.ascontiguousarray((W @ P1).real), lam=lam_k, modal_to_state=X)
    with system._lock:
        system._cache[key] = setup
    return setup


def motor2_force(model: BogieModel) -> np.ndarray:
    """Generalized force of a unit driving torque of ID2's motor (rotor −ry, stator +ry)."""
    f = np.zeros(model.n)
    f[model.dofs.index("ID2.rotor.ry")] = -1.0
    f[model.dofs.index("ID2.stator.ry")] = 1.0
    return f


def nonlinear_response(model: BogieModel, op: OperatingPoint,
                       excitation: ShortCircuit | None = None, t_end: float = 2.0,
                       fs: float = 10_000.0, creep: str = "nonlinear",
                       anti_slip: AntiSlip | None = None, outputs: list[str] | None = None,
                       strength: float | None = None, keep_states: bool = False,
                       substeps: int = 1, excitation_scale: float = 1.0,
                       checkpoint: Callable[[], None] | None = None,
                       irregularity: IrregularityHistory | None = None) -> NonlinearResult:
    """Time histories after the short circuit of ID1's motor with nonlinear longitudinal creep.

    ``creep``: "nonlinear" (the law) or "tangent" (its tangent at s0, through the same loop);
    ``anti_slip``: None or disabled = no protection; ``outputs``: names of
    :func:`model.mechanics.outputs.output_matrices` (default all); ``strength`` [N m]: a design strength
    reported as limit "strength" for the disc clutch, claw clutch and (referred by p) driving
    shaft torques; ``substeps``: integration steps per output sample (step h = 1/(fs·substeps));
    ``keep_states``: also return the states [Δq; Δq̇_inertial] at the samples (memory samples x N,
    N states: :class:`model.analysis.linear_system.LinearSystem`);
    ``excitation_scale``: M_C(t) (step and oscillation) multiplied by this factor (checks of the
    small-amplitude limit; the result's ``M_C`` is the scaled torque);
    ``checkpoint``: called between blocks of BLOCK_STEPS integration steps; whatever it raises
    ends the run and reaches the caller (a caller's cancellation: an interactive session that no
    longer wants the result stops it within one block, not at the end of the run);
    ``irregularity``: the four wheels' rail–wheel surface deviations Δ_j(t) [m]
    (:class:`IrregularityHistory`): the running system is the linear part, the creep forces
    follow the varying wheel forces (T_j = N_j μ(s_j)) and the result reports N_j
    (``wheel_force`` [N]); None: N = N0 throughout (module docstring).

    Example::

        >>> from model import (AntiSlip, build_model, default_operating_point, load_parameters,
        ...                    nonlinear_response)
        >>> parameters = load_parameters()
        >>> model = build_model(parameters)
        >>> r = nonlinear_response(model, default_operating_point(parameters, s0=0.014), t_end=0.5,
        ...                        fs=5000.0, anti_slip=AntiSlip(enabled=True, delay=0.1))
        >>> bool(abs(r.peaks["ID2.disc_clutch.torque"]) < 2 * r.limits["M_ad"])   # bounded
        True
    """
    excitation = ShortCircuit() if excitation is None else excitation
    request = _check_inputs(model, op, t_end, fs, creep, anti_slip, outputs, strength, keep_states,
                            substeps, excitation_scale, irregularity)
    run = _set_up_run(model, op, excitation, request)
    histories = _step(run, request, checkpoint)
    return _pack_result(model, op, excitation, request, run, histories)


@dataclass(frozen=True)
class _Request:
    """The checked arguments of one :func:`nonlinear_response` call and the time grid."""

    creep: str  # "nonlinear" or "tangent"
    protection: AntiSlip | None  # the anti-slip protection, None if absent or disabled
    strength: float | None  # design strength of the clutches [N m], if given
    keep_states: bool  # also return the states at the samples
    excitation_scale: float  # factor on M_C(t) [-]
    names: list[str]  # the outputs asked for, in order
    matrices: OutputMatrices  # the output map at the operating point
    fs: float  # sampling rate of the outputs [Hz]
    substeps: int  # integration steps per output sample
    n_points: int  # output samples (t = 0 included)
    n_steps: int  # integration steps
    h: float  # integration step [s]
    irregularity: IrregularityHistory | None = None  # the rail–wheel deviations, if any


def _check_inputs(model: BogieModel, op: OperatingPoint, t_end: float, fs: float, creep: str,
                  anti_slip: AntiSlip | None, outputs: list[str] | None, strength: float | None,
                  keep_states: bool, substeps: int, excitation_scale: float,
                  irregularity: IrregularityHistory | None = None) -> _Request:
    """The arguments of :func:`nonlinear_response` checked (:class:`NonlinearError` with a one-line
    message otherwise) and the time grid: ``t_end`` [s], ``fs`` [Hz], ``strength`` [N m]."""
    if creep not in CREEP_MODELS:
        raise NonlinearError(f"creep model '{creep}' is not allowed: nonlinear or tangent")
    if anti_slip is not None and not isinstance(anti_slip, AntiSlip):
        raise NonlinearError("anti_slip must be an AntiSlip or None")
    if strength is not None and (isinstance(strength, bool) or not isinstance(strength, int | float)
                                 or not math.isfinite(strength) or strength <= 0):
        raise NonlinearError(f"strength = {strength!r} is not allowed: must be a positive number "
                             "[N m]")
    if isinstance(substeps, bool) or not isinstance(substeps, int) or not 1 <= substeps <= 64:
        raise NonlinearError(f"substeps = {substeps!r} is not allowed: a whole number 1…64")
    n_points = time_grid_points(t_end, fs, NonlinearError)
    n_steps = (n_points - 1) * substeps
    if n_steps + 1 > 4 * MAX_POINTS:
        raise NonlinearError("t_end × fs × substeps is too many steps")
    matrices = output_matrices(model, op)
    names = list(matrices.names) if outputs is None else list(outputs)
    if not names:
        raise NonlinearError("no outputs requested")
    for name in names:
        if name not in matrices.names:
            raise NonlinearError(f"unknown output '{name}': use an output name "
                                 f"({', '.join(matrices.names[:3])}, …)")
    if isinstance(excitation_scale, bool) or not isinstance(excitation_scale, int | float) \
            or not math.isfinite(excitation_scale):
        raise NonlinearError(f"excitation_scale = {excitation_scale!r} must be a finite number")
    protection = anti_slip if anti_slip is not None and anti_slip.enabled else None
    h = 1.0 / (fs * substeps)
    _check_irregularity(model, irregularity, (n_points - 1) / fs, h)
    return _Request(creep=creep, protection=protection, strength=strength, keep_states=keep_states,
                    excitation_scale=excitation_scale, names=names, matrices=matrices, fs=fs,
                    substeps=substeps, n_points=n_points, n_steps=n_steps,
                    h=h, irregularity=irregularity)


STEPS_PER_PERIOD = 20  # a harmonic irregularity needs at least this many steps per period


def _check_irregularity(model: BogieModel, irregularity: IrregularityHistory | None,
                        t_end: float, h: float) -> None:
    """An irregularity history fits the run: its inputs are the model's
    (:func:`irregularity_inputs`), a sampled one covers 0 … ``t_end`` [s], a harmonic one's
    frequencies leave :data:`STEPS_PER_PERIOD` steps ``h`` [s] per period (the creep remainder
    is held over a step)."""
    if irregularity is None:
        return
    if not isinstance(irregularity, IrregularityHistory):
        raise NonlinearError("irregularity must be an IrregularityHistory or None")
    if tuple(irregularity.names) != irregularity_inputs(model):
        raise NonlinearError(f"irregularity inputs {', '.join(irregularity.names)} are not the "
                             f"model's: {', '.join(irregularity_inputs(model))}")
    start, end = irregularity.span
    if start > 0.0 or end < t_end * (1 - 1e-12):
        raise NonlinearError(f"the irregularity history covers {start:g} … {end:g} s, not the run's "
                             f"0 … {t_end:g} s")
    if irregularity.is_harmonic:
        f_max = float(irregularity.frequency.max())
        if f_max * STEPS_PER_PERIOD * h > 1.0:
            raise NonlinearError(f"irregularity frequency {f_max:g} Hz is too high for the step "
                                 f"{h:g} s: at most {1.0 / (STEPS_PER_PERIOD * h):g} Hz (raise fs "
                                 "or substeps)")


@dataclass(frozen=True)
class _Run:
    """The set-up of one run: what the step loop takes and the post-processing needs."""

    inputs: StepInputs  # everything fixed over the step loop (block_stepper.StepInputs)
    law: PolachLaw  # the creep law at N0
    rims: list[str]  # contact names, in the order of the creep channels
    loads: list[str]  # the requested outputs formed in the loop (y = Re(V ζ)), in V's row order
    system: LinearSystem  # the linear part: the bogie, or with irregularities the running system
    irregularity: IrregularityLoop | None = None  # the irregularities' part of the loop


def _excitation_increments(setup: _Setup, excitation: ShortCircuit, step: float, scale: float,
                           h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, complex]:
    """Exact modal increments per step of M_C(t) (a step and a damped complex exponential, times
    ``scale``): (M_C's step part [modal units per step], the exponential's and its conjugate's
    weights, e^(μh)); ``step`` = M(s0, v) [N m], ``h`` [s]."""
    u0, a, mu = excitation.terms(step)
    u0, a = u0 * scale, a * scale
    lam = setup.lam
    phi1_step, _ = hold_weights(lam * h)
    inc_step = setup.beta_mc * u0 * h * phi1_step
    if excitation.M0 > 0 and scale != 0:
        phi_p, _ = hold_weights((mu - lam) * h)
        phi_m, _ = hold_weights((np.conj(mu) - lam) * h)
        cp = setup.beta_mc * 0.5 * a * setup.E * h * phi_p
        cm = setup.beta_mc * 0.5 * np.conj(a) * setup.E * h * phi_m
    else:
        cp = cm = np.zeros_like(lam)
    return inc_step, cp, cm, complex(np.exp(mu * h))


def _output_map(request: _Request, setup: _Setup,
                system: LinearSystem) -> tuple[list[str], np.ndarray]:
    """The requested outputs the loop forms (all but the creep forces and adhesion moments, which
    come from the contact velocities) and V (rows x m) with y = Re(V ζ) [their units]; with
    ``keep_states`` V also holds the states x = Re(X ζ) below them."""
    matrices = request.matrices
    loads = [name for name in request.names
             if not name.endswith(("creep_force", "adhesion_moment"))]
    rows = [matrices.index(nm) for nm in loads]
    C = system.state_output(matrices.C_q[rows], matrices.C_v[rows]).reshape(len(loads), system.N)
    V = C @ setup.modal_to_state  # loads x m
    if request.keep_states:  # the states x = Re(X ζ) as further outputs of the loop
        V = np.vstack([V, setup.modal_to_state])
    return loads, V


def _set_up_run(model: BogieModel, op: OperatingPoint, excitation: ShortCircuit,
                request: _Request) -> _Run:
    """The run's step-loop inputs (modal increments of the excitation, creep law, anti-slip
    settings, output map, the stepper's block matrices) from the cached per-step set-up."""
    h = request.h
    system = bogie_system(model, op) if request.irregularity is None else running_system(model, op)
    setup = _setup(model, op, h, system)
    p = model.parameters
    law = creep_law(p, op.N0)
    coefficients = creep_coefficients(p, op)
    step = motor_torque(p, op)
    inc_step, cp, cm, g_step = _excitation_increments(setup, excitation, step,
                                                      request.excitation_scale, h)
    rims = contact_names(model)
    # channels: the four contacts, then ID2's slope torque (not a detection signal)
    detect_rows = np.array([0.5 if rim.startswith("ID2.") else 0.0 for rim in rims] + [0.0])
    protection = request.protection
    loads, V = _output_map(request, setup, system)
    loop = wheel = None
    if request.irregularity is not None:
        scale = request.excitation_scale
        loop = irregularity_loop(
            model, op, system, request.irregularity, h, setup.modal_to_state, setup.E,
            np.column_stack([creep_force_map(model), motor2_force(model)]),
            model.short_circuit_force, lambda t: excitation.torque(t, step) * scale)
        wheel = (loop.W, loop.D)
    inputs = StepInputs(
        h=h, E=setup.E, inc_step=inc_step, cp=cp, cm=cm, g_step=g_step, g0=complex(1.0),
        P0=setup.P0, p0_2=setup.p0_2, p1_2=setup.p1_2, contact_scale=max(op.s0 * op.v, 1e-3),
        law_params=np.array([law.mu0, law.A, law.B, law.kA, law.kS, law.slope]), s0=op.s0,
        v=op.v, N0=op.N0, mu_s0=coefficients.mu, dmu_s0=coefficients.dmu_ds,
        tangent=request.creep == "tangent", detect_rows=detect_rows,
        threshold=protection.threshold if protection else math.inf, M_step=step,
        delay=protection.delay if protection else 0.0,
        rate=protection.rate if protection else 1.0,
        floor=protection.floor if protection else 0.0,
        blocks=step_matrices(setup.W, setup.E, setup.P0, setup.P1, setup.D1, V, len(rims), wheel),
        irregularity=loop)
    return _Run(inputs=inputs, law=law, rims=rims, loads=loads, system=system, irregularity=loop)


@dataclass(frozen=True)
class _Histories:
    """What the step loop leaves at the output samples (samples x …)."""

    Y: np.ndarray  # samples x rows of V: the loads' perturbations Δy [units] (then the states)
    z: np.ndarray  # samples x channels: contact velocities H Δq̇ [m/s], ID2's slope torque [N m]
    r: np.ndarray  # samples x channels: remainder forces [N], the protection's cut of the slope
    # torque [N m]
    u2: np.ndarray  # samples: ΔM_2, the reduction of ID2's motor torque M(s0, v) [N m]
    detection: float | None  # when the protection detected the slip [s] (None: never)
    iterations: int  # Newton iterations summed over the steps
    wheel: np.ndarray | None = None  # samples x contacts: wheel-force changes ΔN [N]
    # (irregularities only)


def _step(run: _Run, request: _Request, checkpoint: Callable[[], None] | None) -> _Histories:
    """Step the run from the pre-fault state to the end, block by block of ≈ BLOCK_STEPS steps
    (:func:`model.analysis.block_stepper.march`), and keep every ``substeps``-th step;
    ``checkpoint`` is called before each block."""
    inputs = run.inputs
    n_points, n_steps, substeps, h = request.n_points, request.n_steps, request.substeps, request.h
    m = len(inputs.E)
    nc = len(run.rims) + 1
    zeta = np.zeros(m, dtype=complex)
    phi = np.zeros(nc)
    z = np.zeros(nc)
    det_state = np.array([-1.0])
    iterations = np.zeros(1, dtype=np.int64)
    rows = inputs.blocks.rows_out
    Y = np.empty((n_points, rows))
    Y[0] = 0.0
    z_hist = np.zeros((n_points, nc))
    r_hist = np.zeros((n_points, nc))
    u2_hist = np.zeros(n_points)
    block = BLOCK_STEPS - BLOCK_STEPS % substeps
    Y_out = np.empty((block, rows))
    z_out = np.empty((block, nc))
    phi_out = np.empty((block, nc))
    u2_out = np.empty(block)
    wheel_hist = wheel_out = None
    if run.irregularity is not None:  # ΔN at t = 0 (Δq = 0): the deviations' own terms
        wheel_hist = np.zeros((n_points, len(run.rims)))
        wheel_hist[0] = run.irregularity.at(np.zeros(1))[0]
        wheel_out = np.empty((block, len(run.rims)))
    u2_now = 0.0
    k = 0
    while k < n_steps:
        if checkpoint is not None:
            checkpoint()
        k1 = min(n_steps, k + block)
        status = march(k, k1, inputs, zeta, phi, z, u2_now, det_state, Y_out, z_out, phi_out,
                       u2_out, iterations, wheel_out)
        if status < 0:
            raise NonlinearError(f"the creep-force iteration did not converge at t = "
                                 f"{-status * h:.6g} s")
        sel = np.arange(substeps - 1, k1 - k, substeps)  # block rows that are samples
        samples = (k + sel + 1) // substeps
        u2_now = float(u2_out[k1 - k - 1])
        Y[samples] = Y_out[sel]
        z_hist[samples] = z_out[sel]
        r_hist[samples] = phi_out[sel]
        u2_hist[samples] = u2_out[sel]
        if wheel_out is not None:
            _check_contact(wheel_out[:k1 - k], inputs.N0, run.rims, k, h)
            wheel_hist[samples] = wheel_out[sel]
        k = k1
    detection = float(det_state[0]) if det_state[0] >= 0 else None
    return _Histories(Y=Y, z=z_hist, r=r_hist, u2=u2_hist, detection=detection,
                      iterations=int(iterations[0]), wheel=wheel_hist)


def _check_contact(wheel: np.ndarray, N0: float, rims: list[str], k: int, h: float) -> None:
    """Every wheel force N0 + ΔN of a block's steps (steps k+1 …, step h [s]) stays positive: the
    track's spring is linear and T = N μ has no meaning once a wheel would pull on the rail, so
    a run in which a wheel lifts ends with a one-line :class:`NonlinearError`."""
    lowest = np.unravel_index(int(np.argmin(wheel)), wheel.shape)
    if N0 + wheel[lowest] <= 0.0:
        raise NonlinearError(f"the wheel force of {rims[lowest[1]]} falls to "
                             f"{N0 + wheel[lowest]:.4g} N at t = {(k + lowest[0] + 1) * h:.6g} s: "
                             "a wheel lifting off the rail is not modelled")


def _with_free_velocity(system: LinearSystem, forces: np.ndarray, states: np.ndarray,
                        inputs: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The sampled states (samples x N, the modal part the loop forms) with the vehicle's rolling
    velocity added: no damping meets it, so it is deflated with the rigid-body modes and the loop
    does not carry it, but it holds kinetic energy.  Its rate is the deflated row of
    ``A x + b u`` (it depends on the other states and the inputs only), integrated by the
    trapezoidal rule over the samples [s] (second order in 1/fs).  ``inputs``: M_C, ID2's motor
    torque change and the contacts' remainder forces (samples x 2 + contacts) [N m, N], with
    irregularities also their (Δ, Δ̇, Δ̈) [m, m/s, m/s²]; ``forces``: their generalized forces
    (n x inputs); ``system``: the run's linear part."""
    deflation = system.deflation
    rates = deflation.to_deflated(system.A @ states.T + system.input_map(forces) @ inputs.T)
    free = np.arange(system.R.shape[1], system.rigid_count)
    velocity = np.zeros((len(t), len(free)))
    velocity[1:] = np.cumsum(0.5 * (rates[free, 1:] + rates[free, :-1]).T * np.diff(t)[:, None],
                             axis=0)
    shape = np.zeros((system.N, len(free)))
    shape[free, np.arange(len(free))] = 1.0
    return states + velocity @ deflation.apply(shape).T


def _limits(p: Parameters, op: OperatingPoint, mu_max: float,
            strength: float | None) -> tuple[dict[str, float], list[tuple[str, str]]]:
    """The limits the totals are checked against ("M_ad", "M_ad/p" [N m], "mu_max N0" [N], and
    "strength", "strength/p" [N m] if given) and the (output suffix, limit) pairs to check."""
    M_ad = adhesion_moment(p, op.v, op.N0)
    limits = {"M_ad": M_ad, "M_ad/p": M_ad / p["gear_ratio"], "mu_max N0": float(mu_max) * op.N0}
    checks = list(LIMITED)
    if strength is not None:
        limits["strength"] = float(strength)
        limits["strength/p"] = float(strength) / p["gear_ratio"]
        checks += [("disc_clutch.torque", "strength"), ("claw_clutch.torque", "strength"),
                   ("driving_shaft.torque", "strength/p")]
    return limits, checks


def _totals(model: BogieModel, op: OperatingPoint, request: _Request, run: _Run, Y: np.ndarray,
            creep_total: np.ndarray, wheel_force: np.ndarray | None = None
            ) -> tuple[dict[str, np.ndarray], dict[str, str], dict[str, float]]:
    """The requested outputs as totals (pre-fault value + Δy; the creep forces N μ [N] and the
    wheelsets' adhesion moments r0 Σ N μ [N m] from ``creep_total``, samples x contacts: μ [-],
    with N = ``wheel_force`` (samples x contacts) [N] or N0), in the requested order, with their
    units and pre-fault values."""
    matrices, names, rims = request.matrices, request.names, run.rims
    totals, units, steady = {}, {}, {}
    for j, name in enumerate(run.loads):
        i = matrices.index(name)
        totals[name] = Y[:, j] + matrices.steady[i]
    forces = (op.N0 if wheel_force is None else wheel_force) * creep_total  # totals [N]
    r0 = model.parameters["wheel_radius"]
    for i, rim in enumerate(rims):
        totals_name = f"{rim}.creep_force"
        if totals_name in names:
            totals[totals_name] = forces[:, i]
    for drive in DRIVES:
        name = f"{drive}.wheelset.adhesion_moment"
        if name in names:
            columns = [rims.index(f"{drive}.rim{k}") for k in RIM_NODES]
            totals[name] = r0 * forces[:, columns].sum(axis=1)
    outputs_total = {name: totals[name] for name in names}
    for name in names:
        i = matrices.index(name)
        units[name], steady[name] = matrices.units[i], float(matrices.steady[i])
    return outputs_total, units, steady


def _pack_result(model: BogieModel, op: OperatingPoint, excitation: ShortCircuit,
                 request: _Request, run: _Run, histories: _Histories) -> NonlinearResult:
    """The result from the sampled histories: totals (pre-fault value + Δy) of the loads, creep
    forces [N] and adhesion moments [N m] from the law, motor torques [N m], creepages [-], slip
    velocities [m/s], utilisations [-], peaks and limit crossings."""
    p = model.parameters
    law, rims = run.law, run.rims
    inputs = run.inputs
    mu_s0, dmu_s0, step = inputs.mu_s0, inputs.dmu_s0, inputs.M_step
    Y, z_hist, r_hist, u2_hist = histories.Y, histories.z, histories.r, histories.u2
    t = np.arange(request.n_points) / request.fs
    X_hist = None
    if request.keep_states:
        inputs_hist = np.column_stack([excitation.torque(t, inputs.M_step)
                                       * request.excitation_scale,
                                       u2_hist + r_hist[:, -1], r_hist[:, :-1]])
        forces = np.column_stack([model.short_circuit_force, motor2_force(model),
                                  creep_force_map(model)])
        if run.irregularity is not None:
            forces = np.column_stack([forces, force_columns(model, op)])
            inputs_hist = np.column_stack([inputs_hist, run.irregularity.inputs(t)])
        X_hist = _with_free_velocity(run.system, forces, Y[:, len(run.loads):], inputs_hist, t)
    if not np.all(np.isfinite(Y)) or not np.all(np.isfinite(z_hist)):
        raise NonlinearError("the nonlinear response is not finite")
    slope_torque, slope_cut = z_hist[:, -1], r_hist[:, -1]
    z_hist, r_hist = z_hist[:, :-1], r_hist[:, :-1]
    creep_total = np.asarray(law.mu(op.s0 + z_hist / op.v, op.v)) if request.creep == "nonlinear" \
        else mu_s0 + dmu_s0 * z_hist / op.v
    _, mu_max = law.maximum(op.v)
    wheel = None if histories.wheel is None else op.N0 + histories.wheel  # N_j [N]
    outputs_total, units, steady = _totals(model, op, request, run, Y, creep_total, wheel)
    M_C = excitation.torque(t, step) * request.excitation_scale
    motor = {"ID1.motor.torque": step + M_C,
             "ID2.motor.torque": step + slope_torque + u2_hist + slope_cut}
    creepage = {rim: op.s0 + z_hist[:, i] / op.v for i, rim in enumerate(rims)}
    slip = {rim: creepage[rim] * op.v for rim in rims}
    utilisation = {rim: creep_total[:, i] / mu_max for i, rim in enumerate(rims)}
    limits, checks = _limits(p, op, mu_max, request.strength)
    found = history_peaks_and_crossings(t, outputs_total, steady, limits, checks)
    detection = histories.detection
    return NonlinearResult(
        t=t, outputs=outputs_total, units=units, steady=steady, M_C=M_C, motor_torques=motor,
        creepage=creepage, slip_velocity=slip, utilisation=utilisation, peaks=found.peaks,
        peak_times=found.peak_times, perturbation_peaks=found.perturbation_peaks,
        perturbation_peak_times=found.perturbation_peak_times,
        limit_crossings=found.limit_crossings,
        limits=limits, operating_point=op, excitation=excitation, creep_model=request.creep,
        anti_slip=request.protection, detection_time=detection,
        action_time=None if detection is None else detection + inputs.delay, motor_torque=step,
        mu_max=float(mu_max), newton_iterations=float(histories.iterations) / max(request.n_steps, 1),
        torque_reduction=u2_hist + slope_cut,
        contact_velocity=z_hist, remainder_force=r_hist, states=X_hist,
        irregularity=request.irregularity,
        wheel_force=None if wheel is None else {rim: wheel[:, i] for i, rim in enumerate(rims)})
