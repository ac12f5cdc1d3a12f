"""Studies in the store: tasks stream in as they finish, resume redoes nothing, kill -9 loses nothing."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from horde.runs.store import Store
from horde.scenarios import find_scenario
from horde.studies.runner import InProcess, RayGoneError, create_study, run_study, summarize_study
from horde.studies.spec import StudySpec

SMALL = {
    "scenario": "classroom-offpolicy",
    "runs": 2,
    "measure": {"episodes": 60, "checkpoints": 3},
    "axes": [{"path": "learning.alpha", "values": [0.03, 0.1]}, {"path": "learning.lambda", "values": [0.0, 0.9]}],
}


def test_a_study_runs_every_task_and_summarizes_each_configuration(tmp_path: Path) -> None:
    store = Store(tmp_path)
    study = StudySpec.model_validate(SMALL)
    record, configs = create_study(store, study, find_scenario("classroom-offpolicy"))
    seen: list[tuple[int, int]] = []
    assert run_study(store, record.id, InProcess(), lambda done, total: seen.append((done, total))) == "finished"
    assert seen[0] == (0, 8) and seen[-1] == (8, 8)
    assert store.get_study(record.id).status == "finished"  # type: ignore[union-attr]
    summaries = summarize_study(store, record.id)
    assert [s.axes for s in summaries] == [c.axes for c in configs]
    assert all(s.runs == 2 for s in summaries) and sum(s.best for s in summaries) == 1
    store.close()


def test_a_cancelled_study_resumes_with_only_the_unfinished_tasks(tmp_path: Path) -> None:
    store = Store(tmp_path)
    record, _ = create_study(store, StudySpec.model_validate(SMALL), find_scenario("classroom-offpolicy"))
    done: list[int] = []
    status = run_study(store, record.id, InProcess(), lambda d, t: done.append(d), cancelled=lambda: len(done) > 3)
    assert status == "cancelled"
    before = {(t.config, t.run): t for t in store.study_tasks(record.id)}
    assert len(before) == 3
    resumed: list[int] = []
    assert run_study(store, record.id, InProcess(), lambda d, t: resumed.append(d)) == "finished"
    assert resumed == [3, 4, 5, 6, 7, 8]  # starts from the finished three
    after = {(t.config, t.run): t for t in store.study_tasks(record.id)}
    assert len(after) == 8
    for key, task in before.items():
        assert after[key] == task  # the same row, not redone
    store.close()


class DiesAfter(InProcess):
    """Runs `tasks` tasks, then its Ray ends under it (as `RayExecutor.map` says it)."""

    def __init__(self, tasks: int) -> None:
        self.tasks = tasks

    def map(self, tasks, measure, on_done, cancelled):  # type: ignore[no-untyped-def]
        super().map(tasks[: self.tasks], measure, on_done, cancelled)
        raise RayGoneError("Ray ended under it (its driver was told to exit, code 1)")


def test_a_study_whose_ray_ends_fails_saying_how_far_it_got_and_resumes(tmp_path: Path) -> None:
    store = Store(tmp_path)
    record, _ = create_study(store, StudySpec.model_validate(SMALL), find_scenario("classroom-offpolicy"))
    with pytest.raises(RayGoneError):
        run_study(store, record.id, DiesAfter(2))
    failed = store.get_study(record.id)
    assert failed is not None and failed.status == "failed"
    assert failed.message == ("Ray ended under it (its driver was told to exit, code 1) after 2 of 8 tasks; its "
                              "finished tasks are kept: resume it once Ray is back")  # fmt: skip
    assert run_study(store, record.id, InProcess()) == "finished" and store.count_study_tasks(record.id) == 8
    store.close()


def test_kill_9_during_a_study_then_resume_loses_no_finished_task(tmp_path: Path) -> None:
    study_file = tmp_path / "small.toml"
    study_file.write_text(
        'scenario = "classroom-offpolicy"\nruns = 3\n[measure]\nepisodes = 1500\ncheckpoints = 2\n'
        '[[axes]]\npath = "learning.alpha"\nvalues = [0.01, 0.03, 0.1]\n'
    )
    data = tmp_path / "data"
    command = [sys.executable, "-m", "horde.cli", "study", str(study_file), "--local", "--quiet", "--data", str(data)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        store = None
        while time.monotonic() < deadline:
            if (data / "horde.db").exists():
                store = store or Store(data)
                studies = store.list_studies()
                if studies and store.count_study_tasks(studies[0].id) >= 2:
                    break
            assert process.poll() is None, f"the study ended before it could be killed: {process.communicate()}"
            time.sleep(0.05)
        else:
            pytest.fail("no two tasks finished within 120 s")
        os.kill(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(timeout=10)
    assert store is not None
    (record,) = store.list_studies()
    assert record.status == "running"  # killed: it never got to say otherwise
    before = {(t.config, t.run): t for t in store.study_tasks(record.id)}
    assert 2 <= len(before) < 9
    store.close()
    out = tmp_path / "out.json"
    resume = [sys.executable, "-m", "horde.cli", "study", "--resume", record.id, "--local", "--data", str(data)]
    finished = subprocess.run([*resume, "--json", str(out)], capture_output=True, text=True, timeout=300)
    assert finished.returncode == 0, finished.stderr
    assert f"{len(before)}/9 tasks" in finished.stderr  # the bar starts at the finished tasks
    store = Store(data)
    after = {(t.config, t.run): t for t in store.study_tasks(record.id)}
    assert len(after) == 9 and store.get_study(record.id).status == "finished"  # type: ignore[union-attr]
    for key, task in before.items():
        assert after[key] == task  # same data, same finishing time: not redone
    store.close()
    rows = json.loads(out.read_text())
    assert [r["axes"] for r in rows] == [{"learning.alpha": a} for a in (0.01, 0.03, 0.1)]
    assert all(r["runs"] == 3 for r in rows)


def test_deleting_a_study_that_has_stored_its_end_waits_for_its_driver_to_leave(tmp_path: Path) -> None:
    """A study's driver stores "finished" and then leaves the running ones (`StudyJobs._ended`): a DELETE in between
    deletes it once it has left, rather than setting the cancel flag of a study that runs no more (the server's
    study test once read 200 after such a DELETE)."""
    import threading

    from horde.studies.jobs import Progress, StudyJobs

    store = Store(tmp_path)
    record, _ = create_study(store, StudySpec.model_validate(SMALL), find_scenario("classroom-offpolicy"))
    jobs = StudyJobs(store, None, kind="local")  # type: ignore[arg-type]
    progress = Progress(done=8, total=8)
    jobs._running[record.id] = progress
    store.set_study_status(record.id, "finished", "")
    leaves = threading.Timer(0.3, jobs._ended, (record.id, None))
    leaves.start()
    try:
        jobs.cancel(record.id)
    finally:
        leaves.join(5.0)
    assert not progress.cancel.is_set()
    assert store.get_study(record.id) is None
    store.close()
