"""Run a study's tasks, in this process or on Ray, streaming each finished task into the store.

Every configuration x run is one task (`task.run_task`). `RayExecutor` makes each a Ray task on a cluster it
joins by address: the one-node Ray of this machine that `local_ray.LocalRay` starts (every core, no dashboard,
loopback only, token authentication), or the cluster given (`--address`, `HORDE_RAY_ADDRESS`). `InProcess`
runs them one after the other here (the tests' reference, and small studies). Either way, each result is
written to the store the moment its task finishes, and a study resumed later runs only the tasks that have no
row yet.
"""

from __future__ import annotations

import json
import logging
import secrets
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from horde.runs.errors import NotFoundError
from horde.runs.store import Store, StudyRecord
from horde.spec import RunSpec
from horde.studies.spec import Configuration, MeasureSpec, StudySpec, expand
from horde.studies.stats import ConfigSummary, mark_best, summarize_configuration
from horde.studies.task import TaskData, run_task

Progress = Callable[[int, int], None]  # (tasks done, tasks in all)
log = logging.getLogger(__name__)


class CancelledError(Exception):
    """The study was asked to stop; its finished tasks are kept."""


class RayGoneError(Exception):
    """The Ray a study ran on ended or failed under it (not one of its tasks); its finished tasks are kept."""


@dataclass(frozen=True)
class Task:
    config: int
    run: int
    spec: str  # the configuration's RunSpec, JSON


OnDone = Callable[[Task, TaskData], None]


class Executor(Protocol):
    """Runs tasks and reports each as it finishes; stops early when `cancelled()` turns true."""

    def map(
        self, tasks: Sequence[Task], measure: MeasureSpec, on_done: OnDone, cancelled: Callable[[], bool]
    ) -> None: ...  # fmt: skip


def execute(spec_json: str, run: int, measure_json: str) -> TaskData:
    """One task from its JSON form (what a Ray worker runs)."""
    return run_task(RunSpec.model_validate_json(spec_json), run, MeasureSpec.model_validate_json(measure_json))


class InProcess:
    """Run the tasks one after the other in this process."""

    def map(self, tasks: Sequence[Task], measure: MeasureSpec, on_done: OnDone, cancelled: Callable[[], bool]) -> None:
        measure_json = measure.model_dump_json()
        for task in tasks:
            if cancelled():
                raise CancelledError
            on_done(task, execute(task.spec, task.run, measure_json))


def _ray_task(spec_json: str, run: int, measure_json: str) -> TaskData:
    import ray

    data = execute(spec_json, run, measure_json)
    data["node"] = ray.get_runtime_context().get_node_id()
    return data


class RayExecutor:
    """Each task a Ray task of one CPU, on the cluster at `address` (joined once per process, left by `shutdown`).

    The cluster is given: a server's own Ray (`local_ray.LocalRay`, one node on this machine) or one of the
    user's (`--address`, HORDE_RAY_ADDRESS). The process that joins it is its driver: a study's driver process
    (`driver.py`) for the server, the `horde study` process on the command line; never the server itself.

    Args:
        address: the cluster's address (host:port).
    """

    _lock = threading.Lock()

    def __init__(self, address: str) -> None:
        self.address = address

    def start(self) -> None:
        """Join the cluster unless this process has already."""
        with self._lock:
            import ray

            if not ray.is_initialized():
                ray.init(address=self.address, log_to_driver=False)

    @classmethod
    def shutdown(cls) -> None:
        """Leave the cluster (its processes are the cluster's to stop)."""
        with cls._lock:
            if "ray" in sys.modules:
                import ray

                if ray.is_initialized():
                    ray.shutdown()

    def map(self, tasks: Sequence[Task], measure: MeasureSpec, on_done: OnDone, cancelled: Callable[[], bool]) -> None:
        self.start()
        import ray

        remote = ray.remote(num_cpus=1, max_retries=2)(_ray_task)
        measure_ref = measure.model_dump_json()
        pending: dict[Any, Task] = {remote.remote(t.spec, t.run, measure_ref): t for t in tasks}
        try:
            while pending:
                if cancelled():
                    raise CancelledError
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=0.5)
                for ref in ready:
                    on_done(pending.pop(ref), ray.get(ref))
        except ray.exceptions.RayTaskError:  # a task's own failure: as it is
            raise
        except SystemExit as exc:  # what Ray's core worker does to its driver when its node has gone
            raise RayGoneError(f"Ray ended under it (its driver was told to exit, code {exc.code})") from None
        except ray.exceptions.RayError as exc:
            raise RayGoneError(f"Ray failed under it ({type(exc).__name__}: {exc})") from exc
        finally:
            for ref in pending:
                ray.cancel(ref, force=True)


