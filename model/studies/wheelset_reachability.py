"""Which published numbers a bogie can reach together (continued from
:mod:`model.studies.reachability`).

**(c) The wheelsets' longitudinal and yaw modes against the divergence.**  Table 1's ranks 7/8
(8.583/9.183 Hz) and 9/10 (12.208/12.580 Hz; Re −3.958/−4.010 at 0.005, +0.911/+0.809 at 0.014)
beside the +7.031 divergence.  :func:`creep_slope_relation` solves stage A over the creep-shape
box: R = ∂μ/∂s(0.005)/|∂μ/∂s(0.014)| stays near 3.3 for every law that meets the operating data.
:class:`WheelsetModel` is one wheelset on its guides under a clamped frame (x, ψ, the wheelset
side's and the drive's spin; the longitudinal creep 2 e² b11 on ψ and 2 b11 between x and r0 φ),
checked against the full model; :func:`key_inequality_ratio` is the I/J_eff that the study's
yaw real parts and its divergence need; :func:`yaw_proof` scans the plausible drives with the
longitudinal mode at its acceptance's upper end and reports the yaw frequencies reachable;
:func:`realize_case`, :func:`full_ranks` and :func:`frame_side_ranks` carry a case into the
full model (where the frame splits the wheelsets' in-phase pairs).

Plain dataclasses; numpy/scipy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq

from model.mechanics.parameters import Parameters
from model.studies.calibration_bounds import FREE_PARAMETERS
from model.studies.calibration_targets import (
    DIVERGENCE_RATES,
    S0_STABLE,
    TABLE1_IM_HZ,
    TABLE1_RE,
    TABLE1_UNSTABLE,
)
from model.studies.reachability import J2_RANGE

_BOUNDS = {f.name: f for f in FREE_PARAMETERS}
RANK7_HZ, RANK8_HZ, RANK9_HZ, RANK10_HZ = TABLE1_IM_HZ[6:10]  # [Hz] at s0 = 0.005
YAW_RE_STABLE = (TABLE1_RE[8], TABLE1_RE[9])  # [1/s] ranks 9, 10 at 0.005
YAW_RE_UNSTABLE = (TABLE1_UNSTABLE[8][0], TABLE1_UNSTABLE[9][0])  # [1/s] ranks 9, 10 at 0.014
RANK_TOLERANCE = 0.05  # [-] Table 1 by rank's acceptance
DIVERGENCE_TOLERANCE = 0.10  # [-] the divergence's acceptance
STAGE_A_TOLERANCE = 1e-3  # [-] the four operating data met to 0.1 % (the bundled set: 1e-15)
V_REF = 120 / 3.6  # [m/s]


@dataclass(frozen=True)
class CreepSlopes:
    """One creep shape (Polach's kA, kS and initial slope) with stage A solved for it: μ0, A, B
    and the gear ratio p from the four operating data, and the law's slopes at the two
    creepages."""

    kA: float
    kS: float
    slope: float  # initial creep slope [-]
    gear_ratio: float  # p [-]
    mu0: float
    A: float
    B: float  # [s/m]
    error: float  # largest relative error of the four operating data [-]
    dmu_stable: float  # ∂μ/∂s at 0.005 [-] (rising branch, > 0)
    dmu_unstable: float  # ∂μ/∂s at 0.014 [-] (falling branch, < 0)

    @property
    def ratio(self) -> float:
        """R = ∂μ/∂s(0.005) / |∂μ/∂s(0.014)| [-]."""
        return self.dmu_stable / -self.dmu_unstable

    @property
    def met(self) -> bool:
        """Whether stage A meets the four operating data (to :data:`STAGE_A_TOLERANCE`) on the
        law's falling branch at 0.014."""
        return self.error <= STAGE_A_TOLERANCE and self.dmu_unstable < 0 < self.dmu_stable


def creep_slope_relation(parameters: Parameters, points: int = 5) -> list[CreepSlopes]:
    """Stage A (:func:`model.studies.calibration.fit_operating_data`) on a grid of the creep
    shape box (kA, kS within their bounds with kS <= kA, the initial slope log-spaced within its
    bounds; ``points`` values each) from ``parameters``: every shape for which the law has a
    maximum, with its slopes at 0.005 and 0.014."""
    from model.mechanics.operating_point import creep_law
    from model.studies.calibration import fit_operating_data
    from model.studies.calibration_targets import operating_rows

    kA, kS, slope = (_BOUNDS[n] for n in ("polach_kA", "polach_kS", "creep_slope"))
    out = []
    for a in np.linspace(kA.low, kA.high, points):
        for s in np.linspace(kS.low, kS.high, points):
            if s > a:
                continue
            for k in np.geomspace(slope.low, slope.high, points):
                trial = parameters.replace(polach_kA=float(a), polach_kS=float(s),
                                           creep_slope=float(k))
                try:
                    fitted = fit_operating_data(trial)
                    error = max(abs(row.error) for row in operating_rows(fitted))
                except ValueError:  # no creep maximum below s = 1
                    continue
                law = creep_law(fitted)
                out.append(CreepSlopes(
                    float(a), float(s), float(k), fitted["gear_ratio"], fitted["polach_mu0"],
                    fitted["polach_A"], fitted["polach_B"], float(error),
                    float(law.dmu_ds(S0_STABLE, V_REF)), float(law.dmu_ds(0.014, V_REF))))
    return out


@dataclass(frozen=True)
class WheelsetModel:
    """One wheelset on its primary guides under a fixed frame, with its drive (SI units).

    Coordinates [x, ψ, φ, θ]: the wheelset's longitudinal displacement [m] and yaw [rad], the
    spin of the wheelset side beyond the disc clutch [rad] and of the drive (rotor, pinion and
    gear reduced to the wheelset's speed) [rad].  The guides (k_x per axle box at the journals'
    lateral places ±d) hold x with 2 k_x and ψ with 2 k_x d²; the drive's own parts (hollow
    shaft, clutches, the motor on its silent blocks) add ``drive_share_x`` and
    ``drive_share_yaw``.  The longitudinal creep at the two contacts (lateral places ±e) is the
    damper b11 = N0 ∂μ/∂s / v on each contact's slip velocity ẋ ∓ e ψ̇ − r0 φ̇ (eq. 14): on ψ it
    is 2 e² b11, on (x, φ) 2 b11 [[1, −r0], [−r0, r0²]]; Kalker's spin creep adds 2 b33 on ψ.
    The disc clutch joins φ and θ; the motor slope b_M p² acts on θ.  The yaw is a single
    degree of freedom here (the drive's lateral asymmetry, which couples it to x in the full
    model, is left out): λ² I + λ (2 e² b11 + 2 b33) + K_ψ = 0."""

    mass: float  # m [kg]: axle, wheel discs, rims, axle boxes, hollow shaft
    yaw_inertia: float  # I [kg m^2] about the vertical through the axle centre
    spin_inertia: float  # J_w [kg m^2]: the wheelset side beyond the disc clutch (the chain's J2)
    drive_inertia: float  # J1 = (J_rotor + J_pinion) p² + J_gear [kg m^2]
    guide_stiffness: float  # k_x per axle box [N/m]
    journal_half_distance: float  # d [m]
    contact_half_distance: float  # e [m]
    wheel_radius: float  # r0 [m]
    disc_clutch_stiffness: float  # [N m/rad]
    drive_share_x: float = 0.0  # [N/m]
    drive_share_yaw: float = 0.0  # [N m/rad]
    spin_creep: float = 0.0  # b33 per contact [N m s]
    motor: float = 0.0  # b_M p² on θ [N m s/rad]

    @property
    def stiffness_x(self) -> float:
        """K_x = 2 k_x + the drive's share [N/m]."""
        return 2 * self.guide_stiffness + self.drive_share_x

    @property
    def stiffness_yaw(self) -> float:
        """K_ψ = 2 k_x d² + the drive's share [N m/rad]."""
        return 2 * self.guide_stiffness * self.journal_half_distance**2 + self.drive_share_yaw

    def longitudinal_eigenvalues(self, b11: float) -> np.ndarray:
        """The six eigenvalues of (x, φ, θ) [1/s] with the creep damper b11 [N s/m] per contact."""
        r0, k = self.wheel_radius, self.disc_clutch_stiffness
        M = np.diag([self.mass, self.spin_inertia, self.drive_inertia])
        K = np.array([[self.stiffness_x, 0, 0], [0, k, -k], [0, -k, k]])
        B = 2 * b11 * np.array([[1, -r0, 0], [-r0, r0**2, 0], [0, 0, 0]]) \
            + np.diag([0, 0, self.motor])
        Minv = np.linalg.inv(M)
        A = np.block([[np.zeros((3, 3)), np.eye(3)], [-Minv @ K, -Minv @ B]])
        return np.linalg.eigvals(A)

    def longitudinal(self, b11: float) -> complex:
        """The longitudinal mode [1/s]: of the oscillating pairs the one nearest the undamped
        √(K_x/m) (the other is the drive's twisting on the disc clutch)."""
        lam = self.longitudinal_eigenvalues(b11)
        upper = lam[lam.imag > 0]
        guide = math.sqrt(self.stiffness_x / self.mass)
        return complex(upper[np.argmin(np.abs(upper.imag - guide))])

    def spin(self, b11: float) -> float:
        """The largest real eigenvalue [1/s]: the spin of the wheelset with its drive (> 0 on
        the falling creep slope; 0 for the free spin at b11 = 0)."""
        lam = self.longitudinal_eigenvalues(b11)
        real = lam[np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()].real
        return float(real.max())

    def yaw(self, b11: float) -> complex:
        """The yaw mode [1/s] (closed form; the upper root)."""
        c = 2 * self.contact_half_distance**2 * b11 + 2 * self.spin_creep
        a = -c / (2 * self.yaw_inertia)
        return complex(a, math.sqrt(self.stiffness_yaw / self.yaw_inertia - a * a))

    def b11_for_spin(self, rate: float) -> float:
        """The creep damper b11 < 0 [N s/m] whose spin is ``rate`` [1/s]."""
        r0 = self.wheel_radius
        rigid = -rate * (self.spin_inertia + self.drive_inertia) / (2 * r0**2)
        low = 1.5 * rigid
        while self.spin(low) < rate:
            low *= 2
        return brentq(lambda b: self.spin(b) - rate, low, 0.1 * rigid, xtol=1e-9, rtol=1e-12)

    def with_longitudinal_at(self, frequency_hz: float, b11: float) -> WheelsetModel:
        """The same wheelset with the guide stiffness k_x that puts the longitudinal mode at
        ``frequency_hz`` with the creep damper b11 (k_x may leave its bounds: the caller checks)."""
        def error(log_k: float) -> float:
            trial = replace(self, guide_stiffness=math.exp(log_k))
            return trial.longitudinal(b11).imag / (2 * math.pi) - frequency_hz

        return replace(self, guide_stiffness=math.exp(brentq(error, math.log(1e5),
                                                             math.log(1e9), xtol=1e-12)))


def _clamped_drive(parameters: Parameters, b11: float | None = None):
    """The full model's drive 1 alone under a clamped frame: (M, B, K, names) at s0 = 0.005 with
    the set's creep, or with the longitudinal creep damper replaced by ``b11`` [N s/m]."""
    from model.mechanics.assembly import build_model
    from model.mechanics.operating_point import creep_coefficients, creep_damping
    from model.studies.calibration_targets import reference_point

    model = build_model(parameters)
    op = reference_point(parameters, S0_STABLE)
    coefficients = creep_coefficients(parameters, op)
    if b11 is not None:
        coefficients = replace(coefficients, b11=b11)
    B = model.B + creep_damping(model, coefficients)  # ID1: no motor slope
    keep = [i for i, name in enumerate(model.dofs.names) if name.startswith("ID1.")]
    index = np.ix_(keep, keep)
    return model.M[index], B[index], model.K[index], [model.dofs.names[i] for i in keep], model


def clamped_modes(parameters: Parameters, b11: float | None = None) -> dict[str, complex]:
    """The clamped drive's longitudinal and yaw modes and its largest real eigenvalue [1/s]: the
    pairs with the largest axle-centre x and yaw (times the contact half distance) in their
    mode shapes."""
    M, B, K, names, _ = _clamped_drive(parameters, b11)
    n = len(names)
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ B]])
    lam, V = np.linalg.eig(A)
    ix, iz = names.index("ID1.ax13.x"), names.index("ID1.ax13.rz")
    e = parameters["contact_half_distance"]
    best = {"longitudinal": (0.0, 0j), "yaw": (0.0, 0j)}
    for i in np.flatnonzero((lam.imag > 2 * math.pi * 3) & (lam.imag < 2 * math.pi * 30)):
        q = V[:n, i] / np.abs(V[:n, i]).max()
        for key, share in (("longitudinal", abs(q[ix])), ("yaw", e * abs(q[iz]))):
            if share > best[key][0]:
                best[key] = (share, complex(lam[i]))
    real = lam[np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()].real
    return {"longitudinal": best["longitudinal"][1], "yaw": best["yaw"][1],
            "spin": complex(real.max())}


