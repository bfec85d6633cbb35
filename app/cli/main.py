"""The command line ``bogie`` (also ``python -m app``): builds the parser from the command
groups and runs one command.

Every group module has ``register(subparsers)`` adding its sub-commands; the order of
:data:`COMMAND_GROUPS` is the order of ``bogie --help``.  Bad input (one of the project's input
errors, :func:`app.cli.options.input_errors`: a :class:`UsageError`, a bad parameter file,
operating point, excitation, store …): one line on stderr saying what is wrong and what is
allowed, exit status 2, no traceback.  Any other error is a programming error: its traceback
is shown (exit status 1).  Ctrl-C during a study: exit status 130 (:mod:`app.cli.runs`).
"""

from __future__ import annotations

import sys

from app.cli import (
    analysis,
    antislip,
    assess,
    calibrate,
    compare,
    life,
    loads,
    parameters,
    report,
    resonance,
    response,
    sensitivity,
    serve,
    study,
)
from app.cli.options import EXIT_BAD_INPUT, BogieParser, input_errors

COMMAND_GROUPS = (analysis.register, calibrate.register, analysis.register_export, serve.register,
                  response.register, sensitivity.register, antislip.register, study.register,
                  compare.register, report.register, loads.register, resonance.register,
                  assess.register, life.register, parameters.register)


def build_parser() -> BogieParser:
    parser = BogieParser(prog="bogie", description="Locomotive bogie drive dynamics: eigenvalues, "
                         "stability, traction-motor short-circuit response and resonances.")
    subparsers = parser.add_subparsers(dest="command", required=True, parser_class=BogieParser)
    for register in COMMAND_GROUPS:
        register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    from threadpoolctl import threadpool_limits

    parser = build_parser()
    args = parser.parse_args(argv)
    args.command_line = argv is None  # a process of its own (may run itself again), not a call
    try:
        with threadpool_limits(1):  # dense 200-400 sized problems: one BLAS thread is fastest
            args.func(args)
    except input_errors() as error:
        message = error.args[0] if error.args else str(error)
        print(f"bogie {args.command}: error: {message}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:
        return 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
