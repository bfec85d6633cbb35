"""Reliability of the served dashboard: isolation of concurrent sessions with different design
variants, memory over a soak, and a fuzz of query strings, control values and uploaded files.

    .venv/bin/python scripts/reliability_app.py [--sessions 20] [--soak-minutes 10]
                                                [--fuzz 50] [--json FILE]
    .venv/bin/python scripts/reliability_app.py --distinct-points 30 [--cache-mb 100]

Starts ``bogie serve`` on a free port (a separate process, as users run it) and talks to it with
Bokeh's protocol client (``bokeh.client``: the same messages a browser sends, no rendering):

1. isolation: ``--sessions`` sessions opened at once, each with its own variant in the URL
   (``variant=silent_block_stiffness_z:…``, a different stiffness each); every session's shown
   eigenvalues must be those of its own variant (computed here with ``model``) and differ from
   every other session's;
2. soak: one session changes a control every second (s0 through the slider's values, the speed
   every tenth change) for ``--soak-minutes``; the server's resident memory (VmRSS) is sampled
   every 10 s; reported: start (after the first minute), end, maximum, growth per minute over
   the second half;
3. fuzz: ``--fuzz`` random query strings (NaN, huge, negative, wrong types, unknown names,
   oversized and malformed variants; each GET builds a session on the server) must each give
   HTTP 200 (a page with a notice, never a server error); bad slider values (NaN, ±1e300,
   strings) and bad uploads (malformed, not UTF-8, oversized, NaN, wrong types) sent through a
   session must leave it working (a valid change afterwards still gives new results) and the
   server alive (liveness 200).

4. ``--distinct-points N`` (alone): a server with ``--cache-mb``, one session visiting six
   distinct operating points and then N more, each with its slower stages; the server's memory
   after the six and after each further point (the results cache is bounded in bytes: the
   memory levels off).

The functions are also used by ``tests/app/server/test_reliability.py`` with short settings.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import random
import statistics
import sys
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import served_app  # noqa: E402 - the scripts' own helpers
from served_app import alive, free_port  # noqa: E402


def log(message: str) -> None:
    print(f"reliability_app: {time.strftime('%H:%M:%S')} {message}", file=sys.stderr, flush=True)


def start_server(port: int, *options: str):
    return served_app.start_server(port, "reliability_app", *options)


def rss_mb(pid: int) -> float:
    """Resident memory [MB] of a process (Linux /proc)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError(f"no VmRSS for process {pid}")


def _register_panel_models() -> None:
    """Import every module of Panel's Bokeh models: a pulled document that holds a model type
    the client does not know (e.g. the mode table's DataTabulator) cannot be deserialized."""
    import importlib
    import pkgutil

    import panel.models

    for module in pkgutil.iter_modules(panel.models.__path__):
        try:
            importlib.import_module(f"panel.models.{module.name}")
        except ImportError:  # optional extras (e.g. a plotting library not installed)
            pass


def _control(doc, css: str):
    return next(m for m in doc.models if css in (getattr(m, "css_classes", None) or []))


def _current_eigenvalues(doc) -> list[complex]:
    import math

    data = doc.get_model_by_name("locus_current").data
    return [complex(x, y * 2 * math.pi) for x, y in zip(data["x"], data["y"], strict=True)]


def _wait_change(session, sources, action, timeout: float = 300.0) -> float:
    """Run ``action()`` and wait until every source's data changed; seconds taken."""
    seen = set()
    callbacks = []
    for source in sources:
        def changed(attr, old, new, source=source):
            seen.add(source.id)
        source.on_change("data", changed)
        callbacks.append((source, changed))
    t0 = time.perf_counter()
    action()
    _run_until(session, lambda: len(seen) == len(sources), timeout)
    for source, changed in callbacks:
        source.remove_on_change("data", changed)
    if len(seen) < len(sources):
        raise TimeoutError(f"no new results after {timeout:.0f} s")
    return time.perf_counter() - t0