def wheelset_model(parameters: Parameters) -> WheelsetModel:
    """The reduced model of ``parameters``' wheelset: masses and inertias from the full model's
    mass matrix moved rigidly (the wheelset with its hollow shaft in x, ψ, φ; the drive's rigid
    spin reduced to the wheelset), the drive's stiffness shares from the frequencies of the full
    model's drive under a clamped frame with no longitudinal creep (b11 = 0: its longitudinal
    and yaw modes are then the undamped √(K_x/m), √(K_ψ/I))."""
    from model.mechanics.operating_point import kalker

    model = _clamped_drive(parameters)[4]
    full = model.dofs.names
    rigid = {"x": np.zeros(len(full)), "rz": np.zeros(len(full)), "ry": np.zeros(len(full))}
    for i, name in enumerate(full):
        part, axis = name.rsplit(".", 1)
        if not any(part.startswith(f"ID1.{g}") for g in ("ax", "rim", "hs")):
            continue
        if axis in rigid:
            rigid[axis][i] = 1.0
        if axis == "x":  # yaw about the axle centre moves a node at y by −ψ y
            rigid["rz"][i] = -float(np.real(model.positions[part][1]))
    spin_column = np.argmax(np.abs(model.rigid_body_modes[full.index("ID1.rotor.ry")]))
    spin = model.rigid_body_modes[:, spin_column] / model.rigid_body_modes[
        full.index("ID1.ax13.ry"), spin_column]
    drive = np.where(rigid["ry"] > 0, 0.0, spin)
    drive[[i for i, name in enumerate(full) if not name.startswith("ID1.")]] = 0.0
    m, I_yaw, Jw, J1 = (float(r @ model.M @ r)
                        for r in (rigid["x"], rigid["rz"], rigid["ry"], drive))
    p = parameters
    b33 = kalker(p, p["wheel_force"]).f33 / V_REF
    base = WheelsetModel(m, I_yaw, Jw, J1, p["primary_stiffness_x"], p["journal_half_distance"],
                         p["contact_half_distance"], p["wheel_radius"],
                         p["disc_clutch_torsional_stiffness"], spin_creep=b33)
    free = clamped_modes(parameters, b11=0.0)
    wx, wz = abs(free["longitudinal"]), abs(free["yaw"])
    return replace(base, drive_share_x=m * wx**2 - 2 * base.guide_stiffness,
                   drive_share_yaw=I_yaw * wz**2 - base.stiffness_yaw)


