"""Workers in threads of the test process, for tests that reach into a worker's loop (a kernel that raises, a
first batch held back): `ThreadExecutor` runs each worker's entry in a thread over an in-memory channel
(`horde.runs.thread_host.QueueChannel`), as a Ray actor hosts one, and keeps each live run's `RunWorker` by
run id. The server never runs workers this way: its workers are processes (or Ray actors)."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from horde.runs import messages as m
from horde.runs.link import STALL_SECONDS, Listener, WorkerLink
from horde.runs.thread_host import QueueChannel, run_in_thread
from horde.runs.worker import RunWorker, serve_run


class ThreadExecutor:
    """`ProcessExecutor`'s face, with each worker in a thread of this process."""

    kind = "thread"

    def __init__(self, stall_seconds: float = STALL_SECONDS) -> None:
        self.stall_seconds = stall_seconds
        self.workers: dict[str, RunWorker] = {}

    def start(self) -> None:
        pass

    def stop(self) -> None:
        pass

    def spawn(self, entry: Callable[[Any], None], init: m.WorkerInit, listener: Listener) -> WorkerLink:
        channel = QueueChannel()
        link = WorkerLink("process", channel.deliver, listener, lambda link: channel.close())
        if entry is serve_run:
            assert isinstance(init, m.RunInit)

            def serve(ch: Any) -> None:
                worker = self.workers[init.run_id] = RunWorker(ch, ch.recv())
                worker.serve()

            entry = serve
        channel.deliver(init)
        run_in_thread(entry, channel, f"test-worker-{getattr(init, 'run_id', '')}")

        def pump() -> None:
            while True:
                ended = channel.ended.is_set()  # before the take: whatever it sent before it ended is taken
                for message in channel.take(0.1):
                    link.deliver(message)
                link.check(self.stall_seconds)
                if ended:
                    link.end("exited")
                    return

        threading.Thread(target=pump, name="test-worker-pump", daemon=True).start()
        return link
