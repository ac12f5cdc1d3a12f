"""The one message protocol between the API process and its workers: what starts a worker, the commands it is
sent, and everything it sends back (replies, published views, history rows, events, saves, heartbeats).

Every message is a small frozen dataclass of plain values and numpy arrays, pickled over the worker's
connection (a socket to a process of this machine, or Ray's calls to an actor on a cluster: the same objects
either way). The API process sends a command as `Call(cid, command)` and waits for the `Reply` of the same
`cid`; the worker publishes on its own, as it learns:

    API -> worker   Call(cid, Start | Pause | Reset | Step | Patch | AddDemon | RemoveDemon | Export | ValueMapOf
                              | GreedyOf | PhaseOf | StarOf | StateValuesOf | Evaluate | Shutdown | Push
                              | StreamHistoryOf | StreamReadoutOf | Crash)
                    Cancel(cid)          stop an evaluation whose client has gone
                    SaveDone(...)        the API process wrote a save (or could not): the worker paces its saves by it
                    SetThreads(n)        the share of the machine's cores the worker's step may take
    worker -> API   Reply(cid, value | failure, update, save)
                    Update(view, rows, events, skipped)     at most every PUBLISH_INTERVAL while running
                    Save(...)                               periodic snapshots (the API process writes the store)
                    Beat(progress, doing, since)            every BEAT_SECONDS, from a thread of its own
                    Progress(done, total), Finished(...)    protocol jobs and studies

Why one module of about 420 lines: the protocol is defined once, every message beside the others, so that a
change to what crosses the boundary is one change in one place (the wire formats are kept the same way).

Who writes the store: the API process, always. A worker freezes and encodes its snapshot (off the API's
GIL) and sends the bytes; the API process writes them in its saver thread. So a worker on another node (a
Ray actor, which cannot reach this machine's SQLite) saves exactly as a local one does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from horde.core.evaluate import StoppedError
from horde.runs.errors import BusyError, ConflictError, FieldProblem, NotFoundError, RunError, SaveError, SpecError
from horde.runs.run_setup import Limits
from horde.runs.run_view import PublishedView as PublishedView  # defined beside the view it makes; sent as a message
from horde.runs.run_view import RunStatus, Summary
from horde.runs.store import RunRecord
from horde.spec import BehaviourSpec, DemonSpec, RunSpec

BEAT_SECONDS = 1.0  # a worker says it is alive this often, however busy
# What a worker says it does while numba compiles (or loads) its kernels: its main loop does not turn meanwhile,
# for a minute or more on a cold cache, and that is work, not a stall.
COMPILING = "preparing the learning kernels"

# ----------------------------------------------------------------------------------------------
# What starts a worker (its first message)


@dataclass(frozen=True)
class RunInit:
    """A live run: built from `spec` (fresh), from `data` (a spec to validate here, its problems located under
    `loc`: a Horde of thousands of demons is validated and compiled off the API process), from `stored` (a
    snapshot as the store keeps it, zlib'd JSON) or from `snapshot` (an imported `Snapshot` document); the
    run-level state comes with it."""

    run_id: str
    limits: Limits
    spec: RunSpec | None = None
    data: dict[str, Any] | None = None
    loc: tuple[str | int, ...] = ("body",)
    stored: bytes | None = None
    snapshot: Any = None  # horde.runs.snapshot.Snapshot (kept out of this module's imports)
    status: RunStatus = "created"
    hz: float | None = None
    message: str = ""
    created_at: float = 0.0
    summary: Summary | None = None
    persist: bool = True  # send saves (a server with a store)
    first_save: bool = False  # save the run before it is listed (a new run, an import)
    resumed: bool = False  # a run that was running when its server died: its message says from which step
    threads: int | None = None  # the worker's share of the cores (None: every core it may use)
    hooks: bool = False  # honour `Crash` (tests only: HORDE_TEST_HOOKS)


@dataclass(frozen=True)
class StreamInit:
    """A stream run: `spec` fresh, or going on from an imported `StreamSnapshot`."""

    run_id: str
    spec: RunSpec
    snapshot: Any = None  # horde.runs.stream_snapshot.StreamSnapshot
    hooks: bool = False


@dataclass(frozen=True)
class ProtocolInit:
    """A protocol job: the spec's whole protocol (`run_protocol`), its progress told as it goes."""

    job_id: str
    spec: RunSpec
    hooks: bool = False


@dataclass(frozen=True)
class StudyInit:
    """A study's driver: runs the study's unfinished tasks (on Ray, or one by one in this worker) and writes each
    to the store under `data` as it finishes; `env` is set before Ray is imported (its address, token, ...)."""

    data: str
    study_id: str
    executor: Literal["ray", "local"]
    address: str | None = None
    workers: int | None = None
    env: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class BridgeInit:
    """The Ray bridge: the process that joins the cluster at `address` (its driver) and hosts workers there as
    actors of `cpus` CPUs each; `env` is set before Ray is imported (its token, ...)."""

    address: str
    cpus: float = 1.0
    env: dict[str, str] = field(default_factory=dict)


WorkerInit = RunInit | StreamInit | ProtocolInit | StudyInit | BridgeInit

# ----------------------------------------------------------------------------------------------
# Commands (each sent inside a Call)


@dataclass(frozen=True)
class Start:
    pass


@dataclass(frozen=True)
class Pause:
    pass


@dataclass(frozen=True)
class Reset:
    pass


@dataclass(frozen=True)
class Step:
    steps: int


@dataclass(frozen=True)
class Patch:
    set_hz: bool = False
    hz: float | None = None
    behaviour: BehaviourSpec | None = None


@dataclass(frozen=True)
class AddDemon:
    demon: DemonSpec


@dataclass(frozen=True)
class RemoveDemon:
    name: str


@dataclass(frozen=True)
class Export:
    """The run's snapshot document, as JSON bytes (a live run's `Snapshot`, a stream run's `StreamSnapshot`)."""


@dataclass(frozen=True)
class ValueMapOf:
    """A demon's value map over the grid world (`readout.value_map`): replies a `ValueMap`."""

    demon: str
    resolution: int


@dataclass(frozen=True)
class GreedyOf:
    """A control demon's greedy action per cell: replies [R, R] ints, or None for a prediction demon."""

    demon: str
    resolution: int


@dataclass(frozen=True)
class PhaseOf:
    """A demon's values over two sensors (the others held at the agent's readings): replies a `PhaseValues`."""

    demon: str
    x: str
    y: str
    resolution: int


@dataclass(frozen=True)
class StarOf:
    """A demon's values at the seven states of Baird's star: replies [7] floats."""

    demon: str


@dataclass(frozen=True)
class StateValuesOf:
    """A demon's value at every state of a world with known transitions (a chain, Baird's star), beside the truth
    (`readout.state_values`): replies a dict, or None on any other world."""

    demon: str


@dataclass(frozen=True)
class Evaluate:
    """Monte-Carlo truth of a demon's question (`readout.evaluate`), within `seconds`: replies an `Evaluation`."""

    demon: str
    start: tuple[float, float] | None
    episodes: int
    cap: int
    seed: int | None
    seconds: float


@dataclass(frozen=True)
class Shutdown:
    """Save the run (a running one as paused; not if it is being deleted) and end the worker."""

    save: bool = True


@dataclass(frozen=True)
class Push:
    """Records for a stream run, learned in order; with `whole`, a batch with any refused record is learned not at
    all (the REST route's all-or-nothing): replies a `PushResult`."""

    items: list[Any]
    whole: bool = False


@dataclass(frozen=True)
class StreamHistoryOf:
    sensors: list[str]
    demons: list[str]
    last: int


@dataclass(frozen=True)
class StreamReadoutOf:
    """The stream run's demon table: replies (Readout, [D] step sizes)."""


@dataclass(frozen=True)
class StreamPhaseOf:
    demon: str
    x: str
    y: str
    resolution: int


CrashKind = Literal["segv", "abort", "hang", "exit"]


@dataclass(frozen=True)
class Crash:
    """Tests only (a worker started with `hooks`): die as a crash would, or stop answering."""

    how: CrashKind


Command = (
    Start | Pause | Reset | Step | Patch | AddDemon | RemoveDemon | Export | ValueMapOf | GreedyOf | PhaseOf | StarOf
    | StateValuesOf | Evaluate | Shutdown | Push | StreamHistoryOf | StreamReadoutOf | StreamPhaseOf | Crash
)  # fmt: skip


@dataclass(frozen=True)
class Call:
    cid: int
    command: Command


@dataclass(frozen=True)
class Cancel:
    """Stop the call `cid` (an evaluation) at its next chance."""

    cid: int


@dataclass(frozen=True)
class SaveDone:
    """The API process wrote save `save_id` in `seconds` (or could not: `error`)."""

    save_id: int
    seconds: float
    error: str | None = None


@dataclass(frozen=True)
class SetThreads:
    count: int | None


ToWorker = Call | Cancel | SaveDone | SetThreads


# ----------------------------------------------------------------------------------------------
# The Ray bridge (ray_bridge.py): the workers it hosts as actors, their messages in envelopes


@dataclass(frozen=True)
class Open:
    """Host a worker running `entry` as an actor (`key` names it from now on); `init` is its first message."""

    key: int
    entry: Any
    init: Any


@dataclass(frozen=True)
class Envelope:
    """A message to or from the worker `key`."""

    key: int
    message: Any


@dataclass(frozen=True)
class Close:
    """End the worker `key` (its actor is killed)."""

    key: int


@dataclass(frozen=True)
class Ended:
    """The worker `key` has ended (`reason`: why; empty when it ended by itself, asked to)."""

    key: int
    reason: str = ""


ToBridge = Open | Envelope | Close

# ----------------------------------------------------------------------------------------------
# What a worker sends


@dataclass(frozen=True)
class Rows:
    """History rows: steps [R] and values [Q, R, D] (Q = history.QUANTITIES)."""

    steps: np.ndarray
    values: np.ndarray


@dataclass(frozen=True)
class EventData:
    step: int
    episode: int
    kind: Literal["status", "episode", "demon", "error"]
    message: str
    value: float | None = None


@dataclass(frozen=True)
class Update:
    """What changed since the last update: the view, history rows, events (`skipped` more were left out), and
    `history`: "new" when the history starts afresh (a reset run), "remap" when it follows new demons."""

    view: PublishedView | None = None
    rows: Rows | None = None
    events: tuple[EventData, ...] = ()
    skipped: int = 0
    history: Literal["", "remap", "new"] = ""


@dataclass(frozen=True)
class Save:
    """A run's row, and with it (in one transaction) its snapshot (the store's bytes) and summary if given."""

    save_id: int
    record: RunRecord
    snapshot: bytes | None
    summary: str | None


FailureKind = Literal["not_found", "conflict", "busy", "spec", "save", "stopped", "internal"]


@dataclass(frozen=True)
class Failure:
    """An exception of a command, rebuilt in the API process by `raise_failure`."""

    kind: FailureKind
    message: str
    problems: tuple[FieldProblem, ...] = ()


@dataclass(frozen=True)
class Reply:
    """The answer to `Call(cid)`: its value or its failure, and the update and the save the command made (the API
    writes the save before answering its client)."""

    cid: int
    value: Any = None
    failure: Failure | None = None
    update: Update | None = None
    save: Save | None = None


@dataclass(frozen=True)
class Beat:
    """The worker is alive; `progress` counts its main loop's turns (stuck when it stops moving), `doing` names
    the command it is in since `since` (monotonic seconds of the worker), or is empty."""

    progress: int
    doing: str = ""
    busy_seconds: float = 0.0


@dataclass(frozen=True)
class Ready:
    """The worker has built what its init asked: `value` says what (a run's first update, a stream's counters);
    `save` is a new run's first save (the API writes it before listing the run)."""

    value: Any = None
    save: Save | None = None
    failure: Failure | None = None
    pid: int = 0
    node: str = ""
    spec: bytes | None = None  # a run built from `data`: its validated spec, pickled (the API loads it)


@dataclass(frozen=True)
class Progress:
    done: int
    total: int


@dataclass(frozen=True)
class Finished:
    """A protocol job's or study's end: its result, or its failure."""

    value: Any = None
    failure: Failure | None = None


FromWorker = Reply | Update | Save | Beat | Ready | Progress | Finished | Envelope | Ended

# ----------------------------------------------------------------------------------------------
# Exceptions across the boundary

_KINDS: dict[type[RunError], FailureKind] = {
    NotFoundError: "not_found",
    ConflictError: "conflict",
    BusyError: "busy",
    SpecError: "spec",
    SaveError: "save",
}


def failure_of(exc: BaseException) -> Failure:
    """The message of an exception raised in a worker: the run layer's errors keep their kind (and a SpecError its
    fields); anything else is an internal error named by its type."""
    if isinstance(exc, SpecError):
        return Failure("spec", str(exc), tuple(exc.problems))
    for kind, name in _KINDS.items():
        if isinstance(exc, kind):
            return Failure(name, str(exc))
    if isinstance(exc, StoppedError):
        return Failure("stopped", str(exc))
    return Failure("internal", f"{type(exc).__name__}: {exc}")


def raise_failure(failure: Failure) -> None:
    """Raise the exception a `Failure` stands for (an internal one as a RunError: the route answers 500 for it
    no more than for a worker's failure, which the run's message and events tell)."""
    if failure.kind == "spec":
        raise SpecError(list(failure.problems))
    if failure.kind == "stopped":
        raise StoppedError(failure.message)
    exception = {"not_found": NotFoundError, "conflict": ConflictError, "busy": BusyError, "save": SaveError}.get(
        failure.kind, ConflictError
    )
    raise exception(failure.message)