@dataclass(frozen=True)
class WheelsetCase:
    """One plausible wheelset of the scan, its guides set to put the longitudinal mode at the
    scan's cap, and its modes (frequencies [Hz], real parts [1/s])."""

    kA: float
    kS: float
    creep_slope: float
    ratio: float  # R of its creep law
    gear_ratio: float
    J_rotor: float  # [kg m^2]
    spin_inertia: float  # J_w [kg m^2]
    drive_inertia: float  # J1 [kg m^2]
    spin_rate: float  # [1/s] the divergence it is set to
    b11_unstable: float  # [N s/m] the creep damper at 0.014 that gives it
    b11_stable: float  # [N s/m] R times its magnitude, at 0.005
    longitudinal_cap_hz: float  # [Hz] where the longitudinal mode is put
    guide_stiffness: float  # [N/m] the k_x that puts it there
    longitudinal_re: float  # [1/s] at 0.005
    yaw_hz: float  # at 0.005
    yaw_re: float  # at 0.005
    yaw_hz_unstable: float  # at 0.014
    yaw_re_unstable: float  # at 0.014

    @property
    def within_bounds(self) -> bool:
        """k_x within its calibration bounds."""
        return _BOUNDS["primary_stiffness_x"].low <= self.guide_stiffness \
            <= _BOUNDS["primary_stiffness_x"].high

    @property
    def effective_spin_inertia(self) -> float:
        """J_eff = −2 r0² b11(0.014) / spin rate [kg m^2]: the inertia a rigid drive with the
        same creep damper would spin up with (r0 = 0.625 m)."""
        return -2 * 0.625**2 * self.b11_unstable / self.spin_rate

    @property
    def yaw_re_within_acceptance(self) -> bool:
        """Its yaw real part at 0.005 within 30 % of rank 9's or rank 10's published one (the
        literature tests' acceptance)."""
        return any(abs(self.yaw_re / published - 1) <= 0.3 for published in YAW_RE_STABLE)