def _run_until(session, predicate, timeout: float) -> None:
    """Run the client's event loop until ``predicate()`` or ``timeout`` [s].  Bokeh's client
    checks the predicate only when a message arrives: a timer stops the loop otherwise."""
    connection = session._connection
    loop = connection._loop
    handle = loop.call_later(timeout, loop.stop)
    try:
        connection._loop_until(predicate)
    finally:
        loop.remove_timeout(handle)


def _pause(_session, seconds: float) -> None:
    """Wait ``seconds``; messages arriving meanwhile are read by the next :func:`_run_until`."""
    if seconds > 0:
        time.sleep(seconds)


def _release(slider, value) -> None:
    slider.value = value
    slider.set_from_json("value_throttled", value)  # as BokehJS does on release


# --- 1. isolation ------------------------------------------------------------------------------

def variant_of(index: int) -> dict[str, float]:
    """Session ``index``'s variant: the silent blocks' vertical stiffness × (1 + 0.1 index)."""
    from model.mechanics.parameters import load_parameters

    base = load_parameters()
    return {"silent_block_stiffness_z": base["silent_block_stiffness_z"] * (1 + 0.1 * index)}


def isolation(url: str, sessions: int) -> dict:
    """Open ``sessions`` sessions at once, each with its own variant; check each shows its own
    eigenvalues.  Returns counts and the first failures."""
    import numpy as np
    from bokeh.client import pull_session

    from app.results.variants import encode, parameters_of_key, set_key
    from model import build_model, eigen_analysis
    from model.mechanics.operating_point import OperatingPoint

    _register_panel_models()
    shown: dict[int, list[complex]] = {}
    failures: list[str] = []

    def client(index: int) -> None:
        try:
            session = pull_session(url=f"{url}/app",
                                   arguments={"variant": encode(variant_of(index))})
            try:
                shown[index] = _current_eigenvalues(session.document)
            finally:
                session.close()
        except Exception as error:  # reported below
            failures.append(f"session {index}: {error!r}")

    t0 = time.perf_counter()
    threads = [threading.Thread(target=client, args=(i,)) for i in range(sessions)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=600)
    elapsed = time.perf_counter() - t0
    wrong = 0
    for index, eigenvalues in sorted(shown.items()):
        parameters = parameters_of_key(set_key("", variant_of(index)))
        op = OperatingPoint.from_kmh(0.005, 120.0, parameters["wheel_force"],
                                     parameters["motor_slope"])
        expected = eigen_analysis(build_model(parameters), op).complex_pairs[:len(eigenvalues)]
        if not np.allclose(eigenvalues, expected, rtol=1e-6):
            wrong += 1
            failures.append(f"session {index} shows other eigenvalues than its variant's")
    distinct = len({tuple(np.round(v, 9)) for v in shown.values()})
    return {"sessions": sessions, "answered": len(shown), "own_results": len(shown) - wrong,
            "distinct": distinct, "seconds": elapsed, "failures": failures[:10]}


# --- 2. soak -------------------------------------------------------------------------------------

