"""The command line ``bogie`` (also ``python -m app``): a module per command group.

:mod:`.main` builds the parser from the groups' ``register`` functions and runs a command.
Groups: :mod:`.analysis` (eigen, limit, modes, locus, export), :mod:`.calibrate`, :mod:`.serve`,
:mod:`.response`, :mod:`.antislip`, :mod:`.sensitivity` (sensitivity, uncertainty),
:mod:`.study`, :mod:`.compare`, :mod:`.report`, :mod:`.resonance` (campbell, frf, ripple, track).
What several groups need lives below them:
:mod:`.options` (the parser, numbers with bounds, the operating point, ranges, the time grid, the
short circuit, the creep, anti-slip and uncertainty options, input files), :mod:`.case_lists`
(the value lists of the case's quantities) and :mod:`.output` (JSON or a table, time histories to
files, limit lines, outputs checked writable).  No group imports another (an import-linter contract in
pyproject.toml).  Bad input: one line on stderr, exit status 2.
"""
