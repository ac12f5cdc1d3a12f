"""The wire format of the REST API: input models (…In) and output models (…Out).

Specs (RunSpec, WorldSpec, DemonSpec, BehaviourSpec) are the core's own pydantic models and are
used as they are; the snapshot format lives with its code in `horde.runs.snapshot`. Numbers that can be
non-finite (a diverged demon's prediction) travel as null: a `MaybeFloat` field makes NaN, infinities and
numbers beyond MAX_MAGNITUDE null as the model is built, so outputs are built by validation
(`Model.model_validate(obj, from_attributes=True)`, or the fields given as they are) and no caller maps
numbers one by one.

Why one module of about 420 lines: the models reference one another (runs, demons, metrics, values), and the
dashboard's generated types follow this one file; split, each part would re-import the others.
"""

from __future__ import annotations

import numbers
from datetime import datetime
from typing import Annotated, Any, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Discriminator, Field, Tag

from horde.runs.divergence import meaningful
from horde.runs.events import EventKind
from horde.runs.run_view import RunStatus
from horde.spec import MAX_DEMONS, MAX_FAMILIES, BehaviourSpec, DemonSpec, Hz, Name, RunSpec, WorldSpec
from horde.view.live import VIEWER_KEY_PATTERN

MAX_RESOLUTION = 256
MAX_EVAL_EPISODES = 5_000
MAX_EVAL_CAP = 10_000


def _meaningful_or_none(value: object) -> object:
    """A number made null where JSON cannot carry it or a diverged demon made it meaningless; the rest as is."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):  # numpy's scalars too
        return meaningful(float(value))
    return value


MaybeFloat = Annotated[float | None, BeforeValidator(_meaningful_or_none)]


class In(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


class Out(BaseModel):
    model_config = ConfigDict(frozen=True, populate_by_name=True)


class ErrorOut(Out):
    """A refused request: 401, 404, 409 and 429 carry one message."""

    detail: str


# ----------------------------------------------------------------------------------------------
# Inputs


class WorldCreate(WorldSpec):
    """A world to store under its name (POST /api/worlds)."""

    name: Name


class RunTemplateIn(In):
    """A run from a scenario and/or a stored world, with overrides of any top-level RunSpec field.

    Objects (world, features, behaviour, learning, protocol, thesis) are merged key by key into the
    scenario's, recursively; plain values (name, description, seed) replace it; `demons` replaces the
    scenario's demons (its families already expanded into them); `families` are expanded into more demons
    beside those (kept or replaced), so `{scenario, families}` adds a family to a scenario. Without a
    scenario the base is the default RunSpec. `world` names a stored world, or is an object merged into
    the scenario's world.
    """

    scenario: Name | None = Field(default=None, description="a scenario name (GET /api/scenarios)")
    world: Name | dict[str, Any] | None = Field(default=None, description="a stored world's name, or overrides")
    seed: int | None = Field(default=None, ge=0, le=2**63 - 1)
    name: Name | None = None
    description: str | None = Field(default=None, max_length=2000)
    features: dict[str, Any] | None = None
    behaviour: dict[str, Any] | str | None = None
    learning: dict[str, Any] | None = None
    demons: list[dict[str, Any]] | None = Field(default=None, max_length=MAX_DEMONS)
    families: list[dict[str, Any]] | None = Field(default=None, max_length=MAX_FAMILIES)
    protocol: dict[str, Any] | None = None
    thesis: dict[str, Any] | None = None


def run_form(value: Any) -> str:
    if isinstance(value, dict):
        return "RunTemplate" if "scenario" in value or isinstance(value.get("world"), str) else "RunSpec"
    return "RunTemplate" if isinstance(value, RunTemplateIn) else "RunSpec"


RunCreate = Annotated[
    Annotated[RunSpec, Tag("RunSpec")] | Annotated[RunTemplateIn, Tag("RunTemplate")],
    Discriminator(run_form),
]


class RunPatchIn(In):
    """Change a run's speed and/or behaviour policy; a field left out stays as it is."""

    hz: Hz | None = None
    behaviour: BehaviourSpec | None = None


class StepIn(In):
    steps: int = Field(default=1, ge=1, le=10_000)


class EvaluateIn(In):
    """A Monte-Carlo evaluation of one demon's question, as the run's world allows (`RunOut.evaluation`).

    On the grid ("grid") from a point `from` = [x, y], by default the world's start (the centre of a start
    rectangle); on a Gymnasium world ("rollouts") from the agent's current state, `from` left out.
    """

    demon: Name
    from_: list[Annotated[float, Field(allow_inf_nan=False)]] | None = Field(
        default=None,
        alias="from",
        min_length=2,
        max_length=2,
        description="[x, y] on the grid (default: the world's start); left out on a Gymnasium world",
    )
    episodes: int = Field(default=100, ge=1, le=MAX_EVAL_EPISODES, description="rollouts")
    cap: int | None = Field(
        default=None, ge=1, le=MAX_EVAL_CAP, description="steps per rollout at most (default: the protocol's)"
    )
    seed: int | None = Field(default=None, ge=0, le=2**63 - 1)