def soak(url: str, pid: int | None, minutes: float, interval: float = 1.0,
         sample_every: float = 10.0, s0_values: list[float] | None = None,
         speeds_kmh: list[float] | None = None, warm: float = 0.0) -> dict:
    """One session changing a control every ``interval`` s for ``minutes``; server memory [MB]
    sampled every ``sample_every`` s (``pid``: the server process; None: this process).

    The creepages visited are ``s0_values`` (default: every page step of the s0 slider, 0.0005)
    and the speeds ``speeds_kmh`` [km/h] (default 80…160 km/h).  ``warm``: first visit every
    combination once, wait for its first answer and ``warm`` s more for the slower stages
    (the dense root locus, the assessment), so that the memory samples (taken after it) see
    the caches already holding every result the soak asks for: what grows then is a leak."""
    from bokeh.client import pull_session

    _register_panel_models()
    pid = pid or os.getpid()
    session = pull_session(url=f"{url}/app")
    doc = session.document
    s0, v = _control(doc, "ctl-s0"), _control(doc, "ctl-v")
    fast = [doc.get_model_by_name("locus_current")]
    samples: list[tuple[float, float]] = []
    latencies: list[float] = []
    errors = 0
    t0 = time.monotonic()
    next_sample = t0
    changes = 0
    # the s0 values on the slider's page steps (0.0005): the values a reviewer steps through,
    # revisited as the soak goes on
    page = 5 * s0.step
    values = s0_values or [round(s0.start + k * page, 6)
                           for k in range(int((s0.end - s0.start) / page))]
    speeds = speeds_kmh or [80.0, 100.0, 120.0, 140.0, 160.0]
    rng = random.Random(7)
    warm_seconds = 0.0
    if warm:
        for speed in speeds:
            for value in values:
                if (value, speed) == (s0.value, v.value):
                    continue
                _wait_change(session, fast, lambda value=value, speed=speed: (
                    _release(v, speed), _release(s0, value)), timeout=120)
                _pause(session, warm)
        warm_seconds = time.monotonic() - t0
        t0 = next_sample = time.monotonic()
    try:
        while time.monotonic() - t0 < minutes * 60:
            now = time.monotonic()
            if now >= next_sample:
                samples.append((now - t0, rss_mb(pid)))
                next_sample += sample_every
            changes += 1
            try:
                if changes % 10 == 0:
                    speed = rng.choice(speeds)
                    if speed != v.value:
                        _release(v, speed)
                else:
                    value = rng.choice(values)
                    if value != s0.value:
                        latencies.append(_wait_change(session, fast,
                                                      lambda value=value: _release(s0, value),
                                                      timeout=60))
            except TimeoutError:
                errors += 1
            _pause(session, interval - (time.monotonic() - now))
    finally:
        session.close()
    samples.append((time.monotonic() - t0, rss_mb(pid)))
    warm = [m for t, m in samples if t >= min(60.0, minutes * 30)] or [m for _, m in samples]
    half = [(t, m) for t, m in samples if t >= samples[-1][0] / 2]
    slope = 0.0
    if len(half) >= 2:
        ts, ms = zip(*half, strict=True)
        mean_t, mean_m = statistics.fmean(ts), statistics.fmean(ms)
        slope = sum((t - mean_t) * (m - mean_m) for t, m in half) / max(
            sum((t - mean_t) ** 2 for t in ts), 1e-9) * 60
    return {"minutes": minutes, "changes": changes, "timeouts": errors, "warm_s": warm_seconds,
            "median_latency_s": statistics.median(latencies) if latencies else None,
            "rss_start_mb": warm[0], "rss_end_mb": samples[-1][1],
            "rss_max_mb": max(m for _, m in samples), "growth_mb": samples[-1][1] - warm[0],
            "growth_second_half_mb_per_min": slope, "samples": samples}


