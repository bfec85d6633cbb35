"""Sensitivities (model/analysis/sensitivity.py) and the uncertainty pipeline (model/studies/uncertainty.py).

* analytic dλ/dp against fourth-order central differences of eigenvalues (test-only) for every
  parameter and s0, v, N0, b_M at three operating points (slow).  Tolerance 1e-5 relative to the
  parameter's largest derivative over the ten modes (1e-3 for the few that hardly move the modes,
  see WEAK).  The reference's step h is chosen so that the
  largest eigenvalue change is 1e-3 of |λ| (capped at 5 % of the parameter), and the best of the
  steps h/4 … 4h counts (a wrong derivative disagrees at every step): the eigenvalues of the
  386-state problem carry rounding noise (condition numbers up to 1.6e7 among the ten modes),
  so a parameter that hardly moves the ten lowest modes (shaft_loss_time, the gear mesh:
  p |dλ/dp| ≈ 1e-5…2e-4 |λ|) needs a large step, while a 5 % step of a strongly nonlinear one
  leaves a truncation error of ~2.5e-5 (both measured: with one fixed step, 1e-3 relative, the
  references disagreed with themselves by up to 1e-3; with 5 % alone, ten parameters missed by
  1.2-3.5e-5; with h/4 … h, shaft_loss_time still missed by 1.8-3.2e-4);
* completeness (Euler's theorem for homogeneous functions): all masses, stiffnesses and dampers
  scaled by one factor leave every eigenvalue unchanged, so the sensitivities summed along that
  direction vanish; and the derivative matrices sum to M, K, B along it;
* the rigid-body spin's damping: only the creep acts on it, so s0* is the creep maximum and no
  structural parameter moves it (checked by recomputing s0* with a changed parameter);
* the Sobol pipeline on the Ishigami function (known indices);
* bad input: one line, exit status 2.
"""

from __future__ import annotations

import numpy as np
import pytest

from app.cli.main import main
from model.analysis.eigen import eigen_analysis
from model.analysis.sensitivity import (
    NOT_IN_ASSEMBLY,
    OPERATING_PARAMETERS,
    MatrixDerivative,
    SensitivityError,
    complex_step_parameters,
    eigen_sensitivities,
    null_vectors,
    structural_derivatives,
)
from model.analysis.stability import stability_limit
from model.mechanics.assembly import build_model
from model.mechanics.operating_point import KMH, OperatingPoint, creep_law, damping_matrix
from model.mechanics.parameters import SCHEMA, Parameters, load_parameters
from model.studies.uncertainty import UncertaintyError, run_uncertainty, sobol_study


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    return parameters, build_model(parameters)


def _op(parameters, s0, v_kmh=120.0):
    return OperatingPoint(s0, v_kmh * KMH, parameters["wheel_force"], parameters["motor_slope"])


def _eigenvalues(parameters, model, op, name, value):
    if name in OPERATING_PARAMETERS:
        return eigen_analysis(model, OperatingPoint(**{**op.__dict__, name: value}),
                              vectors=False).eigenvalues
    values = dict(parameters.values)
    values[name] = value
    return eigen_analysis(build_model(Parameters(values)), op, vectors=False).eigenvalues


# Parameters that hardly move the ten modes (|p| max|dλ/dp| < WEAK · min|λ|: shaft_loss_time
# 7.7e-6, pressure_angle 5.5e-5, gear_mesh_stiffness 2.2e-4, track_mass 2.3e-4 at s0 = 0.005):
# the differences of eigenvalues cannot resolve 1e-5 of their derivatives (measured at s0 = 0.005
# over the steps h/4 … 4h: best 1.7e-4, 2.1e-5, 2.5e-5, 2.9e-6 — the references scatter by as much
# between neighbouring steps); they are checked at WEAK_TOLERANCE, and their derivative matrices
# are covered exactly by the Euler checks below.
# a parameter whose |p|·max|dλ/dp| is below WEAK·min|λ| hardly moves the ten modes: the
# differences cannot resolve 1e-5 for it (on the calibrated set the driving shaft at s0 = 0.008,
# influence 1.5e-3: best error 1.1e-5 over the steps, no convergence — rounding)
WEAK, WEAK_TOLERANCE = 2e-3, 1e-3


