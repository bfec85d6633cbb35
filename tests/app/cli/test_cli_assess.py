"""``bogie assess``: the JSON contract, the short-circuit loads equal to ``bogie envelope --phase
all`` on the same grid (in this process and on a local cluster, the envelope's engine options),
the envelope's rail and anti-slip options, and bad input refused in one line with exit status 2."""

from __future__ import annotations

import json
import math

import pytest
from test_cli import assert_one_line_error, run, run_process

from app.cli.main import main
from model.mechanics.parameters import dumps_parameters, load_parameters

GRID = ["--s0", "0.003,0.005", "--v", "120,200", "--t-end", "3", "--fs", "2500"]
RIPPLE = ["--ripple-v", "40:120:5"]  # the ripple case's coarse grid (refined at the resonances)
FOUR = ["--no-running"]  # the contract tests of the four other cases (the running case: below)


@pytest.fixture(scope="module")
def assessed():
    """``bogie assess --no-running --json`` on a small grid (module scope: one run for the
    contract tests)."""
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = main(["assess", *GRID, *RIPPLE, *FOUR, "--serial", "--json"])
    assert code == 0
    return json.loads(out.getvalue())


@pytest.mark.slow
def test_json_contract(assessed):
    data = assessed
    assert [c["name"] for c in data["load_cases"]] == ["short_circuit", "unstable_adhesion",
                                                       "starting", "ripple"]
    assert all(isinstance(c["description"], str) and c["description"] for c in data["load_cases"])
    horizons = {c["name"]: c["horizon_s"] for c in data["load_cases"]}
    assert horizons == {"short_circuit": 3.0, "unstable_adhesion": 2.0, "starting": None,
                        "ripple": None}
    checks = data["checks"]
    assert len(checks) == 16 * 4  # every press fit, shaft and coupling of both drives, 4 cases
    for c in checks:
        assert {"component", "kind", "output", "load_case", "load", "capacity", "safety_factor",
                "required", "ok", "inputs", "note", "mean", "alternating", "v_kmh",
                "orders"} <= set(c)
        if c["load_case"] == "ripple":  # under alternating load: recomputable from bogie export
            assert c["kind"] in ("press_fit_slip", "torsional_fatigue", "coupling_vibratory")
            assert c["alternating"] >= 0.0
            assert 40.0 <= c["v_kmh"] <= 120.0
            assert c["orders"]
            assert {"order", "f_hz", "amplitude"} <= set(c["orders"][0])
            continue
        assert c["kind"] in ("press_fit_slip", "torsional_shear", "coupling")
        assert c["mean"] is None
        assert c["alternating"] is None
        assert c["safety_factor"] == pytest.approx(c["capacity"] / c["load"], rel=1e-12)
        assert c["ok"] is (c["safety_factor"] >= c["required"])
        if c["kind"] == "press_fit_slip":
            i = c["inputs"]
            assert {"d", "L", "D", "d_i", "delta", "mu", "E_hub", "E_shaft", "nu_hub",
                    "nu_shaft"} <= set(i)
            p = i["delta"] / (i["d"] * (((i["D"] ** 2 + i["d"] ** 2) / (i["D"] ** 2 - i["d"] ** 2)
                                         + i["nu_hub"]) / i["E_hub"]
                                        + ((i["d"] ** 2 + i["d_i"] ** 2)
                                           / (i["d"] ** 2 - i["d_i"] ** 2) - i["nu_shaft"])
                                        / i["E_shaft"]))
            assert c["capacity"] == pytest.approx(i["mu"] * p * math.pi * i["d"] ** 2 * i["L"] / 2,
                                                  rel=1e-12)
        elif c["kind"] == "torsional_shear":
            i = c["inputs"]
            assert c["capacity"] == pytest.approx(
                i["tau_allow"] * math.pi * (i["D"] ** 4 - i["d_i"] ** 4) / (16 * i["D"]), rel=1e-12)
    governing = min(checks, key=lambda c: c["safety_factor"] / c["required"])
    assert data["governing"]["component"] == governing["component"]
    assert data["governing"]["load_case"] == governing["load_case"]
    assert data["governing"]["safety_factor"] == governing["safety_factor"]


@pytest.mark.slow
def test_short_circuit_loads_are_the_envelopes_phase_all_extremes(assessed, capsys):
    outputs = sorted({c["output"] for c in assessed["checks"]})
    code, out, err = run(["envelope", *GRID, "--phase", "all", "--serial", "--json",
                          "--outputs", ",".join(outputs)], capsys)
    assert code == 0, err
    envelope = {o["name"]: max(abs(o["max"]), abs(o["min"])) for o in json.loads(out)["outputs"]}
    loads = {c["output"]: c["load"] for c in assessed["checks"]
             if c["load_case"] == "short_circuit"}
    assert set(loads) == set(envelope)
    for name, load in loads.items():
        assert load == pytest.approx(envelope[name], rel=1e-12), name


