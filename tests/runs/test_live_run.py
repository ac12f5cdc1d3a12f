"""The run layer without the web: failures, closing, failed saves, rebuilding for new demons, history remapping.

(A worker that dies, hangs or is killed: tests/runs/test_supervision.py.)"""

from __future__ import annotations

import sqlite3
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from horde.core.experiment import run_trial
from horde.runs import recorder as recorder_module
from horde.runs.errors import NotFoundError, SaveError
from horde.runs.history import History
from horde.runs.manager import RunManager
from horde.runs.run_setup import Limits, new_simulation
from horde.runs.store import Store
from horde.spec import DemonSpec, RunSpec
from polling import wait_until
from server.helpers import make_spec  # tests/server/helpers.py: the specs the server tests use
from workers import ThreadExecutor


def test_an_exception_while_learning_marks_the_run_failed_and_the_worker_lives_on() -> None:
    executor = ThreadExecutor()
    manager = RunManager(executor=executor)
    try:
        run = manager.get(manager.create(RunSpec.model_validate(make_spec())).id)

        def explode(*args: object, **kwargs: object) -> None:
            raise FloatingPointError("boom")

        executor.workers[run.id].session.sim.run = explode  # type: ignore[method-assign]
        run.start()
        wait_until(lambda: run.view.status == "failed", "the run to fail")
        assert "FloatingPointError: boom" in run.view.message
        assert run.is_alive() and run.link is not None and run.link.alive, "the worker lives on"
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


class FlakyStore(Store):
    """A store whose writes fail while `broken` is set, as a full or read-only disk's would."""

    broken = False

    def save_run(self, *args: Any, **kwargs: Any) -> None:
        if self.broken:
            raise sqlite3.OperationalError("disk I/O error")
        super().save_run(*args, **kwargs)


@pytest.fixture
def flaky(tmp_path: Path) -> Iterator[tuple[RunManager, FlakyStore]]:
    store = FlakyStore(tmp_path / "data")
    manager = RunManager(store)
    yield manager, store
    store.broken = False
    manager.stop()
    store.close()


def test_a_command_whose_save_fails_says_so_and_the_change_holds(flaky: tuple[RunManager, FlakyStore]) -> None:
    manager, store = flaky
    run = manager.get(manager.create(RunSpec.model_validate(make_spec()), hz=50.0).id)
    run.start()
    store.broken = True
    with pytest.raises(SaveError, match=r"paused at step \d+, but it could not be saved: disk I/O error"):
        run.pause()
    assert run.view.status == "paused"  # the pause happened; only the save did not
    paused = run.view.message.removesuffix("; not saved: disk I/O error")
    assert paused != run.view.message and paused.startswith("paused at step ")
    assert run.events.recent(1)[0].message == "could not save the run: disk I/O error"
    (stored,) = store.list_runs()
    assert stored.status == "running", "the store still has the state before the failed save"
    store.broken = False
    assert run.step(1).message == paused, "a save that succeeds clears what the message said of the failed one"
    (stored,) = store.list_runs()
    assert (stored.status, stored.message) == ("paused", paused)


def test_a_run_that_finishes_while_its_store_fails_does_not_report_a_clean_finish(
    flaky: tuple[RunManager, FlakyStore],
) -> None:
    manager, store = flaky
    run = manager.get(manager.create(RunSpec.model_validate(make_spec(episodes=2))).id)
    store.broken = True
    with pytest.raises(SaveError, match="running, but it could not be saved"):
        run.start()
    view = wait_until(lambda: run.view if run.view.status == "finished" else None, "the run to finish", 60.0)
    assert view.message.startswith("finished after 2 episodes: its episodes are done; not saved: disk I/O error")


def test_a_run_whose_first_save_fails_is_not_created(flaky: tuple[RunManager, FlakyStore]) -> None:
    manager, store = flaky
    store.broken = True
    with pytest.raises(SaveError, match="disk I/O error"):
        manager.create(RunSpec.model_validate(make_spec()))
    assert manager.list() == []


def test_a_live_run_stops_by_the_rule_where_its_protocol_trial_stops() -> None:
    protocol = {"episodes": 200, "evaluation": {"rollouts": 0}, "stop": {"window": 3, "tolerance": 50.0}}
    spec = RunSpec.model_validate(make_spec(protocol=protocol))
    trial = run_trial(spec, 0)
    assert trial.episodes == 3, "every weight moves by less than 50 in three episodes: the rule fires at once"
    manager = RunManager()
    try:
        run = manager.get(manager.create(spec, start=True).id)
        view = wait_until(lambda: run.view if run.view.status == "finished" else None, "the run to finish", 60.0)
        assert view.summary is not None and view.summary.stopped_early
        assert (view.summary.episodes, view.summary.steps) == (trial.episodes, trial.steps)
        assert view.summary.predictions == pytest.approx(trial.predictions, abs=1e-12)
        assert view.message.endswith("the stopping rule fired")
    finally:
        manager.stop()


def test_a_periodic_snapshot_encoded_across_a_pause_does_not_undo_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A running run's periodic snapshot is frozen, then encoded in its own thread; a pause meanwhile saves the run
    as paused. The periodic save, sent after the pause's, is stale: written, it would store the run as running again
    (a server killed then would restart it running). Seen once in tests/server/test_restart.py."""
    entered, release = threading.Event(), threading.Event()
    encode = recorder_module.encode_frozen

    def held_encode(frozen: Any) -> Any:
        if threading.current_thread().name.startswith("horde-encoder-"):
            entered.set()
            assert release.wait(30.0), "the test did not release the encoder"
        return encode(frozen)

    monkeypatch.setattr(recorder_module, "encode_frozen", held_encode)
    store = Store(tmp_path / "data")
    executor = ThreadExecutor()
    manager = RunManager(store, Limits(snapshot_every=0.05), executor=executor)
    try:
        run = manager.get(manager.create(RunSpec.model_validate(make_spec()), hz=200.0).id)
        run.start()
        assert entered.wait(30.0), "no periodic snapshot began"
        paused = run.pause()
        assert paused.status == "paused"
        release.set()
        recorder = executor.workers[run.id].recorder
        wait_until(lambda: recorder._pending is None, "the periodic save to be answered", 30.0)
        (stored,) = store.list_runs()
        assert (stored.status, stored.message) == ("paused", paused.message)
        assert run.step(1).status == "paused", "the worker's periodic snapshots go on being answered"
    finally:
        release.set()
        manager.stop()
        store.close()