@dataclass(frozen=True)
class YawProof:
    """The scan of the plausible wheelsets against ranks 7–10 and the divergence."""

    wheelset: WheelsetModel  # the set's, as identified
    creep: list[CreepSlopes]  # the creep shapes scanned (met and not)
    cases: list[WheelsetCase]
    inertia_ratio_needed: dict  # Table 1 row (9, 10) -> (least, largest) I/J_eff that the
    # study's yaw real parts at both creepages and its divergence need, over the R of the creep
    # laws that meet the operating data (:func:`key_inequality_ratio`)

    def best(self, cap_hz: float, yaw_re_within_acceptance: bool = False,
             exact_divergence: bool = False, max_spin_inertia: float = math.inf) -> WheelsetCase:
        """The case with the highest yaw frequency at 0.005 among those with the longitudinal
        mode at ``cap_hz`` [Hz] and k_x within its bounds (and, if asked, its yaw real part at
        0.005 within the acceptance, its divergence the published one, its J_w at most
        ``max_spin_inertia`` [kg m^2])."""
        return max((c for c in self.cases if c.longitudinal_cap_hz == cap_hz and c.within_bounds
                    and (c.yaw_re_within_acceptance or not yaw_re_within_acceptance)
                    and (c.spin_rate == DIVERGENCE_RATES[0] or not exact_divergence)
                    and c.spin_inertia <= max_spin_inertia),
                   key=lambda c: c.yaw_hz)

    @property
    def ratio_range(self) -> tuple[float, float]:
        """The least and largest R of the creep laws that meet the operating data."""
        ratios = [c.ratio for c in self.creep if c.met]
        return min(ratios), max(ratios)


