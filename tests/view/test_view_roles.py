"""Roles on the viser port: a browser's commands follow its token's role as the API's routes do (runs/access.py).

A student's browser gets the commands of the runs the student created, not of the teacher's (a click there is
refused, naming the owner); a viewer's gets none; a browser with no token gets a Token field; a revoked token
loses its commands. Raw viser clients (tests/view/viewers.py) click as a browser would.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from horde.runs.access import TEACHER, Access
from horde.runs.manager import RunManager
from horde.runs.store import Store
from horde.scenarios import load_scenario, scenario_dir
from horde.view import LiveView, ManagerSource
from polling import wait_until

from .viewers import RawClient, started_by_hand


@dataclass
class Client:
    notes: list[tuple[str, str]] = field(default_factory=list)

    def add_notification(self, title: str, body: str, color: str = "") -> None:
        self.notes.append((title, body))


@dataclass
class Click:
    client: Client = field(default_factory=Client)


@dataclass
class Classroom:
    view: LiveView
    access: Access
    source: ManagerSource
    teachers: str  # the teacher's run
    alices: str  # the student alice's run
    alice: str  # alice's token
    alice_id: str
    vic: str  # a viewer's token


@pytest.fixture
def classroom(tmp_path: Path) -> Iterator[Classroom]:
    store = Store(tmp_path / "data")
    access = Access(store, "s3cret")
    manager = RunManager()
    spec = load_scenario(scenario_dir() / "experiment1.toml")
    teachers = manager.create(spec.model_copy(update={"name": "teachers"}), hz=50.0).id
    alices = manager.create(spec.model_copy(update={"name": "alices"}), hz=50.0).id
    alice, alice_secret = access.issue(TEACHER, "student", "alice")
    _, vic = access.issue(TEACHER, "viewer", "vic")
    access.claim(access.identify(alice_secret), "run", alices)  # type: ignore[arg-type]
    source = ManagerSource(manager)
    view = started_by_hand(source, access=access)
    try:
        yield Classroom(view, access, source, teachers, alices, alice_secret, alice.id, vic)
    finally:
        view.stop()
        manager.stop()
        store.close()


def status(room: Classroom, run: str) -> str:
    return room.source.snapshot(run).status


def test_a_students_browser_commands_their_own_run_only(classroom: Classroom) -> None:
    room, view = classroom, classroom.view
    student = RawClient(view, "tab-alice")
    panel = student.viewer.panel
    view.show("tab-alice", room.alices, secret=room.alice)
    view.refresh()
    assert panel.commands.token_field is None, "the dashboard's token is the browser's"
    assert panel.commands.folder is not None and panel.commands.owner.value == "alice (yours to change)"
    student.update_gui(panel.commands.buttons["Play"], True)  # the click of a browser, through viser
    wait_until(lambda: status(room, room.alices) == "running", "alice's run to start from her click", 10.0)
    student.update_gui(panel.commands.buttons["Pause"], True)
    wait_until(lambda: status(room, room.alices) == "paused", "alice's run to pause", 10.0)

    play = panel.commands.buttons["Play"]
    view.show("tab-alice", room.teachers, secret=room.alice)
    view.refresh()
    assert panel.commands.folder is None and panel.commands.buttons == {}, "no commands shown on the teacher's run"
    assert panel.commands.owner.value == "teacher (read-only here)"
    student.update_gui(play, True)  # the old button, removed: viser drops its click
    click = Click()
    panel.commands.command(click, room.source.play)  # and a click that got through anyway is refused, naming the owner
    assert click.client.notes == [
        ("Not allowed", f"run '{room.teachers}' belongs to 'teacher': a student changes only what they created")
    ]
    view.refresh()
    assert status(room, room.teachers) == "created"


def test_a_viewers_browser_has_no_commands_and_a_revoked_token_loses_them(classroom: Classroom) -> None:
    room, view = classroom, classroom.view
    viewer = RawClient(view, "tab-viewer").viewer.panel
    student = RawClient(view, "tab-alice").viewer.panel
    view.show("tab-viewer", room.alices, secret=room.vic)
    view.show("tab-alice", room.alices, secret=room.alice)
    view.refresh()
    assert viewer.commands.folder is None and viewer.commands.owner.value == "alice (read-only here)"
    click = Click()
    viewer.commands.command(click, room.source.play)
    assert click.client.notes == [("Not allowed", "'vic' holds a viewer token: a viewer changes nothing")]
    assert student.commands.folder is not None

    room.access.revoke(TEACHER, room.alice_id)
    view.refresh()
    assert student.commands.folder is None, "a revoked token's commands go at the next frame"
    student.commands.command(click, room.source.play)
    assert click.client.notes[-1] == ("Not allowed", "the token 'alice' was revoked by the teacher")
    assert status(room, room.alices) == "created"


def test_a_browser_without_a_token_enters_one_in_its_token_field(classroom: Classroom) -> None:
    room, view = classroom, classroom.view
    browser = RawClient(view)  # the live view opened on its own: no dashboard tab, no token
    panel = browser.viewer.panel
    view.refresh()
    assert panel.run_id == room.teachers and panel.commands.folder is None and panel.commands.token_field is not None
    click = Click()
    panel.commands.command(click, room.source.play)
    assert click.client.notes == [("Not allowed", "this server needs a token to change a run: enter yours under Token")]
    browser.update_gui(panel.commands.token_field, "not-a-token")
    wait_until(lambda: panel.commands.entered == "not-a-token", "the typed token to reach the panel", 10.0)
    view.refresh()
    assert panel.commands.token_field is not None and panel.commands.secret is None
    browser.update_gui(panel.commands.token_field, room.alice)
    wait_until(lambda: panel.commands.entered == room.alice, "the typed token to reach the panel", 10.0)
    view.refresh()
    assert panel.commands.token_field is None and panel.commands.secret == room.alice
    assert panel.commands.folder is None, "alice's token on the teacher's run: still no commands"
    browser.update_gui(panel.run, f"alices [{room.alices}]")  # its own Run dropdown
    wait_until(lambda: panel.run_id == room.alices, "the browser's own choice of run", 10.0)
    view.refresh()
    assert panel.commands.folder is not None