NEAR_DEFECTIVE_CONDITION = 1e8  # the other modes' condition numbers are 1e4-1e7
# s0 = 0.005 stable, 0.0080 just below the limit (s0* = 0.0082), 0.014 unstable (Table 1)
@pytest.mark.slow
@pytest.mark.parametrize("s0", [0.005, 0.0080, 0.014])
def test_against_finite_differences(setup, s0):
    parameters, model = setup
    op = _op(parameters, s0)
    sens = eigen_sensitivities(model, op)
    assert sens.reliable.all()
    # a pair next to an exceptional point (two real eigenvalues about to meet: on the calibrated
    # set the vehicle's longitudinal motion against ID2's disc clutch at s0 = 0.014,
    # +1.99 ± 0.0056i 1/s, condition 5e10) moves as the square root of a perturbation: the
    # fourth-order differences below are not in their asymptotic range there (2e-4), the
    # analytic derivative is; such a mode is left out of the comparison, at most one
    near_defective = sens.condition > NEAR_DEFECTIVE_CONDITION
    assert np.count_nonzero(near_defective) <= 1
    assert np.all(np.abs(sens.eigenvalues[near_defective].imag)
                  < 0.01 * np.abs(sens.eigenvalues[near_defective]))
    lam = sens.eigenvalues
    failures = []
    for i, name in enumerate(sens.names):
        analytic = sens.derivatives[i]
        largest = np.abs(analytic).max()
        if largest == 0.0:  # e.g. motor_slope at a fixed b_M: no entry at all; checked below
            continue
        value = sens.values[i]
        h = 1e-3 * np.abs(lam).min() / largest
        if value != 0.0:
            h = min(h, 0.05 * abs(value))
        if name in ("wheel_radius", "rail_head_radius"):  # Kalker's table is piecewise linear in
            h = min(h, 1e-3 * abs(value))  # a/b (1.629; next node 1.667): stay between its nodes
        if name == "polach_kA":  # at its upper bound 1: the law is analytic beyond it
            h = min(h, 0.01)
        ev: dict[float, np.ndarray] = {}  # eigenvalues at value + c h/4, computed when needed

        def at(c, name=name, value=value, h=h, ev=ev):
            if c not in ev:
                ev[c] = _eigenvalues(parameters, model, op, name, value + c * h / 4)
            return ev[c]

        pick = lambda e, target: e[np.argmin(np.abs(e - target))]  # noqa: E731
        influence = abs(value) * largest / np.abs(lam).min()
        tolerance = 1e-5 if value == 0.0 or influence >= WEAK else WEAK_TOLERANCE
        errors = []
        # steps h/8 … 4h: the best step of the reference is not known.  h/8 since the set
        # calibrated by rank: its wheelsets' yaw pair (12.04 / 12.07 Hz) lies near the frame's
        # lateral–roll (12.42 Hz) and bends strongly with the frame's and motors' roll inertias
        # (best error at h/4 … 4h 6.9e-5 and 4.0e-5, at h/8 4.7e-6 and 5.1e-6).  The parameter
        # passes when any step's error is within the tolerance: the steps are tried in the order
        # they are most often the best, and the first within it ends the search (the eigenvalues
        # of the remaining steps, two full analyses per step, are not computed).
        for k in (1, 2, 0.5, 4, 8, 16):
            fd = np.array([(-pick(at(2 * k), t) + 8 * pick(at(k), t) - 8 * pick(at(-k), t)
                            + pick(at(-2 * k), t)) / (12 * k * h / 4) for t in lam])
            errors.append(np.abs(analytic - fd)[~near_defective].max() / np.abs(fd).max())
            if errors[-1] <= tolerance:
                break
        if min(errors) > tolerance:
            failures.append(f"{name}: {min(errors):.2e} (influence {influence:.1e})")
    assert not failures, f"at s0 = {s0}: " + ", ".join(failures)


def test_unlinked_motor_slope_and_linked_rows(setup):
    parameters, model = setup
    op = _op(parameters, 0.005)
    free = eigen_sensitivities(model, op, parameters=["motor_slope", "wheel_force"])
    assert np.all(free.row("motor_slope") == 0)  # b_M of the operating point is fixed
    linked = eigen_sensitivities(model, op, linked=["motor_slope", "wheel_force"],
                                 parameters=["motor_slope", "wheel_force"])
    np.testing.assert_array_equal(linked.row("motor_slope"), free.row("b_M"))
    np.testing.assert_allclose(linked.row("wheel_force"), free.row("wheel_force") + free.row("N0"))


