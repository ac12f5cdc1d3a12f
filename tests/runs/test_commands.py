"""The command queue of a learner thread: answers, refusals after close, shutdown, a busy owner."""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

import pytest

from horde.runs.commands import CommandQueue, ShutdownError
from horde.runs.errors import BusyError, NotFoundError
from polling import wait_until


def test_a_call_is_answered_by_the_owner_with_its_result_or_its_exception() -> None:
    commands = CommandQueue("run 'r'")
    with ThreadPoolExecutor(2) as callers:
        ok = callers.submit(commands.call, lambda: threading.current_thread().name, 10.0)
        bad = callers.submit(commands.call, lambda: 1 / 0, 10.0)
        for _ in range(2):
            command = commands.next(10.0)
            assert command is not None, "a call never reached the queue"
            commands.run(command)
        assert ok.result(10) == threading.current_thread().name, "the action ran in the owner's thread"
        with pytest.raises(ZeroDivisionError):
            bad.result(10)


def test_close_refuses_what_is_queued_and_what_comes_after() -> None:
    commands = CommandQueue("run 'r'")
    with ThreadPoolExecutor(1) as callers:
        queued = callers.submit(commands.call, lambda: "never", 10.0)
        wait_until(lambda: not commands._queue.empty(), "the call to be queued", 10.0)
        commands.close()
        with pytest.raises(NotFoundError, match="run 'r' has been deleted"):
            queued.result(10)
    with pytest.raises(NotFoundError):
        commands.call(lambda: None, 1.0)


def test_a_shutdown_answers_its_caller_then_leaves_the_loop() -> None:
    commands = CommandQueue("run 'r'")
    failure = RuntimeError("the last save failed")

    def shut() -> None:
        raise ShutdownError(failure)

    with ThreadPoolExecutor(1) as callers:
        answer = callers.submit(commands.call, shut, 10.0)
        command = commands.next(10.0)
        assert command is not None
        with pytest.raises(ShutdownError):
            commands.run(command)
        with pytest.raises(RuntimeError, match="the last save failed"):
            answer.result(10)


def test_a_call_the_owner_does_not_take_in_time_is_busy() -> None:
    with pytest.raises(BusyError, match=r"run 'r' did not answer within 0\.05 s"):
        CommandQueue("run 'r'").call(lambda: None, 0.05)