@pytest.mark.slow
def test_the_short_circuit_grid_on_a_local_cluster_equals_serial(assessed):
    """The envelope's engine options: ``--workers 2`` (a local cluster of worker processes, the
    default engine) gives the serial run's checks; a wet rail and the protection's options reach
    the load cases."""
    cluster = run_process(["assess", *GRID, *RIPPLE, *FOUR, "--workers", "2", "--json"])
    assert cluster.returncode == 0, cluster.stderr
    assert "local cluster of 2 worker process(es)" in cluster.stderr
    data = json.loads(cluster.stdout)
    assert data["checks"] == assessed["checks"]
    assert data["rail"] == "calibrated"


@pytest.mark.slow
def test_rail_and_anti_slip_options_reach_the_load_cases(assessed, capsys):
    code, out, err = run(["assess", *GRID, *RIPPLE, *FOUR, "--serial", "--json", "--rail", "wet",
                          "--anti-slip-delay", "0.25", "--anti-slip-rate", "5"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["rail"] == "wet"
    unstable = next(c for c in data["load_cases"] if c["name"] == "unstable_adhesion")
    assert unstable["scenario"]["anti_slip_delay_s"] == 0.25
    assert "after 0.25 s" in unstable["description"]
    starting = next(c for c in data["load_cases"] if c["name"] == "starting")
    before = next(c for c in assessed["load_cases"] if c["name"] == "starting")
    assert starting["scenario"]["mu_max"] < before["scenario"]["mu_max"]  # wet: less adhesion


@pytest.fixture(scope="module")
def bad_set(tmp_path_factory):
    path = tmp_path_factory.mktemp("sets") / "bad.toml"
    text = dumps_parameters(load_parameters())
    path.write_text(text.replace("wheel_hub_outer_diameter = { value = 0.33",
                                 "wheel_hub_outer_diameter = { value = 0.2"), encoding="utf-8")
    return str(path)


@pytest.fixture(scope="module")
def bad_ranges(tmp_path_factory):
    """A ranges file with a negative friction coefficient."""
    path = tmp_path_factory.mktemp("ranges") / "ranges.toml"
    path.write_text("gear_seat_friction_min = { low = -0.1, high = 0.2 }\n", encoding="utf-8")
    return str(path)


@pytest.mark.parametrize(("argv", "message"), [
    (["--s0", "0.014", "--v", "120"], "--s0 0.014 at --v 120 km/h is not stable"),
    (["--s0", "0.005,0.003"], "--s0 must increase"),
    (["--v", "abc"], "--v must be numbers"),
    (["--fs", "100"], "too low to resolve the excitation"),
    (["--unstable-s0", "2"], "--unstable-s0 (creepage) = 2 is not allowed"),
    (["--params", "BAD"], "'wheel_hub_outer_diameter' = 0.2 m must exceed the seat's diameter"),
    (["--rail", "icy"], "invalid choice: 'icy'"),
    (["--workers", "0"], "--workers = 0 is not allowed"),
    (["--anti-slip-rate", "-1"], "--anti-slip-rate (1/s)"),
    (["--ripple", "el:6=-5"], "the amplitude must be in [0, 1e7] N m"),
    (["--ripple", "el:x=5"], "the order must be a number"),
    (["--ripple-v", "200,100"], "must increase"),
    (["--samples", "3", "--serial"], "must be a power of 2"),
    (["--indices"], "--indices needs --samples"),
    (["--samples", "4", "--serial", "--ranges", "RANGES"], "gear_seat_friction_min"),
    (["--running", "--wheel-polygon", "20"], "is not order=amplitude"),
    (["--running", "--running-v", "200,100"], "must increase"),
    (["--running", "--samples", "2", "--serial"], "--running and --samples"),
])
def test_bad_input_is_one_line_with_exit_status_2(argv, message, bad_set, bad_ranges, capsys):
    argv = [{"BAD": bad_set, "RANGES": bad_ranges}.get(a, a) for a in argv]
    code, out, err = run(["assess", *argv], capsys)
    assert_one_line_error(code, out, err)
    assert err.startswith("bogie assess: error:")
    assert message in err
    assert out == ""


@pytest.mark.slow
def test_a_sample_of_the_verdict_under_uncertainty_reruns_from_its_file(tmp_path, capsys):
    """``--samples`` lists each sample's governing check and safety factor and writes its
    complete parameter set (``--write-samples``); ``bogie assess --params`` on that file with the
    same options gives the recorded governing safety factor (to 1e-9)."""
    options = ["--s0", "0.005", "--v", "120", "--t-end", "3", "--fs", "2500", *RIPPLE, "--serial"]
    code, out, err = run(["assess", *options, "--samples", "2", "--seed", "3",
                          "--write-samples", str(tmp_path), "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["n"] == 2
    assert len(data["samples"]) == 2
    sample = data["samples"][1]
    assert sample["values"]  # what this sample changed
    files = sorted(tmp_path.glob("*.toml"))
    assert len(files) == 2
    # the verdict under uncertainty has the four cases without the running one
    code, out, err = run(["assess", *options, "--params", str(files[1]), "--no-running", "--json"],
                         capsys)
    assert code == 0, err
    again = json.loads(out)["governing"]
    assert again["component"] == sample["governing"]["component"]
    assert again["load_case"] == sample["governing"]["load_case"]
    assert again["safety_factor"] == pytest.approx(sample["governing"]["safety_factor"], rel=1e-9)


@pytest.mark.slow
def test_running_case_recomputed_from_the_export(capsys, tmp_path):
    """``bogie assess``'s running case (a default case): the running checks carry v_kmh, rms and
    the wheel polygon's orders (order, f_hz, input_amplitude [m], wheels with their phases); the
    check with the
    largest deterministic polygon amplitude is recomputed from ``bogie export`` at its creepage
    and speed with numpy alone — Σ over its orders of |Σ_wheels H_wheel(2π f) e^(i phase)| ·
    input_amplitude, H from the exported running system — to 1e-3 (the JSON's speed and phases
    are exact; 1e-3 leaves room for the rounding of the frequency through f = n v / 2π r0)."""
    code, out, err = run(["assess", *GRID, "--ripple-v", "40:120:3", "--running-v", "100,200",
                          "--serial", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert [c["name"] for c in data["load_cases"]] == ["short_circuit", "unstable_adhesion",
                                                       "starting", "ripple", "running"]
    assert data["load_cases"][-1]["scenario"]["unstable"] == []
    running = [c for c in data["checks"] if c["load_case"] == "running"]
    assert len(running) == 16
    for c in running:
        assert {"v_kmh", "rms", "orders", "amplitude", "mean", "alternating"} <= set(c)
        assert c["v_kmh"] in (100.0, 200.0)
        assert c["rms"] > 0
        (order,) = c["orders"]
        assert {"order", "f_hz", "input_amplitude", "wheels"} <= set(order)
        assert order["order"] == 20
        assert order["input_amplitude"] == pytest.approx(30e-6)
        assert [w["input"] for w in order["wheels"]] == [
            "ID1.rim12.irregularity", "ID1.rim14.irregularity", "ID2.rim12.irregularity",
            "ID2.rim14.irregularity"]
        if c["kind"] == "torsional_fatigue":  # the random part's spectral damage beside it
            damage = c["scenario"]["random_damage_per_hour"]
            # below the knee Haibach's slope still counts every cycle: both rates are positive
            assert damage["dirlik"] > 0
            assert damage["narrow_band"] > 0
            assert damage["sn_curve"]["amplitude_at_knee"] == pytest.approx(c["capacity"])
        # the parts the check adds: ripple + polygon + 3 × RMS
        assert c["alternating"] == pytest.approx(
            c["scenario"]["ripple_amplitude"] + c["amplitude"] + 3.0 * c["rms"], rel=1e-12)
    worst = max(running, key=lambda c: c["amplitude"])
    path = tmp_path / "system.npz"
    code, _, err = run(["export", "--s0", str(worst["scenario"]["s0"]), "--v",
                        str(worst["v_kmh"]), "--out", str(path)], capsys)
    assert code == 0, err
    import numpy as np

    with np.load(path, allow_pickle=False) as arrays:
        M = arrays["M"] + arrays["M_irr_coupling"]
        B = arrays["B"] + arrays["B_irr_coupling"]
        K = arrays["K"] + arrays["K_irr_coupling"]
        inputs = list(arrays["irregularity_inputs"])
        row = list(arrays["outputs"]).index(worst["output"])
        C_q, C_v = arrays["C_q"][row], arrays["C_v"][row]
        G = (arrays["G_irr_q"], arrays["G_irr_v"], arrays["G_irr_a"])
    amplitude = 0.0
    for order in worst["orders"]:
        w = 2 * math.pi * order["f_hz"]
        s = 1j * w
        q = np.linalg.solve(s * s * M + s * B + K, G[0] + s * G[1] + s * s * G[2])
        H = (C_q + s * C_v) @ q  # (4,) per wheel
        total = sum(H[inputs.index(wheel["input"])] * np.exp(1j * math.radians(wheel["phase_deg"]))
                    for wheel in order["wheels"])
        amplitude += abs(total) * order["input_amplitude"]
    assert worst["amplitude"] == pytest.approx(amplitude, rel=1e-3)
