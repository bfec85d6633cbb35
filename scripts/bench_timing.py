"""What the in-process benchmark scripts time with: the machine's load average as they print it,
and a call's wall time."""

from __future__ import annotations

import os
import time


def load() -> str:
    """The load average over 1, 5 and 15 minutes, as "a / b / c"."""
    return " / ".join(f"{x:.2f}" for x in os.getloadavg())


def timed(function) -> tuple[float, object]:
    """(wall time [s], value) of ``function()``."""
    start = time.perf_counter()
    value = function()
    return time.perf_counter() - start, value
