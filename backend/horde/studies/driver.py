"""A study's driver: the worker process that runs a server's study, on Ray or one task after the other.

The server never joins Ray itself (a Ray driver dies with Ray, and the server must not): each study it runs
gets a worker of its own (forked by the server's fork server, as a run's is), which joins the cluster, runs
the study's unfinished tasks (`runner.run_study`), writes each to the store the moment it finishes (the
store is on this machine, as the driver is), tells the server its `Progress`, and stops at a `Cancel`. When
Ray dies under it, the driver fails (Ray raises, or ends the process): the study is then `failed`, saying
why, and resumes once Ray is back.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from horde.runs import messages as m
from horde.runs.store import Store
from horde.runs.worker_life import Channel, Heart
from horde.studies.runner import Executor, InProcess, RayExecutor, run_study

log = logging.getLogger(__name__)


def serve_study(channel: Channel) -> None:
    """A study's driver (the fork server's entry): its first message is its `StudyInit`."""
    init = channel.recv()
    assert isinstance(init, m.StudyInit)
    os.environ.update(init.env)  # before Ray is imported: its address, token, timeouts
    done = 0
    heart = Heart(channel, lambda: done)
    store = Store(Path(init.data))

    def progress(finished: int, total: int) -> None:
        nonlocal done
        done = finished
        channel.send(m.Progress(finished, total))

    def cancelled() -> bool:
        while channel.poll(0.0):
            if isinstance(channel.recv(), m.Cancel):
                return True
        return False

    executor: Executor = InProcess()
    if init.executor == "ray":
        assert init.address is not None
        executor = RayExecutor(init.address)
    channel.send(m.Ready(pid=os.getpid()))
    try:
        heart.busy("the study")
        finished = m.Finished(run_study(store, init.study_id, executor, progress, cancelled))
    except BaseException as exc:  # run_study stored the failure in the study's status and message
        finished = m.Finished(failure=m.failure_of(exc))
    try:
        channel.send(finished)
    except OSError:
        log.info("study %s: the server has gone", init.study_id)
    finally:
        heart.stop()
        RayExecutor.shutdown()
        store.close()
