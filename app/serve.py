"""``bogie serve``: run the dashboard with ``panel serve`` semantics (liveness endpoint on)."""

from __future__ import annotations

import os


def create_app(params: str | None = None):
    """Build the dashboard for one session (placeholder page until the dashboard exists)."""
    import panel as pn

    return pn.Column("# Bogie drive dynamics", "Dashboard under construction.")


def serve(port: int = 5006, address: str = "127.0.0.1",
          allow_websocket_origin: list[str] | None = None, params: str | None = None) -> None:
    import panel as pn

    origins = allow_websocket_origin or os.environ.get(
        "BOGIE_ALLOWED_ORIGINS", f"localhost:{port},127.0.0.1:{port}").split(",")
    pn.serve({"app": lambda: create_app(params)}, port=int(port), address=address,
             websocket_origin=[o.strip() for o in origins if o.strip()], show=False,
             liveness=True, title="Bogie drive dynamics")
