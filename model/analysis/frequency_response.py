"""Frequency response H(f) of the linearized bogie: from a motor's air-gap torque (or a creep-force
disturbance at a wheel, or a rail–wheel surface deviation) to every named output, exact from the
state space.

The bogie at an operating point is ``M Δq̈ + B_total Δq̇ + K Δq = F u(t)``, outputs ``y = C_q Δq +
C_v Δq̇`` (:mod:`model.mechanics.outputs`).  For ``u = Re(û e^(iωt))`` the steady state is ``y =
Re(H(iω) û e^(iωt))`` with ``H(s) = C (sI − A)⁻¹ b`` on the state of
:mod:`model.analysis.linear_system` (no direct feed-through: the inputs never act on a massless
coordinate).

Modal form (the method).  With the rigid-body subspace deflated, ``Qᵀ A Q = [[0, A12], [0, A22]]``
and ``A22 = T Y Λ Y⁻¹ T⁻¹`` (the eigendecomposition the eigen-analysis has computed and cached
for the operating point), so

    H(s) = Σ_j R_j / (s − λ_j)  +  g / s,     R_j = (C₂ T Y)_j (Y⁻¹ T⁻¹ b₂)_j + (C₁ A12 T Y)_j (…)_j / λ_j

with ``[C₁ C₂] = C Q``, ``[b₁; b₂] = Qᵀ b`` and the rigid-body drift ``g = C₁ b₁ − C₁ A12 A22⁻¹ b₂``.
The named outputs are forces and torques of elements, which a rigid-body motion does not strain
(``C₁ = 0`` to rounding), so ``g = 0`` and the static gain ``H(0) = −Σ R_j / λ_j`` is finite.  One
evaluation at F frequencies is a product of the residues (outputs × modes) with the kernel
``1/(i 2π f − λ_j)`` (modes × F): an FRF of every output at 2000 frequencies costs about as much
as the eigen-analysis it reuses (BENCHMARKS.md).  Rounding: ``ε · cond(Y) · Σ_j |R_j|/|s − λ_j|`` estimates the error of
every value; a frequency whose estimate exceeds :data:`MODAL_TOLERANCE` of the largest |H| is
solved directly instead.

Irregularity inputs ``IDk.rimNN.irregularity`` [m] (:mod:`model.mechanics.irregularity`) drive
the running system (:func:`model.analysis.eigen.running_system`: the bogie with the wheel-force
coupling) through ``G_q Δ + G_v Δ̇ + G_a Δ̈``.  With the modal forms ``H_q``, ``H_v``, ``H_a`` of
the three force patterns, ``H(s) = H_q + s H_v + s² H_a``; since ``s/(s − λ) = 1 + λ/(s − λ)`` and
``s²/(s − λ) = s + λ + λ²/(s − λ)`` it is again a sum over the modes, residues ``R_q + λ R_v +
λ² R_a``, plus the feed-through ``D0 + D1 s`` with the Markov parameters ``D1 = C b_a`` and
``D0 = C b_v + C A b_a`` (the velocity a Δ̈ gives at once, the force a Δ̇ does).

Direct form (the reference, and for a few frequencies).  ``(−ω² M + iω B_total + K) Q̂ = F`` and
``Ĥ = (C_q + iω C_v) Q̂``: one complex solve of the n x n dynamic stiffness per frequency.

The grid.  ``N`` frequencies spaced logarithmically over [f_lo, f_hi], plus nine points on each
mode's resonance ``Im λ/2π + {0, ±½, ±1, ±2, ±3} · |Re λ|/2π`` (the half-power half-width of
the mode is |Re λ|/2π): a peak cannot fall between two grid points unseen.  Every local maximum
of |H| on the grid is then refined by golden-section search to 1e-12 of its frequency, so peak
heights are those of H itself, not of the grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model.analysis.eigen import bogie_system, non_neutral, running_system
from model.analysis.linear_system import LinearSystem
from model.mechanics.assembly import DRIVES, RIM_NODES, BogieModel
from model.mechanics.irregularity import UNIT as IRREGULARITY_UNIT
from model.mechanics.irregularity import irregularity_forces, irregularity_inputs, is_irregularity
from model.mechanics.operating_point import OperatingPoint, damping_matrix, longitudinal_creep_pattern
from model.mechanics.outputs import OutputMatrices, output_matrices

EPS = np.finfo(float).eps
# The model's frequency range [Hz].  The shafts are beam meshes whose longest element (the
# axle between the claw clutch and its centre, 0.6 m) has its own first clamped–clamped bending
# frequency at ≈ 2.4 kHz: below half of that every shaft mode spans two elements or more per half
# wave, which cubic beam elements resolve (tests/model/analysis/test_frequency_response.py checks
# the criterion on the model's elements).  Beyond the shafts the model has no modes of its own for
# what is rigid in it (gear wheels, wheel discs, the stator housing, bogie frame and car body)
# and one constant gear mesh stiffness: docs/resonance.md, "Limits".
MODEL_FREQUENCY_LIMIT_HZ = 1000.0
RIGID_FREE_RTOL = 1e-10  # an output row with |C₁| below this x |C| does not see rigid motion
MODAL_TOLERANCE = 1e-8  # a modal value whose rounding estimate exceeds this x max|H| is solved directly
STATIC_GAIN_RTOL = 1e-6  # a static gain below this x the output's largest |H| counts as zero
DEFAULT_MIN_PEAK = 0.01  # peaks below this fraction of an output's largest |H| are not listed
RESONANCE_OFFSETS = (-3.0, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0, 3.0)  # in half-power half-widths
GOLDEN_ITERATIONS = 60  # golden-section steps: the bracket shrinks by 0.618^60 ≈ 3e-13
DEFAULT_INPUT = "ID1.motor.torque"


class FrequencyResponseError(ValueError):
    """Bad input for a frequency response (one-line message)."""


# --- inputs ------------------------------------------------------------------------------------

def input_names(model: BogieModel) -> tuple[str, ...]:
    """The inputs H can be computed from: each motor's air-gap torque ``IDk.motor.torque`` [N m],
    a longitudinal creep-force disturbance at each wheel ``IDk.rimN.creep_disturbance`` [N] and
    each wheel's rail–wheel surface deviation ``IDk.rimN.irregularity`` [m]."""
    motors = tuple(f"{drive}.motor.torque" for drive in DRIVES)
    wheels = tuple(f"{drive}.rim{k}.creep_disturbance" for drive in DRIVES for k in RIM_NODES)
    return motors + wheels + irregularity_inputs(model)


