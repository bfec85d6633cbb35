"""Argument helpers every command group of ``bogie`` shares, so that no command imports another.

The parser whose errors are one line with exit status 2; argparse types for numbers with
bounds (:func:`bounded` takes the allowed interval as it is printed, ``"(0, 60]"``, so the check
and its message cannot drift apart); the options of the case's quantities, each added by one
loop from its declaration (:data:`app.results.case.QUANTITIES`: option, label, interval, unit,
default — :func:`add_case_option`): the operating point (``--s0 --v --n0 --bm``, with
``--params --json``) and the model it builds, the short circuit (``--m0 --f --decay --phase``),
the simulated time (``--t-end``, with ``--fs``) and the rail (``--rail``), and their value lists
(:func:`quantity_values`; their options: :mod:`app.cli.case_lists`); ranges ``A:B:N`` and value
lists ``x1,x2,…``; input files (:func:`input_file`) and scheduler addresses; the nonlinear creep
and anti-slip options of ``bogie response`` and ``bogie antislip``; the uncertainty options of
``bogie uncertainty`` and ``bogie study uncertainty``; the study engine's options.  A check that
fails raises :class:`UsageError`; :data:`INPUT_ERRORS` are the errors of bad input, which
:func:`app.cli.main.main` prints as one line on stderr with exit status 2.
"""

from __future__ import annotations

import argparse
import itertools
import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np

from app.results.case import Case, Quantity
from model.mechanics.parameters import load_parameters

EXIT_BAD_INPUT = 2
MAX_WORKERS = 256  # worker processes a command starts: more than the cores only queue, and each
# holds a model (docs/memory.md)


class UsageError(Exception):
    """Bad input from the command line (reported in one line, exit status 2)."""


def input_errors() -> tuple[type[BaseException], ...]:
    """The errors that mean bad input (a malformed value, parameter file, store, study): the
    project's own input-error types, each raised with a one-line message.  Any other error —
    a ``KeyError`` or ``ValueError`` included — is a programming error and shows its
    traceback."""
    from app.results.variants import VariantError
    from app.services.settings import SettingsError
    from model.analysis.campbell import CampbellError
    from model.analysis.fatigue import FatigueError
    from model.analysis.frequency_response import FrequencyResponseError
    from model.analysis.load_spectrum import SpectrumError
    from model.analysis.response import ResponseError
    from model.analysis.sensitivity import SensitivityError
    from model.analysis.spectral_fatigue import SpectralFatigueError
    from model.analysis.stability import NoStabilityLimit
    from model.analysis.track_spectrum import TrackSpectrumError
    from model.analysis.wheel_excitation import WheelExcitationError
    from model.mechanics.excitation import ExcitationError
    from model.mechanics.operating_point import OperatingPointError
    from model.mechanics.parameters import ParameterError
    from model.studies.life import LifeError
    from model.studies.posterior import PosteriorError
    from model.studies.route import RouteError
    from model.studies.store import StoreMismatch
    from model.studies.uncertainty import UncertaintyError
    from model.studies.verdict_priors import VerdictUncertaintyError

    # ResponseError covers the nonlinear solver's, the design loads' and the assessment's
    return (UsageError, ParameterError, OperatingPointError, NoStabilityLimit, ResponseError,
            ExcitationError, FrequencyResponseError, CampbellError, SensitivityError,
            WheelExcitationError, TrackSpectrumError,
            SpectrumError, UncertaintyError, PosteriorError, StoreMismatch, VariantError,
            SettingsError, VerdictUncertaintyError, FatigueError, RouteError, LifeError,
            SpectralFatigueError)


class BogieParser(argparse.ArgumentParser):
    """argparse with the error contract of ``bogie``: one line on stderr, exit status 2."""

    def error(self, message: str) -> None:  # one line, no usage block
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


# --- numbers -------------------------------------------------------------------------------------

