"""The workers of stream runs and protocol jobs: each learns in a process of its own, as a live run does.

- `serve_stream`: a stream run's `StreamLearning`; it answers `Push` (records learned in order), the demon
  table, the strip chart's history, phase planes and `Export` (its `StreamSnapshot`), one call at a time.
- `serve_protocol`: a scenario's whole protocol (`run_protocol`), telling its `Progress` at most every
  PROGRESS_SECONDS and checking for `Cancel` between episodes; it ends with `Finished` (the result, or why not).

Both beat as a live run's worker does (`worker.Heart`), so a worker that stops answering is seen.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable
from typing import Any

from horde.core.experiment import run_protocol
from horde.runs import messages as m
from horde.runs.collector import keep_out_of_collector
from horde.runs.errors import ConflictError
from horde.runs.stream_learning import StreamLearning
from horde.runs.stream_snapshot import restore_stream
from horde.runs.worker import MAX_WAIT
from horde.runs.worker_life import Channel, Heart, crash

log = logging.getLogger(__name__)

PROGRESS_SECONDS = 0.25  # a protocol's progress is told at most this often


class _CancelledError(Exception):
    pass


def answer_calls(channel: Channel, heart: Heart, handlers: dict[type, Callable[[Any], Any]]) -> None:
    """Answer calls with `handlers` until Shutdown (answered) or the API process has gone."""
    turns = 0
    heart.progress = lambda: turns
    while True:
        turns += 1
        if not channel.poll(MAX_WAIT):
            continue
        try:
            message = channel.recv()
        except (EOFError, OSError):
            return
        if not isinstance(message, m.Call):
            continue
        command = message.command
        if isinstance(command, m.Shutdown):
            channel.send(m.Reply(message.cid))
            return
        heart.busy(type(command).__name__)
        try:
            reply = m.Reply(message.cid, handlers[type(command)](command))
        except Exception as exc:
            reply = m.Reply(message.cid, failure=m.failure_of(exc))
        finally:
            heart.idle()
        channel.send(reply)


def serve_stream(channel: Channel) -> None:
    """A stream run's worker (the fork server's entry)."""
    init: m.StreamInit = channel.recv()  # type: ignore[assignment]
    heart = Heart(channel, lambda: 0)
    try:
        learner = restore_stream(init.snapshot) if init.snapshot is not None else None
        learning = StreamLearning(init.run_id, init.spec, learner)
    except Exception as exc:
        channel.send(m.Ready(failure=m.failure_of(exc), pid=os.getpid()))
        heart.stop()
        return
    keep_out_of_collector()

    def crash_hook(command: m.Crash) -> None:
        if not init.hooks:
            raise ConflictError("this worker was not started with test hooks")
        crash(command.how)

    handlers: dict[type, Callable[[Any], Any]] = {
        m.Push: lambda c: learning.push(c.items, c.whole),
        m.StreamReadoutOf: lambda c: learning.readout(),
        m.StreamHistoryOf: lambda c: learning.history(c.sensors, c.demons, c.last),
        m.StreamPhaseOf: lambda c: learning.phase_plane(c.demon, c.x, c.y, c.resolution),
        m.Export: lambda c: learning.snapshot().model_dump_json(by_alias=True).encode(),
        m.Crash: crash_hook,
    }
    channel.send(m.Ready(learning.status(), pid=os.getpid()))
    try:
        answer_calls(channel, heart, handlers)
    finally:
        heart.stop()


def serve_protocol(channel: Channel) -> None:
    """A protocol job's worker (the fork server's entry): runs the protocol, then says Finished."""
    init: m.ProtocolInit = channel.recv()  # type: ignore[assignment]
    episodes = 0
    heart = Heart(channel, lambda: episodes)
    told = 0.0

    def progress(done: int, total: int) -> None:
        nonlocal episodes, told
        episodes = done
        while channel.poll(0.0):
            message = channel.recv()
            if isinstance(message, m.Cancel):
                raise _CancelledError
            if isinstance(message, m.Call) and isinstance(message.command, m.Crash) and init.hooks:
                crash(message.command.how)
        if time.monotonic() - told >= PROGRESS_SECONDS:
            told = time.monotonic()
            channel.send(m.Progress(done, total))

    channel.send(m.Ready(pid=os.getpid()))
    try:
        heart.busy("the protocol")
        result = run_protocol(init.spec, progress)
        channel.send(m.Progress(episodes, init.spec.protocol.trials * init.spec.protocol.episodes))
        channel.send(m.Finished(result))
    except _CancelledError:
        channel.send(m.Progress(episodes, init.spec.protocol.trials * init.spec.protocol.episodes))
        channel.send(m.Finished(failure=m.Failure("stopped", "cancelled")))
    except (EOFError, OSError):
        return  # the API process has gone
    except Exception as exc:  # a protocol that fails ends its job, not the worker's process with a traceback
        channel.send(m.Finished(failure=m.failure_of(exc)))
    finally:
        heart.stop()