def distinct_points(url: str, pid: int, base_points: int, points: int, settle: float = 3.0,
                    speeds_kmh: tuple[float, ...] = (80.0, 100.0, 120.0, 140.0, 160.0, 180.0)
                    ) -> dict:
    """One session visiting ``base_points`` and then ``points`` more distinct operating points
    (creepages on the s0 slider's steps × ``speeds_kmh``, none visited twice), waiting for each
    first answer and ``settle`` s more for the slower stages (root locus, s0*(v), verdict): the
    server's memory [MB] after the base points and after each further one (``pid``: the
    server process).  With a results cache bounded in bytes the memory levels off."""
    from bokeh.client import pull_session

    _register_panel_models()
    session = pull_session(url=f"{url}/app")
    doc = session.document
    s0, v = _control(doc, "ctl-s0"), _control(doc, "ctl-v")
    fast = [doc.get_model_by_name("locus_current")]
    visits = [(round(0.0035 + 0.0005 * (k // len(speeds_kmh)), 6), speeds_kmh[k % len(speeds_kmh)])
              for k in range(base_points + points)]
    samples: list[float] = []
    timeouts = 0
    t0 = time.monotonic()
    try:
        for k, (value, speed) in enumerate(visits):
            try:
                _wait_change(session, fast, lambda value=value, speed=speed: (
                    _release(v, speed), _release(s0, value)), timeout=120)
            except TimeoutError:
                timeouts += 1
            _pause(session, settle)
            if k >= base_points - 1:
                samples.append(rss_mb(pid))
    finally:
        session.close()
    return {"base_points": base_points, "points": points, "timeouts": timeouts,
            "rss_base_mb": samples[0], "rss_end_mb": samples[-1], "rss_max_mb": max(samples),
            "growth_mb": max(samples) - samples[0], "samples_mb": samples,
            "seconds": time.monotonic() - t0}


# --- 3. fuzz -------------------------------------------------------------------------------------

BAD_NUMBERS = ["nan", "NaN", "inf", "-inf", "1e308", "1e999", "-1", "0", "", " ", "abc", "0x10",
               "1,5", "[1]", "None", "true", "1" * 300, "%00", "\u00e9", "1e-400"]
NAMES = ["s0", "v", "n0", "bm", "m0", "f", "decay", "phase", "t_end", "rail", "locus", "zoom",
         "mode", "tab", "variant", "unknown", "s0[]", ""]
BAD_VARIANTS = ["gear_ratio:nan", "gear_ratio:1e300", "gear_ratio:-1", "gear_ratio",
                "no_such:1", "gear_ratio:4,gear_ratio:5", ":", ",,,", "x" * 5000,
                "polach_kS:0.9,polach_kA:0.1", "gear_ratio:1e-300"]


def fuzz_queries(url: str, count: int, seed: int = 1) -> dict:
    """``count`` random bad query strings: every answer must be HTTP 200."""
    rng = random.Random(seed)
    statuses: dict[int, int] = {}
    failures: list[str] = []
    for _ in range(count):
        items = []
        for _ in range(rng.randint(1, 5)):
            name = rng.choice(NAMES)
            value = rng.choice(BAD_VARIANTS) if name == "variant" else rng.choice(BAD_NUMBERS)
            items.append((name, value))
        query = urllib.parse.urlencode(items)
        try:
            with urllib.request.urlopen(f"{url}/app?{query}", timeout=300) as r:
                status = r.status
        except urllib.error.HTTPError as error:
            status = error.code
        except OSError as error:
            status = -1
            failures.append(f"{query[:80]}: {error!r}")
        statuses[status] = statuses.get(status, 0) + 1
        if status != 200 and len(failures) < 10:
            failures.append(f"{query[:80]}: HTTP {status}")
    return {"queries": count, "statuses": statuses, "failures": failures,
            "alive_after": alive(url, timeout=60)}


def _upload(doc, data: bytes, filename: str = "set.toml") -> None:
    upload = _control(doc, "var-upload")
    upload.set_from_json("filename", filename)
    upload.set_from_json("mime_type", "application/toml")
    upload.set_from_json("value", base64.b64encode(data).decode())


def bad_uploads() -> dict[str, bytes]:
    from model.mechanics.parameters import dumps_parameters, load_parameters

    text = dumps_parameters(load_parameters())
    line = next(x for x in text.splitlines() if x.startswith("gear_ratio ="))
    return {
        "malformed": b"gear_ratio = { value = ",
        "not utf-8": b"\xff\xfe\x00bad",
        "oversized": b"#" * 300_000,
        "nan": text.replace(line, 'gear_ratio = { value = nan, unit = "1", note = "" }').encode(),
        "wrong type": text.replace(line, 'gear_ratio = { value = "4", unit = "1", note = "" }')
        .encode(),
        "huge": text.replace(line, 'gear_ratio = { value = 1e300, unit = "1", note = "" }')
        .encode(),
        "empty": b"",
    }


def fuzz_session(url: str) -> dict:
    """Bad slider values and bad uploads through one session; afterwards a valid change must
    still give new results, and the server must be alive."""
    from bokeh.client import pull_session

    _register_panel_models()
    # the Variant tab open: its upload widget reaches the client only then (dynamic tabs)
    session = pull_session(url=f"{url}/app", arguments={"tab": "variant"})
    failures: list[str] = []
    sent = 0
    try:
        doc = session.document
        fast = [doc.get_model_by_name("locus_current")]
        for css in ("ctl-s0", "ctl-v", "ctl-N0", "ctl-t_end"):
            slider = _control(doc, css)
            for value in (float("nan"), 1e300, -1e300, -1.0, "abc"):
                try:
                    slider.set_from_json("value_throttled", value)
                    sent += 1
                except Exception as error:  # the client library refused to send it: fine
                    failures.append(f"{css} {value!r} not sent: {type(error).__name__}")
        for data in bad_uploads().values():
            _upload(doc, data)
            sent += 1
        _pause(session, 3.0)
        s0 = _control(doc, "ctl-s0")
        value = round(s0.value + s0.step if s0.value + s0.step <= s0.end else s0.start, 6)
        try:
            _wait_change(session, fast, lambda: _release(s0, value), timeout=120)
            still_working = True
        except TimeoutError:
            still_working = False
    finally:
        session.close()
    return {"bad_inputs_sent": sent, "session_still_working": still_working,
            "alive_after": alive(url, timeout=60), "notes": failures}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sessions", type=int, default=20)
    parser.add_argument("--soak-minutes", type=float, default=10.0)
    parser.add_argument("--fuzz", type=int, default=50)
    parser.add_argument("--json", default=None, help="write the results here")
    parser.add_argument("--distinct-points", type=int, default=None, metavar="N",
                        help="instead of the runs above: a server with --cache-mb (below), one "
                             "session visiting 6 distinct points and then N more; its memory")
    parser.add_argument("--cache-mb", type=int, default=100)
    args = parser.parse_args()
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    port = free_port()
    if args.distinct_points is not None:
        server = start_server(port, "--cache-mb", str(args.cache_mb))
        try:
            result = distinct_points(f"http://127.0.0.1:{port}", server.pid, 6,
                                     args.distinct_points)
        finally:
            server.terminate()
            server.wait(timeout=30)
        if args.json:
            Path(args.json).write_text(json.dumps(result, indent=1))
        print(f"--cache-mb {args.cache_mb}: server RSS {result['rss_base_mb']:.0f} MB after 6 "
              f"points, {result['rss_end_mb']:.0f} MB after {args.distinct_points} more (max "
              f"{result['rss_max_mb']:.0f}, growth {result['growth_mb']:.0f} MB), "
              f"{result['timeouts']} timeouts, {result['seconds']:.0f} s")
        return
    server = start_server(port)
    url = f"http://127.0.0.1:{port}"
    results = {}
    try:
        log(f"isolation: {args.sessions} sessions with different variants at once")
        results["isolation"] = isolation(url, args.sessions)
        log(json.dumps(results["isolation"]))
        log(f"fuzz: {args.fuzz} query strings, bad control values and uploads")
        results["fuzz_queries"] = fuzz_queries(url, args.fuzz)
        results["fuzz_session"] = fuzz_session(url)
        log(json.dumps(results["fuzz_queries"]) + " " + json.dumps(results["fuzz_session"]))
        log(f"soak: {args.soak_minutes} min, a control changed every second")
        results["soak"] = soak(url, server.pid, args.soak_minutes)
        summary = {k: v for k, v in results["soak"].items() if k != "samples"}
        log(json.dumps(summary))
        results["alive_at_end"] = alive(url, timeout=60)
    finally:
        server.terminate()
        server.wait(timeout=30)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))
    iso, soak_ = results["isolation"], results["soak"]
    print(f"isolation: {iso['own_results']}/{iso['sessions']} sessions showed their own "
          f"variant's eigenvalues ({iso['distinct']} distinct) in {iso['seconds']:.1f} s")
    print(f"fuzz: {results['fuzz_queries']['statuses']} for {args.fuzz} query strings; session "
          f"still working after bad values/uploads: {results['fuzz_session']['session_still_working']}"
          f"; server alive: {results['alive_at_end']}")
    print(f"soak: {soak_['changes']} changes in {soak_['minutes']:g} min, server RSS "
          f"{soak_['rss_start_mb']:.0f} -> {soak_['rss_end_mb']:.0f} MB (max "
          f"{soak_['rss_max_mb']:.0f}; second half {soak_['growth_second_half_mb_per_min']:+.1f} "
          f"MB/min), median latency {soak_['median_latency_s']:.2f} s, {soak_['timeouts']} "
          "timeouts")


if __name__ == "__main__":
    main()