def input_unit(model: BogieModel, name: str) -> str:
    """The unit of an input (:func:`input_names`): "N m", "N" or "m"."""
    if is_irregularity(name) and name in irregularity_inputs(model):
        return IRREGULARITY_UNIT
    return input_force(model, name)[1]


def input_force(model: BogieModel, name: str) -> tuple[np.ndarray, str]:
    """(generalized force per unit input (n), the input's unit).

    ``IDk.motor.torque``: the torque on the rotor and its reaction on the stator, in the motor's
    driving sense — for ID1 the generalized force of the short-circuit torque M_C
    (``model.short_circuit_force``), for ID2 the same pattern as its steady torque in
    :func:`model.mechanics.outputs.static_load`.  ``IDk.rimN.creep_disturbance``: a longitudinal
    force [N] at the wheel's contact point, ``e_x − r0 e_ry`` on the rim (as a creep force).
    An irregularity's force depends on the frequency (:meth:`IrregularityForces.force`)."""
    if is_irregularity(name) and name in irregularity_inputs(model):
        raise FrequencyResponseError(f"'{name}' is a displacement input: its generalized force "
                                     "depends on the frequency")
    if name == "ID1.motor.torque":
        return model.short_circuit_force.astype(float), "N m"
    if name == "ID2.motor.torque":
        force = np.zeros(model.n)
        force[model.dofs.index("ID2.rotor.ry")] = -1.0
        force[model.dofs.index("ID2.stator.ry")] = 1.0
        return force, "N m"
    rims = list(model.rims)
    if name.endswith(".creep_disturbance") and name.removesuffix(".creep_disturbance") in rims:
        column = rims.index(name.removesuffix(".creep_disturbance"))
        return longitudinal_creep_pattern(model)[:, column].copy(), "N"
    raise FrequencyResponseError(f"unknown input '{name}'; known: {', '.join(input_names(model))}")


# --- the modal form --------------------------------------------------------------------------------

