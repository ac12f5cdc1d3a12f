"""The run layer without the web: failures, closing, rebuilding for new demons, history remapping."""

from __future__ import annotations

import time

import numpy as np
import pytest

from horde.runs.errors import NotFoundError
from horde.runs.history import History
from horde.runs.manager import RunManager
from horde.runs.run_setup import new_simulation
from horde.spec import DemonSpec, RunSpec
from server.helpers import make_spec  # tests/server/helpers.py: the specs the server tests use


def wait(predicate: object, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():  # type: ignore[operator]
        assert time.monotonic() < deadline
        time.sleep(0.01)


def test_an_exception_while_learning_marks_the_run_failed_and_the_thread_lives_on() -> None:
    manager = RunManager()
    try:
        run = manager.get(manager.create(RunSpec.model_validate(make_spec())).id)

        def explode(*args: object, **kwargs: object) -> None:
            raise FloatingPointError("boom")

        run._sim.run = explode  # type: ignore[method-assign]
        run.start()
        wait(lambda: run.view.status == "failed")
        assert "FloatingPointError: boom" in run.view.message
        assert run.is_alive()
        assert any(e.kind == "error" for e in run.events.recent())
        assert run.reset().status == "created"  # a fresh simulation: the run works again
        assert run.step(10).total_steps == 10
    finally:
        manager.stop()


def test_a_deleted_run_refuses_commands() -> None:
    manager = RunManager()
    run = manager.get(manager.create(RunSpec.model_validate(make_spec()), start=True).id)
    manager.delete(run.id)
    assert not run.is_alive()
    with pytest.raises(NotFoundError):
        run.start()
    with pytest.raises(NotFoundError):
        manager.get(run.id)


def test_rebuild_keeps_weights_generator_and_counters() -> None:
    spec = RunSpec.model_validate(make_spec())
    sim = new_simulation(spec)
    sim.run(500)
    weights = {name: sim.horde.weights(sim.horde_state, name) for name in sim.horde.names}
    rng_state = sim.rng.bit_generator.state
    extra = DemonSpec.model_validate({"name": "bump", "policy": "uniform", "cumulant": {"sensor": "bump"}})
    grown = sim.with_spec(spec.model_copy(update={"demons": [*spec.demons, extra]}))
    assert grown.horde.names == ["base", "steps", "bump"]
    for name, theta in weights.items():
        np.testing.assert_array_equal(grown.horde.weights(grown.horde_state, name), theta)
    assert grown.rng.bit_generator.state == rng_state
    assert (grown.total_steps, grown.episode, grown.position) == (sim.total_steps, sim.episode, sim.position)
    assert grown.episode_return == sim.episode_return and grown.last_return == sim.last_return


def test_history_keeps_the_rows_of_remaining_demons() -> None:
    history = History(["a", "b"], capacity=16)
    for step in range(1, 21):
        history.record(step, *(np.array([step, -step], dtype=float) for _ in range(5)))
    assert history.series("a").steps.tolist() == list(range(5, 21))  # a ring of 16 rows
    moved = history.remap(["b", "c"])
    assert moved.series("b").values["prediction"].tolist() == [-float(s) for s in range(5, 21)]
    assert np.isnan(moved.series("c").values["prediction"]).all()
    with pytest.raises(KeyError):
        moved.series("a")