def number(label: str, low: float = -math.inf, high: float = math.inf, low_open: bool = True,
           high_open: bool = True, allowed: str = "") -> Callable[[str], float]:
    """argparse type: a finite float within bounds, with a clear message otherwise."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{label} must be a number, got '{text}'") from None
        ok_low = value > low if low_open else value >= low
        ok_high = value < high if high_open else value <= high
        if not math.isfinite(value) or not (ok_low and ok_high):
            raise argparse.ArgumentTypeError(f"{label} = {text} is not allowed: {allowed}")
        return value

    return parse


_INTERVAL = re.compile(r"^([\[(])(\S+), (\S+)([\])])$")


def interval_ends(interval: str) -> tuple[float, float, bool, bool]:
    """(low, high, low open, high open) of an interval written as it is printed (``"(0, 60]"``:
    0 excluded, 60 included); a malformed one is a programming error (ValueError)."""
    match = _INTERVAL.match(interval)
    try:
        opening, low, high, closing = match.groups()
        return float(low), float(high), opening == "(", closing == ")"
    except (AttributeError, ValueError):
        raise ValueError(f"interval {interval!r} is not written as '(a, b]' or the like") from None


def bounded(label: str, interval: str, unit: str = "") -> Callable[[str], float]:
    """argparse type: a finite float in ``interval``, written as it is printed (``"(0, 60]"``:
    0 excluded, 60 included; ``"[1, 500]"``; ``"(0, 1e7)"``) followed by ``unit``.  A value
    outside: ``<label> = <text> is not allowed: must be in <interval> <unit>``."""
    low, high, low_open, high_open = interval_ends(interval)
    allowed = f"must be in {interval}" + (f" {unit}" if unit else "")
    return number(label, low, high, low_open=low_open, high_open=high_open, allowed=allowed)


def non_negative_int(label: str, high: int | None = None) -> Callable[[str], int]:
    """argparse type: a whole number >= 0 (and <= ``high``), with a clear message otherwise."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{label} must be a whole number, got '{text}'") from None
        if value < 0 or (high is not None and value > high):
            allowed = ">= 0" if high is None else f"in [0, {high}]"
            raise argparse.ArgumentTypeError(f"{label} = {text} is not allowed: must be {allowed}")
        return value

    return parse


