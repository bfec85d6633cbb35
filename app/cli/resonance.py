"""``bogie campbell``, ``frf``, ``ripple`` and ``track``: where the drive resonates, what the track
and the wheels do to it (docs/resonance.md).

    bogie campbell --v 5:200:200 --s0 0.005 [--orders wheel:1,rotor:1,mesh:1,el:1,el:2,el:6,el:12]
                   [--freq 450,900] [--input ID1.motor.torque] [--participation 0.01] [--json]
    bogie frf --s0 0.005 --v 120 [--input ID1.motor.torque] [--f 0.1:1000:2000]
              [--outputs A,B] [--min-peak 0.01] [--csv FILE] [--json]
    bogie ripple --v 5:200:200 --s0 0.005 --ripple el:6=250,el:12=120 [--outputs A,B] [--json]
    bogie ripple --v 5:200:200 --s0 0.005 --wheel-polygon 20=30 [--outputs A,B] [--json]
    bogie track --s0 0.002 --v 120 [--spectrum low] [--outputs A,B] [--json]

Speeds in km/h, frequencies in Hz, amplitudes of H in output unit per N m of motor torque (per N
of a creep disturbance, per m of a rail–wheel surface deviation).  Bad input: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

from app.cli.options import (
    WHEEL_POLYGON,
    UsageError,
    add_operating_point,
    bounded,
    checked_output_names,
    input_file,
    load_model,
    parse_range,
    parse_values,
    parsed_text,
    positive_int,
)
from app.cli.output import emit, writable_path

SPEEDS = "5:200:200"  # [km/h]
BAND = "0.1:1000:2000"  # [Hz]


def register(subparsers) -> None:
    """campbell, frf, ripple, track."""
    from model.analysis.campbell import DEFAULT_PARTICIPATION
    from model.analysis.frequency_response import DEFAULT_INPUT, DEFAULT_MIN_PEAK
    from model.mechanics.excitation import DEFAULT_ORDERS

    p = subparsers.add_parser("campbell", help="Campbell diagram over speed: modes, excitation "
                              "orders, crossings with their severity")
    _add_sweep_point(p)
    p.add_argument("--orders", default=DEFAULT_ORDERS, metavar="LIST",
                   help="excitation orders: wheel:k, rotor:k, mesh:k (gear mesh harmonic), el:k "
                        "or k (harmonic of the motor's electrical frequency) "
                        "(default %(default)s)")
    p.add_argument("--freq", default=None, metavar="LIST",
                   help="fixed excitation frequencies [Hz], e.g. the inverter's switching "
                        "frequency and its side bands: f1,f2,…")
    p.add_argument("--input", default=DEFAULT_INPUT, metavar="NAME",
                   help="the motor torque the severities are per unit of: ID1.motor.torque or "
                        "ID2.motor.torque (default %(default)s)")
    p.add_argument("--participation", type=bounded("--participation", "[0, 1]"),
                   default=DEFAULT_PARTICIPATION,
                   help="track the modes whose resonance reaches this fraction of the largest a "
                        "motor's torque drives (0: every mode, slower) (default %(default)s)")
    _add_excitation(p)
    p.set_defaults(func=cmd_campbell)

    p = subparsers.add_parser("frf", help="frequency response from a motor torque (or a creep "
                              "disturbance, or a wheel's surface deviation) to every output: "
                              "magnitude, phase, peaks")
    add_operating_point(p)
    p.add_argument("--input", default=DEFAULT_INPUT, metavar="NAME",
                   help="ID1.motor.torque (the short-circuit torque's generalized force), "
                        "ID2.motor.torque, IDk.rimN.creep_disturbance [N] or IDk.rimN.irregularity "
                        "(the rail–wheel surface deviation [m]) (default %(default)s)")
    p.add_argument("--f", default=BAND, metavar="A:B:N",
                   help="N log-spaced frequencies from A to B Hz, refined across every "
                        "resonance; the static gain (0 Hz) comes first (default %(default)s)")
    p.add_argument("--outputs", default=None, metavar="LIST",
                   help="comma-separated output names (default: all)")
    p.add_argument("--min-peak", type=bounded("--min-peak", "[0, 1)"), default=DEFAULT_MIN_PEAK,
                   help="list peaks of at least this fraction of the output's largest |H| "
                        "(default %(default)s)")
    p.add_argument("--csv", default=None, metavar="FILE",
                   help="also write f, |H| and phase of every output to a CSV file")
    p.set_defaults(func=cmd_frf)

    p = subparsers.add_parser("ripple", help="steady amplitude of every output over speed under "
                              "a motor torque ripple or polygonal wheels")
    _add_sweep_point(p)
    p.add_argument("--ripple", default=None, metavar="LIST",
                   help="order=amplitude [N m], e.g. el:6=250,el:12=120 (orders as --orders of "
                        "bogie campbell)")
    p.add_argument("--wheel-polygon", type=WHEEL_POLYGON, default=None, metavar="LIST",
                   help="instead of --ripple: polygonal wheels, order=radial amplitude [µm], e.g. "
                        "20=30 (every wheel; the rear wheelset a wheelbase later)")
    p.add_argument("--input", default=DEFAULT_INPUT, metavar="NAME",
                   help="the rippling motor: ID1.motor.torque or ID2.motor.torque "
                        "(default %(default)s)")
    p.add_argument("--outputs", default=None, metavar="LIST",
                   help="comma-separated output names (default: all)")
    _add_excitation(p)
    p.set_defaults(func=cmd_ripple)

    p = subparsers.add_parser("track", help="PSD and RMS of every output under the random "
                              "vertical track irregularity at one speed")
    add_operating_point(p)
    p.add_argument("--spectrum", type=parsed_text("model.analysis.track_spectrum",
                                                  "track_spectrum"), default="low", metavar="NAME",
                   help="the track spectrum: low (the German high-speed / ERRI B176 low level) "
                        "(default %(default)s)")
    p.add_argument("--outputs", default=None, metavar="LIST",
                   help="comma-separated output names (default: all)")
    p.set_defaults(func=cmd_track)


def _add_sweep_point(p: argparse.ArgumentParser) -> None:
    """The operating point without a speed, and the speed range ``--v A:B:N`` [km/h]."""
    p.add_argument("--v", default=SPEEDS, metavar="A:B:N",
                   help="N speeds from A to B km/h, 1 <= A < B <= 500 (default %(default)s)")
    add_operating_point(p, speed=False)


MAX_TEETH = 1000  # the most pole pairs and pinion teeth model.mechanics.excitation accepts


def _load_excitation(path: str):
    from model.mechanics.excitation import load_excitation

    return load_excitation(path)


def _add_excitation(p: argparse.ArgumentParser) -> None:
    p.add_argument("--excitation", type=input_file(_load_excitation), default=None, metavar="FILE",
                   help="the motor's pole pairs and the pinion's teeth (TOML; default "
                        "assets/parameters/excitation.toml)")
    p.add_argument("--pole-pairs", type=positive_int("--pole-pairs", MAX_TEETH), default=None,
                   help="pole pairs of the traction motor (default: the excitation file's)")
    p.add_argument("--pinion-teeth", type=positive_int("--pinion-teeth", MAX_TEETH), default=None,
                   help="teeth of the pinion (default: the excitation file's)")


def _speeds(args: argparse.Namespace) -> np.ndarray:
    """``--v A:B:N`` [km/h] -> speeds [m/s] (A < B, both in [1, 500] km/h)."""
    from model.mechanics.operating_point import KMH

    speeds = parse_range(args.v, "--v (speed range, km/h)")
    if not speeds[0] < speeds[-1]:
        raise UsageError(f"--v = '{args.v}' is an empty range: A must be below B")
    if speeds[0] < 1 or speeds[-1] > 500:
        raise UsageError(f"--v = '{args.v}': speeds must be in [1, 500] km/h")
    return speeds * KMH


def _sweep_model(args: argparse.Namespace):
    """(model, operating point at the middle of the speed range, speeds [m/s])."""
    from model.mechanics.operating_point import KMH

    speeds = _speeds(args)
    middle = float(0.5 * (speeds[0] + speeds[-1]))  # [m/s]: the modes are named there
    model, op, _ = load_model(argparse.Namespace(**{**vars(args), "v": middle / KMH}))
    return model, op, speeds


def _excitation(args: argparse.Namespace):
    from dataclasses import replace

    from model.mechanics.excitation import load_excitation

    excitation = load_excitation(args.excitation)
    if args.pole_pairs is not None:
        excitation = replace(excitation, pole_pairs=args.pole_pairs)
    if args.pinion_teeth is not None:
        excitation = replace(excitation, pinion_teeth=args.pinion_teeth)
    return excitation


def _check_input(model, name: str) -> None:
    from model.analysis.frequency_response import input_names

    known = input_names(model)
    if name not in known:
        raise UsageError(f"--input: unknown input '{name}'; known: {', '.join(known)}")


def _check_motor_input(model, name: str) -> None:
    from model.analysis.frequency_response import input_names

    motors = [n for n in input_names(model) if n.endswith(".motor.torque")]
    if name not in motors:
        raise UsageError(f"--input must be a motor's torque: {', '.join(motors)}; got '{name}'")


def cmd_campbell(args: argparse.Namespace) -> None:
    from model.analysis.campbell import campbell
    from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ
    from model.mechanics.excitation import MAX_ORDERS, ExcitationError, Order, parse_orders

    model, op, speeds = _sweep_model(args)
    _check_motor_input(model, args.input)
    try:
        orders = parse_orders(args.orders)
    except ExcitationError as error:
        raise UsageError(f"--orders: {error}") from None
    if args.freq is not None:
        fixed = parse_values(args.freq, "--freq (Hz)", 1e-3, MODEL_FREQUENCY_LIMIT_HZ, "Hz (the "
                             "model's validity)")
        if len(orders) + len(fixed) > MAX_ORDERS:
            raise UsageError(f"--orders and --freq: {len(orders) + len(fixed)} lines, at most "
                             f"{MAX_ORDERS}")
        orders = orders + tuple(Order("fixed", f) for f in fixed if Order("fixed", f) not in orders)
    diagram = campbell(model, op, speeds, orders, _excitation(args), input=args.input,
                       participation_threshold=args.participation)
    v_kmh = diagram.v_kmh.tolist()
    data = {"modes": [{"name": m.name, "v_kmh": v_kmh, "f_hz": m.f_hz.tolist(),
                       "zeta": m.zeta.tolist()} for m in diagram.modes],
            "orders": [{"name": o.name, "f_hz": line.tolist()}
                       for o, line in zip(diagram.orders, diagram.lines_hz, strict=True)],
            "crossings": [{"mode": c.mode, "order": c.order.name, "v_kmh": c.v_kmh,
                           "f_hz": c.f_hz, "zeta": c.zeta, "severity": c.severity}
                          for c in diagram.crossings]}
    emit(args, data, _campbell_table(diagram))


def _campbell_table(diagram) -> str:
    op = diagram.operating_point
    v = diagram.v_kmh
    ref = diagram.modes[0].reference_index if diagram.modes else 0
    lines = [f"Campbell diagram over {v[0]:g}…{v[-1]:g} km/h ({len(v)} speeds) at s0 = {op.s0:g}, "
             f"N0 = {op.N0:g} N, b_M = {op.b_M:g} N m s/rad",
             f"modes a motor's torque drives (participation >= {diagram.participation:g}; "
             f"{diagram.dense_points} speeds solved densely), named at {v[ref]:.4g} km/h:",
             f"{'f [Hz] at ' + format(v[0], 'g'):>14} {'at ' + format(v[-1], 'g'):>9} "
             f"{'ζ [-]':>7}  mode"]
    for mode in diagram.modes:
        lines.append(f"{mode.f_hz[0]:>14.4g} {mode.f_hz[-1]:>9.4g} {mode.zeta[ref]:>7.4f}  "
                     f"{mode.name}")
    lines += ["", "orders: " + ", ".join(o.name for o in diagram.orders), "",
              f"crossings ({len(diagram.crossings)}) by severity = torque amplitude per N m of "
              f"{diagram.input} at that order [N m/N m]:",
              f"{'v [km/h]':>9} {'f [Hz]':>9} {'order':>9} {'ζ [-]':>7} {'severity':>9}  worst "
              "output; mode"]
    for c in diagram.crossings:
        name, value = c.worst
        lines.append(f"{c.v_kmh:>9.2f} {c.f_hz:>9.3f} {c.order.name:>9} {c.zeta:>7.4f} "
                     f"{value:>9.3g}  {name}; {c.mode}")
    return "\n".join(lines)


def cmd_frf(args: argparse.Namespace) -> None:
    from model.analysis.frequency_response import frequency_response

    band = parse_range(args.f, "--f (Hz)")
    if not band[0] < band[-1]:
        raise UsageError(f"--f = '{args.f}' is an empty range: A must be below B")
    count = len(band)
    csv_path = _check_csv(args.csv)
    model, op, _ = load_model(args)
    outputs = checked_output_names(args, model, op, loads_only=True)
    _check_input(model, args.input)
    result = frequency_response(model, op, input=args.input, f_lo=float(band[0]),
                                f_hi=float(band[-1]), points=count, outputs=outputs,
                                min_peak=args.min_peak)
    if not np.all(np.isfinite(result.H)):
        raise UsageError("an output drifts with the rigid-body motion: no finite static gain")
    if csv_path is not None:
        _write_csv(csv_path, result)
    magnitude, phase = result.magnitude, result.phase_deg
    data = {"input": result.input, "operating_point": op.as_dict(), "f_hz": result.f_hz.tolist(),
            "outputs": [{"name": name, "unit": unit, "abs": magnitude[i].tolist(),
                         "phase_deg": phase[i].tolist(),
                         "peaks": [{"f_hz": p.f_hz, "abs": p.abs} for p in result.peaks[i]]}
                        for i, (name, unit) in enumerate(zip(result.names, result.units,
                                                             strict=True))]}
    emit(args, data, _frf_table(result) + (f"\nwrote {csv_path}" if csv_path else ""))


def _check_csv(path: str | None) -> Path | None:
    return writable_path(path, "--csv", suffixes=(".csv",))


def _write_csv(path: Path, result) -> None:
    """f [Hz], then |H| and phase [deg] of every output, one row per frequency."""
    per = f"/{result.input_unit}"
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        header = ["f [Hz]"]
        for name, unit in zip(result.names, result.units, strict=True):
            header += [f"{name} |H| [{unit}{per}]", f"{name} phase [deg]"]
        writer.writerow(header)
        columns = [result.f_hz]
        for i in range(len(result.names)):
            columns += [result.magnitude[i], result.phase_deg[i]]
        writer.writerows([[repr(float(x)) for x in row] for row in np.column_stack(columns)])


def _frf_table(result) -> str:
    op = result.operating_point
    lines = [f"frequency response from {result.input} [{result.input_unit}] at s0 = {op.s0:g}, "
             f"v = {op.v_kmh:g} km/h, N0 = {op.N0:g} N, b_M = {op.b_M:g} N m s/rad",
             f"{len(result.f_hz)} frequencies: 0 Hz (static gain), {result.base_points} "
             f"log-spaced over {result.f_hz[1]:g}…{result.f_hz[-1]:g} Hz and "
             f"{len(result.f_hz) - 1 - result.base_points} across the resonances "
             f"(modal form; {result.direct_points} solved directly)",
             *([] if result.stable else [
                 "UNSTABLE operating point: a mode grows, H(f) is no steady state"]),
             f"{'output':<34} {'unit':>5} {'static':>10}  peaks: f [Hz] |H| (× static)"]
    for i, (name, unit) in enumerate(zip(result.names, result.units, strict=True)):
        peaks = "; ".join(
            f"{p.f_hz:.4g} {p.abs:.4g}" + (f" ({p.amplification:.3g}×)"
                                            if p.amplification is not None else "")
            for p in result.peaks[i]) or "none"
        lines.append(f"{name:<34} {unit + '/' + result.input_unit:>9} "
                     f"{abs(result.static_gain[i]):>10.4g}  {peaks}")
    return "\n".join(lines)


def cmd_ripple(args: argparse.Namespace) -> None:
    if (args.ripple is None) == (args.wheel_polygon is None):
        raise UsageError("give either --ripple (a motor torque ripple) or --wheel-polygon "
                         "(polygonal wheels)")
    if args.wheel_polygon is not None:
        _polygon(args)
        return
    _ripple(args)


def _polygon(args: argparse.Namespace) -> None:
    from model.analysis.wheel_excitation import parse_polygon, polygon_response
    from model.mechanics.operating_point import KMH

    polygon = parse_polygon(args.wheel_polygon)
    model, op, speeds = _sweep_model(args)
    result = polygon_response(model, op, speeds, polygon,
                              outputs=checked_output_names(args, model, op, loads_only=True))

    def listed(values: np.ndarray) -> list[float | None]:
        return [float(x) if np.isfinite(x) else None for x in values]

    outputs = []
    for i, (name, unit) in enumerate(zip(result.names, result.units, strict=True)):
        finite = np.isfinite(result.total[i])
        peak, at = result.peak(name) if finite.any() else (None, None)
        outputs.append({"name": name, "unit": unit, "amplitude": listed(result.total[i]),
                        "peak": peak, "peak_v_kmh": at / KMH if at is not None else None,
                        "by_order": {str(n): listed(result.by_order[k, i])
                                     for k, n in enumerate(result.orders)}})
    data = {"operating_point": {"s0": op.s0, "N0": op.N0, "b_M": op.b_M},
            "v_kmh": result.v_kmh.tolist(),
            "wheel_polygon": [
                {"order": n, "input_amplitude": float(a), "f_hz": listed(f),
                 "wheels": [{"input": name, "phase_deg": float(phase)}
                            for name, phase in zip(result.inputs, phases, strict=True)]}
                for n, a, f, phases in zip(result.orders, result.amplitudes,
                                           result.frequencies_hz, result.phases_deg, strict=True)],
            "unstable_v_kmh": list(result.unstable_kmh),
            "outputs": outputs}
    given = ", ".join(f"order {n}: {a * 1e6:g} µm"
                      for n, a in zip(result.orders, result.amplitudes, strict=True))
    lines = [f"steady amplitude under polygonal wheels ({given}; every wheel, the rear wheelset "
             f"a wheelbase later), {result.v_kmh[0]:g}…{result.v_kmh[-1]:g} km/h at s0 = "
             f"{op.s0:g} (sum over the orders)",
             *([] if not result.unstable_kmh else [
                 "UNSTABLE running system at " + ", ".join(f"{v:g}" for v in result.unstable_kmh)
                 + " km/h: a mode grows, the amplitudes are no steady state"]),
             f"{'output':<34} {'unit':>5} {'peak':>11} {'at [km/h]':>10}"]
    for row in outputs:
        peak = "—" if row["peak"] is None else f"{row['peak']:.4g}"
        at = "—" if row["peak_v_kmh"] is None else f"{row['peak_v_kmh']:.4g}"
        lines.append(f"{row['name']:<34} {row['unit']:>5} {peak:>11} {at:>10}")
    emit(args, data, "\n".join(lines))


def _ripple(args: argparse.Namespace) -> None:
    from model.analysis.campbell import ripple_response
    from model.mechanics.excitation import ExcitationError, parse_amplitudes
    from model.mechanics.operating_point import KMH

    model, op, speeds = _sweep_model(args)
    _check_motor_input(model, args.input)
    try:
        ripple = parse_amplitudes(args.ripple)
    except ExcitationError as error:
        raise UsageError(f"--ripple: {error}") from None
    outputs = checked_output_names(args, model, op, loads_only=True)
    result = ripple_response(model, op, speeds, ripple, _excitation(args), input=args.input,
                             outputs=outputs)

    def listed(values: np.ndarray) -> list[float | None]:
        return [float(x) if np.isfinite(x) else None for x in values]

    outputs = []
    for i, (name, unit) in enumerate(zip(result.names, result.units, strict=True)):
        finite = np.isfinite(result.total[i])
        peak, at = result.peak(name) if finite.any() else (None, None)
        outputs.append({"name": name, "unit": unit, "amplitude": listed(result.total[i]),
                        "peak": peak, "peak_v_kmh": at / KMH if at is not None else None,
                        "by_order": {o.name: listed(result.by_order[k, i])
                                     for k, o in enumerate(result.orders)}})
    data = {"input": result.input,
            "operating_point": {"s0": op.s0, "N0": op.N0, "b_M": op.b_M},
            "v_kmh": result.v_kmh.tolist(),
            "ripple": [{"order": o.name, "amplitude": float(a), "f_hz": listed(f)}
                       for o, a, f in zip(result.orders, result.amplitudes, result.frequencies_hz,
                                          strict=True)],
            "outputs": outputs}
    given = ", ".join(f"{o.name} = {a:g} N m"
                      for o, a in zip(result.orders, result.amplitudes, strict=True))
    lines = [f"steady amplitude under the ripple {given} "
             f"of {result.input}, {result.v_kmh[0]:g}…{result.v_kmh[-1]:g} km/h at s0 = {op.s0:g} "
             "(sum over the orders: the largest the steady state reaches)",
             f"{'output':<34} {'unit':>5} {'peak':>11} {'at [km/h]':>10}"]
    for row in outputs:
        peak = "—" if row["peak"] is None else f"{row['peak']:.4g}"
        at = "—" if row["peak_v_kmh"] is None else f"{row['peak_v_kmh']:.4g}"
        lines.append(f"{row['name']:<34} {row['unit']:>5} {peak:>11} {at:>10}")
    emit(args, data, "\n".join(lines))


def cmd_track(args: argparse.Namespace) -> None:
    from model.analysis.track_spectrum import random_response, track_spectrum

    spectrum = track_spectrum(args.spectrum)
    model, op, _ = load_model(args)
    result = random_response(model, op, spectrum,
                             outputs=checked_output_names(args, model, op, loads_only=True))
    f_lo, f_hi = spectrum.band_hz(op.v)
    data = {"operating_point": op.as_dict(),
            "spectrum": {"name": spectrum.name, "A_v": spectrum.A_v, "omega_c": spectrum.omega_c,
                         "omega_r": spectrum.omega_r, "wavelength_min": spectrum.wavelength_min,
                         "wavelength_max": spectrum.wavelength_max, "source": spectrum.source,
                         "rms_m": spectrum.variance() ** 0.5},
            "stable": result.stable, "f_hz": result.f_hz.tolist(),
            "input_psd": result.input_psd.tolist(),
            "outputs": [{"name": name, "unit": unit, "rms": float(result.rms[i]),
                         "moments": result.moments[i].tolist(), "psd": result.psd[i].tolist()}
                        for i, (name, unit) in enumerate(zip(result.names, result.units,
                                                             strict=True))]}
    lines = [f"random vertical track ({spectrum.name}: A_v = {spectrum.A_v:g} m² rad/m, Ω_c = "
             f"{spectrum.omega_c:g}, Ω_r = {spectrum.omega_r:g} rad/m, wavelengths "
             f"{spectrum.wavelength_min:g}…{spectrum.wavelength_max:g} m, RMS "
             f"{spectrum.variance() ** 0.5 * 1e3:.3g} mm) at s0 = {op.s0:g}, v = {op.v_kmh:g} "
             f"km/h: {f_lo:.3g}…{f_hi:.3g} Hz; both rails alike, the rear wheelset a wheelbase "
             "later",
             *([] if result.stable else [
                 "UNSTABLE running system: a mode grows, the RMS is no stationary response"]),
             f"{'output':<34} {'unit':>5} {'RMS':>11}"]
    for i, (name, unit) in enumerate(zip(result.names, result.units, strict=True)):
        lines.append(f"{name:<34} {unit:>5} {result.rms[i]:>11.4g}")
    emit(args, data, "\n".join(lines))