@dataclass(frozen=True)
class ModalTransfer:
    """H(s) = Σ_j residues[:, j] / (s − λ_j) + drift / s for the outputs of one input."""

    eigenvalues: np.ndarray  # (m,) non-rigid eigenvalues [1/s]
    residues: np.ndarray  # (p, m) complex [output unit per input unit / s]
    drift: np.ndarray  # (p,) rigid-body drift coefficient g (0 for element loads)
    magnitudes: np.ndarray  # (p, m) |(C₂TY)_j| |(Y⁻¹T⁻¹b₂)_j| etc.: the terms' sizes before cancellation
    condition: float  # cond(Y) of the eigenvector matrix (1-norm estimate)
    # (p, 2) complex: H gains D0 + D1 s (an irregularity's Δ̇ and Δ̈ parts); None: no feed-through
    feedthrough: np.ndarray | None = None
    static: np.ndarray | None = None  # (p,) H(0) if known apart from the residues (feed-through)

    def direct_part(self, s: np.ndarray) -> np.ndarray:
        """D0 + D1 s (p x F complex; zeros without feed-through) at Laplace points ``s``."""
        s = np.atleast_1d(s)
        if self.feedthrough is None:
            return np.zeros((self.residues.shape[0], len(s)), dtype=complex)
        return self.feedthrough[:, :1] + self.feedthrough[:, 1:] * s[None, :]

    def __call__(self, f_hz: np.ndarray) -> np.ndarray:
        """H at frequencies ``f_hz`` [Hz] (p x F complex; f = 0 gives the static gain)."""
        f_hz = np.atleast_1d(np.asarray(f_hz, dtype=float))
        s = 2j * np.pi * f_hz
        out = np.empty((self.residues.shape[0], len(f_hz)), dtype=complex)
        nonzero = s != 0
        if np.any(nonzero):
            out[:, nonzero] = self.residues @ (1.0 / (s[None, nonzero] - self.eigenvalues[:, None]))
            out[:, nonzero] += self.drift[:, None] / s[None, nonzero]
            out[:, nonzero] += self.direct_part(s[nonzero])
        if np.any(~nonzero):
            out[:, ~nonzero] = self.static_gain()[:, None]
        return out

    def static_gain(self) -> np.ndarray:
        """H(0) (p complex): −Σ R_j/λ_j over the eigenvalues that are not neutral (a neutral
        eigenvalue, zero to rounding, is a rigid-body velocity without damping: it has no static
        deflection); infinite for an output with a rigid-body drift."""
        if self.static is not None:
            return self.static
        keep = non_neutral(self.eigenvalues)
        gain = -(self.residues[:, keep] @ (1.0 / self.eigenvalues[keep]))
        return np.where(self.drift != 0, np.inf, gain)

    def rounding_estimate(self, f_hz: np.ndarray) -> np.ndarray:
        """ε · cond(Y) · Σ_j |terms_j| / |s − λ_j| (p x F): the size of the cancelling terms."""
        s = 2j * np.pi * np.atleast_1d(np.asarray(f_hz, dtype=float))
        distance = np.abs(s[None, :] - self.eigenvalues[:, None])
        distance[distance == 0] = np.inf
        return EPS * self.condition * (self.magnitudes @ (1.0 / distance))


def modal_transfer(system: LinearSystem, C: np.ndarray, b: np.ndarray) -> ModalTransfer:
    """The modal form of ``C (sI − A)⁻¹ b`` (C: p x N state output rows, b: N state input) from
    the system's cached eigendecomposition (module docstring)."""
    lam, Y, _, cond, scale = system.modal
    r = system.rigid_count
    deflation = system.deflation
    bz = deflation.to_deflated(b)
    CQ = deflation.rows(C)
    b1, b2 = bz[:r], bz[r:]
    C1, C2 = CQ[:, :r], CQ[:, r:].copy()
    # an output that a rigid-body motion does not change (every element load) has C₁ = 0 but for
    # the rounding of the deflation (≈ 1e-17 of the row): it is set to 0, so that the output has
    # no drift g/s of rounding size (which would make its static gain infinite)
    rigid_free = np.linalg.norm(C1, axis=1) <= RIGID_FREE_RTOL * np.linalg.norm(C, axis=1)
    C1 = np.where(rigid_free[:, None], 0.0, C1)
    right = system.solve_eigenvectors(b2 / scale)  # Y⁻¹ T⁻¹ b₂  (m,)
    left = (C2 * scale[None, :]) @ Y  # C₂ T Y  (p, m)
    magnitudes = np.abs(left) * np.abs(right)[None, :]
    residues = left * right[None, :]
    drift = C1 @ b1 if r else np.zeros(C.shape[0])
    if r:
        A12 = system.reduced[0]
        left_rigid = (C1 @ (A12 * scale[None, :])) @ Y  # C₁ A12 T Y  (p, m)
        rigid = left_rigid * (right / lam)[None, :]  # 1/(s(s−λ)) = (1/λ)(1/(s−λ) − 1/s)
        residues = residues + rigid
        drift = drift - rigid.sum(axis=1)
        magnitudes = magnitudes + np.abs(left_rigid) * np.abs(right / lam)[None, :]
    return ModalTransfer(lam, residues, np.asarray(drift, dtype=complex), magnitudes, cond)


