"""`RunCommands`: one browser's commands of the run it shows (play, pause, step, reset, speed), its token, and
the run's owner; and the helpers every part of a browser's panel uses on viser's widgets.

The commands change a run, which every viewer sees, so they follow the token the browser acts with
(runs/access.py, the rule of the API's routes): they are shown only while that token may change the run shown
(the teacher's, or the student who created it), and checked again on every click, a refusal answered with a
notification to that browser alone. The token is the browser's dashboard's (POST /api/view), or one typed into
the panel's Token field, which a server with roles offers until the browser holds a good one.

As in `horde.view.gui`: callbacks (viser's thread pool) only record and forward; the view thread alone adds,
removes and sets widgets (`sync`, `show_speed`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import numpy as np
import viser

from horde.runs.access import Access, ForbiddenError, Principal, UnauthorizedError
from horde.view.source import CommandRefusedError, ViewSource

SCALARS = (bool, int, float, str)  # the values `set_value` compares itself
SPEED_RANGE = (1, 200)  # steps per second the speed slider offers (a faster run is shown at its end)


def tell(event: Any, title: str, body: str) -> None:
    """A red notification to the one client behind a GUI event (none for an event without a client)."""
    client = getattr(event, "client", None)
    if client is not None:
        client.add_notification(title, body, color="red")


def removed(handle: Any) -> bool:
    """Whether viser has removed the widget (a client that left, or the view thread's own removal)."""
    impl = getattr(handle, "_impl", handle)
    return bool(getattr(impl, "removed", False))


def set_value(handle: Any, value: object) -> None:
    """Assign a GUI input's value (viser sends it only if it changed); nothing for a removed widget. A value of the
    very type and value the widget holds is left at once (the view assigns a dozen values a browser and frame:
    most are unchanged, and viser's setter would coerce and compare each)."""
    impl = getattr(handle, "_impl", None)
    held = getattr(impl, "value", None)
    same = type(held) is type(value) and isinstance(value, SCALARS) and held == value
    if same and not getattr(impl, "is_button", False):
        return
    if removed(handle):
        return
    try:
        handle.value = value
    except RuntimeError:
        if not removed(handle):  # removed meanwhile (a client that left): nothing to show it to
            raise


def remove(handle: Any) -> None:
    if not removed(handle):
        handle.remove()


def from_browser(event: Any) -> bool:
    """Whether a GUI event came from a browser (the view thread's own assignments have no client)."""
    return getattr(event, "client", None) is not None


class RunCommands:
    """The commands of the run a browser shows, its token and the run's owner, in the browser's panel.

    Args:
        client: the viser client whose own GUI they are in.
        source: where commands go.
        changed: set when the browser typed a token (the view thread checks it at once).
        access: the server's tokens and owners (None: no roles, every browser may command every run).
        shown: the run the browser shows now (the panel's choice).
    """

    def __init__(
        self,
        client: viser.ClientHandle,
        source: ViewSource,
        changed: threading.Event,
        access: Access | None,
        shown: Callable[[], str | None],
    ) -> None:
        self.client = client
        self.gui = client.gui
        self.source = source
        self.changed = changed
        self.access = access
        self.shown = shown
        self.lock = threading.Lock()
        self.secret: str | None = None  # the token this browser acts with (its dashboard's, or typed)
        self.entered: str | None = None  # a token typed into the Token field, not yet checked
        self.folder: viser.GuiFolderHandle | None = None  # the commands, while shown
        self.buttons: dict[str, viser.GuiButtonHandle] = {}  # their buttons by label, while shown
        self._speed: tuple[Any, Any] | None = None  # (slider, full-speed box), while shown
        self._built_for: tuple[str | None, bool] = (None, False)  # (run, may command) the commands were built for
        self.token_field: viser.GuiTextHandle | None = None
        if access is not None and access.required:
            self.token_field = self.gui.add_text(
                "Token", "", hint="a token from the teacher: unlocks the commands of the runs it may change", order=-1
            )
            self.token_field.on_update(self._on_token)
        self.owner = self.gui.add_text("Owner", "", disabled=True, hint="who created the run shown", order=0.5)

    # ------------------------------------------------------------------------------------------
    # Callbacks (viser's thread pool)

    def _on_token(self, event: Any) -> None:
        if from_browser(event) and self.token_field is not None:
            with self.lock:
                self.entered = self.token_field.value.strip()
            self.changed.set()

    def command(self, event: Any, command: Callable[[str], None]) -> None:
        """Forward a command on the run shown, if this browser's token may change it; a refusal (a role that may
        not, a run gone meanwhile, a command the run refuses) is told to the client who clicked, as a
        notification, the others seeing nothing."""
        run_id = self.shown()
        if not from_browser(event) or run_id is None:
            return
        try:
            self.authorize(run_id)
            command(run_id)
        except (UnauthorizedError, ForbiddenError) as exc:
            tell(event, "Not allowed", str(exc))
        except CommandRefusedError as exc:
            tell(event, "Not done", str(exc))
        except KeyError:
            tell(event, "Run gone", "This run no longer exists; choose another under Run.")
        self.changed.set()

    def _set_hz(self, event: Any, hz: Any, full_speed: Any) -> None:
        self.command(event, lambda run: self.source.set_hz(run, None if full_speed.value else float(hz.value)))

    # ------------------------------------------------------------------------------------------
    # Who may change what

    def principal(self) -> Principal | None:
        """Who this browser acts as (None: no token, on a server with roles; also without `access`).

        Raises:
            UnauthorizedError: its token is not the server's, or was revoked.
        """
        if self.access is None:
            return None
        return self.access.identify(self.secret)

    def may_command(self, run_id: str) -> bool:
        """Whether this browser's commands may change the run (no token on a server with roles: no)."""
        if self.access is None:
            return True
        try:
            principal = self.principal()
        except UnauthorizedError:
            return False
        return self.access.may_change(principal, "run", run_id)

    def authorize(self, run_id: str) -> None:
        """Raise unless this browser may change the run.

        Raises:
            UnauthorizedError: no token (on a server with roles), or a wrong or revoked one.
            ForbiddenError: a viewer's token, or a student's on another's run (naming its owner).
        """
        if self.access is None:
            return
        principal = self.principal()
        if principal is None:
            raise UnauthorizedError("this server needs a token to change a run: enter yours under Token")
        self.access.check(principal, "run", run_id)

    # ------------------------------------------------------------------------------------------
    # The view thread

    def sync(self, run_id: str | None, commands: bool) -> None:
        """The Token field (while the browser has no good token), the owner of the run shown, and the commands
        (shown only when this browser may change that run; `commands` False: the run takes none, a stream run)."""
        if self.entered is not None:
            self._take_token(self.entered)
        if self.token_field is not None:
            try:
                holds = self.principal() is not None
            except UnauthorizedError:
                holds = False
            if holds:
                remove(self.token_field)
                self.token_field = None
        may = commands and run_id is not None and self.may_command(run_id)
        if run_id is not None and self.access is not None:
            owner = self.access.owner_name("run", run_id)
            set_value(self.owner, f"{owner} (yours to change)" if may else f"{owner} (read-only here)")
        if (run_id, may) == self._built_for:
            return
        self._built_for = (run_id, may)
        if self.folder is not None:
            remove(self.folder)
            self.folder, self._speed, self.buttons = None, None, {}
        if may:
            self._add_commands()

    def _take_token(self, entered: str) -> None:
        """Check the token typed into the Token field: the right one gives this browser its role's commands."""
        with self.lock:
            self.entered = None
        if not entered or self.access is None:
            return
        try:
            principal = self.access.identify(entered)
        except UnauthorizedError as exc:
            self.client.add_notification("Wrong token", str(exc), color="red")
            return
        if principal is None:
            return
        with self.lock:
            self.secret = entered
        self.client.add_notification(
            "Token taken", f"This browser acts as {principal.name} ({principal.role}) now.", color="green"
        )

    def _add_commands(self) -> None:
        """Play, pause, step, reset and speed, in a folder of their own."""
        gui = self.gui
        self.folder = gui.add_folder("Commands", order=2)
        with self.folder:
            play, pause = gui.add_button("Play"), gui.add_button("Pause")
            play.on_click(lambda event: self.command(event, self.source.play))
            pause.on_click(lambda event: self.command(event, self.source.pause))
            steps = gui.add_number("Steps per click", 1, min=1, max=10_000, step=1)
            step = gui.add_button("Step")
            step.on_click(lambda event: self.command(event, lambda run: self.source.step(run, int(steps.value))))
            reset = gui.add_button("Reset")
            reset.on_click(lambda event: self.command(event, self.source.reset))
            hz = gui.add_slider("Speed (steps/s)", *SPEED_RANGE, 1, 10)
            full_speed = gui.add_checkbox("Full speed", False, hint="as fast as possible")
        hz.on_update(lambda event: self._set_hz(event, hz, full_speed))
        full_speed.on_update(lambda event: self._set_hz(event, hz, full_speed))
        self._speed = (hz, full_speed)
        self.buttons = {"Play": play, "Pause": pause, "Step": step, "Reset": reset}

    def show_speed(self, hz: float | None) -> None:
        """The run's speed, which may change elsewhere (say over REST), on the commands' inputs."""
        if self._speed is None:
            return
        slider, full_speed = self._speed
        set_value(full_speed, hz is None)
        if hz is not None:
            set_value(slider, int(np.clip(round(hz), *SPEED_RANGE)))
