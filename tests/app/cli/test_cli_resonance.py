"""``bogie campbell``, ``frf`` and ``ripple``: the documented JSON contracts (the keys exactly),
the CSV file, and bad input answered by one line on stderr with exit status 2."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from app.cli.main import main

CAMPBELL_KEYS = {"modes", "orders", "crossings"}
MODE_KEYS = {"name", "v_kmh", "f_hz", "zeta"}
CROSSING_KEYS = {"mode", "order", "v_kmh", "f_hz", "zeta", "severity"}
FRF_KEYS = {"input", "operating_point", "f_hz", "outputs"}
FRF_OUTPUT_KEYS = {"name", "unit", "abs", "phase_deg", "peaks"}


def run(argv, capsys):
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    out, err = capsys.readouterr()
    return code, out, err


def test_campbell_json_contract(capsys):
    """Keys exactly as documented; every mode over the same speeds; crossings by severity, each
    inside the range and naming a listed mode and order; severities per torque output."""
    code, out, err = run(["campbell", "--v", "40:160:25", "--freq", "450", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) == CAMPBELL_KEYS
    v = data["modes"][0]["v_kmh"]
    assert v[0] == 40
    assert v[-1] == 160
    assert len(v) == 25
    names = {mode["name"] for mode in data["modes"]}
    assert len(names) == len(data["modes"])
    for mode in data["modes"]:
        assert set(mode) == MODE_KEYS
        assert mode["v_kmh"] == v
        assert len(mode["f_hz"]) == len(mode["zeta"]) == 25
    orders = [order["name"] for order in data["orders"]]
    assert "fixed:450" in orders
    assert "el:6" in orders
    assert all(len(order["f_hz"]) == 25 for order in data["orders"])
    assert data["crossings"]
    worst = []
    for crossing in data["crossings"]:
        assert set(crossing) == CROSSING_KEYS
        assert crossing["mode"] in names
        assert crossing["order"] in orders
        assert 40 <= crossing["v_kmh"] <= 160
        assert all(name.endswith(("torque", "moment")) for name in crossing["severity"])
        worst.append(max(crossing["severity"].values()))
    assert worst == sorted(worst, reverse=True)


def test_frf_json_contract_and_csv(capsys, tmp_path):
    """Keys exactly as documented; f starts at 0 Hz (the static gain); peaks are local maxima
    of abs; the CSV holds the same numbers."""
    path = tmp_path / "frf.csv"
    code, out, err = run(["frf", "--f", "1:400:300", "--outputs",
                          "ID1.driving_shaft.torque,ID1.disc_clutch.torque", "--csv", str(path),
                          "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) == FRF_KEYS
    assert data["input"] == "ID1.motor.torque"
    assert set(data["operating_point"]) == {"s0", "v_kmh", "N0", "b_M"}
    f = np.array(data["f_hz"])
    assert f[0] == 0
    assert f[1] == 1
    assert f[-1] == 400
    assert np.all(np.diff(f) > 0)
    assert len(f) > 300  # refined across the resonances
    assert [o["name"] for o in data["outputs"]] == ["ID1.driving_shaft.torque",
                                                    "ID1.disc_clutch.torque"]
    for output in data["outputs"]:
        assert set(output) == FRF_OUTPUT_KEYS
        assert output["unit"] == "N m"
        assert len(output["abs"]) == len(output["phase_deg"]) == len(f)
        assert output["peaks"]
        for peak in output["peaks"]:
            assert set(peak) == {"f_hz", "abs"}
            assert peak["abs"] >= np.interp(peak["f_hz"], f, output["abs"]) * (1 - 1e-9)
    # at 0 Hz the torque balance of the whole vehicle accelerating: the driving shaft passes the
    # motor's torque less what the rotor's inertia takes (the model's static gain, tested there)
    assert 0.95 < data["outputs"][0]["abs"][0] < 1.0
    with path.open() as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["f [Hz]", "ID1.driving_shaft.torque |H| [N m/N m]",
                       "ID1.driving_shaft.torque phase [deg]",
                       "ID1.disc_clutch.torque |H| [N m/N m]", "ID1.disc_clutch.torque phase [deg]"]
    table = np.array(rows[1:], dtype=float)
    np.testing.assert_array_equal(table[:, 0], f)
    np.testing.assert_array_equal(table[:, 1], data["outputs"][0]["abs"])


def test_frf_text_states_peaks_and_amplification(capsys):
    code, out, err = run(["frf", "--outputs", "ID1.driving_shaft.torque"], capsys)
    assert code == 0, err
    assert "static gain" in out
    row = next(line for line in out.splitlines() if line.startswith("ID1.driving_shaft.torque"))
    assert "298" in row
    assert "×" in row


def test_frf_at_an_unstable_point_says_it_is_no_steady_state(capsys):
    code, out, err = run(["frf", "--s0", "0.014", "--outputs", "ID1.driving_shaft.torque",
                          "--f", "1:100:50"], capsys)
    assert code == 0, err
    assert "UNSTABLE operating point" in out
    code, out, err = run(["frf", "--s0", "0.005", "--outputs", "ID1.driving_shaft.torque",
                          "--f", "1:100:50"], capsys)
    assert "UNSTABLE" not in out


def test_ripple_json(capsys):
    code, out, err = run(["ripple", "--v", "60:120:13", "--ripple", "el:6=250,el:12=120",
                          "--outputs", "ID1.driving_shaft.torque", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) == {"input", "operating_point", "v_kmh", "ripple", "outputs"}
    assert [r["order"] for r in data["ripple"]] == ["el:6", "el:12"]
    (output,) = data["outputs"]
    total = np.array(output["amplitude"])
    parts = np.array([output["by_order"][k] for k in ("el:6", "el:12")])
    np.testing.assert_allclose(total, parts.sum(axis=0), rtol=1e-12)
    assert output["peak"] == pytest.approx(total.max())


def test_wheel_polygon_json(capsys):
    """``bogie ripple --wheel-polygon``: the orders with their amplitudes [m], frequencies and the
    four wheels' phases (the rear wheelset −n · wheelbase / r0); the total is the orders' sum."""
    code, out, err = run(["ripple", "--v", "60:120:7", "--s0", "0.002", "--wheel-polygon",
                          "7=40,20=25", "--outputs", "ID1.driving_shaft.torque", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) == {"operating_point", "v_kmh", "wheel_polygon", "unstable_v_kmh", "outputs"}
    assert [p["order"] for p in data["wheel_polygon"]] == [7, 20]
    assert data["wheel_polygon"][0]["input_amplitude"] == pytest.approx(40e-6)
    wheels = data["wheel_polygon"][1]["wheels"]
    assert [w["input"] for w in wheels] == ["ID1.rim12.irregularity", "ID1.rim14.irregularity",
                                            "ID2.rim12.irregularity", "ID2.rim14.irregularity"]
    from model import load_parameters

    parameters = load_parameters()
    assert wheels[2]["phase_deg"] == pytest.approx(
        np.degrees(-20 * parameters["wheelbase"] / parameters["wheel_radius"]))
    (output,) = data["outputs"]
    total = np.array(output["amplitude"])
    parts = np.array([output["by_order"][k] for k in ("7", "20")])
    np.testing.assert_allclose(total, parts.sum(axis=0), rtol=1e-12)
    assert output["peak"] == pytest.approx(total.max())


def test_track_json(capsys):
    """``bogie track``: the spectrum with its source and class parameters, the RMS from the
    moments (√m0), a PSD per output on the frequency grid, the running system's stability."""
    code, out, err = run(["track", "--s0", "0.002", "--v", "120", "--outputs",
                          "ID1.disc_clutch.torque", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) == {"operating_point", "spectrum", "stable", "f_hz", "input_psd", "outputs"}
    assert data["spectrum"]["name"] == "low"
    assert "ERRI" in data["spectrum"]["source"]
    assert data["stable"] is True
    (output,) = data["outputs"]
    assert output["rms"] == pytest.approx(output["moments"][0] ** 0.5, rel=1e-12)
    assert len(output["psd"]) == len(data["f_hz"]) == len(data["input_psd"])


@pytest.mark.parametrize("argv", [
    ["track", "--spectrum", "class9"],
    ["track", "--outputs", "ID1.nothing"],
    ["campbell", "--v", "200:100:10"],  # an empty range
    ["campbell", "--v", "0:200:10"],  # below the model's speeds
    ["campbell", "--v", "5:200:1"],
    ["campbell", "--orders", "el:-6"],  # a negative order
    ["campbell", "--orders", "wheel:0"],
    ["campbell", "--orders", "gear:1"],
    ["campbell", "--orders", ""],
    ["campbell", "--orders", ",".join(f"el:{k}" for k in range(1, 26))],  # too many lines
    ["campbell", "--orders", "el:1", "--freq", ",".join(str(k) for k in range(1, 25))],
    ["campbell", "--freq", "5000"],  # beyond the model's validity
    ["campbell", "--freq", "-50"],
    ["campbell", "--participation", "2"],
    ["campbell", "--input", "ID1.rim12.creep_disturbance"],
    ["campbell", "--pole-pairs", "0"],
    ["campbell", "--excitation", "/nonexistent/excitation.toml"],
    ["frf", "--f", "0.1:5000:100"],  # beyond the model's validity
    ["frf", "--f", "10:1:100"],  # an empty range
    ["frf", "--f", "0:100:100"],
    ["frf", "--f", "1:100"],
    ["frf", "--input", "ID3.motor.torque"],
    ["frf", "--outputs", "ID1.nothing"],
    ["frf", "--min-peak", "1"],
    ["frf", "--csv", "/nonexistent/frf.csv"],
    ["frf", "--csv", "frf.txt"],
    ["frf", "--v", "0"],
    ["ripple", "--ripple", "el:6"],
    ["ripple", "--ripple", "el:-6=100"],
    ["ripple", "--ripple", "el:6=-1"],
    ["ripple"],  # --ripple or --wheel-polygon is required
    ["ripple", "--ripple", "el:6=250", "--wheel-polygon", "20=30"],  # one of the two
    ["ripple", "--wheel-polygon", "20"],
    ["ripple", "--wheel-polygon", "20.5=30"],
    ["ripple", "--wheel-polygon", "20=-3"],
    ["ripple", "--wheel-polygon", "500=3"],
])
def test_bad_input_is_one_line_with_exit_status_2(argv, capsys):
    code, out, err = run(argv, capsys)
    assert code == 2, (code, err)
    assert "Traceback" not in err
    assert err.count("\n") == 1, err
    assert err.startswith("bogie")
    assert "error" in err
    assert out == ""


def test_frf_of_an_irregularity_equals_an_independent_solve_from_the_export(capsys, tmp_path):
    """``bogie frf --input ID1.rim12.irregularity`` against the running system written by ``bogie
    export`` solved with numpy alone: ``(−ω²(M + M_c) + iω(B + B_c) + K + K_c) Q̂ = G_q + iω G_v −
    ω² G_a``, ``Ĥ = (C_q + iω C_v) Q̂``.  Tolerance 1e-6 of each output's largest |H|: the
    frequency response's modal values are solved directly wherever their rounding estimate
    exceeds 1e-8 of that, so 1e-6 leaves a hundredfold margin for the JSON's magnitude and phase."""
    path = tmp_path / "system.npz"
    code, _, err = run(["export", "--s0", "0.005", "--v", "120", "--out", str(path)], capsys)
    assert code == 0, err
    code, out, err = run(["frf", "--s0", "0.005", "--v", "120", "--input",
                          "ID1.rim12.irregularity", "--json"], capsys)
    assert code == 0, err
    frf = json.loads(out)
    assert frf["input"] == "ID1.rim12.irregularity"
    with np.load(path, allow_pickle=False) as data:
        arrays = {name: data[name] for name in data.files}
    inputs = list(arrays["irregularity_inputs"])
    assert inputs == ["ID1.rim12.irregularity", "ID1.rim14.irregularity",
                      "ID2.rim12.irregularity", "ID2.rim14.irregularity"]
    j = inputs.index("ID1.rim12.irregularity")
    M = arrays["M"] + arrays["M_irr_coupling"]
    B = arrays["B"] + arrays["B_irr_coupling"]
    K = arrays["K"] + arrays["K_irr_coupling"]
    f_all = np.array(frf["f_hz"])
    H = np.array([np.array(o["abs"]) * np.exp(1j * np.radians(o["phase_deg"]))
                  for o in frf["outputs"]])
    assert [o["name"] for o in frf["outputs"]] == list(arrays["outputs"])
    assert all(o["unit"] for o in frf["outputs"])
    # every 25th grid point and each output's highest grid value (0 Hz, the static gain of the
    # vehicle accelerating under the net creep force, is the modal form's alone)
    chosen = set(range(1, len(f_all), 25))
    chosen |= {int(np.argmax(np.abs(row[1:]))) + 1 for row in H}
    largest = np.abs(H).max(axis=1)
    for k in sorted(chosen):
        w = 2 * np.pi * f_all[k]
        force = arrays["G_irr_q"][:, j] + 1j * w * arrays["G_irr_v"][:, j] - w * w * arrays["G_irr_a"][:, j]
        q = np.linalg.solve(-w * w * M + 1j * w * B + K, force)
        expected = (arrays["C_q"] + 1j * w * arrays["C_v"]) @ q
        assert np.all(np.abs(H[:, k] - expected) <= 1e-6 * largest), f_all[k]