def positive_int(label: str, high: int | None = None) -> Callable[[str], int]:
    """argparse type: a whole number >= 1 (and <= ``high``), with a clear message otherwise."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{label} must be a whole number, got '{text}'") from None
        if value < 1 or (high is not None and value > high):
            allowed = ">= 1" if high is None else f"in [1, {high}]"
            raise argparse.ArgumentTypeError(f"{label} = {text} is not allowed: must be {allowed}")
        return value

    return parse


# --- a Dask scheduler's address ------------------------------------------------------------------

_ADDRESS = re.compile(r"^(?:[a-z]+://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):([0-9]{1,5})$")


def scheduler_address(text: str) -> str:
    """argparse type: a Dask scheduler's address ``[tcp://]host:port`` (port 1…65535): a
    malformed one is refused at once, not after a connection attempt."""
    match = _ADDRESS.match(text.strip())
    if match is None or not 0 < int(match.group(2)) < 65536:
        raise argparse.ArgumentTypeError(f"'{text}' is not an address tcp://HOST:PORT")
    return text.strip()


# --- input files ---------------------------------------------------------------------------------

def input_file(load: Callable[[str], object] | None = None) -> Callable[[str], str]:
    """argparse type: a file that exists and can be read (``load``: and that it reads — a
    parameter file, a ranges file —, its input error said as the option's); returns the path as
    given, the command reads it again.  The message names the option (argparse's ``argument
    --params: …``) and is one line."""

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError("the path is empty")
        path = Path(text)
        if not path.is_file():
            what = "is a directory, not a file" if path.is_dir() else "does not exist"
            raise argparse.ArgumentTypeError(f"'{text}' {what}")
        try:
            with path.open("rb") as handle:
                handle.read(1)
        except OSError as error:
            reason = (error.strerror or type(error).__name__).lower()
            raise argparse.ArgumentTypeError(f"cannot read '{text}' ({reason})") from None
        if load is not None:
            try:
                load(text)
            except input_errors() as error:
                message = str(error.args[0] if error.args else error).splitlines()[0]
                raise argparse.ArgumentTypeError(message) from None
        return text

    return parse


PARAMETER_FILE = input_file(load_parameters)  # a parameter file (TOML) it can read


def parsed_text(module: str, function: str) -> Callable[[str], str]:
    """argparse type: a text the model's ``module.function`` reads (a wheel polygon, a track
    spectrum's name), checked by reading it — its input error said as the option's, one line;
    returns the text as given (imported when an option is given: the parser stays light)."""

    def parse(text: str) -> str:
        import importlib

        try:
            getattr(importlib.import_module(module), function)(text)
        except input_errors() as error:
            message = str(error.args[0] if error.args else error).splitlines()[0]
            raise argparse.ArgumentTypeError(message) from None
        return text

    return parse


WHEEL_POLYGON = parsed_text("model.analysis.wheel_excitation", "parse_polygon")  # order=µm,…


# --- the case's quantities: one option each, from its declaration --------------------------------

def _unit(q: Quantity) -> str:
    return "" if q.outer_unit == "-" else q.outer_unit


def dest(q: Quantity) -> str:
    """The namespace attribute of a quantity's option (``--t-end`` -> ``t_end``)."""
    return q.option.lstrip("-").replace("-", "_")


def dashboard_interval(q: Quantity) -> str:
    """The dashboard's range of ``q`` as a closed interval in the command line's unit (a
    command that reproduces the dashboard accepts exactly what its sliders allow)."""
    return f"[{q.to_outer(q.low):g}, {q.to_outer(q.high):g}]"


def add_case_option(parser, q: Quantity, *, interval: str | None = None,
                    default=..., help: str | None = None) -> None:
    """``q.option`` with the declared type, interval (``interval``: a narrower one; give the
    reason at the call), unit and default (the declared one in the command line's unit; a
    quantity whose default is the set's, or automatic, defaults to None); ``help``: what the
    value means for the command (default: the declaration's doc)."""
    doc = q.doc if help is None else help
    if q.choice:
        parser.add_argument(q.option, choices=q.choices,
                            default=q.default if default is ... else default,
                            help=f"{doc} (default %(default)s)")
        return
    if default is ...:
        default = None if q.from_set or q.default is None else q.to_outer(q.default)
    unit = _unit(q)
    if default is not None:
        said = " (default %(default)s)"
    elif q.from_set:
        said = " (default: parameter set)"
    else:
        said = f" (default: {q.automatic})" if q.automatic else ""
    parser.add_argument(q.option, type=bounded(q.option_label, interval or q.option_interval,
                                               unit),
                        default=default, help=f"{doc} [{q.outer_unit}]{said}")


def case_option_values(args: argparse.Namespace) -> dict:
    """name -> value (the command line's unit; None: not given or not an option of the
    command) of every quantity of the case."""
    return {q.name: getattr(args, dest(q), None) for q in Case.quantities}


def add_operating_point(parser: argparse.ArgumentParser, s0: float | None = 0.005,
                        speed: bool = True) -> None:
    """The operating point's options (``--s0 --v --n0 --bm`` and every quantity that changes
    the parameter set's values), ``--params`` and ``--json`` (``s0``: the default creepage;
    None: not given; ``speed`` False: no ``--v``, for a command that sweeps the speed)."""
    for q in Case.of_role("point", "override"):
        if q.name == "v" and not speed:
            continue
        add_case_option(parser, q, default=s0 if q.name == "s0" else ...)
    parser.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                        help="parameter file (TOML; default: the calibrated set)")
    parser.add_argument("--json", action="store_true", help="machine-readable JSON output")


def add_wheel_force_and_motor_slope(parser: argparse.ArgumentParser) -> None:
    """One value each of the quantities whose default is the parameter set's (``--n0`` [N],
    ``--bm`` [N m s/rad], …; None: the set's)."""
    for q in Case.of_role("point", "override"):
        if q.from_set:
            add_case_option(parser, q)


RAILS = Case.quantity("rail").choices  # the creep laws: the set's own, Polach's presets


def add_rail(parser: argparse.ArgumentParser) -> None:
    """``--rail``: one creep law, the set's own (calibrated) or Polach's dry/wet preset."""
    add_case_option(parser, Case.quantity("rail"))


def overrides_from(args: argparse.Namespace) -> dict[str, float]:
    """The parameter set's values the options replace (quantities of role ``override`` given
    on the command line), SI."""
    values = case_option_values(args)
    return {q.target: q.outer_to_si(values[q.name]) for q in Case.of_role("override")
            if values[q.name] is not None}


def load_parameters_from(args: argparse.Namespace):
    """The parameter set of ``--params`` with the values the options replace."""
    parameters = load_parameters(args.params)
    overrides = overrides_from(args)
    return parameters.replace(**overrides) if overrides else parameters


