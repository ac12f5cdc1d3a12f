"""Keeping a run's objects out of the cyclic garbage collector's reach.

A full collection holds the GIL for as long as it walks the objects it tracks: at 100,000 to 200,000 objects
(a Horde of a thousand demons is about 30,000: its spec models, questions and blocks) that is 50 to 150 ms,
during which the server's event loop cannot answer even `/api/health`. A run's objects live as long as the
run, so walking them again and again finds nothing: once a run is made they are frozen (`gc.freeze`), and a
full collection walks only what was made since. Objects frozen are still freed when their last reference
goes (reference counting does not depend on the collector); only garbage in reference cycles that was
already old at the freeze would stay, and a run's objects are not kept in cycles.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def building() -> Iterator[None]:
    """Make many long-lived objects (a Horde's spec, loaded) without a collection on the way: the collector is
    off meanwhile (an automatic full collection during a 9,000-demon spec's loading held the GIL for a quarter of
    a second), and what was made is frozen at the end (a few temporaries in cycles, if any, are kept with it)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if enabled:
            gc.enable()


def keep_out_of_collector() -> None:
    """Collect the young generations (the garbage of the moment is there), then freeze every object alive."""
    gc.collect(1)
    gc.freeze()