def test_not_in_assembly_is_true(setup):
    """The parameters skipped by structural_derivatives really do not enter M, B, K."""
    parameters, _model = setup
    for name in sorted(NOT_IN_ASSEMBLY):
        perturbed = build_model(complex_step_parameters(parameters, name, 1e-20))
        for matrix in (perturbed.M, perturbed.B, perturbed.K):
            assert np.all(np.imag(matrix) == 0), name


def _homogeneous_direction():
    masses = [n for n, (unit, _, _) in SCHEMA.items() if unit in ("kg", "kg m^2", "kg/m^3")]
    stiffnesses = [n for n, (unit, _, _) in SCHEMA.items()
                   if unit in ("N/m", "N m/rad") or n == "young_modulus"]
    dampers = [n for n, (unit, _, _) in SCHEMA.items() if unit == "N s/m"]
    return masses, stiffnesses, dampers


def test_euler_matrices(setup):
    """Σ p ∂M/∂p over the masses = M, Σ p ∂K/∂p over the stiffnesses = K, and B (structural) is
    reproduced by stiffnesses (loss-time dampers) plus dampers: no parameter is missing."""
    parameters, model = setup
    derivatives = structural_derivatives(model)
    masses, stiffnesses, dampers = _homogeneous_direction()

    def summed(names, which):
        total = np.zeros((model.n, model.n))
        for name in names:
            d = derivatives.get(name)
            if d is not None and getattr(d, which) is not None:
                total[np.ix_(d.index, d.index)] += parameters[name] * getattr(d, which)
        return total

    np.testing.assert_allclose(summed(masses, "M"), model.M, atol=1e-9 * np.abs(model.M).max())
    np.testing.assert_allclose(summed(stiffnesses, "K"), model.K, atol=1e-9 * np.abs(model.K).max())
    np.testing.assert_allclose(summed(stiffnesses + dampers, "B"), model.B,
                               atol=1e-9 * np.abs(model.B).max())


@pytest.mark.parametrize("s0", [0.005, 0.014])
def test_euler_eigenvalues(setup, s0):
    """Scaling M, K and all damping (structural, b_M, B_ad) by one factor leaves λ unchanged:
    Σ p ∂λ/∂p along that direction + the B_ad and b_M terms = 0 (to 1e-8 of the terms)."""
    parameters, model = setup
    op = _op(parameters, s0)
    masses, stiffnesses, dampers = _homogeneous_direction()
    result = eigen_analysis(model, op)
    indices = result.complex_index[:10]
    lam = result.eigenvalues[indices]
    B_total = damping_matrix(model, op)
    X = np.empty((model.n, len(lam)), complex)
    Y = np.empty_like(X)
    for k, i in enumerate(indices):
        X[:, k], Y[:, k] = null_vectors(model, B_total, lam[k], result.vectors[:model.n, i])
    denominator = np.einsum("ik,ik->k", Y.conj(), 2 * lam * (model.M @ X) + B_total @ X)
    derivatives = structural_derivatives(model)
    total = np.zeros(len(lam), complex)
    magnitude = np.zeros(len(lam))
    for name in masses + stiffnesses + dampers:
        if name in derivatives:
            term = -parameters[name] * derivatives[name].quadratic(lam, X, Y) / denominator
            total += term
            magnitude += np.abs(term)
    operating = B_total - model.B  # b_M B_M + B_ad: scaled with the rest
    index = np.arange(model.n)
    term = -MatrixDerivative(index, None, operating, None).quadratic(lam, X, Y) / denominator
    total += term
    magnitude += np.abs(term)
    assert np.all(np.abs(total) <= 1e-8 * magnitude), np.abs(total) / magnitude


def test_limit_is_creep_maximum_and_structure_cannot_move_it(setup):
    parameters, model = setup
    from model.analysis.sensitivity import limit_sensitivity

    v, N0, b_M = 120 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    limit = limit_sensitivity(model, v, N0, b_M)
    s_max, _ = creep_law(parameters, N0).maximum(v)
    assert limit.mechanism == "creep maximum"
    assert abs(limit.s0_limit - s_max) < 1e-6
    d = dict(zip(limit.names, limit.derivatives, strict=True))
    assert d["disc_clutch_torsional_stiffness"] == 0.0
    assert d["polach_B"] != 0.0
    # a 30 % stiffer disc clutch: s0* unchanged (within Brent's xtol 1e-7)
    stiffer = build_model(parameters.replace(
        disc_clutch_torsional_stiffness=1.3 * parameters["disc_clutch_torsional_stiffness"]))
    assert abs(stability_limit(stiffer, v, N0, b_M).s0_limit - limit.s0_limit) < 2e-7
    # polach_B: the implicit-function derivative against the creep maximum's central difference
    h = 1e-4 * parameters["polach_B"]
    up = creep_law(parameters.replace(polach_B=parameters["polach_B"] + h), N0).maximum(v)[0]
    down = creep_law(parameters.replace(polach_B=parameters["polach_B"] - h), N0).maximum(v)[0]
    assert d["polach_B"] == pytest.approx((up - down) / (2 * h), rel=1e-5)


