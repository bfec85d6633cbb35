"""The dashboard's worker threads, one pool per priority, shared by all sessions of a process.

A change must show its first answer (eigenvalues, status, time histories) within ≈ 300 ms, while
the results that follow it (dense root locus, s0*(v), sensitivities, nonlinear histories,
reaction times, a variant's comparison) may take seconds of CPU on a 2-core machine.  Python
threads cannot be given priorities, but Linux schedules each thread on its own: the pools below
run their threads at a higher niceness (lower priority), so a background computation keeps a
core only while nothing more urgent wants it, and the next change's first answer is not slowed
down by the previous change's follow-ups.  (The computations release the GIL in LAPACK; the
Python parts still share it.)  Where the niceness cannot be set (another OS), the threads keep
the process's priority.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

from model.locus import set_thread_niceness

# niceness (0 .. 19; CPU share against a niceness-0 thread: 5 → 33 %, 10 → 11 %, 19 → 1.5 %)
FIRST_ANSWER = 0  # eigenvalues, status, time histories; the coarse root locus
FOLLOW_UP = 5  # dense root locus, nonlinear histories: awaited on screen
SIDE_VIEW = 10  # s0*(v), sensitivities, the variant comparison
SEARCH = 19  # reaction-time searches (tens of nonlinear runs)


def prioritized_pool(workers: int, niceness: int, name: str) -> ThreadPoolExecutor:
    """A pool of ``workers`` threads running at ``niceness``."""
    return ThreadPoolExecutor(max_workers=workers, thread_name_prefix=name,
                              initializer=set_thread_niceness, initargs=(niceness,))


# the first answers of several sessions run side by side (one BLAS thread each)
FIRST_ANSWER_POOL = prioritized_pool(3, FIRST_ANSWER, "bogie-compute")
FOLLOW_UP_POOL = prioritized_pool(2, FOLLOW_UP, "bogie-follow-up")
SIDE_VIEW_POOL = prioritized_pool(2, SIDE_VIEW, "bogie-side-view")
# the nonlinear runs have workers of their own: a running reaction search never holds up the
# next nonlinear history
NONLINEAR_POOL = prioritized_pool(1, FOLLOW_UP, "bogie-nonlinear")
SEARCH_POOL = prioritized_pool(1, SEARCH, "bogie-reaction")