def load_model(args: argparse.Namespace):
    """(model, operating point or None without ``--s0``, (N0 [N], b_M [N m s/rad])) from the
    operating point options; N0 and b_M default to the parameter set's."""
    from model.mechanics.assembly import build_model
    from model.mechanics.operating_point import OperatingPoint

    parameters = load_parameters_from(args)
    model = build_model(parameters)
    n0 = parameters["wheel_force"] if args.n0 is None else args.n0
    bm = parameters["motor_slope"] if args.bm is None else args.bm
    op = OperatingPoint.from_kmh(args.s0, args.v, n0, bm) if args.s0 is not None else None
    return model, op, (n0, bm)


def case_from_args(args: argparse.Namespace, set_key: str, parameters) -> Case:
    """The case record of the options (the command line's units), the quantities not given at
    their defaults (``parameters``: the set's values)."""
    return Case.from_outer(set_key, case_option_values(args), parameters)


def quantity_values(text: str, name: str, increasing: bool = False,
                    option: str | None = None) -> list[float]:
    """A value list ``x1,x2,…`` or ``A:B:N`` of the quantity ``name`` in the command line's
    unit, each within the interval its option accepts; ``option``: the option the user typed,
    where it is not the quantity's own (``--ripple-v`` gives speeds)."""
    q = Case.quantity(name)
    low, high, low_open, high_open = interval_ends(q.option_interval)
    return parse_values(text, option or q.option, low, high, q.outer_unit, increasing, low_open,
                        high_open)


# --- ranges and value lists ----------------------------------------------------------------------

def parse_range(text: str, label: str, scale: float = 1.0) -> np.ndarray:
    """'A:B:N' -> N values from A to B (times ``scale``)."""
    parts = text.split(":")
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except (ValueError, IndexError):
        raise UsageError(f"{label} must be A:B:N (two numbers and a whole count), got '{text}'") from None
    if len(parts) != 3 or count < 2 or count > 5000 or not (math.isfinite(start) and math.isfinite(stop)):
        raise UsageError(f"{label} must be A:B:N with finite A, B and 2 <= N <= 5000, got '{text}'")
    return np.linspace(start, stop, count) * scale


MAX_VALUES = 100_000  # the longest value list of an option


def parse_values(text: str, label: str, low: float, high: float, unit: str,
                 increasing: bool = False, low_open: bool = False,
                 high_open: bool = False) -> list[float]:
    """'A:B:N' (N values from A to B) or 'x1,x2,…' -> values within [low, high] (an end
    excluded where ``low_open``/``high_open``)."""
    text = text.strip()
    if ":" in text:
        parts = text.split(":")
        try:
            if len(parts) != 3:
                raise ValueError
            start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise UsageError(f"{label} must be A:B:N (two numbers and a whole count) or a "
                             f"comma-separated list, got '{text}'") from None
        if count < 1:
            raise UsageError(f"{label} = '{text}': N = {count} is not allowed, must be >= 1")
        if count > MAX_VALUES:  # refused before the values are made
            raise UsageError(f"{label}: {count} values, at most {MAX_VALUES} allowed")
        if count > 1 and not start < stop:
            raise UsageError(f"{label} = '{text}' is an empty range: A must be below B")
        values = [start] if count == 1 else list(np.linspace(start, stop, count))
    else:
        try:
            values = [float(x) for x in text.split(",") if x.strip()]
        except ValueError:
            raise UsageError(f"{label} must be numbers separated by commas or A:B:N, "
                             f"got '{text}'") from None
        if not values:
            raise UsageError(f"{label} is empty")
    for value in values:
        inside = ((low < value if low_open else low <= value)
                  and (value < high if high_open else value <= high))
        if not (math.isfinite(value) and inside):
            raise UsageError(f"{label}: {value:g} is not allowed, must be in "
                             f"{'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
                             f" {unit}")
    if increasing and any(b <= a for a, b in itertools.pairwise(values)):
        raise UsageError(f"{label} must increase")
    if len(values) > MAX_VALUES:
        raise UsageError(f"{label}: {len(values)} values, at most {MAX_VALUES} allowed")
    return [float(v) for v in values]


# --- the time grid of a response ----------------------------------------------------------------

FS = "(0, 1e7)"  # [Hz]
MAX_SAMPLES = 2_000_000  # t_end × fs: the longest history model.analysis.response computes