# ----------------------------------------------------------------------------------------------
# Outputs


class HealthOut(Out):
    status: Literal["ok"] = "ok"
    version: str
    runs: int


class CountsOut(Out):
    positive: int
    negative: int
    none: int


class DemonResultOut(Out):
    """One demon's line of a protocol's results (as `horde run --json` writes it)."""

    name: str
    prediction: MaybeFloat = Field(description="the prediction at the start, mean over trials (null: diverged)")
    truth: MaybeFloat = Field(description="Monte-Carlo truth at the start, mean over trials")
    truth_stderr: MaybeFloat
    error: MaybeFloat = Field(description="prediction - truth")
    thesis: float | None = Field(description="the thesis's number, where it has one")
    counts: CountsOut | None = Field(default=None, description="where the test runs ended (control protocols)")


class ProtocolOut(Out):
    """A protocol job: a scenario's trials x episodes, truth and test runs, in the background."""

    id: str
    owner: str = Field(description="who started it: 'teacher', or the name of the student's token")
    name: str | None
    seed: int
    status: Literal["running", "finished", "failed", "cancelled", "interrupted"] = Field(
        description="interrupted: the server stopped (or died) while it ran; `error` says how far it got"
    )
    episodes_done: int
    episodes_total: int
    trials: int
    episodes: int
    max_steps: int
    rollouts: int
    seconds: float | None = Field(description="learning and evaluation time, once finished")
    steps: int | None
    results: list[DemonResultOut] | None
    thesis_counts: CountsOut | None
    error: str
    created_at: datetime
    finished_at: datetime | None


class ViewOut(Out):
    """Whether the viser live view runs, where it listens, and which run it shows one dashboard tab."""

    enabled: bool = Field(description="false when the server runs without the live view (`horde serve --no-view`)")
    url: str | None = Field(
        description="the viser client's address (embed it in an iframe or open it); with `viewer`, the address "
        "whose browsers follow that tab's choice"
    )
    run: str | None = Field(description="the run shown to the browsers of `viewer`, if it chose one")
    browsers: int = Field(default=0, description="browsers connected to the live view now, each with its own view")
    frame_rate: float = Field(
        default=0.0, description="frames drawn a second over the last 5 s (a frame draws every browser's view)"
    )


ViewerKey = Annotated[
    str,
    Field(
        pattern=VIEWER_KEY_PATTERN,
        description="a dashboard tab's own random key (8 to 64 letters, digits, - or _): the browsers that "
        "opened the view at GET /api/view?viewer=<key>'s url follow this tab's choice, no others",
    ),
]


class ViewIn(In):
    viewer: ViewerKey
    run: str = Field(min_length=1, max_length=64, description="the run the tab's live view should show")
    demons: list[Name] | None = Field(
        default=None, max_length=12, description="the demons to label and chart (the first ones by default)"
    )
    large: bool | None = Field(
        default=None, description="Large text: the view's labels and panel larger (for a projector); null: unchanged"
    )


class ScenarioOut(Out):
    name: str
    description: str
    error: str | None = Field(default=None, description="why the file does not load, if it does not")
    watch_hz: float | None = Field(
        default=None, description="the speed to watch it at live, steps per second (its `[watch]` table); null: full"
    )
    watch_note: str = Field(default="", description="why that speed, and what to watch for")


class WorldOut(Out):
    name: str
    owner: str = Field(description="who stored it: 'teacher', or the name of the student's token")
    world: WorldSpec
    created_at: datetime
    updated_at: datetime


class SummaryOut(Out):
    """How a finished run ended; predictions are read at the world's start point."""

    predictions: dict[str, MaybeFloat]
    rupee: dict[str, MaybeFloat]
    ude: dict[str, MaybeFloat]
    episodes: int
    steps: int
    last_return: MaybeFloat
    stopped_early: bool


class EvaluationSupportOut(Out):
    """What POST /api/runs/{id}/evaluate can do in this run's world."""

    kind: Literal["grid", "rollouts", "none"] = Field(
        description="grid: from a point [x, y], and a value map over the world; rollouts: from the agent's "
        "current state, no value map; none: no evaluation (`note` says why)"
    )
    note: str = Field(description="one sentence: what an evaluation is here, or why there is none")


class WorkerOut(Out):
    """Where a run learns: a process of the server's machine, or a Ray actor on a node of its cluster."""

    kind: Literal["process", "ray", "none"] = Field(description="none: the run has no worker (its worker died)")
    pid: int | None = Field(description="the worker's process id, on its node")
    node: str | None = Field(description="the Ray node the worker runs on (null for a process of this machine)")
    alive: bool


class RunBriefOut(Out):
    id: str
    owner: str = Field(description="who created it: 'teacher', or the name of the student's token")
    name: str | None
    status: RunStatus
    message: str
    hz: float | None
    episode: int = Field(description="episodes completed")
    step: int = Field(description="steps taken in all")
    demons: list[str]
    evaluation: EvaluationSupportOut
    worker: WorkerOut
    created_at: datetime
    updated_at: datetime


class RunOut(RunBriefOut):
    spec: RunSpec
    summary: SummaryOut | None