def key_inequality_ratio(ratio: float, published_stable: float, published_unstable: float,
                         spin_rate: float = DIVERGENCE_RATES[0], e: float = 0.75,
                         r0: float = 0.625) -> float:
    """I/J_eff [-] that a single-DOF yaw (λ² I + λ (2 e² b11 + d) + K_ψ = 0, d >= 0 the yaw's
    damping other than the longitudinal creep) needs to have the published yaw real parts at
    0.005 and 0.014 together with the divergence ``spin_rate`` [1/s] (J_eff = −2 r0² b11(0.014)
    / spin_rate, the drive's effective spin inertia), when its creep law has
    R = ∂μ/∂s(0.005)/|∂μ/∂s(0.014)| = ``ratio``.  To first order Re = −(2 e² b11 + d)/(2 I), so
    d drops out of the difference: Re(0.014) − Re(0.005) = (R + 1) e² N0 |μ'14| / (v I), which
    with the divergence 2 r0² N0 |μ'14| / (v J_eff) gives I/J_eff = e² spin_rate (R + 1) /
    (2 r0² (Re14 − Re5)); d = X − Re14 >= 0 (X = e² N0 |μ'14| / (v I)) needs R <= −Re5/Re14."""
    return e**2 * spin_rate * (ratio + 1) / (2 * r0**2 * (published_unstable - published_stable))