def add_time_grid(p: argparse.ArgumentParser, t_end_help: str, fs_help: str | None = None, *,
                  t_end: str | None = None, fs: str = FS, t_end_default: float | None = ...
                  ) -> None:
    """``--t-end`` [s] (the horizon quantity's option; default ``t_end_default``, else the
    declared one; None: the command chooses, and ``t_end_help`` says how) and, with
    ``fs_help``, ``--fs`` [Hz] (default 10 000).  ``t_end_help``/``fs_help`` say what the
    values mean for the command ("horizon of each run"); ``t_end``/``fs`` are the allowed
    intervals, narrower where a command needs it (give the reason at the call; default the
    declared one, the horizons model.analysis.response accepts).  With ``--fs``, call
    :func:`check_samples` before computing."""
    (horizon,) = Case.of_role("horizon")
    add_case_option(p, horizon, interval=t_end, default=t_end_default, help=t_end_help)
    if fs_help is not None:
        p.add_argument("--fs", type=bounded("--fs (sampling rate, Hz)", fs, "Hz"),
                       default=10_000.0, help=f"{fs_help} [Hz] (default %(default)s)")


def check_samples(args: argparse.Namespace) -> None:
    """Refuse a grid ``--t-end × --fs`` longer than :data:`MAX_SAMPLES` before any work."""
    if args.t_end * args.fs > MAX_SAMPLES:
        raise UsageError(f"--t-end × --fs = {args.t_end * args.fs:.0f} samples is too many: at "
                         f"most {MAX_SAMPLES}")


# --- the short circuit ---------------------------------------------------------------------------

def add_short_circuit(p: argparse.ArgumentParser, *, dashboard: bool = False,
                      phase: bool = True, intervals: dict[str, str] | None = None) -> None:
    """The short circuit's options (``--m0`` [N m], ``--f`` [Hz], ``--decay`` [-] and, unless
    ``phase`` is False, ``--phase`` [s]), each from its declaration: defaults those of the
    dashboard and of :class:`model.analysis.response.ShortCircuit` (``--phase``: none, the
    motor torque is continuous); ``dashboard``: the intervals are the dashboard's sliders' (a
    command that reproduces the dashboard); ``intervals``: name -> a narrower interval where a
    command needs it (give the reason at the call).  :func:`short_circuit_from` builds the
    excitation."""
    intervals = intervals or {}
    for q in Case.of_role("short_circuit"):
        if q.automatic and not phase:
            continue
        interval = intervals.get(q.name, dashboard_interval(q) if dashboard else None)
        add_case_option(p, q, interval=interval)


def short_circuit_from(args: argparse.Namespace):
    """The :class:`model.analysis.response.ShortCircuit` of the options of
    :func:`add_short_circuit` (SI)."""
    from model.analysis.response import ShortCircuit

    values = case_option_values(args)
    return ShortCircuit(**{q.target: None if values[q.name] is None
                           else q.outer_to_si(values[q.name])
                           for q in Case.of_role("short_circuit")})


# --- nonlinear creep and the anti-slip protection ------------------------------------------------

ANTI_SLIP_OPTIONS = ("anti_slip_delay", "anti_slip_threshold", "anti_slip_rate", "anti_slip_floor")


def add_anti_slip_arguments(p: argparse.ArgumentParser, with_delay: bool = True) -> None:
    """The protection's options, defaults those of :class:`model.analysis.nonlinear.AntiSlip`
    (None in the namespace: :func:`anti_slip_from` fills them in, :func:`check_creep_arguments`
    sees which were given)."""
    from model.analysis.nonlinear import AntiSlip

    defaults = AntiSlip()
    if with_delay:
        p.add_argument("--anti-slip-delay", type=bounded("--anti-slip-delay (s)", "[0, 60]", "s"),
                       default=None,
                       help=f"reaction delay after detection [s] (default {defaults.delay:g})")
    p.add_argument("--anti-slip-threshold", type=number(
        "--anti-slip-threshold (m/s)", 0, 100, high_open=False,
        allowed="must be > 0 and at most 100 m/s"), default=None,
        help="change of ID2's wheelset slip velocity that trips the protection [m/s] "
             f"(default {defaults.threshold:g})")
    p.add_argument("--anti-slip-rate", type=number(
        "--anti-slip-rate (1/s)", 0, 1e6, high_open=False,
        allowed="must be > 0 and at most 1e6 1/s"), default=None,
        help=f"torque reduction rate [fraction of M(s0, v) per s] (default {defaults.rate:g})")
    p.add_argument("--anti-slip-floor", type=bounded("--anti-slip-floor", "[0, 1)"), default=None,
                   help="torque kept after the reduction [fraction of M(s0, v)] "
                        f"(default {defaults.floor:g})")


