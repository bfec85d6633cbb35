"""What several commands run alike: the history an option set describes (``bogie response``,
``bogie spectrum``), and a study on the engine (:func:`study_engine`: Ctrl-C exits with status
130 wherever it comes) with its progress bar (``bogie study``, ``bogie envelope``, ``bogie
assess``).  Below the command modules (none of them imports another), above the options."""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from app.cli.options import (
    EXIT_INTERRUPTED,
    UsageError,
    anti_slip_from,
    check_creep_arguments,
    check_samples,
    check_sampling,
    checked_output_names,
    load_model,
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
    model, op, _ = load_model(args)
    names = checked_output_names(args, model, op, loads_only=args.creep != "linear")
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


def resume_store(path, study, parameters) -> None:
    """Check that the store ``path`` of ``--out … --resume`` is this study's (it exists, same
    parameters and arguments), before any work; a mismatch is bad input naming both options."""
    from model.studies.store import StoreMismatch, prepare_store

    try:
        prepare_store(path, study, parameters, resume=True)
    except StoreMismatch as error:
        raise UsageError(f"--out with --resume: {error}") from None


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


@contextmanager
def study_engine(args: argparse.Namespace, label: str,
                 interrupted: Callable[[], str] = lambda: "") -> Iterator[tuple]:
    """The study engine of the options (``--serial``, ``--scheduler``, else a local cluster) for
    the ``with`` block: ``(map_unordered, where)``.  Ctrl-C while the engine starts, runs or
    stops prints ``<label>: interrupted<interrupted()>`` on stderr and exits with status 130
    (:data:`EXIT_INTERRUPTED`), no traceback; an unreachable scheduler is bad input
    (:class:`UsageError`); the engine is closed whatever happens."""
    from model.studies.engine import EngineUnavailable, StudyEngine, serial_map_unordered

    engine = None
    try:
        try:
            if args.serial:
                yield serial_map_unordered, "this process (serial)"
                return
            engine = StudyEngine(args.scheduler, args.workers, args.connect_timeout)
            try:
                engine.start()
            except EngineUnavailable as error:
                raise UsageError(str(error)) from None
            yield engine.map_unordered, engine.description
        finally:
            if engine is not None:
                engine.close()
    except KeyboardInterrupt:
        print(f"\n{label}: interrupted{interrupted()}", file=sys.stderr)
        raise SystemExit(EXIT_INTERRUPTED) from None