def output_indices(model: BogieModel, op: OperatingPoint,
                   outputs: list[str] | None = None) -> tuple[OutputMatrices, np.ndarray]:
    """(the output matrices, indices of the chosen named outputs in them; None: all of them):
    the rows of ``C_q``/``C_v`` the frequency response and the forced response evaluate at any
    speed.  (:func:`model.analysis.response.output_rows` gives a history's state-output rows,
    DOF names included.)"""
    matrices = output_matrices(model, op)
    if outputs is None:
        return matrices, np.arange(len(matrices.names))
    if not outputs:
        raise FrequencyResponseError("no outputs chosen")
    try:
        return matrices, np.array([matrices.index(name) for name in outputs], dtype=int)
    except KeyError as error:
        raise FrequencyResponseError(error.args[0]) from None


def transfer(model: BogieModel, op: OperatingPoint, input: str = DEFAULT_INPUT,
             outputs: list[str] | None = None) -> tuple[ModalTransfer, OutputMatrices, np.ndarray]:
    """(the modal form of H from ``input`` to the chosen outputs, the output matrices, the chosen
    rows) at ``op``; the eigendecomposition is the cached one of :func:`bogie_system`."""
    matrices, rows = output_indices(model, op, outputs)
    if is_irregularity(input) and input in irregularity_inputs(model):
        return irregularity_transfer(model, op, input, matrices, rows), matrices, rows
    force, _ = input_force(model, input)
    system = bogie_system(model, op)
    C = system.state_output(matrices.C_q[rows], matrices.C_v[rows])
    return modal_transfer(system, C, system.input_map(force)), matrices, rows


def irregularity_transfer(model: BogieModel, op: OperatingPoint, input: str,
                          matrices: OutputMatrices, rows: np.ndarray) -> ModalTransfer:
    """The modal form of H from the surface deviation ``input`` [m] to the output rows on the
    running system: ``H_q + s H_v + s² H_a`` as residues and feed-through (module docstring)."""
    system = running_system(model, op)
    forces = irregularity_forces(model, op)
    j = forces.column(input)
    C = system.state_output(matrices.C_q[rows], matrices.C_v[rows])
    inputs = [system.input_map(G[:, j]) for G in (forces.G_q, forces.G_v, forces.G_a)]
    q, v, a = (modal_transfer(system, C, b) for b in inputs)
    lam = q.eigenvalues
    residues = q.residues + lam[None, :] * v.residues + (lam * lam)[None, :] * a.residues
    magnitudes = (q.magnitudes + np.abs(lam)[None, :] * v.magnitudes
                  + (np.abs(lam) ** 2)[None, :] * a.magnitudes)
    D1 = C @ inputs[2]
    D0 = C @ inputs[1] + C @ (system.A @ inputs[2])
    feedthrough = np.column_stack([D0, D1]).astype(complex)
    return ModalTransfer(lam, residues, q.drift, magnitudes, q.condition, feedthrough,
                         q.static_gain())


# --- direct solves (the reference; a few frequencies) -----------------------------------------

def direct_response(model: BogieModel, op: OperatingPoint, f_hz, input: str = DEFAULT_INPUT,
                    outputs: list[str] | None = None) -> np.ndarray:
    """H at frequencies ``f_hz`` [Hz] (all > 0) by solving the dynamic stiffness
    ``(−ω²M + iωB_total + K) Q̂ = F`` at each: (p x F complex), outputs as :func:`transfer`."""
    f_hz = np.atleast_1d(np.asarray(f_hz, dtype=float))
    if np.any(f_hz <= 0) or not np.all(np.isfinite(f_hz)):
        raise FrequencyResponseError("direct solves need frequencies > 0 Hz")
    matrices, rows = output_indices(model, op, outputs)
    if is_irregularity(input) and input in irregularity_inputs(model):
        return solve_irregularity(model, op, input, matrices.C_q[rows], matrices.C_v[rows], f_hz)
    force, _ = input_force(model, input)
    return solve_direct(model, damping_matrix(model, op), force, matrices.C_q[rows],
                   matrices.C_v[rows], f_hz)


