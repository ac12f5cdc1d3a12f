"""The tests' one way to wait for something that happens in another thread or process.

`wait_until(condition, what)` polls `condition` until it returns a truthy value and returns that
value; after `timeout` seconds it fails with an AssertionError that names what it waited for and the
last value it saw, so that a regression fails the test with a reason instead of hanging the suite.
`condition` may raise AssertionError to mean "not yet" (its message then becomes the last value seen).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

DEFAULT_TIMEOUT = 30.0  # seconds: long enough for a loaded two-core machine, short enough to fail a test


def wait_until(condition: Callable[[], T], what: str, timeout: float = DEFAULT_TIMEOUT, interval: float = 0.02) -> T:
    """Poll `condition` every `interval` seconds until it is truthy; return its value.

    Raises:
        AssertionError: `timeout` seconds passed first; the message names `what` and the last value seen.
    """
    deadline = time.monotonic() + timeout
    while True:
        try:
            value = condition()
        except AssertionError as exc:
            value, seen = None, str(exc)  # type: ignore[assignment]
        else:
            seen = repr(value)
        if value:
            return value
        if time.monotonic() >= deadline:
            raise AssertionError(f"waited {timeout:g} s for {what}; last seen: {seen[:500]}")
        time.sleep(interval)
