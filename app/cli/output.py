"""Output helpers every command group of ``bogie`` shares: a result as JSON or as a table, time
histories written to ``.npz``/``.csv``/``.json``, the limit lines of a response and the tail of a
command that writes a file and prints its summary.
"""

from __future__ import annotations

import argparse
import csv
import json
import tempfile
from pathlib import Path

import numpy as np

from app.cli.options import UsageError

HISTORY_SUFFIXES = (".npz", ".csv", ".json")


def emit(args: argparse.Namespace, data: dict, table: str) -> None:
    """Print ``data`` as JSON with ``--json`` (NaN refused), else the human-readable ``table``."""
    if args.json:
        print(json.dumps(data, indent=1, allow_nan=False))
    else:
        print(table)


def writable_path(text: str | None, option: str, *, suffixes: tuple[str, ...] = (),
                  directory: bool = False, parents: bool = False) -> Path | None:
    """The output ``text`` of ``option`` (``--out``), checked before any work: not empty, ending
    in one of ``suffixes`` (any without), in an existing directory (``parents``: the command
    creates the missing ones, the nearest existing one is checked), not a directory itself (a
    file) or not a file (``directory``: a folder the command fills, created if missing), and
    writable — a temporary file is created there and removed at once (a permission check
    alone says yes to root on a read-only or virtual file system such as /proc).  None
    without the option."""
    if text is None:
        return None
    if not text.strip():
        raise UsageError(f"{option}: the path is empty")
    path = Path(text).expanduser()
    if suffixes and path.suffix not in suffixes:  # as the writers check it: case-sensitive
        raise UsageError(f"{option} '{text}': the file name must end in {' or '.join(suffixes)}")
    folder = path.parent
    while parents and not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if folder.exists() and not folder.is_dir():
        raise UsageError(f"{option} '{text}' cannot be used: '{folder}' is a file, not a "
                         "directory")
    if not folder.is_dir():
        raise UsageError(f"{option} '{text}': directory '{folder}' does not exist")
    if path.exists():
        if directory and not path.is_dir():
            raise UsageError(f"{option} '{text}': not a directory")
        if not directory and path.is_dir():
            raise UsageError(f"{option} '{text}': is a directory, give a file name")
        if directory:
            folder = path
    try:
        if path.exists() and not directory:
            with path.open("ab"):  # appends nothing: the file stays as it is
                pass
        else:
            with tempfile.NamedTemporaryFile(dir=folder, prefix=".bogie-write-check-"):
                pass
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise UsageError(f"{option} '{text}': cannot write there ({reason.lower()})") from None
    return path


def check_history_file(path: str | None, option: str = "--out") -> Path | None:
    """The ``--out`` file of a time history (``.npz``, ``.csv`` or ``.json`` in an existing,
    writable directory), checked before any work; None without ``--out``."""
    return writable_path(path, option, suffixes=HISTORY_SUFFIXES)


def finish(args: argparse.Namespace, result, out: Path | None, write, summarize, table) -> None:
    """The tail of a response command: ``write(result, out)`` if asked, then the summary
    (``summarize(result)``, JSON) or the table (``table(result)``, text)."""
    if out is not None:
        write(result, out)
    summary = summarize(result)
    if out is not None:
        summary["out"] = str(out)
    emit(args, summary, table(result) + (f"\nwrote {out}" if out else ""))


def limit_lines(result) -> list[str]:
    """The limits and their first crossings of a (linear or nonlinear) response, as text lines."""
    lines = ["", "limits: " + ", ".join(f"{k} = {v:.5g}" for k, v in result.limits.items())]
    if not result.limit_crossings:
        return [*lines, "no limit crossed"]
    lines.append("limit crossings (|total| > limit), first time:")
    for c in result.limit_crossings:
        lines.append(f"  {c.time:8.4f} s  {c.output} = {c.value:.5g} beyond {c.limit_name} = "
                     f"{c.limit:.5g}")
    return lines


def write_series(path: Path, t: np.ndarray, M_C: np.ndarray,
                 series: dict[str, tuple[np.ndarray, str]], steady: dict[str, float],
                 summary: dict) -> None:
    """Time series (name -> (values, unit)) at times ``t`` [s] with the short-circuit torque
    ``M_C`` [N m] as ``.npz`` (arrays, names, units, steady values; NaN where a series has
    none), ``.csv`` (one column per series, units in the header) or ``.json`` (``summary``
    plus the series)."""
    names = list(series)
    if path.suffix == ".npz":
        arrays = {"t": t, "M_C": M_C, **{n: series[n][0] for n in names},
                  "names": np.array(names, dtype=str),
                  "units": np.array([series[n][1] for n in names], dtype=str),
                  "steady": np.array([steady.get(n, np.nan) for n in names])}
        np.savez(path, **arrays)
    elif path.suffix == ".csv":
        with path.open("w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["t [s]", "M_C [N m]"] + [f"{n} [{series[n][1]}]" for n in names])
            table = np.column_stack([t, M_C] + [series[n][0] for n in names])
            writer.writerows([[repr(float(x)) for x in row] for row in table])
    else:
        data = dict(summary)
        data["t"] = t.tolist()
        data["M_C"] = M_C.tolist()
        data["series"] = {n: series[n][0].tolist() for n in names}
        path.write_text(json.dumps(data, allow_nan=False))