def solve_irregularity(model: BogieModel, op: OperatingPoint, input: str, C_q: np.ndarray,
                       C_v: np.ndarray, f_hz: np.ndarray) -> np.ndarray:
    """H from the surface deviation ``input`` [m] by the running system's dynamic stiffness,
    ``(−ω²(M + M_c) + iω(B_total + B_c) + K + K_c) Q̂ = G_q + iω G_v − ω² G_a``, at each
    frequency of ``f_hz`` [Hz] (p x F complex)."""
    forces = irregularity_forces(model, op)
    M, B = model.M + forces.M_c, damping_matrix(model, op) + forces.B_c
    K = model.K + forces.K_c
    out = np.empty((C_q.shape[0], len(f_hz)), dtype=complex)
    for k, f in enumerate(f_hz):
        w = 2 * np.pi * f
        q = np.linalg.solve(-w * w * M + 1j * w * B + K, forces.force(input, 1j * w))
        out[:, k] = (C_q + 1j * w * C_v) @ q
    return out


def solve_direct(model: BogieModel, damping: np.ndarray, force: np.ndarray, C_q: np.ndarray,
                 C_v: np.ndarray, f_hz: np.ndarray) -> np.ndarray:
    """``(C_q + iω C_v) (−ω²M + iω damping + K)⁻¹ force`` at each frequency of ``f_hz`` [Hz]
    (p x F complex): the dynamic stiffness solved once per frequency."""
    out = np.empty((C_q.shape[0], len(f_hz)), dtype=complex)
    for k, f in enumerate(f_hz):
        w = 2 * np.pi * f
        q = np.linalg.solve(-w * w * model.M + 1j * w * damping + model.K, force)
        out[:, k] = (C_q + 1j * w * C_v) @ q
    return out


# --- the FRF over a grid, its peaks ------------------------------------------------------------

@dataclass(frozen=True)
class Peak:
    """A local maximum of |H| of one output."""

    f_hz: float  # frequency [Hz]
    abs: float  # |H| there [output unit per input unit]
    amplification: float | None  # |H| / |H(0)|: dynamic amplification (None: no static gain)


