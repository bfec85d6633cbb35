"""``bogie serve``: run the dashboard with ``panel serve`` semantics (liveness endpoint on)."""

from __future__ import annotations

import os


def create_app(params: str | None = None):
    """Build the dashboard for one session (placeholder page until the dashboard exists)."""
    import panel as pn

    return pn.Column("# Bogie drive dynamics", "Dashboard under construction.")


def serve(port: int = 5006, address: str = "127.0.0.1",
          allow_websocket_origin: list[str] | None = None, params: str | None = None) -> None:
    """Serve the dashboard at /app (and Panel's /liveness?endpoint=/app) until SIGINT/SIGTERM.

    Websocket origins: ``allow_websocket_origin``, else the comma-separated host[:port] list in
    the environment variable BOGIE_ALLOWED_ORIGINS, else localhost:port and 127.0.0.1:port only.
    """
    import signal
    import sys
    import threading

    import panel as pn

    port = int(port)  # the command line parses it as a number (float)
    origins = allow_websocket_origin or os.environ.get(
        "BOGIE_ALLOWED_ORIGINS", f"localhost:{port},127.0.0.1:{port}").split(",")
    if threading.current_thread() is threading.main_thread():
        # a container stops its PID 1 with SIGTERM, which Python would otherwise ignore there
        signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        pn.serve({"app": lambda: create_app(params)}, port=port, address=address,
                 websocket_origin=[o.strip() for o in origins if o.strip()], show=False,
                 liveness=True, title="Bogie drive dynamics")
    except KeyboardInterrupt:
        print("bogie serve: stopped", file=sys.stderr)