def create_study(store: Store, study: StudySpec, base: RunSpec) -> tuple[StudyRecord, list[Configuration]]:
    """Validate and expand a study (SpecError before anything is stored), then record it as `created`.

    The stored spec has the base run spec inlined, so a resumed study runs exactly what was asked even if
    the scenario file has changed since.
    """
    configurations = expand(study, base)
    resolved = study.model_copy(update={"base": base, "scenario": None, "name": study.name or base.name})
    now = time.time()
    record = StudyRecord(
        id=secrets.token_hex(6),
        name=resolved.name,
        spec=resolved.model_dump_json(by_alias=True),
        status="created",
        message="",
        tasks=len(configurations) * study.runs,
        created_at=now,
        updated_at=now,
    )
    store.create_study(record)
    return record, configurations


def load_study(store: Store, study_id: str) -> tuple[StudyRecord, StudySpec, list[Configuration]]:
    record = store.get_study(study_id)
    if record is None:
        raise NotFoundError(f"no study {study_id!r}")
    study = StudySpec.model_validate_json(record.spec)
    assert study.base is not None  # stored studies have their base inlined
    return record, study, expand(study, study.base)


def run_study(
    store: Store,
    study_id: str,
    executor: Executor,
    progress: Progress | None = None,
    cancelled: Callable[[], bool] = lambda: False,
) -> str:
    """Run every task of the study that has not finished yet; return the study's final status.

    Finished tasks are written one by one as they finish. A cancelled study keeps them (status
    `cancelled`, resumable); a failing task marks the study `failed` with the error and re-raises.
    """
    _, study, configurations = load_study(store, study_id)
    finished = {(t.config, t.run) for t in store.study_tasks(study_id)}
    todo = [
        Task(c.index, run, c.spec.model_dump_json(by_alias=True))
        for c in configurations
        for run in range(study.runs)
        if (c.index, run) not in finished
    ]
    total = len(configurations) * study.runs
    done = total - len(todo)
    store.set_study_status(study_id, "running")
    if progress:
        progress(done, total)

    def on_done(task: Task, data: TaskData) -> None:
        nonlocal done
        store.put_study_task(study_id, task.config, task.run, json.dumps(data))
        done += 1
        if progress:
            progress(done, total)

    try:
        executor.map(todo, study.measure, on_done, cancelled)
    except (CancelledError, KeyboardInterrupt):  # Ctrl-C on the command line is a cancel too
        store.set_study_status(study_id, "cancelled", f"cancelled after {done} of {total} tasks")
        return "cancelled"
    except RayGoneError as exc:
        store.set_study_status(study_id, "failed", f"{exc} after {done} of {total} tasks; its finished tasks "
                               "are kept: resume it once Ray is back")  # fmt: skip
        raise
    except BaseException as exc:
        store.set_study_status(study_id, "failed", f"{type(exc).__name__}: {exc}")
        raise
    store.set_study_status(study_id, "finished")
    return "finished"


SummaryCache = dict[int, tuple[int, ConfigSummary]]  # configuration -> (its finished runs, its summary)


def summarize_study(store: Store, study_id: str, cache: SummaryCache | None = None) -> list[ConfigSummary]:
    """Every configuration with at least one finished run, averaged over its runs; the best one marked.

    With a `cache`, only configurations whose number of finished runs changed are summarized again (a
    running study polled by the dashboard re-averages one configuration per finished task, not all). A
    configuration whose stored tasks no longer read (an older version's, or changed by hand) is left out, logged.
    """
    _, _, configurations = load_study(store, study_id)
    by_config: dict[int, list[str]] = {}  # configuration -> its finished tasks' data, as stored
    for task in store.study_tasks(study_id):
        by_config.setdefault(task.config, []).append(task.data)
    cache = {} if cache is None else cache
    summaries = []
    for c in configurations:
        tasks = by_config.get(c.index)
        if not tasks:
            continue
        cached = cache.get(c.index)
        if cached is None or cached[0] != len(tasks):
            try:
                cached = (len(tasks), summarize_configuration(c.index, c.axes, [json.loads(t) for t in tasks]))
            except (KeyError, TypeError, ValueError, IndexError) as exc:  # a stored task that no longer reads
                log.error(
                    "study %s: configuration %d left out: a stored task does not read: %r", study_id, c.index, exc
                )
                continue
            cache[c.index] = cached
        summaries.append(cached[1])
    mark_best(summaries)
    return summaries
