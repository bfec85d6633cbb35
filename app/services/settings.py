"""What the operator of a served dashboard decides, and no browser can change.

The operator is whoever starts ``bogie serve`` (or the container): the Dask cluster studies run
on, the folder studies are written to and opened from, the limits of the study work every
review session shares, and the memory the results cache may hold (docs/memory.md).  Each
setting is a ``bogie serve`` option with an environment variable of the same meaning (the
container's way to set it); the option wins over the variable.  A browser only *asks* within
these settings (docs/security.md).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

# option -> environment variable of the same meaning (bogie serve --help lists them)
ENVIRONMENT = {
    "scheduler": "BOGIE_SCHEDULER",
    "studies_dir": "BOGIE_STUDIES_DIR",
    "max_study_points": "BOGIE_MAX_STUDY_POINTS",
    "max_running_studies": "BOGIE_MAX_RUNNING_STUDIES",
    "max_waiting_studies": "BOGIE_MAX_WAITING_STUDIES",
    "cache_mb": "BOGIE_CACHE_MB",
    "background_workers": "BOGIE_BACKGROUND_WORKERS",
}
DEFAULT_MAX_STUDY_POINTS = 10_000  # s0 × v points of one map: the 100 × 100 map (≈ 25 s on 2 workers)
DEFAULT_MAX_RUNNING_STUDIES = 1
DEFAULT_MAX_WAITING_STUDIES = 16  # more requests are refused (a notice), never queued without end
UPPER_STUDY_POINTS = 4_000_000  # the largest study limit an operator may set (2000 × 2000)
# worker processes of the work no slider waits for (app.services.background); 0: the server's
# own threads (without a local cluster of its own: with --scheduler they run on that cluster)
DEFAULT_BACKGROUND_WORKERS = 2
# what an operator may set as the results cache's budget [MB] (its default: app.results.cache)
MIN_CACHE_MB, MAX_CACHE_MB = 32, 1_000_000


class SettingsError(ValueError):
    """An operator setting is malformed (one-line message naming the option and variable)."""


def default_studies_dir() -> Path:
    """``$XDG_DATA_HOME/bogie/studies`` (default ``~/.local/share/bogie/studies``): the user's
    own folder, not a shared temporary one another local user could prepare."""
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "bogie" / "studies"


@dataclass(frozen=True)
class ServerSettings:
    """The operator's settings of one server process."""

    scheduler: str | None = None  # Dask scheduler address; None: one local cluster of this server
    studies_dir: Path = None  # type: ignore[assignment] - filled by __post_init__
    max_study_points: int = DEFAULT_MAX_STUDY_POINTS  # s0 points × v points of one study
    max_running_studies: int = DEFAULT_MAX_RUNNING_STUDIES  # studies running at once
    max_waiting_studies: int = DEFAULT_MAX_WAITING_STUDIES  # studies waiting in the queue
    cache_mb: int | None = None  # the results cache's budget [MB]; None: its default (docs/memory.md)
    background_workers: int = DEFAULT_BACKGROUND_WORKERS  # local processes of the verdicts, searches

    def __post_init__(self) -> None:
        if self.studies_dir is None:
            object.__setattr__(self, "studies_dir", default_studies_dir())
        object.__setattr__(self, "studies_dir", Path(self.studies_dir).expanduser())
        if self.scheduler is not None and not str(self.scheduler).strip():
            object.__setattr__(self, "scheduler", None)
        for name, low, high in (("max_study_points", 1, UPPER_STUDY_POINTS),
                                ("max_running_studies", 1, 64),
                                ("max_waiting_studies", 0, 10_000),
                                ("cache_mb", MIN_CACHE_MB, MAX_CACHE_MB),
                                ("background_workers", 0, 64)):
            value = getattr(self, name)
            if name == "cache_mb" and value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                raise SettingsError(f"--{name.replace('_', '-')} ({ENVIRONMENT[name]}) = {value!r} "
                                    f"is not allowed: must be an integer in [{low}, {high}]")

    @classmethod
    def from_options(cls, scheduler: str | None = None, studies_dir: str | None = None,
                     max_study_points: int | None = None, max_running_studies: int | None = None,
                     max_waiting_studies: int | None = None, cache_mb: int | None = None,
                     background_workers: int | None = None,
                     environ: dict | None = None) -> ServerSettings:
        """The settings of command-line options (``None``: not given), else of the environment
        variables in :data:`ENVIRONMENT`, else the defaults (raises :class:`SettingsError`)."""
        environ = os.environ if environ is None else environ
        given = {"scheduler": scheduler, "studies_dir": studies_dir,
                 "max_study_points": max_study_points, "max_running_studies": max_running_studies,
                 "max_waiting_studies": max_waiting_studies, "cache_mb": cache_mb,
                 "background_workers": background_workers}
        values = {}
        for name, value in given.items():
            if value is None and environ.get(ENVIRONMENT[name], "").strip():
                value = environ[ENVIRONMENT[name]].strip()
                if name.startswith("max_") or name in ("cache_mb", "background_workers"):
                    try:
                        value = int(value)
                    except ValueError:
                        raise SettingsError(f"{ENVIRONMENT[name]} = {value!r} is not an "
                                            "integer") from None
            if value is not None:
                values[name] = value
        return cls(**values)

    @property
    def engine_description(self) -> str:
        """Where studies run, as a reviewer may read it (no address)."""
        if self.scheduler:
            return "the Dask cluster the server was started with"
        return f"the server's local Dask cluster ({local_workers()} worker processes)"


def local_workers() -> int:
    """Worker processes of the server's own local cluster: one per core this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


_current: ServerSettings | None = None


def configure(settings: ServerSettings) -> None:
    """Set this process's settings (``bogie serve``, before the first session)."""
    global _current
    _current = settings


def current() -> ServerSettings:
    """This process's settings: those given to :func:`configure`, else the defaults (a dashboard
    built without ``bogie serve``: tests, a notebook)."""
    global _current
    if _current is None:
        _current = ServerSettings.from_options()
    return _current
