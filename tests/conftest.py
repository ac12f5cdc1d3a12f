"""Settings every test shares: the in-process test client's `Host` is allowed; Hypothesis sets no deadline; no two
tests that make test runs in two processes share one id.

Hypothesis' default deadline (200 ms an example) fails an example that compiles a kernel on a cold numba
cache (2 s; seen in tests/core/test_features.py after an edit to the engine): a property test asserts
results, and its time is bounded by the test's timeout (pytest-timeout) like every other test's.

Starlette's TestClient sends `Host: testserver`, which the server's DNS-rebinding guard refuses
(server/hosts.py). The tests' servers accept that one name through HORDE_ALLOWED_HOSTS, as a user
would allow a name of theirs; the built-in default stays empty (tests/server/test_hosts.py).
"""

from __future__ import annotations

import os
from collections import Counter

import pytest
from hypothesis import settings

os.environ["HORDE_ALLOWED_HOSTS"] = '["testserver"]'
settings.register_profile("horde", deadline=None)
settings.load_profile("horde")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """pytest-xdist hands items to its processes by id: of two items with one id it runs one, silently. So an id
    shared outside the `serial` tests (which make test runs in one process) stops the run, naming it."""
    ids = Counter(item.nodeid for item in items if item.get_closest_marker("serial") is None)
    shared = sorted(nodeid for nodeid, count in ids.items() if count > 1)
    if shared:
        raise pytest.UsageError(f"tests share an id, and pytest-xdist would run one of each: {shared[:3]}; "
                                "make their ids unique or mark them `serial`")  # fmt: skip