def add_creep_arguments(p: argparse.ArgumentParser) -> None:
    """``--creep`` and the anti-slip options of ``bogie response``."""
    p.add_argument("--creep", choices=("linear", "nonlinear", "tangent"), default="linear",
                   help="longitudinal creep forces: linear (closed form, default), nonlinear "
                        "(Polach's law), tangent (the nonlinear solver with the law's tangent)")
    p.add_argument("--anti-slip", choices=("off", "on"), default="off",
                   help="anti-slip protection on ID2's motor torque (needs --creep nonlinear or "
                        "tangent; default off)")
    add_anti_slip_arguments(p)
    p.add_argument("--strength", type=bounded("--strength (N m)", "(0, 1e9)", "N m"), default=None,
                   help="design strength [N m] of the disc and claw clutch (the driving shaft: "
                        "strength/p); crossings are listed (needs --creep nonlinear or tangent)")


def anti_slip_from(args: argparse.Namespace, delay: bool = True):
    """The :class:`model.analysis.nonlinear.AntiSlip` of the options (its defaults where not
    given; ``delay=False``: the default delay, for ``bogie antislip``, which varies it)."""
    from model.analysis.nonlinear import AntiSlip

    defaults = AntiSlip()
    values = {name: getattr(args, name, None) for name in ANTI_SLIP_OPTIONS}
    return AntiSlip(
        delay=defaults.delay if not delay or values["anti_slip_delay"] is None
        else values["anti_slip_delay"],
        threshold=defaults.threshold if values["anti_slip_threshold"] is None
        else values["anti_slip_threshold"],
        rate=defaults.rate if values["anti_slip_rate"] is None else values["anti_slip_rate"],
        floor=defaults.floor if values["anti_slip_floor"] is None else values["anti_slip_floor"])


def check_creep_arguments(args: argparse.Namespace) -> None:
    """Refuse combinations that would be silently ignored."""
    given = [name for name in ANTI_SLIP_OPTIONS if getattr(args, name, None) is not None]
    if args.anti_slip == "on" and args.creep == "linear":
        raise UsageError("--anti-slip on needs --creep nonlinear or tangent (the closed form has "
                         "no protection)")
    if given and args.anti_slip == "off":
        raise UsageError(f"--{given[0].replace('_', '-')} needs --anti-slip on")
    if getattr(args, "strength", None) is not None and args.creep == "linear":
        raise UsageError("--strength needs --creep nonlinear or tangent")
    if args.creep != "linear" and getattr(args, "method", "auto") != "auto":
        raise UsageError("--method applies to --creep linear only")


# --- the uncertainty study -----------------------------------------------------------------------

MAX_SOBOL_SAMPLES = 2**16  # each sample is a model run or a whole assessment: days beyond


def check_sample_count(n: int) -> None:
    """``--samples``: a power of 2 >= 2 (the balance of the Sobol' points) and at most
    :data:`MAX_SOBOL_SAMPLES` (refused before the points are drawn)."""
    if n < 2 or n & (n - 1) or n > MAX_SOBOL_SAMPLES:
        raise UsageError(f"--samples = {n} is not allowed: must be a power of 2 >= 2 (the "
                         f"balance of the Sobol' points) and at most {MAX_SOBOL_SAMPLES}")


def add_uncertainty_options(p: argparse.ArgumentParser) -> None:
    """--posterior, --no-indices, --speeds (shared with ``bogie study uncertainty``)."""
    p.add_argument("--posterior", action="store_true",
                   help="sample the linearized posterior given the calibration's targets "
                        "(model/studies/posterior.py; n runs, distributions only) instead of the prior "
                        "ranges")
    p.add_argument("--no-indices", action="store_true",
                   help="prior: distributions only from n QMC samples (n runs, no Sobol indices)")
    p.add_argument("--speeds", default=None, metavar="LIST",
                   help="speeds of s0* [km/h]: x1,x2,… or A:B:N (default 120,200); several "
                        "speeds give the s0*(v) band the dashboard's Studies view draws")