def yaw_proof(parameters: Parameters, points: int = 5, creep_points: int = 5) -> YawProof:
    """Scan the plausible wheelsets: each creep shape whose stage A meets the operating data
    (:func:`creep_slope_relation`, its R and gear ratio) x J_rotor within its bounds x J_w within
    :data:`J2_RANGE` (``points`` values each, log-spaced) x the divergence at 0.9, 1.0, 1.1 times
    +7.031 1/s; each with b11(0.014) set by the reduced model's spin, b11(0.005) = R |b11(0.014)|,
    and the guide stiffness that puts the longitudinal mode at rank 7's or rank 8's upper
    acceptance (8.583 and 9.183 Hz + 5 %); the yaw mode there.  The wheelset's mass, yaw
    inertia and the drive's stiffness shares are the set's (:func:`wheelset_model`)."""
    base = wheelset_model(parameters)
    creep = creep_slope_relation(parameters, creep_points)
    rotor = _BOUNDS["rotor_inertia"]
    J_pinion, J_gear = parameters["pinion_inertia"], parameters["gear_inertia"]
    caps = tuple((1 + RANK_TOLERANCE) * f for f in (RANK7_HZ, RANK8_HZ))
    rates = tuple(DIVERGENCE_RATES[0] * f for f in (1 - DIVERGENCE_TOLERANCE, 1.0,
                                                     1 + DIVERGENCE_TOLERANCE))
    cases = []
    for shape in (c for c in creep if c.met):
        for J_rotor in np.geomspace(rotor.low, rotor.high, points):
            J1 = (J_rotor + J_pinion) * shape.gear_ratio**2 + J_gear
            for Jw in np.geomspace(*J2_RANGE, points):
                wheelset = replace(base, spin_inertia=float(Jw), drive_inertia=float(J1))
                for rate in rates:
                    b14 = wheelset.b11_for_spin(rate)
                    b5 = -shape.ratio * b14
                    for cap in caps:
                        tuned = wheelset.with_longitudinal_at(cap, b5)
                        yaw5, yaw14 = tuned.yaw(b5), tuned.yaw(b14)
                        cases.append(WheelsetCase(
                            shape.kA, shape.kS, shape.slope, shape.ratio, shape.gear_ratio,
                            float(J_rotor), float(Jw), float(J1), rate, b14, b5, cap,
                            tuned.guide_stiffness, tuned.longitudinal(b5).real,
                            yaw5.imag / (2 * math.pi), yaw5.real, yaw14.imag / (2 * math.pi),
                            yaw14.real))
    ratios = [c.ratio for c in creep if c.met]
    needed = {row: tuple(key_inequality_ratio(R, s, u, e=base.contact_half_distance,
                                              r0=base.wheel_radius)
                         for R in (min(ratios), max(ratios)))
              for row, s, u in zip((9, 10), YAW_RE_STABLE, YAW_RE_UNSTABLE, strict=True)}
    return YawProof(base, creep, cases, needed)


