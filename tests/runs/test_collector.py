"""A run's objects are kept out of the cyclic collector's reach once the run is made (runs/collector.py):
a full collection, which holds the GIL and so stalls the server's event loop, must not walk them again."""

from __future__ import annotations

import gc
from collections.abc import Iterator

import pytest

from horde.runs.manager import RunManager
from horde.spec import RunSpec
from server.helpers import make_spec


@pytest.fixture
def unfrozen() -> Iterator[None]:
    yield
    gc.unfreeze()  # give the objects back to the collector: other tests expect the usual collection


def test_a_made_runs_objects_leave_the_collectors_generations(unfrozen: None) -> None:
    many = [{"name": f"x{i}", "cumulant": {"mul": [1, 2]}} for i in range(300)]
    spec = RunSpec.model_validate(make_spec(demons=make_spec()["demons"] + many))
    frozen_before = gc.get_freeze_count()
    manager = RunManager()
    try:
        manager.create(spec)
        walked = {id(o) for o in gc.get_objects()}
        assert id(spec) not in walked and id(spec.demons[-1]) not in walked, "the run's spec is still walked"
        assert gc.get_freeze_count() > frozen_before + 300, "fewer objects frozen than the run's demons"
    finally:
        manager.stop()
