"""What several commands run alike: the history an option set describes (``bogie response``,
``bogie spectrum``), and a study on the engine with its progress bar (``bogie study``, ``bogie
envelope``).  Below the command modules (none of them imports another), above the options."""

from __future__ import annotations

import argparse
import math
import sys
import time

from app.cli.options import (
    UsageError,
    anti_slip_from,
    check_creep_arguments,
    check_samples,
    check_sampling,
    load_model,
    output_names,
    short_circuit_from,
)


def history_from_args(args: argparse.Namespace):
    """The response the options of ``bogie response`` describe: a
    :class:`model.analysis.response.ResponseResult` (``--creep linear``) or a
    :class:`model.analysis.nonlinear.NonlinearResult`; bad options raise :class:`UsageError`."""
    from model.analysis.response import short_circuit_response

    check_creep_arguments(args)
    excitation = short_circuit_from(args)
    check_sampling(args, excitation.f, f"the excitation at f = {excitation.f:g} Hz")
    check_samples(args)
    names = output_names(args)
    model, op, _ = load_model(args)
    if args.creep != "linear":
        from model.analysis.nonlinear import nonlinear_response

        anti_slip = anti_slip_from(args) if args.anti_slip == "on" else None
        return nonlinear_response(model, op, excitation, args.t_end, args.fs, creep=args.creep,
                                  anti_slip=anti_slip, outputs=names, strength=args.strength)
    result = short_circuit_response(model, op, excitation, args.t_end, args.fs, names,
                                    method=args.method)
    if result.highest_excited_hz:
        check_sampling(args, result.highest_excited_hz,
                       f"the highest excited frequency {result.highest_excited_hz:.4g} Hz", ".4g")
    return result


class ProgressBar:
    """``[#####-----] 5/10 chunks, 12 s elapsed, ~12 s left`` on stderr (redrawn in place on a
    terminal; otherwise a line at most every 2 s and at the end)."""

    def __init__(self, label: str, stream=None, width: int = 30, unit: str = "chunks"):
        self.label, self.stream, self.width, self.unit = label, stream or sys.stderr, width, unit
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.first: tuple[int, float] | None = None
        self.last_print = -math.inf

    def __call__(self, finished: int, total: int, elapsed: float) -> None:
        if self.first is None:
            self.first = (finished, elapsed)
        done_here = finished - self.first[0]
        if done_here > 0 and finished < total:
            left = f", ~{(elapsed - self.first[1]) / done_here * (total - finished):.0f} s left"
        else:
            left = ""
        filled = int(self.width * finished / max(total, 1))
        text = (f"{self.label}: [{'#' * filled}{'-' * (self.width - filled)}] {finished}/{total} "
                f"{self.unit}, {elapsed:.0f} s elapsed{left}")
        now = time.monotonic()
        if self.tty:
            self.stream.write("\r" + text.ljust(100) + ("\n" if finished == total else ""))
        elif finished == total or now - self.last_print >= 2.0:
            self.stream.write(text + "\n")
        else:
            return
        self.last_print = now
        self.stream.flush()


def start_engine(args: argparse.Namespace):
    """(engine or None, map_unordered, where) for --serial / --scheduler / a local cluster."""
    from model.studies.engine import EngineUnavailable, StudyEngine, serial_map_unordered

    if args.serial:
        return None, serial_map_unordered, "this process (serial)"
    engine = StudyEngine(args.scheduler, args.workers, args.connect_timeout)
    try:
        engine.start()
    except EngineUnavailable as error:
        raise UsageError(str(error)) from None
    return engine, engine.map_unordered, engine.description
