"""`horde serve`: run the server with uvicorn, printing where it listens.

`add_serve_parser(subparsers)` adds the `serve` subcommand to the CLI's argparse parser and sets
`handler=serve` on it; `python -m horde.server` takes the same options.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from horde.runs.errors import StoreOpenError
from horde.runs.store import Store
from horde.server.settings import Settings

DEFAULT_VISER_PORT = 8080

# How uvicorn serves the app, for `horde serve` and for the tests' servers alike.
UVICORN_OPTIONS: dict[str, Any] = {
    # The streams are small JSON messages to a dashboard on this machine or the LAN: compressing each one costs
    # more CPU (taken from learning) than it saves.
    "ws_per_message_deflate": False,
    # An idle kept-alive connection is closed by the client, not by the server. uvicorn's own 5 s equals
    # httpx's idle expiry: a script's request sent as the server closes its connection met a reset (seen in CI on a
    # loaded machine, and made 9 times in 80 in a loop). With the server waiting longer, a client drops its idle
    # connection first and opens a new one.
    "timeout_keep_alive": 75,
}


def add_serve_arguments(parser: argparse.ArgumentParser) -> None:
    """--host, --port, --data (each defaults to its HORDE_* variable, then to the built-in default)."""
    parser.add_argument("--host", default=None, help="address to bind (default: HORDE_HOST or 127.0.0.1)")
    parser.add_argument("--port", type=int, default=None, help="port (default: HORDE_PORT or 8000)")
    parser.add_argument("--data", type=Path, default=None, help="data directory (default: HORDE_DATA or ./.horde)")
    parser.add_argument(
        "--viser-port", type=int, default=None, help="port of the viser live view (default: HORDE_VISER_PORT or 8080)"
    )
    parser.add_argument("--no-view", action="store_true", help="do not start the viser live view")
    parser.add_argument(
        "--allow-open",
        action="store_true",
        default=None,
        help="bind beyond loopback without HORDE_TOKEN anyway (anyone who reaches the server may change runs)",
    )
    parser.add_argument("--log-level", default="info", choices=["critical", "error", "warning", "info", "debug"])


def add_serve_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add `serve` to an argparse subparsers object; the parsed args carry `handler=serve`."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        "serve",
        help="run the web server (REST API, streams, dashboard)",
        description="Serve the Horde Lab API. Set HORDE_TOKEN to require a bearer token on every change.",
    )
    add_serve_arguments(parser)
    parser.set_defaults(handler=serve, func=serve)
    return parser


def settings_from_args(args: argparse.Namespace) -> Settings:
    overrides = {key: getattr(args, key, None) for key in ("host", "port", "data", "viser_port", "allow_open")}
    settings = Settings(**{key: value for key, value in overrides.items() if value is not None})
    if getattr(args, "no_view", False):
        return settings.model_copy(update={"viser_port": None})
    if settings.viser_port is None:  # serve starts the live view unless told not to
        return settings.model_copy(update={"viser_port": DEFAULT_VISER_PORT})
    return settings


def urls(settings: Settings) -> dict[str, str]:
    host = f"[{settings.host}]" if ":" in settings.host else settings.host
    base = f"http://{host}:{settings.port}"
    return {"Dashboard": f"{base}/", "API": f"{base}/api", "API docs": f"{base}/docs"}


def security_warning(settings: Settings) -> str | None:
    """Why binding this host without a token is dangerous, or None when it is not (loopback, or a token)."""
    if settings.is_loopback() or settings.token is not None:
        return None
    return (
        f"binding {settings.host}, which other machines can reach, without HORDE_TOKEN: "
        "anyone who reaches it can create, change and delete runs. Set HORDE_TOKEN or bind 127.0.0.1"
    )


def serve(args: argparse.Namespace) -> int:
    """Run the server until interrupted; returns the exit code."""
    import uvicorn

    from horde.server.app import create_app
    from horde.server.logs import log_config

    settings = settings_from_args(args)
    warning = security_warning(settings)
    if warning and not settings.allow_open:
        print(
            f"refusing to start: {warning} (or pass --allow-open, HORDE_ALLOW_OPEN=1, to do it anyway).",
            file=sys.stderr,
        )
        return 2
    if warning:
        print(f"WARNING: {warning}.", file=sys.stderr)
    try:  # here, where it can be said in one line: in the app's start-up uvicorn would print a traceback
        Store(settings.data).close()
    except StoreOpenError as exc:
        print(f"refusing to start: {exc}", file=sys.stderr)
        return 2
    print(f"Horde Lab serving (data in {settings.data.resolve()}):")
    for label, url in urls(settings).items():
        print(f"  {label + ':':10} {url}")
    sys.stdout.flush()

    def announce(view_url: str) -> None:
        print(f"  {'Live view:':10} {view_url}", flush=True)

    uvicorn.run(
        create_app(settings, announce),
        host=settings.host,
        port=settings.port,
        log_level=getattr(args, "log_level", "info"),
        log_config=log_config(),  # uvicorn's, with `?token=` hidden
        **UVICORN_OPTIONS,
    )
    return 0