def test_limit_sensitivity_finds_the_critical_eigenvalue_without_the_full_analysis(setup,
                                                                                 monkeypatch):
    """At the creep maximum λc is found by block inverse iteration at 0 on the deflated state
    matrix, without any eigen-analysis (counted: none), at 120 and 200 km/h; the same
    derivatives and mechanism as with the full eigen-analysis, and λc at the rounding level of
    that analysis' eigenvalue nearest to 0 (both drivetrains' spins sit at 0 to working
    precision there: |λ| ≤ 1e-3 1/s, while the next real eigenvalue is ≈ -0.055 1/s).  A single
    vector stalled between the two spins and fell back to the full analysis unnoticed."""
    import model.analysis.sensitivity as sensitivity
    from model import eigen_analysis

    parameters, model = setup
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    full_analysis = sensitivity.eigen_analysis
    calls = []
    for v in (120 * KMH, 200 * KMH):
        s0_limit = sensitivity.limit_sensitivity(model, v, N0, b_M).s0_limit
        calls.clear()
        monkeypatch.setattr(sensitivity, "eigen_analysis",
                            lambda *args, **kw: calls.append(kw) or full_analysis(*args, **kw))
        fast = sensitivity.limit_sensitivity(model, v, N0, b_M, s0_limit=s0_limit)
        assert calls == []  # the shortcut found λc
        monkeypatch.setattr(sensitivity, "eigen_analysis", full_analysis)
        full_eigenvalues = eigen_analysis(model, OperatingPoint(s0_limit, v, N0, b_M),
                                          vectors=False).eigenvalues
        nearest = full_eigenvalues[np.argmin(np.abs(full_eigenvalues))]
        assert abs(nearest) < 1e-3
        assert fast.critical_eigenvalue.imag == 0.0
        assert abs(fast.critical_eigenvalue) < 1e-3
        monkeypatch.setattr(sensitivity, "_real_eigenvalue_nearest_zero", lambda *args, **kw: None)
        full = sensitivity.limit_sensitivity(model, v, N0, b_M, s0_limit=s0_limit)
        monkeypatch.undo()
        assert full.mechanism == fast.mechanism == "creep maximum"
        np.testing.assert_array_equal(full.derivatives, fast.derivatives)


def test_unknown_parameter(setup):
    parameters, model = setup
    with pytest.raises(SensitivityError, match="unknown parameter 'nope'"):
        eigen_sensitivities(model, _op(parameters, 0.005), parameters=["nope"])


def test_ishigami_sobol_indices():
    """Ishigami f = sin x1 + 7 sin² x2 + 0.1 x3⁴ sin x1 on [−π, π]³ (a = 7, b = 0.1): first order
    (0.3139, 0.4424, 0), total (0.5576, 0.4424, 0.2437) (Saltelli et al., Global Sensitivity
    Analysis: The Primer, 2008).  With n = 4096 the estimates sit within 0.03 of them and inside
    their bootstrap intervals widened by 0.02."""
    from scipy import stats

    def ishigami(chunk):
        x1, x2, x3 = np.atleast_2d(chunk).T
        return (np.sin(x1) + 7 * np.sin(x2) ** 2 + 0.1 * x3**4 * np.sin(x1))[:, None]

    calls = []

    def counting_map(func, chunks):  # a map-like executor: every chunk goes through it
        for chunk in chunks:
            calls.append(len(chunk))
            yield func(chunk)

    dists = [stats.uniform(-np.pi, 2 * np.pi)] * 3
    runs, samples, values, first, total, first_ci, _total_ci = sobol_study(
        ishigami, dists, 4096, map_fn=counting_map, chunk_size=1000, n_resamples=99)
    assert runs == 4096 * 5 == sum(calls)
    assert samples.shape == (8192, 3)
    assert values.shape == (8192, 1)
    # the recorded outputs are the function's own (scipy centres its copies in place): mean a/2
    np.testing.assert_allclose(values, ishigami(samples))
    assert values.mean() == pytest.approx(3.5, abs=0.1)
    np.testing.assert_allclose(first[0], [0.3139, 0.4424, 0.0], atol=0.03)
    np.testing.assert_allclose(total[0], [0.5576, 0.4424, 0.2437], atol=0.03)
    assert np.all(first_ci[0, 0] - 0.02 <= [0.3139, 0.4424, 0.0])
    assert np.all([0.3139, 0.4424, 0.0] <= first_ci[1, 0] + 0.02)