@dataclass(frozen=True)
class FrequencyResponse:
    """H(f) from one input to the named outputs at an operating point."""

    input: str  # input name (:func:`input_names`)
    input_unit: str  # "N m" (motor torque), "N" (creep disturbance) or "m" (irregularity)
    operating_point: OperatingPoint
    f_hz: np.ndarray  # (F,) [Hz], ascending, f_hz[0] = 0: the static gain
    names: tuple[str, ...]  # output names
    units: tuple[str, ...]  # output units (H is in output unit per input unit)
    H: np.ndarray  # (p, F) complex
    static_gain: np.ndarray  # (p,) H(0) (complex; inf: the output drifts)
    peaks: tuple[tuple[Peak, ...], ...]  # per output, by frequency
    base_points: int  # the log-spaced points of the grid (the rest refine resonances)
    direct_points: int  # grid values solved directly (modal rounding estimate too large)
    stable: bool = True  # False: a mode grows, H(f) is no steady state (only its definition)

    @property
    def magnitude(self) -> np.ndarray:
        """|H| (p x F) [output unit per input unit]."""
        return np.abs(self.H)

    @property
    def phase_deg(self) -> np.ndarray:
        """arg H (p x F) [degrees, −180…180]."""
        return np.degrees(np.angle(self.H))

    def output(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise FrequencyResponseError(
                f"unknown output '{name}'; known: {', '.join(self.names)}") from None


def resonance_grid(eigenvalues: np.ndarray, f_lo: float, f_hi: float, points: int) -> np.ndarray:
    """``points`` log-spaced frequencies over [f_lo, f_hi] [Hz] and, for every eigenvalue with
    f_lo ≤ Im λ/2π ≤ f_hi, nine points across its resonance (:data:`RESONANCE_OFFSETS` half-power
    half-widths |Re λ|/2π from Im λ/2π), sorted and unique, within [f_lo, f_hi]."""
    base = np.geomspace(f_lo, f_hi, points)
    upper = eigenvalues[eigenvalues.imag > 0]
    centre = upper.imag / (2 * np.pi)
    width = np.abs(upper.real) / (2 * np.pi)
    inside = (centre >= f_lo) & (centre <= f_hi)
    extra = (centre[inside, None] + np.outer(width[inside], RESONANCE_OFFSETS)).ravel()
    extra = extra[(extra >= f_lo) & (extra <= f_hi)]
    return np.unique(np.concatenate([base, extra]))


def check_band(f_lo: float, f_hi: float, points: int) -> None:
    """Refuse a band outside (0, :data:`MODEL_FREQUENCY_LIMIT_HZ`] or empty, or a bad count."""
    if not (math.isfinite(f_lo) and math.isfinite(f_hi)) or not 0 < f_lo < f_hi:
        raise FrequencyResponseError(f"the frequency band must have 0 < f_lo < f_hi, got "
                                     f"{f_lo:g} … {f_hi:g} Hz")
    if f_hi > MODEL_FREQUENCY_LIMIT_HZ:
        raise FrequencyResponseError(
            f"{f_hi:g} Hz is beyond the model's validity: at most {MODEL_FREQUENCY_LIMIT_HZ:g} Hz "
            "(beam meshes of the shafts, rigid gears and wheel discs; docs/resonance.md)")
    if not 2 <= points <= 100_000:
        raise FrequencyResponseError(f"the grid needs 2 to 100000 points, got {points}")


def frequency_response(model: BogieModel, op: OperatingPoint, input: str = DEFAULT_INPUT,
                       f_lo: float = 0.1, f_hi: float = MODEL_FREQUENCY_LIMIT_HZ,
                       points: int = 2000, outputs: list[str] | None = None,
                       min_peak: float = DEFAULT_MIN_PEAK) -> FrequencyResponse:
    """H(f) from ``input`` to the outputs (default: every named output) at ``op`` on the
    resonance-refined grid over [f_lo, f_hi] [Hz] with ``points`` log-spaced base points, the
    static gain at f = 0 first; peaks (local maxima of |H| at least ``min_peak`` of the output's
    largest |H|) refined by golden-section search.

    Example::

        >>> from model import build_model, default_operating_point, frequency_response, load_parameters
        >>> parameters = load_parameters()
        >>> frf = frequency_response(build_model(parameters), default_operating_point(parameters))
        >>> peak = max(frf.peaks[frf.output("ID1.driving_shaft.torque")], key=lambda p: p.abs)
        >>> round(peak.f_hz)                            # the driving shaft's mode [Hz]
        298
    """
    check_band(f_lo, f_hi, points)
    if not 0 <= min_peak < 1:
        raise FrequencyResponseError(f"min_peak must be in [0, 1), got {min_peak!r}")
    model_transfer, matrices, rows = transfer(model, op, input, outputs)
    grid = resonance_grid(model_transfer.eigenvalues, f_lo, f_hi, points)
    H_grid = model_transfer(grid)
    estimate = model_transfer.rounding_estimate(grid)
    largest = np.abs(H_grid).max(axis=1, keepdims=True)
    suspect = np.flatnonzero(np.any(estimate > MODAL_TOLERANCE * largest, axis=0))
    if len(suspect) and is_irregularity(input):
        H_grid[:, suspect] = solve_irregularity(model, op, input, matrices.C_q[rows],
                                                matrices.C_v[rows], grid[suspect])
    elif len(suspect):
        force, _ = input_force(model, input)
        H_grid[:, suspect] = solve_direct(model, damping_matrix(model, op), force,
                                     matrices.C_q[rows], matrices.C_v[rows], grid[suspect])
    gain = model_transfer.static_gain()
    f_all = np.concatenate([[0.0], grid])
    H = np.concatenate([gain[:, None], H_grid], axis=1)
    peaks = _peaks(model_transfer, grid, H_grid, gain, min_peak)
    unit = input_unit(model, input)
    lam = model_transfer.eigenvalues
    stable = bool(np.all(lam[non_neutral(lam)].real <= 0))
    return FrequencyResponse(input, unit, op, f_all, tuple(matrices.names[i] for i in rows),
                             tuple(matrices.units[i] for i in rows), H, gain, peaks, points,
                             len(suspect), stable)


def _peaks(model_transfer: ModalTransfer, grid: np.ndarray, H_grid: np.ndarray,
           gain: np.ndarray, min_peak: float) -> tuple[tuple[Peak, ...], ...]:
    """Local maxima of |H| on the grid, each refined by golden-section search on the modal form
    between its two neighbours (all outputs' peaks at once)."""
    magnitude = np.abs(H_grid)
    largest = np.maximum(magnitude.max(axis=1), np.abs(gain))
    rows, centres = [], []
    for p in range(magnitude.shape[0]):
        m = magnitude[p]
        interior = np.flatnonzero((m[1:-1] > m[:-2]) & (m[1:-1] >= m[2:])) + 1
        # the grid has points within a quarter of a half-power width of every resonance, so a
        # peak's grid value is within a few per cent of its height: smaller ones are not refined
        interior = interior[m[interior] >= 0.5 * min_peak * largest[p]]
        rows += [p] * len(interior)
        centres += list(interior)
    rows_a, centres_a = np.array(rows, dtype=int), np.array(centres, dtype=int)
    f_peak, h_peak = _peak_maximum(model_transfer, rows_a, grid[centres_a - 1],
                                   grid[centres_a + 1], grid[centres_a],
                                   magnitude[rows_a, centres_a])
    out: list[list[Peak]] = [[] for _ in range(magnitude.shape[0])]
    for p, f, h in zip(rows_a, f_peak, h_peak, strict=True):
        if h < min_peak * largest[p]:
            continue
        static = abs(gain[p])
        # a static gain that is zero but for rounding (a yaw damper's force: the vehicle settles)
        # has no amplification to state
        meaningful = math.isfinite(static) and static > STATIC_GAIN_RTOL * largest[p]
        amplification = float(h / static) if meaningful else None
        out[p].append(Peak(float(f), float(h), amplification))
    return tuple(tuple(sorted(row, key=lambda peak: peak.f_hz)) for row in out)


def golden_section_maximum(evaluate, low, high, rtol: float, max_steps: int | None = None):
    """Golden-section search for the maximum of a function on brackets [low, high] where it is
    unimodal, every bracket of the arrays ``low``, ``high`` at once (one evaluation per step:
    ``evaluate(x)`` gives the values at the points ``x``, one per bracket), until every bracket
    is at most ``rtol`` times its upper end wide or after ``max_steps`` steps: (the argument, the
    value) of the better of the last two interior points of each bracket.  The one search of
    the frequency response's peaks and the Campbell diagram's crossings."""
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = np.array(low, dtype=float), np.array(high, dtype=float)
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    hc, hd = evaluate(c), evaluate(d)
    steps = 0
    while not np.all(b - a <= rtol * b) and (max_steps is None or steps < max_steps):
        left = hc > hd  # the maximum lies in [a, d]
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        new_c = np.where(left, b - ratio * (b - a), d)
        new_d = np.where(left, c, a + ratio * (b - a))
        h_new = evaluate(np.where(left, new_c, new_d))
        hc, hd = np.where(left, h_new, hd), np.where(left, hc, h_new)
        c, d = new_c, new_d
        steps += 1
    return np.where(hc > hd, c, d), np.maximum(hc, hd)


def _peak_maximum(model_transfer: ModalTransfer, rows: np.ndarray, low: np.ndarray,
                  high: np.ndarray, start_f: np.ndarray, start_h: np.ndarray):
    """The maximum of |H_row(f)| in [low, high] for every row at once
    (:func:`golden_section_maximum`; H unimodal there: the bracket holds one grid maximum); the
    best of the search and the grid point (start_f, start_h) is returned: (f [Hz], |H|)."""
    if not len(rows):
        return np.zeros(0), np.zeros(0)
    residues = model_transfer.residues[rows]
    drift = model_transfer.drift[rows]
    lam = model_transfer.eigenvalues
    direct = (np.zeros((len(rows), 2), dtype=complex) if model_transfer.feedthrough is None
              else model_transfer.feedthrough[rows])

    def evaluate(f: np.ndarray) -> np.ndarray:
        s = 2j * np.pi * f
        return np.abs(np.einsum("pj,pj->p", residues, 1.0 / (s[:, None] - lam[None, :]))
                      + drift / s + direct[:, 0] + direct[:, 1] * s)

    f_best, h_best = golden_section_maximum(evaluate, low, high, 1e-12, GOLDEN_ITERATIONS)
    better = h_best >= start_h
    return np.where(better, f_best, start_f), np.where(better, h_best, start_h)