def realize_case(parameters: Parameters, case: WheelsetCase) -> Parameters:
    """``parameters`` carrying a scanned case into the full model: the case's kA and kS with the
    initial creep slope that gives its ∂μ/∂s(0.014) (stage A re-solved), its rotor inertia,
    its J_w (the wheel discs' and rims' polar inertias scaled alike) and its guide stiffness.
    ValueError if no initial slope within its bounds (searched within x8 of the case's own)
    gives that ∂μ/∂s(0.014)."""
    from model.mechanics.operating_point import creep_law
    from model.studies.calibration import fit_operating_data

    wanted = case.b11_unstable * V_REF / parameters["wheel_force"]
    shaped = parameters.replace(polach_kA=case.kA, polach_kS=case.kS,
                                rotor_inertia=case.J_rotor)

    def fitted(log_slope: float) -> Parameters:
        return fit_operating_data(shaped.replace(creep_slope=math.exp(log_slope)))

    def error(log_slope: float) -> float:  # |μ'(0.014)| falls as the initial slope rises
        try:
            dmu = float(creep_law(fitted(log_slope)).dmu_ds(0.014, V_REF))
        except ValueError:  # no creep maximum: a slope far too small for the operating data
            return 10.0
        return math.log(-dmu / -wanted) if dmu < 0 else 10.0

    bounds = _BOUNDS["creep_slope"]
    low = math.log(max(bounds.low, case.creep_slope / 8))
    high = math.log(min(bounds.high, case.creep_slope * 8))
    if error(low) * error(high) > 0:
        raise ValueError(f"no initial creep slope within its bounds gives ∂μ/∂s(0.014) = "
                         f"{wanted:.3g} with kA = {case.kA:.3g}, kS = {case.kS:.3g}")
    out = fitted(brentq(error, low, high, xtol=1e-6))
    rim, disc = out["rim_polar_inertia"], out["wheel_disc_polar_inertia"]
    scale = 1 + (case.spin_inertia - wheelset_model(out).spin_inertia) / (2 * (rim + disc))
    return out.replace(rim_polar_inertia=rim * scale, wheel_disc_polar_inertia=disc * scale,
                       primary_stiffness_x=case.guide_stiffness)


@dataclass(frozen=True)
class FullRanks:
    """Ranks 7–10 of the full model (frequencies [Hz] and real parts [1/s] at 0.005) and its
    largest real eigenvalue at 0.014 [1/s]."""

    frequencies_hz: tuple[float, ...]
    real_parts: tuple[float, ...]
    divergence: float

    @property
    def errors(self) -> tuple[float, ...]:
        """Relative frequency errors against ranks 7–10 [-]."""
        return tuple(f / t - 1 for f, t in zip(self.frequencies_hz, TABLE1_IM_HZ[6:10],
                                                strict=True))


def full_ranks(parameters: Parameters) -> FullRanks:
    """The full model's ranks 7–10 at s0 = 0.005 and its divergence at 0.014."""
    from model.analysis.eigen import eigen_analysis
    from model.mechanics.assembly import build_model
    from model.studies.calibration_targets import reference_point

    model = build_model(parameters)
    stable = eigen_analysis(model, reference_point(parameters, S0_STABLE), vectors=False)
    unstable = eigen_analysis(model, reference_point(parameters, 0.014), vectors=False)
    pairs = stable.complex_pairs[6:10]
    return FullRanks(tuple(float(lam.imag / (2 * math.pi)) for lam in pairs),
                     tuple(float(lam.real) for lam in pairs), float(unstable.real_eigenvalues[0]))


# the frame's side of the wheelsets' in-phase modes: what holds the frame longitudinally and in
# yaw (the yaw dampers with their bushes, the traction link, the frame's yaw inertia) and the
# wheelsets' lateral guides and the motors' silent blocks
FRAME_SIDE = ("yaw_damping", "yaw_damper_series_stiffness", "traction_link_stiffness",
              "frame_inertia_z", "primary_stiffness_y", "silent_block_stiffness_x",
              "secondary_damping_y")


def frame_side_ranks(parameters: Parameters) -> dict[str, FullRanks]:
    """:func:`full_ranks` with each :data:`FRAME_SIDE` parameter at its lower and at its upper
    calibration bound, one at a time (the frame's yaw inertia kept within its triangle
    inequalities); keys ``"name=value"``."""
    from model.studies.calibration_bounds import with_constraints

    out = {}
    for name in FRAME_SIDE:
        for value in (_BOUNDS[name].low, _BOUNDS[name].high):
            out[f"{name}={value:g}"] = full_ranks(with_constraints(parameters.replace(
                **{name: value})))
    return out
