"""The command line ``bogie`` (also ``python -m app``): a module per command group.

:mod:`.main` builds the parser and runs a command; :mod:`.options` holds the argument helpers
every group shares (numbers with bounds, the operating point, the time grid), so that no command
module imports another.  Groups: :mod:`.main` (eigen, limit, modes, locus, calibrate, export,
serve), :mod:`.response`, :mod:`.antislip`, :mod:`.sensitivity`, :mod:`.study`, :mod:`.compare`,
:mod:`.report`.  Bad input: one line on stderr, exit status 2.
"""
