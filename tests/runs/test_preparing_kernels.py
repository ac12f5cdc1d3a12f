"""A run whose first call into the compiled kernels is under way says so, then says it runs."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from horde.runs import session as live_session
from horde.runs.manager import RunManager
from horde.spec import RunSpec
from polling import wait_until
from server.helpers import make_spec  # tests/server/helpers.py: the specs the server tests use
from workers import ThreadExecutor


def test_the_first_batch_in_a_process_is_announced_as_preparing_the_kernels(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(live_session, "_kernels_ready", threading.Event())  # as in a fresh process
    executor = ThreadExecutor()  # the worker in this process, where the test can hold its first batch back
    manager = RunManager(executor=executor)
    release = threading.Event()
    try:
        run = manager.get(manager.create(RunSpec.model_validate(make_spec())).id)
        sim = executor.workers[run.id].session.sim
        real_run = sim.run

        def compiling(*args: Any, **kwargs: Any) -> Any:
            assert release.wait(30), "the test never released the first batch"
            return real_run(*args, **kwargs)

        sim.run = compiling  # type: ignore[method-assign]
        run.start()
        wait_until(lambda: run.view.message == live_session.PREPARING, "the preparing message")
        assert run.view.status == "running" and run.view.total_steps == 0
        release.set()
        wait_until(lambda: run.view.total_steps > 0, "the first steps")
        wait_until(lambda: run.view.message == "running", "the message to say running again")
        # Later runs in the same process start without the message.
        second = manager.get(manager.create(RunSpec.model_validate(make_spec())).id)
        assert second.step(5).message != live_session.PREPARING
    finally:
        release.set()
        manager.stop()
