"""Settings every test shares: the in-process test client's `Host` is allowed; Hypothesis sets no deadline; no two
tests that make test runs in two processes share one id; there, the files likely to take longest go first.

Hypothesis' default deadline (200 ms an example) fails an example that compiles a kernel on a cold numba
cache (2 s; seen in tests/core/test_features.py after an edit to the engine): a property test asserts
results, and its time is bounded by the test's timeout (pytest-timeout) like every other test's.

Starlette's TestClient sends `Host: testserver`, which the server's DNS-rebinding guard refuses
(server/hosts.py). The tests' servers accept that one name through HORDE_ALLOWED_HOSTS, as a user
would allow a name of theirs; the built-in default stays empty (tests/server/test_hosts.py).
"""

from __future__ import annotations

import os
from collections import Counter, defaultdict

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
    if os.environ.get("PYTEST_XDIST_WORKER"):
        longest_files_first(items)


def longest_files_first(items: list[pytest.Item]) -> None:
    """Order the files: those with a browser test first, then those with a long learning check (`slow`), then the
    rest; within each, the most tests first; a file's tests stay together, in order.

    make test gives each of its two processes a file at a time (`--dist loadfile --no-loadscope-reorder`: in the
    order collected, which the processes send to the controller). pytest-xdist's own order, the most tests first,
    left the files of one long browser test (20 to 95 s each) to the end: one process ran a 78-second test while
    the other had finished (35 s of a core idle). With the long kinds first, the last files are short ones and the
    two processes end together."""
    kind: defaultdict[str, int] = defaultdict(int)  # 2: a browser test, 1: a slow one, 0: neither
    count: Counter[str] = Counter()
    for item in items:
        rank = 2 if item.get_closest_marker("e2e") else 1 if item.get_closest_marker("slow") else 0
        kind[str(item.path)] = max(kind[str(item.path)], rank)
        count[str(item.path)] += 1
    items.sort(key=lambda item: (-kind[str(item.path)], -count[str(item.path)]))  # stable: files stay whole
