"""``bogie serve``: serve the dashboard (:func:`app.server.serve.serve`) with the operator's
settings (:class:`app.services.settings.ServerSettings`; docs/security.md).  Bad settings: one
line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse

from app.cli.options import (
    MAX_WORKERS,
    PARAMETER_FILE,
    bounded,
    non_negative_int,
    number,
    positive_int,
    scheduler_address,
)
from app.cli.output import writable_path
from app.results.cache import DEFAULT_CACHE_MB
from app.services.settings import DEFAULT_BACKGROUND_WORKERS, MAX_CACHE_MB, MIN_CACHE_MB


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "serve", help="serve the dashboard (panel serve semantics)",
        description="Serve the dashboard at /app (liveness: /liveness?endpoint=/app).  The options "
                    "below are the operator's: no browser can change them (docs/security.md).  "
                    "Each study option has an environment variable of the same meaning (named in "
                    "its help); the option wins over the variable.")
    p.add_argument("--port", type=number("--port", 0, 65536, low_open=False,
                                         allowed="must be 0…65535"), default=5006)
    p.add_argument("--address", default="127.0.0.1", help="interface to listen on (default "
                   "%(default)s; 0.0.0.0: every interface)")
    p.add_argument("--allow-websocket-origin", action="append", default=None,
                   help="host[:port] allowed to open the websocket (repeatable; environment: "
                        "BOGIE_ALLOWED_ORIGINS, comma-separated)")
    p.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE", help="parameter file (TOML)")
    p.add_argument("--scheduler", type=scheduler_address, default=None, metavar="ADDR",
                   help="Dask scheduler the dashboard's studies run on (tcp://host:port; "
                        "environment: BOGIE_SCHEDULER); default: one local cluster of this server, "
                        "started on the first study, one worker process per core, shared by all "
                        "sessions")
    p.add_argument("--studies-dir", default=None, metavar="DIR",
                   help="folder studies are written to and opened from (created if missing; "
                        "environment: BOGIE_STUDIES_DIR; default ~/.local/share/bogie/studies)")
    p.add_argument("--max-study-points", type=positive_int("--max-study-points"), default=None,
                   metavar="N", help="largest study a session may ask for, s0 points × v points "
                                     "(environment: BOGIE_MAX_STUDY_POINTS; default 10000)")
    p.add_argument("--max-running-studies", type=positive_int("--max-running-studies"),
                   default=None, metavar="K",
                   help="studies running at once; more wait in a queue (environment: "
                        "BOGIE_MAX_RUNNING_STUDIES; default 1)")
    p.add_argument("--max-waiting-studies", type=non_negative_int("--max-waiting-studies"),
                   default=None, metavar="W",
                   help="studies waiting at most; more requests are refused with a notice "
                        "(environment: BOGIE_MAX_WAITING_STUDIES; default 16)")
    p.add_argument("--cache-mb", type=bounded("--cache-mb", f"[{MIN_CACHE_MB}, {MAX_CACHE_MB}]",
                                              "MB"),
                   default=None, metavar="N",
                   help="memory the results every session shares may hold [MB]; beyond it the "
                        "least recently used go first (environment: BOGIE_CACHE_MB; default "
                        f"{DEFAULT_CACHE_MB}; docs/memory.md)")
    p.add_argument("--background-workers", type=non_negative_int("--background-workers", MAX_WORKERS),
                   default=None, metavar="N",
                   help="worker processes, at a lower priority than the server, of the work no "
                        "slider waits for (the verdict's load cases, the reaction-time search); "
                        "0: the server's own threads; with --scheduler that cluster runs it "
                        "(environment: BOGIE_BACKGROUND_WORKERS; default "
                        f"{DEFAULT_BACKGROUND_WORKERS}; docs/memory.md)")
    p.set_defaults(func=cmd_serve)


def cmd_serve(args: argparse.Namespace) -> None:
    from app.server.serve import serve
    from app.services.settings import ServerSettings

    writable_path(args.studies_dir, "--studies-dir", directory=True, parents=True)
    settings = ServerSettings.from_options(
        scheduler=args.scheduler, studies_dir=args.studies_dir,
        max_study_points=args.max_study_points, max_running_studies=args.max_running_studies,
        max_waiting_studies=args.max_waiting_studies,
        cache_mb=None if args.cache_mb is None else int(args.cache_mb),
        background_workers=args.background_workers)
    serve(port=args.port, address=args.address, allow_websocket_origin=args.allow_websocket_origin,
          params=args.params, settings=settings)