def test_uncertainty_bad_input(setup):
    parameters, _ = setup
    with pytest.raises(UncertaintyError, match="power of 2"):
        run_uncertainty(parameters, 3)
    with pytest.raises(UncertaintyError, match="power of 2"):
        run_uncertainty(parameters, 1)


@pytest.mark.parametrize(("argv", "message"), [
    (["sensitivity", "--s0", "0.005", "--only", "nope"], "unknown parameter 'nope'"),
    (["sensitivity", "--s0", "2"], "--s0"),
    (["uncertainty", "--samples", "1"], "power of 2"),
    (["uncertainty", "--samples", "6"], "power of 2"),
    (["uncertainty", "--samples", "x"], "invalid int"),
    (["uncertainty", "--samples", "4", "--out", "/no/such/dir/u.json"], "does not exist"),
])
def test_cli_bad_input(argv, message, capsys):
    try:
        status = main(argv)
    except SystemExit as stop:  # argparse's own errors (one line, see app.cli.options.BogieParser)
        status = stop.code
    assert status == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1


def test_cli_json_keys(capsys):
    import json

    status = main(["sensitivity", "--s0", "0.005", "--v", "120", "--json",
                   "--only", "disc_clutch_torsional_stiffness,polach_B"])
    assert status == 0
    data = json.loads(capsys.readouterr().out)
    assert {"operating_point", "modes", "parameters"} <= set(data)
    assert len(data["modes"]) == 10
    assert {"re", "im_hz", "description"} <= set(data["modes"][0])
    row = data["parameters"][0]
    assert row["name"] == "disc_clutch_torsional_stiffness"
    assert set(row) == {"name", "value", "unit", "d_re_dp", "d_im_hz_dp", "d_s0_limit_dp"}
    assert len(row["d_re_dp"]) == 10
    assert len(row["d_im_hz_dp"]) == 10
    assert row["d_s0_limit_dp"] == 0.0
    assert data["parameters"][1]["d_s0_limit_dp"] != 0.0


@pytest.mark.slow
def test_uncertainty_pipeline_on_the_model(setup):
    """Two parameters, n = 2: 8 model runs through a map-like executor, in chunks; the result's
    distributions are the model's own outputs at the sampled values."""
    from model.studies.uncertainty import OUTPUT_NAMES, UNCERTAIN_PARAMETERS, sample_outputs

    parameters, _ = setup
    chosen = [u for u in UNCERTAIN_PARAMETERS if u.name in ("polach_B", "rotor_inertia")]
    chunks = []

    def recording_map(func, items):
        for chunk in items:
            chunks.append(len(chunk))
            yield func(chunk)

    progress = []
    result = run_uncertainty(parameters, 2, uncertain=chosen, map_fn=recording_map, chunk_size=3,
                             progress=lambda done, total: progress.append((done, total)),
                             n_resamples=9)
    assert result.runs == 8 == sum(chunks)
    assert max(chunks) <= 3
    assert progress[-1] == (8, 8)
    assert result.values.shape == (4, len(OUTPUT_NAMES))
    values = dict(parameters.values)
    values.update(zip(result.names, result.samples[0], strict=True))
    np.testing.assert_allclose(result.values[0], sample_outputs(values), rtol=1e-12)
    data = result.as_dict()
    assert [o["name"] for o in data["outputs"]] == list(OUTPUT_NAMES)
    assert data["runs"] == 8


def test_modes_are_the_ten_lowest_pairs_with_the_tools_descriptions(setup):
    from model.analysis.modes import describe_modes

    parameters, model = setup
    op = _op(parameters, 0.005)
    result = eigen_analysis(model, op)
    sens = eigen_sensitivities(model, op, parameters=["gear_ratio"])
    np.testing.assert_array_equal(sens.indices, result.complex_index[:10])
    assert list(sens.descriptions) == describe_modes(model, result, result.complex_index[:10])
    for shares in sens.participation:  # participation factors per subsystem sum to one
        assert sum(shares.values()) == pytest.approx(1.0, abs=1e-9)
