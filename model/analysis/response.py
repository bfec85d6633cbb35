"""Short-circuit response of the bogie (spec §4): exact closed-form time histories of the loads.

API (stable; used by the dashboard)::

    from model.analysis.response import ShortCircuit, short_circuit_response
    result = short_circuit_response(model, op, ShortCircuit(), t_end=2.0, fs=10_000.0)
    result.t                                  # time points [s], uniform, t[0] = 0
    result.outputs["ID1.disc_clutch.torque"]  # TOTAL value (pre-fault steady + perturbation) [N m]
    result.perturbation("ID1.disc_clutch.torque")
    result.M_C                                # short-circuit torque M_C(t) [N m] (eq. 23)
    result.peaks, result.peak_times, result.dominant_frequencies, result.limit_crossings

``short_circuit_response(model, op, excitation, t_end, fs, outputs=None, method="auto")``

* ``outputs``: names from :func:`model.mechanics.outputs.output_matrices` (default: all of them) and/or
  generalized coordinates by DOF name (e.g. ``"ID1.rotor.ry"``).
* Every output is reported as a **total**: the pre-fault static value (``result.steady``: the
  loads of :class:`model.mechanics.outputs.OutputMatrices` ``.steady``; for a DOF its static deflection
  under traction) plus the perturbation Δy(t) of the linear system.  The limit checks (M_ad)
  use the totals; ``result.perturbation(name)`` gives Δy.
* ``peaks[name]`` is the signed total value of largest magnitude, ``peak_times[name]`` its time
  [s]; ``dominant_frequencies[name]`` the strongest spectral peaks of Δy [Hz], strongest first.

The excitation (eq. 23), on ID1's rotor with the reaction on ID1's stator::

    M_C(t) = −M(s0, v) H(t) − M0 e^(−D ω t) sin[ω (t − Δt)],   ω = 2π f

Method.  The system ``M Δq̈ + B_total Δq̇ + K Δq = f_mc M_C(t)`` is LTI and M_C is a step plus a
damped complex exponential ``Re(a e^(μt))``, ``μ = −Dω + iω``.  Two exact evaluations:

* ``"modal"``: particular solutions in closed form — for the step ``α + β t`` (the rigid spins
  of the drivetrains, ``K r = 0``, take a constant velocity ``R c`` with ``Rᵀ B R c = Rᵀ f u0``:
  the drift of the spin angles is a ramp), for the exponential ``(μ²M + μB + K)⁻¹ f a e^(μt)`` —
  plus the homogeneous solution ``e^(At) x_h(0)`` in the eigenbasis of A with the rigid-body
  subspace deflated exactly (as in :mod:`model.analysis.eigen`).  Outputs are projected onto the modes
  before any time loop.
* ``"expm"``: the state augmented by the generator of M_C (``w = [1, e^(−σt)cos ωt,
  e^(−σt)sin ωt]``), ``Φ = expm(F Δt)`` and ``y_k = C Φ^k z0`` evaluated in blocks
  (``C Φ^(am) · [Φ^b z0]``), exact on the uniform grid for any eigenstructure: repeated or
  defective eigenvalues, the stability limit, the rigid-body zero eigenvalues, resonance of the
  excitation with a mode.
* ``"auto"`` (default) uses the modal form unless its rounding-error estimate (eigenvector
  condition × size of the cancelling terms) exceeds 1e-8 of the response, then ``"expm"``.

The eigendecomposition is cached per (model, operating point), so changing the excitation, the
horizon or the sampling is cheap.  Growth (unstable cases) never overflows: if a response would
exceed 1e250 the time grid is cut there and ``truncated_at`` says when.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.fft
import scipy.linalg as sla

from model.analysis.eigen import bogie_system
from model.analysis.linear_system import LinearSystem
from model.analysis.load_peaks import (  # noqa: F401 (re-export)
    GROWTH_RATE,
    LIMITED,
    LimitCrossing,
    LoadPeaks,
    history_peaks_and_crossings,
    load_peaks,
)
from model.mechanics.assembly import BogieModel
from model.mechanics.operating_point import (
    OperatingPoint,
    adhesion_moment,
    creep_law,
    motor_torque,
)
from model.mechanics.outputs import output_matrices, static_deflection

EPS = np.finfo(float).eps
HUGE_LOG = math.log(1e250)  # beyond this the time grid is truncated (no overflow, no NaN)
# Largest accepted rounding-error estimate of the modal form (relative).  The estimate detects
# ill-conditioning, it is not a bound: near the stability limit (a real eigenvalue through zero,
# the step's particular solution and one mode cancel) the measured error was 24-150x the estimate,
# elsewhere errors of 2e-7 to 1e-6 (two near-degenerate 73 Hz pairs of the two drives) sit far
# above estimates of ~1e-11.  With 1e-8 the modal form is used everywhere except within a relative
# 2e-5 of s0*, and its measured error stayed below 1.4e-6 (docs/response.md, scan around s0*).
AUTO_TOLERANCE = 1e-8
WINDOW_TOLERANCE = 1e-13  # a decayed mode's terms below this x the largest term are not evaluated
MAX_POINTS = 2_000_001  # time points per response
MAX_T_END = 60.0  # [s]
# The quasi-static part of a response: the static response and the modes that do not oscillate
# or oscillate slower than this (|Im λ| / 2π), not completing a cycle in the study's 2 s window.
# The bogie's slow modes (creep-damped drifts of the wheelsets and the frame) lie well below its
# lowest structural mode (the car body's bounce): no mode between 0.6 and 2 times this at stable points
# (tests/model/analysis/test_response_model.py::test_no_mode_near_the_quasi_static_cutoff).
QUASI_STATIC_HZ = 0.5
# the split is given when the modal form's rounding-error estimate of the quasi-static part stays
# below this (relative; the estimate is not a bound, measured errors were up to 150x it): 3 digits
QUASI_STATIC_TOLERANCE = 1e-6


class ResponseError(ValueError):
    """Bad input for a response computation (one-line message)."""


# --- excitation ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class ShortCircuit:
    """Oscillating part of the short-circuit torque (eq. 23); the step −M(s0, v) comes from the
    operating point.

    Defaults (not published; chosen and argued in docs/response.md):

    * ``M0 = 50 000 N m``: the peak torque of a terminal short circuit of an asynchronous motor
      is several times its rated torque; 50 kN m is ≈ 4× the published pre-fault torque
      M(s0, v) = 12 800 N m.
    * ``f = 90 Hz`` (published).
    * ``D = 0.04``: decay rate D ω = 22.6 1/s, so e^(−Dω·0.2 s) = 1.1 %: the oscillating part
      has died out after about 0.2 s, as the published figure describes.
    * ``dt = None``: Δt chosen so that the total motor torque is continuous at the fault,
      M(s0, v) + M_C(0+) = M(s0, v), i.e. sin(ω Δt) = M(s0, v)/M0 (the flux linkages of the
      machine cannot jump); ω Δt = π/2 if M(s0, v) > M0.  Give a number [s] to override.
    """

    M0: float = 50_000.0  # amplitude of the oscillating part [N m], ≥ 0
    f: float = 90.0  # its frequency [Hz], > 0
    D: float = 0.04  # decay: the envelope is e^(−D·2πf·t) [-], ≥ 0
    dt: float | None = None  # time shift Δt [s]; None: continuous motor torque at t = 0

    def __post_init__(self) -> None:
        checks = (("M0 (amplitude, N m)", self.M0, 0.0, 1e8, "in [0, 1e8] N m"),
                  ("f (frequency, Hz)", self.f, 1e-3, 1e5, "in [0.001, 1e5] Hz"),
                  ("D (decay)", self.D, 0.0, 10.0, "in [0, 10]"))
        for label, value, low, high, allowed in checks:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ResponseError(f"{label} must be a number, got {value!r}")
            if not math.isfinite(value) or not low <= value <= high:
                raise ResponseError(f"{label} = {value} is not allowed: must be {allowed}")
        if self.dt is not None:
            if isinstance(self.dt, bool) or not isinstance(self.dt, int | float) \
                    or not math.isfinite(self.dt) or abs(self.dt) > 10.0:
                raise ResponseError(f"dt (phase shift, s) = {self.dt!r} is not allowed: must be "
                                    "a number in [-10, 10] s")

    @property
    def omega(self) -> float:
        """ω = 2π f [rad/s]."""
        return 2 * math.pi * self.f

    def shift(self, step: float) -> float:
        """Δt [s] actually used, given the pre-fault motor torque ``step`` = M(s0, v) [N m]."""
        if self.dt is not None:
            return float(self.dt)
        if self.M0 == 0.0:
            return 0.0
        return math.asin(min(1.0, abs(step) / self.M0)) * math.copysign(1.0, step) / self.omega

    def terms(self, step: float) -> tuple[float, complex, complex]:
        """M_C(t) = u0 + Re(a e^(μ t)) for t > 0: returns (u0 [N m], a [N m], μ [1/s])."""
        phase = self.omega * self.shift(step)
        # −M0 e^(−σt) sin(ωt − φ) = Re(i M0 e^(−iφ) e^((−σ + iω) t))
        return -step, 1j * self.M0 * np.exp(-1j * phase), complex(-self.D * self.omega,
                                                                  self.omega)

    def torque(self, t: np.ndarray, step: float) -> np.ndarray:
        """M_C(t) [N m] at times ``t`` [s] (zero before the fault, t < 0)."""
        t = np.asarray(t, dtype=float)
        u0, a, mu = self.terms(step)
        value = u0 + (a * np.exp(mu * np.clip(t, 0.0, None))).real
        return np.where(t >= 0.0, value, 0.0)


# --- exact LTI core ------------------------------------------------------------------------------

def _grid_exponentials(lam: np.ndarray, n_points: int, dt: float, block: int):
    """exp(λ t) on t = k dt as E_block (block x r), E_outer (n_blocks x r): t = (a·block + b) dt."""
    b = np.arange(block) * dt
    a = np.arange(-(-n_points // block)) * (block * dt)
    return np.exp(np.outer(b, lam)), np.exp(np.outer(a, lam))


@dataclass(frozen=True)
class _ModalTerms:
    """The modal closed form's pieces for the outputs C: the perturbation outputs are
    ``y(t) = Re Σ_j coef_j e^(λ_j t) + const_h + lin_h t + C (α + β t + γ t²)
    + Re(C x_μ e^(μt))`` (coef p x m over every eigenvalue of the deflated system)."""

    lam: np.ndarray  # m eigenvalues of the deflated system [1/s]
    coef: np.ndarray  # p x m
    const_h: np.ndarray  # p: the rigid coordinates' part of the homogeneous solution, constant
    lin_h: np.ndarray  # p: … and its ramp (a free mode's velocity moving its position) [1/s]
    alpha: np.ndarray  # N: the step's particular solution α + β t + γ t²
    beta: np.ndarray
    gamma: np.ndarray
    x_mu: np.ndarray  # N: the exponential input's particular solution


def _modal_terms(system: LinearSystem, C: np.ndarray, u0: float, a: complex,
                 mu: complex) -> _ModalTerms:
    """The modal closed form's pieces for the outputs ``C`` (:class:`_ModalTerms`).  The last
    ones of each system are kept: a response, its quasi-static part and its peaks' split ask
    for the same pieces."""
    return system.last("modal terms", (C.shape, C.tobytes(), float(u0), complex(a), complex(mu)),
                       lambda: _modal_terms_of(system, C, u0, a, mu))


def _modal_terms_of(system: LinearSystem, C: np.ndarray, u0: float, a: complex,
                    mu: complex) -> _ModalTerms:
    deflation, r = system.deflation, system.rigid_count
    lam, Y, _, _, scale = system.modal  # A22 = (T Y) Λ (T Y)⁻¹, T = diag(scale)
    alpha, beta, gamma = system.step_particular(u0)
    x_mu = system.exponential_particular(a, mu)
    xh0 = -(alpha + x_mu.real)
    z0 = deflation.to_deflated(xh0)  # W⁻¹ x_h(0)
    a0, c0 = z0[:r], z0[r:]
    d = system.solve_eigenvectors(c0 / scale)
    CQ = deflation.rows(C)  # C W
    CQ1 = CQ[:, :r]
    W = (CQ[:, r:] * scale) @ Y  # p x m
    const_h = np.zeros(C.shape[0], dtype=complex)
    lin_h = np.zeros(C.shape[0], dtype=complex)
    if CQ1.size and np.abs(CQ1).max() > 0.0:
        # rigid coordinates: ȧ = N a + A12 c with N² = 0  ->  a(t) = (I + N t) a0
        #   + A12 Y diag((e^(λt) − 1)/λ) d + N A12 Y diag((e^(λt) − 1 − λt)/λ²) d
        A12Y = (system.reduced[0] * scale) @ Y
        N = system.rigid_block
        G1, G2 = CQ1 @ A12Y, (CQ1 @ N) @ A12Y
        G = G1 / lam + G2 / lam**2
        W = W + G
        const_h = CQ1 @ a0 - G @ d
        lin_h = (CQ1 @ N) @ a0 - (G2 / lam) @ d
    return _ModalTerms(lam, W * d, const_h, lin_h, alpha, beta, gamma, x_mu)


def _modal_outputs(system: LinearSystem, C: np.ndarray, u0: float, a: complex, mu: complex,
                   n_points: int, dt: float, part: str = "all"
                   ) -> tuple[np.ndarray, float, int, float]:
    """Perturbation outputs y (n_points x p) by the modal closed form; (y, error estimate relative
    to the largest |y|, number of valid points, highest frequency [Hz] of a mode contributing
    more than 1 % of some output's peak).  ``part``: "all"; "slow", the quasi-static part (the
    step's particular solution, the rigid coordinates' offset, the terms of the modes slower
    than :data:`QUASI_STATIC_HZ` and the forced oscillation if μ is that slow); "fast", the rest
    ("slow" + "fast" = "all")."""
    cond = system.modal[3]
    terms = _modal_terms(system, C, u0, a, mu)
    lam, coef, const_h, lin_h = terms.lam, terms.coef, terms.const_h, terms.lin_h
    alpha, beta, gamma, x_mu = terms.alpha, terms.beta, terms.gamma, terms.x_mu
    slow_cut = 2 * math.pi * QUASI_STATIC_HZ  # [rad/s]
    keep = lam.imag >= 0  # conjugate pairs: keep Im λ ≥ 0, double the strictly complex ones
    if part == "slow":
        keep &= lam.imag < slow_cut
        if abs(mu.imag) >= slow_cut:
            x_mu = np.zeros_like(x_mu)
    elif part == "fast":
        keep &= lam.imag >= slow_cut
        const_h, lin_h = np.zeros_like(const_h), np.zeros_like(lin_h)
        alpha, beta, gamma = np.zeros_like(alpha), np.zeros_like(beta), np.zeros_like(gamma)
        if abs(mu.imag) < slow_cut:
            x_mu = np.zeros_like(x_mu)
    elif part != "all":
        raise ValueError(f"part '{part}': all, slow or fast")
    weight = np.where(lam.imag > 0, 2.0, 1.0)
    lam_k, coef_k = lam[keep], coef[:, keep] * weight[keep]
    # growth guard: cut the grid before any term exceeds 1e250
    t_end = (n_points - 1) * dt
    magnitude = np.abs(coef_k).max(axis=0) + 1e-300
    valid = n_points
    growth = np.log(magnitude) + np.maximum(lam_k.real, 0.0) * t_end
    if growth.max() > HUGE_LOG:
        t_cut = np.min((HUGE_LOG - np.log(magnitude)) / np.maximum(lam_k.real, 1e-300))
        valid = max(2, int(t_cut / dt))
    block = max(16, int(math.sqrt(valid)))
    # support of each term: a decaying mode is evaluated only while some output's term is above
    # WINDOW_TOLERANCE x that output's largest term (the rest is bounded and added to the error
    # estimate below); modes sorted by support, longest first, so each time block uses a prefix
    reference = np.abs(coef_k).max(axis=1, initial=0.0) + 1e-300  # largest term per output
    relative = (np.abs(coef_k) / reference[:, None]).max(axis=0, initial=0.0)
    with np.errstate(divide="ignore"):
        support = np.where(lam_k.real < 0.0,
                           np.log(np.maximum(relative, 1e-300) / WINDOW_TOLERANCE)
                           / np.maximum(-lam_k.real, 1e-300), np.inf)
    order = np.argsort(-support, kind="stable")
    lam_k, coef_k, support = lam_k[order], coef_k[:, order], support[order]
    E_block, E_outer = _grid_exponentials(lam_k, valid, dt, block)
    starts = np.arange(E_outer.shape[0]) * (block * dt)
    active = (support[None, :] > starts[:, None]).sum(axis=1)  # modes needed per time block
    # y_h[:, a·block + b] = Re Σ_j coef[:, j] E_outer[a, j] E_block[b, j]: a real GEMM pair per
    # run of time blocks with a similar number of active modes
    p = C.shape[0]
    Yh = np.zeros((p, E_outer.shape[0], block))
    first = 0
    while first < len(active) and active[first] > 0:
        m = int(active[first])
        last = first + 1
        while last < len(active) and active[last] > 0.75 * m:
            last += 1
        G = (coef_k[:, None, :m] * E_outer[None, first:last, :m]).reshape(p * (last - first), m)
        run = G.real @ np.ascontiguousarray(E_block.real[:, :m].T)
        run -= G.imag @ np.ascontiguousarray(E_block.imag[:, :m].T)
        Yh[:, first:last, :] = run.reshape(p, last - first, block)
        first = last
    cut = support < t_end  # bound of the terms left out [output units]
    neglected = (np.abs(coef_k[:, cut]) * np.exp(lam_k.real[cut] * support[cut])).sum(axis=1)
    Yh = Yh.reshape(p, -1)[:, :valid]  # p x valid
    t = np.arange(valid) * dt
    Yh += (const_h.real + C @ alpha)[:, None]
    Yh += np.outer(lin_h.real + C @ beta, t)
    Yh += np.outer(C @ gamma, t * t)
    Yh += ((C @ x_mu)[:, None] * np.exp(mu * t)[None, :]).real
    y = Yh.T  # valid x p (a view: each output's column is contiguous)
    # rounding-error estimate: size of the cancelling terms × eigenvector condition
    terms = (np.abs(coef_k) @ np.exp(np.outer(lam_k.real, [0.0, t[-1]]))).max(axis=1)
    terms = terms + np.abs(C @ alpha) + (np.abs(C @ beta) + np.abs(lin_h)) * t[-1] \
        + np.abs(C @ gamma) * t[-1] ** 2 + np.abs(C @ x_mu) + np.abs(const_h)
    scale = np.abs(y).max(axis=0)
    estimate = float(np.max((EPS * cond * terms + neglected) / np.maximum(scale, 1e-300))) \
        if p else 0.0
    share = (np.abs(coef_k) / np.maximum(scale, 1e-300)[:, None]).max(axis=0)
    significant = lam_k.imag[share > 0.01]
    excited = float(significant.max() / (2 * np.pi)) if len(significant) else 0.0
    return y, estimate, valid, excited


def _expm_outputs(system: LinearSystem, C: np.ndarray, u0: float, a: complex, mu: complex,
                  n_points: int, dt: float) -> tuple[np.ndarray, int]:
    """Perturbation outputs by the exact discretization of the state augmented with the
    generator of the input: y_k = C Φ^k z0, Φ = expm(F dt); (y, number of valid points)."""
    n2 = system.N
    sigma, omega = -mu.real, mu.imag
    F = np.zeros((n2 + 3, n2 + 3))
    F[:n2, :n2] = system.A
    F[:n2, n2:] = np.outer(system.b, [u0, a.real, -a.imag])
    F[n2 + 1:, n2 + 1:] = [[-sigma, -omega], [omega, -sigma]]
    z0 = np.zeros(n2 + 3)
    z0[n2:n2 + 2] = 1.0
    Phi = sla.expm(F * dt)
    block = 1 << max(4, math.ceil(math.log2(math.sqrt(n_points * max(C.shape[0], 1)))))
    block = min(block, 1 << max(4, math.ceil(math.log2(n_points))))
    # Z = [z0, Φ z0, …, Φ^(block−1) z0] by doubling; P = Φ^block
    Z = z0[:, None]
    P = Phi
    while Z.shape[1] < block:
        Z = np.hstack([Z, P @ Z])
        P = P @ P
    Caug = np.hstack([C, np.zeros((C.shape[0], 3))])
    rows, L, count = [], Caug, 0
    while count < n_points:
        rows.append(L @ Z)
        count += block
        L = L @ P
        if not np.all(np.isfinite(L)) or np.abs(L).max() * np.abs(Z).max() > 1e250:
            break
    y = np.hstack(rows).T
    valid = min(n_points, y.shape[0])
    return y[:valid], valid


def solve_linear(system: LinearSystem, C: np.ndarray, u0: float, a: complex, mu: complex,
                 n_points: int, dt: float, method: str = "auto",
                 info: dict | None = None) -> tuple[np.ndarray, str, float]:
    """Perturbation outputs ``C x`` (n_points x p; x = [q; q̇], the velocities of massless
    coordinates left out, :class:`model.analysis.linear_system.LinearSystem`) of ``M q̈ + B q̇ + K q = f u(t)``,
    ``u = u0 + Re(a e^(μt))`` for t ≥ 0, at rest at t = 0, on the grid t_k = k dt.

    Returns (y, method used, error estimate relative to max|y| per output; NaN for "expm").
    The number of rows is smaller than n_points if the response had to be truncated (growth).
    ``info``, if given, receives ``"mode_hz"``: the highest frequency [Hz] of a mode that
    contributes more than 1 % of some output's peak (when the modal form was evaluated).
    """
    if method not in ("auto", "modal", "expm"):
        raise ResponseError(f"method '{method}' is not allowed: auto, modal or expm")
    if method in ("auto", "modal"):
        try:
            y, estimate, _, excited = _modal_outputs(system, C, u0, a, mu, n_points, dt)
            if info is not None:
                info["mode_hz"] = excited
        except np.linalg.LinAlgError:
            y, estimate = None, math.inf
        ok = y is not None and np.all(np.isfinite(y)) and estimate <= AUTO_TOLERANCE
        if method == "modal" and y is not None:
            return y, "modal", estimate
        if ok:
            return y, "modal", estimate
    y, _ = _expm_outputs(system, C, u0, a, mu, n_points, dt)
    return y, "expm", math.nan


class QuasiStaticUnavailable(ResponseError):
    """The quasi-static part cannot be separated reliably at this operating point (the modal
    form is ill-conditioned there)."""


@dataclass(frozen=True)
class QuasiStatic:
    """The quasi-static part of a response (perturbations of the outputs; see
    :func:`quasi_static_response`)."""

    y: np.ndarray  # valid x p on the grid t_k = k dt [output units]
    final: np.ndarray  # p: its value long after, t → ∞ (NaN where it grows or drifts) [units]


def quasi_static_response(system: LinearSystem, C: np.ndarray, u0: float, a: complex,
                          mu: complex, n_points: int, dt: float) -> QuasiStatic:
    """The quasi-static part of the response to ``u(t) = u0 + Re(a e^(μt))`` [N m] (the
    excitation's terms, :meth:`ShortCircuit.terms`) of the outputs ``C``, on the grid
    ``t_k = k dt`` [s]: the static response to the step and the terms of the modes that do not
    oscillate or oscillate slower than :data:`QUASI_STATIC_HZ` — the static response to a lost
    motor torque (the vehicle decelerating uniformly) and the creep-damped drifts on the way to
    it.  The rest (the faster modes'
    terms, the forced oscillation at f) is the dynamic part: the oscillation about the
    quasi-static value.  Raises :class:`QuasiStaticUnavailable` where the modal form is not
    reliable (rounding-error estimate above :data:`QUASI_STATIC_TOLERANCE`)."""
    try:
        y, estimate, valid, _ = _modal_outputs(system, C, u0, a, mu, n_points, dt, part="slow")
    except np.linalg.LinAlgError:
        estimate = math.inf
    if not estimate <= QUASI_STATIC_TOLERANCE:
        raise QuasiStaticUnavailable(
            f"the quasi-static part cannot be separated here (modal form ill-conditioned: "
            f"error estimate {estimate:.2g})")
    terms = _modal_terms(system, C, u0, a, mu)
    final = terms.const_h.real + C @ terms.alpha
    slow = terms.lam[terms.lam.imag < 2 * math.pi * QUASI_STATIC_HZ]
    # an output that drifts (a rigid coordinate's ramp or a free one's uniform acceleration)
    # more than 1e-9 of its size per second
    size = np.maximum(np.abs(final), np.abs(y[:valid]).max(axis=0, initial=0.0))
    rate = np.abs(C @ terms.beta + terms.lin_h.real) + np.abs(C @ terms.gamma)
    drift = rate > 1e-9 * np.maximum(size, 1e-300)
    if len(slow) and slow.real.max() > GROWTH_RATE:
        drift[:] = True  # a slow mode grows: no final value
    return QuasiStatic(y[:valid], np.where(drift, np.nan, final))


def quasi_static_step(system: LinearSystem, C: np.ndarray, step: float, n_points: int,
                      dt: float) -> QuasiStatic:
    """:func:`quasi_static_response` to the step ``−step H(t)`` [N m] alone (the loss of a
    motor's torque ``step``)."""
    mu = complex(-1.0, 1.0)  # any μ that is not an eigenvalue: the input has no such term
    return quasi_static_response(system, C, -step, 0j, mu, n_points, dt)


# --- the bogie -----------------------------------------------------------------------------------

@dataclass
class ResponseResult:
    """Short-circuit time histories (plain data; see the module docstring)."""

    t: np.ndarray  # time points [s]
    outputs: dict[str, np.ndarray]  # name -> total value (steady + perturbation) [units]
    units: dict[str, str]  # name -> SI unit
    steady: dict[str, float]  # name -> pre-fault value [units]
    M_C: np.ndarray  # short-circuit torque M_C(t) [N m]
    peaks: dict[str, float]  # name -> signed total of largest magnitude [units]
    peak_times: dict[str, float]  # name -> its time [s]
    perturbation_peaks: dict[str, float]  # name -> signed Δy of largest magnitude [units]
    perturbation_peak_times: dict[str, float]  # name -> its time [s]
    limit_crossings: list[LimitCrossing]  # totals beyond physical limits, by time
    limits: dict[str, float]  # "M_ad" [N m], "M_ad/p" [N m], "mu_max N0" [N]
    operating_point: OperatingPoint
    excitation: ShortCircuit
    phase_shift: float  # Δt actually used [s]
    motor_torque: float  # M(s0, v) before the fault [N m]
    method: str  # "modal" or "expm"
    # rounding-error indicator of the modal form (relative; NaN for expm): it detects
    # ill-conditioning but is not a bound (measured errors 1e-7…1e-6 where it says 1e-11)
    error_estimate: float
    truncated_at: float | None  # [s] if the grid was cut to avoid overflow (growth)
    highest_excited_hz: float | None  # max(f, highest mode with > 1 % of an output) [Hz]

    @cached_property
    def dominant_frequencies(self) -> dict[str, tuple[float, ...]]:
        """name -> the strongest spectral peaks of Δy [Hz], strongest first
        (:func:`dominant_frequencies`; computed when first asked: the dashboard shows none)."""
        if not self.outputs:
            return {}
        fs = 1.0 / (self.t[1] - self.t[0]) if len(self.t) > 1 else 1.0
        names = list(self.outputs)
        y = np.column_stack([self.outputs[name] - self.steady[name] for name in names])
        return dict(zip(names, dominant_frequencies(y, fs), strict=True))

    @property
    def nyquist_ok(self) -> bool:
        """fs/2 above the highest excited frequency (None: not known, method "expm")."""
        if self.highest_excited_hz is None or len(self.t) < 2:
            return True
        return 0.5 / (self.t[1] - self.t[0]) > self.highest_excited_hz

    def perturbation(self, name: str) -> np.ndarray:
        """Δy(t) = total − pre-fault value [unit of the output]."""
        return self.outputs[name] - self.steady[name]


def dominant_frequencies(y: np.ndarray, fs: float, count: int = 4,
                         relative: float = 0.05) -> list[tuple[float, ...]]:
    """Strongest peaks of the amplitude spectrum of each column of ``y`` (sampled at ``fs`` [Hz]),
    strongest first [Hz].

    The mean is removed and only the second half is tapered (half cosine): the response starts
    from rest, and a full window would hide the early, decaying content (the 90 Hz excitation).
    No zero padding (resolution fs/N = 1/T); a parabolic fit of the log amplitude locates each
    peak between the bins; peaks below ``relative`` × the strongest are dropped.  A 1-D ``y``
    gives a list with one tuple.
    """
    y = np.asarray(y, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    N, p = y.shape
    if N < 8:
        return [() for _ in range(p)]
    rows = y.T - y.mean(axis=0)[:, None]  # p x N, each output's samples contiguous (a copy)
    m = max(2, N // 2)
    rows[:, N - m:] *= 0.5 * (1 + np.cos(np.pi * np.arange(1, m + 1) / m))
    n_fft = scipy.fft.next_fast_len(N, real=True)
    spectrum = np.abs(scipy.fft.rfft(rows, n=n_fft, axis=1, overwrite_x=True))
    df = fs / n_fft
    # local maxima of every spectrum at once
    inner = spectrum[:, 1:-1]
    is_peak = (inner > spectrum[:, :-2]) & (inner >= spectrum[:, 2:])
    result = []
    for s, flags in zip(spectrum, is_peak, strict=True):
        peaks = np.flatnonzero(flags) + 1
        if len(peaks) == 0 or s[peaks].max() <= 0.0:
            result.append(())
            continue
        peaks = peaks[s[peaks] >= relative * s[peaks].max()]
        peaks = peaks[np.argsort(-s[peaks])]
        # side lobes: drop peaks closer than 4/T to a stronger one
        chosen: list[int] = []
        for i in peaks:
            if all(abs(i - j) * df > 4.0 * fs / N for j in chosen):
                chosen.append(int(i))
            if len(chosen) == count:
                break
        found = []
        for i in chosen:
            l0, l1, l2 = np.log(s[i - 1: i + 2] + 1e-300)
            den = l0 - 2 * l1 + l2
            shift = 0.5 * (l0 - l2) / den if den < 0 else 0.0
            found.append(float((i + shift) * df))
        result.append(tuple(found))
    return result


def time_grid_points(t_end, fs, error: type[ResponseError] = ResponseError) -> int:
    """Samples of the grid t = k/fs, k = 0 … round(t_end fs) (t_end [s], fs [Hz]); a bad value
    raises ``error`` with a one-line message."""
    for label, value in (("t_end", t_end), ("fs", fs)):
        if isinstance(value, bool) or not isinstance(value, int | float) \
                or not math.isfinite(value) or value <= 0:
            raise error(f"{label} = {value!r} is not allowed: must be a positive number")
    if t_end > MAX_T_END:
        raise error(f"t_end = {t_end} s is not allowed: at most {MAX_T_END:g} s")
    n_points = round(t_end * fs) + 1
    if n_points > MAX_POINTS:
        raise error(f"t_end × fs = {t_end * fs:.0f} samples is too many: at most {MAX_POINTS - 1}")
    if n_points < 3:
        raise error(f"t_end × fs = {t_end * fs:g}: fewer than 2 samples")
    return n_points


def output_rows(model: BogieModel, op: OperatingPoint, outputs: list[str] | None = None
                ) -> tuple[list[str], np.ndarray, dict[str, str], dict[str, float]]:
    """(names, C, units, steady) of the requested outputs: ``C`` (p x N) maps the state
    ``[Δq; Δq̇]`` (the velocities of massless coordinates left out:
    :class:`model.analysis.linear_system.LinearSystem`) to the perturbations,
    ``steady[name]`` is the pre-fault value [unit] (outputs of
    :func:`model.mechanics.outputs.output_matrices`, default all of them, or DOF names); an
    unknown name raises :class:`ResponseError`."""
    system = bogie_system(model, op)
    # kept with the system: the response and its peaks ask for the same rows
    names, C, units, steady = system.kept(
        ("output rows", None if outputs is None else tuple(outputs)),
        lambda: _output_rows(model, op, system, outputs))
    return list(names), C, dict(units), dict(steady)


def _output_rows(model: BogieModel, op: OperatingPoint, system: LinearSystem,
                 outputs: list[str] | None):
    matrices = output_matrices(model, op)
    names = list(matrices.names) if outputs is None else list(outputs)
    if not names:
        raise ResponseError("no outputs requested")
    rows, units, steady = [], {}, {}
    q0 = None
    for name in names:
        if name in matrices.names:
            i = matrices.index(name)
            rows.append(system.state_output(matrices.C_q[i], matrices.C_v[i])[0])
            units[name], steady[name] = matrices.units[i], float(matrices.steady[i])
        elif name in model.dofs.names:
            if q0 is None:
                q0 = static_deflection(model, op)
            i = model.dofs.index(name)
            row = np.zeros(system.N)
            row[i] = 1.0
            rows.append(row)
            units[name], steady[name] = model.dofs.unit(name), float(q0[i])
        else:
            raise ResponseError(f"unknown output '{name}': use an output name "
                                f"({', '.join(matrices.names[:3])}, …) or a DOF name "
                                "(e.g. ID1.rotor.ry)")
    C = np.array(rows)
    C.flags.writeable = False  # shared by every caller of output_rows at this point
    return tuple(names), C, units, steady


def short_circuit_response(model: BogieModel, op: OperatingPoint,
                           excitation: ShortCircuit | None = None, t_end: float = 2.0,
                           fs: float = 10_000.0, outputs: list[str] | None = None,
                           method: str = "auto") -> ResponseResult:
    """Time histories of the loads after the short circuit of ID1's motor (see module docstring).

    ``t_end`` [s] horizon (0 < t_end ≤ 60), ``fs`` [Hz] output sampling rate (the grid is
    ``t = k/fs``, k = 0 … round(t_end fs)); ``outputs`` names (default: all loads of both drives).

    Example::

        >>> from model import (ShortCircuit, build_model, default_operating_point, load_parameters,
        ...                    short_circuit_response)
        >>> parameters = load_parameters()
        >>> model = build_model(parameters)
        >>> r = short_circuit_response(model, default_operating_point(parameters, s0=0.005),
        ...                            ShortCircuit(M0=50e3, f=90.0, D=0.04), t_end=0.5, fs=5000.0)
        >>> swing = abs(r.perturbation_peaks["ID1.disc_clutch.torque"])   # [N m]
        >>> bool(swing > r.limits["M_ad"]), r.units["ID1.disc_clutch.torque"]
        (True, 'N m')
    """
    excitation = ShortCircuit() if excitation is None else excitation
    n_points = time_grid_points(t_end, fs)
    names, C, units, steady = output_rows(model, op, outputs)
    step = motor_torque(model.parameters, op)
    u0, a, mu = excitation.terms(step)
    dt = 1.0 / fs
    system = bogie_system(model, op)
    info: dict = {}
    y, used, estimate = solve_linear(system, C, u0, a, mu, n_points, dt, method, info)
    valid = y.shape[0]
    t = np.arange(valid) * dt
    yT = np.ascontiguousarray(y.T)  # p x valid
    totals = {name: yT[j] + steady[name] for j, name in enumerate(names)}
    M_ad = adhesion_moment(model.parameters, op.v, op.N0)
    _, mu_max = creep_law(model.parameters, op.N0).maximum(op.v)
    limits = {"M_ad": M_ad, "M_ad/p": M_ad / model.parameters["gear_ratio"],
              "mu_max N0": float(mu_max) * op.N0}
    found = history_peaks_and_crossings(t, totals, steady, limits)
    return ResponseResult(
        t=t, outputs=totals, units=units, steady=steady, M_C=excitation.torque(t, step),
        peaks=found.peaks, peak_times=found.peak_times,
        perturbation_peaks=found.perturbation_peaks,
        perturbation_peak_times=found.perturbation_peak_times,
        limit_crossings=found.limit_crossings, limits=limits,
        operating_point=op, excitation=excitation, phase_shift=excitation.shift(step),
        motor_torque=step, method=used, error_estimate=estimate,
        truncated_at=None if valid == n_points else float(t[-1]),
        highest_excited_hz=(max(excitation.f if excitation.M0 > 0 else 0.0, info["mode_hz"])
                            if "mode_hz" in info else None))


def linear_load_peaks(model: BogieModel, result: ResponseResult) -> LoadPeaks:
    """The peaks a reviewer reads of a linear history (:class:`model.analysis.load_peaks.
    LoadPeaks`): per output the maximum, the minimum and the swing from the pre-fault value with
    their times, the swing split into its quasi-static part (:func:`quasi_static_response` of the
    same excitation) and its dynamic part; at an unstable point the growth rate (largest Re λ
    [1/s]) instead of a split."""
    op = result.operating_point
    growth = float(np.max(bogie_system(model, op).eigenvalues().real))
    names = list(result.outputs)
    quasi_static = final = None
    note = ""
    if growth > GROWTH_RATE:
        note = "unbounded with linear creep"
    else:
        _, C, _, _ = output_rows(model, op, names)
        u0, a, mu = result.excitation.terms(result.motor_torque)
        dt = float(result.t[1] - result.t[0])
        try:
            part = quasi_static_response(bogie_system(model, op), C, u0, a, mu, len(result.t), dt)
        except QuasiStaticUnavailable as error:
            note = str(error)
        else:
            quasi_static = {name: part.y[:, j] for j, name in enumerate(names)}
            final = {name: float(part.final[j]) for j, name in enumerate(names)}
    return load_peaks(result.t, result.outputs, result.steady, result.units,
                      result.limit_crossings, "linear", growth, quasi_static, final, note)