def uncertainty_options(args: argparse.Namespace) -> dict:
    """Keyword arguments of :func:`model.studies.uncertainty.run_uncertainty` from the shared options
    (raises UsageError)."""
    from model.studies.uncertainty import V_SPEEDS_KMH

    if args.posterior and args.no_indices:
        raise UsageError("--posterior and --no-indices exclude each other (the posterior never "
                         "has Sobol indices)")
    speeds = (parse_values(args.speeds, "--speeds", *interval_ends(
        Case.quantity("v").option_interval)[:2], "km/h", increasing=True)
              if args.speeds is not None else list(V_SPEEDS_KMH))
    if len(speeds) > 50:
        raise UsageError(f"--speeds: {len(speeds)} speeds, at most 50 allowed")
    return {"method": "posterior" if args.posterior else "prior",
            "indices": not (args.posterior or args.no_indices), "speeds_kmh": speeds}


# --- what a history command reads (bogie response, bogie spectrum) --------------------------

MIN_SAMPLES_PER_PERIOD = 2.5  # fs must exceed 2.5 × the highest excited frequency


def add_history_options(p: argparse.ArgumentParser) -> None:
    """Every option of ``bogie response`` but ``--out``: the operating point, the short circuit,
    the time grid, ``--outputs``, ``--method`` and the creep model (shared with ``bogie
    spectrum``)."""
    add_operating_point(p)
    add_short_circuit(p)
    add_time_grid(p, "horizon", "output sampling rate")
    add_output_selection(p)
    add_creep_arguments(p)


def add_output_selection(p: argparse.ArgumentParser) -> None:
    """``--outputs`` and ``--method`` (the linear closed form's evaluation)."""
    p.add_argument("--outputs", default=None,
                   help="comma-separated output or DOF names (default: all loads)")
    p.add_argument("--method", choices=("auto", "modal", "expm"), default="auto",
                   help="evaluation of the closed form (default %(default)s)")


def output_names(args: argparse.Namespace) -> list[str] | None:
    """The names of ``--outputs`` (None: all loads)."""
    if args.outputs is None:
        return None
    names = [s.strip() for s in args.outputs.split(",") if s.strip()]
    if not names:
        raise UsageError(f"--outputs '{args.outputs}': no output names given")
    return names


def checked_output_names(args: argparse.Namespace, model, op, loads_only: bool = False
                         ) -> list[str] | None:
    """The names of ``--outputs`` (None: all loads), each a load of the model
    (:func:`model.mechanics.outputs.output_matrices`) or, unless ``loads_only`` (nonlinear creep,
    the frequency responses), a DOF name; an unknown one is refused naming the option, before
    any work."""
    from model.mechanics.outputs import output_matrices

    names = output_names(args)
    if names is None:
        return None
    loads = output_matrices(model, op).names
    known = set(loads) if loads_only else set(loads) | set(model.dofs.names)
    for name in names:
        if name not in known:
            dofs = "" if loads_only else f" or a DOF name (e.g. {model.dofs.names[0]})"
            raise UsageError(f"--outputs: unknown output '{name}': use a load "
                             f"({', '.join(loads[:3])}, …){dofs}")
    return names


def check_sampling(args: argparse.Namespace, frequency_hz: float, what: str,
                   digits: str = "g") -> None:
    """Refuse ``--fs`` below 2.5 × ``frequency_hz`` [Hz]; ``what`` names that frequency in the
    message, ``digits`` formats the least allowed rate."""
    least = MIN_SAMPLES_PER_PERIOD * frequency_hz
    if args.fs < least:
        raise UsageError(f"--fs = {args.fs:g} Hz is too low to resolve {what}: must be at least "
                         f"{least:{digits}} Hz")


# --- where a study runs (bogie study, bogie envelope) ------------------------------------------

EXIT_INTERRUPTED = 130  # Ctrl-C: the store keeps the finished chunks (resume with --resume)


def add_engine_options(p: argparse.ArgumentParser) -> None:
    """``--scheduler``, ``--workers``, ``--serial``, ``--connect-timeout``."""
    p.add_argument("--scheduler", type=scheduler_address, default=None, metavar="tcp://HOST:PORT",
                   help="attach to a running Dask scheduler (default: $DASK_SCHEDULER_ADDRESS, "
                        "else a local cluster)")
    p.add_argument("--workers", type=positive_int("--workers", MAX_WORKERS), default=None,
                   help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--serial", action="store_true",
                   help="compute in this process, without Dask (the reference)")
    p.add_argument("--connect-timeout", type=bounded("--connect-timeout (s)", "(0, 600)", "s"),
                   default=10.0, help="seconds to reach the scheduler (default %(default)s)")