class AgentOut(Out):
    x: float
    y: float


class DemonMetricsOut(Out):
    rupee: MaybeFloat
    ude: MaybeFloat
    delta: MaybeFloat
    cumulant: MaybeFloat
    diverged: bool
    step_size: MaybeFloat = Field(
        default=None,
        description="the step size the demon takes now, in alpha's units: alpha for a constant step size; for "
        "autostep and tidbd the sum of its per-weight step sizes over the active features",
    )


class EventOut(Out):
    seq: int
    step: int
    episode: int
    kind: EventKind
    message: str
    value: MaybeFloat = None


class StateOut(Out):
    """The live state of a run; also the message of its WebSocket stream."""

    type: Literal["state"] = "state"
    run: str
    status: RunStatus
    message: str
    hz: float | None
    agent: AgentOut
    episode: int
    step: int
    episode_step: int
    episode_return: MaybeFloat
    last_return: MaybeFloat
    predictions: dict[str, MaybeFloat] = Field(
        description="each demon's prediction at the agent's state (a stream message of a large Horde: some of them)"
    )
    metrics: dict[str, DemonMetricsOut]
    demon_total: int = Field(
        default=0, description="the run's demons; a stream message carries at most 200 of them, the next ones in turn"
    )
    events: list[EventOut] = Field(description="recent events (a stream message: those since the last message)")
    sensors: dict[str, MaybeFloat] | None = Field(
        default=None,
        description="a Gymnasium run's sensors at the agent's state (its `agent` is then the first two of them)",
    )


class DemonOut(Out):
    name: str
    spec: DemonSpec
    control: bool = Field(description="a control demon (its target policy acts on its own action values)")
    prediction: MaybeFloat
    metrics: DemonMetricsOut
    colour: str = Field(description="the demon's colour in the dashboard and the live view (#rrggbb)")


class ValuesOut(Out):
    """On the grid (`kind` "grid"): values[j][i] is the demon's prediction at (x[i], y[j]), the centres of an N x N
    grid. On a world of discrete states with known transitions (`kind` "states": the chains, Baird's star):
    values[0][i] is the prediction at state x[i] (y is empty, N the number of states), beside `exact` (the true
    values), `fixed_point` (the TD fixed point's values), and the errors over the states: `rmsve` and `rmspbe`
    weighted by the behaviour's distribution (`weighting`), `rms_error` every state alike (horde.worlds.state_values).
    """

    kind: Literal["grid", "states"] = "grid"
    demon: str
    resolution: int
    width: float
    height: float
    x: list[float]
    y: list[float]
    values: list[list[MaybeFloat]]
    min: MaybeFloat
    max: MaybeFloat
    exact: list[float] | None = None
    fixed_point: list[float] | None = None
    rmsve: MaybeFloat = None
    rms_error: MaybeFloat = None
    rmspbe: MaybeFloat = None
    weighting: str | None = None


class HistoryOut(Out):
    """A demon's recent history, oldest first (null before the demon joined).

    Rows are sampled: at most one per `every` steps and one per HORDE_HISTORY_INTERVAL seconds (default
    5 ms), so a run paced by hz has a row per step and a run at full speed a row every few milliseconds.
    """

    demon: str
    every: int = Field(description="steps between two rows, at least")
    capacity: int = Field(description="rows kept at most")
    step: list[int]
    prediction: list[MaybeFloat]
    cumulant: list[MaybeFloat]
    delta: list[MaybeFloat]
    rupee: list[MaybeFloat]
    ude: list[MaybeFloat]
    rmsve: list[MaybeFloat] | None = Field(
        default=None,
        description="on a world of discrete states with known transitions (the chains, Baird's star): the RMS error "
        "of the demon's values over the states against the true values, weighted by the behaviour's distribution "
        "over states (on-policy: the book's mu), measured at most every 0.1 s while the run runs and at the last "
        "row of a step or pause (rows between carry the latest measurement); null elsewhere (no states to measure "
        "over), null entries for a demon without a truth (action values, a question that reads other demons)",
    )
    rmspbe: list[MaybeFloat] | None = Field(
        default=None,
        description="as rmsve: the root of the projected Bellman error with the demon's own lambda, under the same "
        "weighting (0 at the TD fixed point)",
    )


class EvaluationOut(Out):
    demon: str
    from_: list[float] = Field(
        alias="from",
        description="the point [x, y] evaluated from on the grid; elsewhere the sensors at the agent's state the "
        "rollouts began from (one per sensor, in the world's order)",
    )
    prediction: MaybeFloat
    truth: MaybeFloat = Field(description="mean realised return over the rollouts")
    stderr: MaybeFloat
    error: MaybeFloat = Field(description="prediction - truth")
    episodes: int
    cap: int
    capped: int = Field(description="rollouts still running at the cap")
    seed: int
    step: int | None = Field(
        default=None,
        description="the run's step whose weights were evaluated (null in evaluations kept before runs said so)",
    )
    exact: MaybeFloat = Field(
        default=None, description="the exact answer at `from` on a small lattice world (no noise), else null"
    )
