"""uvicorn's logging for `horde serve`, with tokens kept out of it.

A WebSocket client that cannot set headers gives the server's token as `?token=` (WS
/api/streams/{id}/records), and uvicorn writes every request's path with its query string into the
log: the access log for HTTP, the error log's "WebSocket ... [accepted]" lines for WebSockets.
`HideTokens` replaces the value of every `token=` query parameter by `***` in what either handler
writes; `log_config()` is uvicorn's own logging configuration with that filter on both handlers.
"""

from __future__ import annotations

import copy
import logging
import re
from typing import Any

import uvicorn.config

TOKEN_PARAMETER = re.compile(r"([?&](?:access_)?token=)[^&#\s\"]*", re.IGNORECASE)
HIDDEN = "***"


def hide_tokens(text: str) -> str:
    """`text` with the value of every `token=` query parameter replaced by ***."""
    return TOKEN_PARAMETER.sub(rf"\g<1>{HIDDEN}", text)


class HideTokens(logging.Filter):
    """A logging filter that hides query-string tokens in a record's message and arguments."""

    def filter(self, record: logging.LogRecord) -> bool:
        if isinstance(record.msg, str):
            record.msg = hide_tokens(record.msg)
        if isinstance(record.args, tuple):
            record.args = tuple(hide_tokens(a) if isinstance(a, str) else a for a in record.args)
        return True


def log_config() -> dict[str, Any]:
    """uvicorn's LOGGING_CONFIG with `HideTokens` on its handlers (pass as `uvicorn.run(log_config=...)`)."""
    config = copy.deepcopy(uvicorn.config.LOGGING_CONFIG)
    config.setdefault("filters", {})["hide_tokens"] = {"()": HideTokens}
    for handler in config["handlers"].values():
        handler["filters"] = [*handler.get("filters", []), "hide_tokens"]
    return config
