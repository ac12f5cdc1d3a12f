"""Stream-run snapshots: a stream run's learner, exported as one JSON document and imported as a new run.

A stream run lives in memory; its snapshot (GET /api/streams/{id}/snapshot) holds what the next record
needs to be learned exactly as if the run had gone on: the spec, the Horde's state (weights, traces, error
measures), the sensors of the last observation, the action taken there with its behaviour probability
(the transition the next record completes), and the counters. POST /api/streams/import makes a new run
from it. The recent records behind the strip chart and the phase plane's trail are not kept.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from horde.core.learner import LearnerState
from horde.runs.errors import SpecError
from horde.runs.snapshot import Count, EncodedArray, Number, _encode_tree, decode, decode_horde, encode
from horde.runs.snapshot_checks import check_finite
from horde.spec import RunSpec
from horde.worlds.records import RecordLearner

FORMAT: Literal["horde-stream-snapshot/1"] = "horde-stream-snapshot/1"


class StreamSnapshot(BaseModel):
    """A stream run's learner at one record, complete enough to go on exactly."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    format: Literal["horde-stream-snapshot/1"] = FORMAT
    spec: RunSpec
    received: Count
    learned: Count
    refused: Count
    pending_action: int | None = Field(default=None, ge=0, description="a_t of the last good record (null: none)")
    pending_probability: Number | None = Field(default=None, gt=0, le=1, description="b(a_t | s_t) there")
    sensors: EncodedArray = Field(description="[S] the sensors of the last observation")
    horde: dict[str, EncodedArray | Number]


def capture_stream(learner: RecordLearner) -> StreamSnapshot:
    """The learner's state (call it holding the stream run's lock)."""
    pending = learner._pending
    return StreamSnapshot(
        spec=learner.spec,
        received=learner.received,
        learned=learner.learned,
        refused=learner.refused,
        pending_action=None if pending is None else pending[0],
        pending_probability=None if pending is None else pending[1],
        sensors=encode(learner.loop.sensors),
        horde=_encode_tree(learner.loop.horde_state()),
    )


def restore_stream(snapshot: StreamSnapshot) -> RecordLearner:
    """A learner that goes on where the snapshot's stood.

    Raises:
        SpecError: the arrays do not fit the snapshot's spec or hold numbers out of range (naming the entry), or
            the pending action is outside the world's actions.
    """
    learner = RecordLearner(snapshot.spec)
    loop = learner.loop
    state = decode_horde(loop.horde, loop.horde_state(), snapshot.horde)
    sensors = decode(snapshot.sensors, ("body", "sensors"))
    if sensors.shape != (loop.num_sensors,):
        raise SpecError.at(("body", "sensors"), f"{sensors.shape[0]} readings, the world has {loop.num_sensors}")
    check_finite(sensors, ("body", "sensors"))
    action = snapshot.pending_action
    if action is not None and (action >= learner.loop.num_actions or snapshot.pending_probability is None):
        raise SpecError.at(("body", "pending_action"), "an action of the world's, with its probability")
    loop.load(LearnerState(state, loop.state().adaptive), np.asarray(sensors, dtype=float))
    learner.received, learner.learned, learner.refused = snapshot.received, snapshot.learned, snapshot.refused
    if action is not None and snapshot.pending_probability is not None:
        learner._pending = (action, float(snapshot.pending_probability))
    return learner
