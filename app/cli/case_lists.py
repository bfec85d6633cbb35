"""The value lists of the case's quantities (``x1,x2,…`` or ``A:B:N``; a choice ``name1,name2``):
the options of the commands that compute a grid of cases (``bogie envelope``, ``bogie study map``
and ``limit``, the short_circuit grid of ``bogie assess``), one per quantity, from its declaration
(:data:`app.results.case.QUANTITIES`) as the single-value options of :mod:`app.cli.options`, the
dashboard's sliders and the links are."""

from __future__ import annotations

import argparse

from app.cli.options import UsageError, dest, quantity_values
from app.results.case import Case


def add_case_lists(parser, *roles: str, names: tuple[str, ...] | None = None,
                   required: tuple[str, ...] = (), defaults: dict[str, str] | None = None,
                   what: str = "") -> None:
    """One value-list option (``x1,x2,…`` or ``A:B:N``; a choice: ``name1,name2``) per quantity
    of ``roles`` (``names``: only these), each from its declaration as the single-value options
    are (:func:`add_case_option`): its option, doc, unit and default — the declared one in the
    command line's unit, or for a quantity whose default is the parameter set's none (the
    set's); ``required``: names the command needs; ``defaults``: name -> a command's own default
    list (give the reason at the call); ``what``: a prefix of every help text.  A quantity that
    may be automatic (the fault instant) is the command's own option.  :func:`case_lists` reads
    them."""
    defaults = defaults or {}
    for q in Case.of_role(*roles):
        if q.automatic or (names is not None and q.name not in names):
            continue
        doc = f"{what}{q.doc}"
        if q.choice:
            parser.add_argument(q.option, default=defaults.get(q.name, q.default), metavar="LIST",
                                help=f"{doc}: one or more of {', '.join(q.choices)}, "
                                     "comma-separated (default %(default)s)")
            continue
        if q.name in required:
            default, said = None, ""
        elif q.name in defaults:
            default, said = defaults[q.name], " (default %(default)s)"
        elif q.from_set or q.default is None:
            default, said = None, " (default: the parameter set's)"
        else:
            default, said = f"{q.to_outer(q.default):g}", " (default %(default)s)"
        parser.add_argument(q.option, default=default, required=q.name in required,
                            metavar="LIST", help=f"{doc} [{q.outer_unit}]: x1,x2,… or A:B:N{said}")


def case_lists(args: argparse.Namespace, parameters, *roles: str,
               names: tuple[str, ...] | None = None, increasing: bool = True) -> dict[str, tuple]:
    """name -> the values of the options of :func:`add_case_lists` (SI; a choice: its names,
    each known): a quantity of the operating point not given is the set's value (one), a value
    of the set the options replace (role ``override``) not given is none (the set's own,
    unchanged); a quantity that is not an option of the command (or not of ``names``) is left
    out."""
    lists = {}
    for q in Case.of_role(*roles):
        if not hasattr(args, dest(q)) or q.automatic or (names is not None and q.name not in names):
            continue
        text = getattr(args, dest(q))
        if q.choice:
            chosen = [x.strip() for x in text.split(",")]
            if not text.strip() or not all(chosen):
                raise UsageError(f"{q.option} must be a comma-separated list of names, got "
                                 f"'{text}'")
            unknown = [x for x in chosen if x not in q.choices]
            if unknown:
                raise UsageError(f"{q.option}: '{unknown[0]}' is not known, use "
                                 f"{', '.join(q.choices)}")
            if len(set(chosen)) != len(chosen):
                raise UsageError(f"{q.option}: give each of {', '.join(q.choices)} at most once")
            lists[q.name] = tuple(chosen)
        elif text is not None:
            lists[q.name] = tuple(q.outer_to_si(x) for x in quantity_values(text, q.name,
                                                                            increasing))
        elif q.role == "override":
            lists[q.name] = ()
        else:
            lists[q.name] = (parameters[q.from_set],)
    return lists
