"""Snapshots: everything a run needs to resume exactly where it stopped, as one JSON document.

A snapshot holds the spec, the Horde's state (weights, traces, error-measure averages), the world's
state, the generator's state (`rng.bit_generator.state`), the counters and the stopping rule's
reference weights. Arrays travel as base64 of their little-endian bytes, so a restored run continues
bit for bit: the same steps give the same predictions as if it had never stopped. The same document
is the export format (GET /api/runs/{id}/snapshot), the import format (POST /api/runs/import) and
what the store keeps on disk (zlib-compressed).
"""

from __future__ import annotations

import base64
import binascii
import math
import zlib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from horde.core.horde import Horde, HordeState
from horde.core.simulation import AdaptiveState
from horde.core.source import Source
from horde.runs.errors import SpecError
from horde.runs.run_setup import new_simulation
from horde.runs.run_view import RunStatus
from horde.runs.snapshot_checks import MAX_COUNT, check_horde, check_interleaved, check_world
from horde.spec import Hz, RunSpec

FORMAT: Literal["horde-snapshot/1"] = "horde-snapshot/1"
DTYPES: dict[str, str] = {"float64": "<f8", "float32": "<f4", "int64": "<i8", "bool": "|b1"}
ArrayDtype = Literal["float64", "float32", "int64", "bool"]
MAX_ARRAY_CHARS = 100_000_000  # base64 characters of one array (75 MB of data)


class EncodedArray(BaseModel):
    """A numpy array: its dtype, shape and the base64 of its little-endian bytes."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    dtype: ArrayDtype
    shape: list[Annotated[int, Field(ge=0, le=1_000_000_000)]] = Field(max_length=4)
    data: str = Field(max_length=MAX_ARRAY_CHARS)


class RngState(BaseModel):
    """The state of a PCG64 generator; the two 128-bit numbers are decimal strings."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    bit_generator: Literal["PCG64"] = "PCG64"
    state: str = Field(pattern=r"^[0-9]{1,39}$")
    inc: str = Field(pattern=r"^[0-9]{1,39}$")
    has_uint32: int = Field(ge=0, le=1)
    uinteger: int = Field(ge=0, le=2**32 - 1)

    @field_validator("state", "inc")
    @classmethod
    def _within_128_bits(cls, value: str) -> str:
        if int(value) >= 2**128:
            raise ValueError("must be below 2**128 (a PCG64 number is 128 bits)")
        return value


Number = Annotated[float, Field(allow_inf_nan=False)]
Count = Annotated[int, Field(ge=0, le=MAX_COUNT)]  # what the store's INTEGER columns hold


class Snapshot(BaseModel):
    """A run at one step, complete enough to resume it exactly."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    format: Literal["horde-snapshot/1"] = FORMAT
    spec: RunSpec
    status: RunStatus
    hz: Hz | None = None
    episode: Count
    total_steps: Count
    episode_return: Number
    last_return: Number
    rng: RngState
    world: dict[str, EncodedArray]
    horde: dict[str, EncodedArray | Number]
    stop_reference: list[EncodedArray] | None = Field(
        default=None, description="weights at the stopping rule's last check, one array per demon group"
    )
    online: dict[str, EncodedArray] | None = Field(
        default=None,
        description="the true online, emphatic and adaptive learners' state beyond the weights and traces: per-weight "
        "step sizes (autostep, tidbd) and their normalisers, v_old, followon traces; absent in older snapshots, "
        "which restore these at their start values",
    )


@dataclass
class Restored:
    """A simulation rebuilt from a snapshot, with the run-level values that came with it."""

    sim: Source
    status: RunStatus
    hz: float | None
    stop_reference: list[np.ndarray] | None


# ----------------------------------------------------------------------------------------------
# Arrays and nested named tuples


def encode(array: np.ndarray) -> EncodedArray:
    name: ArrayDtype = "float32" if array.dtype == np.float32 else "float64"
    if array.dtype == np.bool_:
        name = "bool"
    elif np.issubdtype(array.dtype, np.integer):
        name = "int64"
    data = np.ascontiguousarray(array, dtype=DTYPES[name]).tobytes()
    return EncodedArray(dtype=name, shape=list(array.shape), data=base64.b64encode(data).decode("ascii"))


def _data_bytes(encoded: EncodedArray) -> int | None:
    """How many bytes the array's base64 stands for (None when its length cannot be base64's)."""
    data = encoded.data
    if len(data) % 4:
        return None
    return len(data) // 4 * 3 - (len(data[-2:]) - len(data[-2:].rstrip("=")))


def check_sizes(snapshot: Snapshot) -> None:
    """Every array's data fills its declared shape: checked on the document as it arrives, before a worker is
    started for it (the rest, against the spec, needs the run built: `restore`).

    Raises:
        SpecError: naming the first array that does not.
    """
    arrays: list[tuple[tuple[str | int, ...], EncodedArray]] = [
        *((("body", "world", k), a) for k, a in snapshot.world.items()),
        *((("body", "horde", k), a) for k, a in snapshot.horde.items() if isinstance(a, EncodedArray)),
        *((("body", "online", k), a) for k, a in (snapshot.online or {}).items()),
        *((("body", "stop_reference", i), a) for i, a in enumerate(snapshot.stop_reference or [])),
    ]
    for loc, encoded in arrays:
        size, needed = _data_bytes(encoded), math.prod(encoded.shape) * np.dtype(DTYPES[encoded.dtype]).itemsize
        if size is None:
            raise SpecError.at(loc, "data is not valid base64 (its length is not a multiple of 4)")
        if size != needed:
            raise SpecError.at(loc, f"{size} bytes do not fill shape {encoded.shape} of {encoded.dtype}")


def decode(encoded: EncodedArray, loc: tuple[str | int, ...]) -> np.ndarray:
    """The array back, writable.

    Raises:
        SpecError: bad base64, or data that does not fill the shape.
    """
    try:
        raw = base64.b64decode(encoded.data, validate=True)
    except (binascii.Error, ValueError):
        raise SpecError.at(loc, "data is not valid base64") from None
    dtype = np.dtype(DTYPES[encoded.dtype])
    count = math.prod(encoded.shape)
    if len(raw) != count * dtype.itemsize:
        raise SpecError.at(loc, f"{len(raw)} bytes do not fill shape {encoded.shape} of {encoded.dtype}")
    array = np.frombuffer(raw, dtype=dtype).reshape(encoded.shape)
    return (array != 0) if encoded.dtype == "bool" else array.astype(dtype.newbyteorder("="), copy=True)


def _leaves(value: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """(dotted path, leaf) of a structure of named tuples and tuples whose leaves are arrays or numbers."""
    if isinstance(value, tuple):
        keys = value._fields if hasattr(value, "_fields") else [str(i) for i in range(len(value))]
        for key, item in zip(keys, value, strict=True):
            yield from _leaves(item, f"{prefix}.{key}" if prefix else key)
    else:
        yield prefix, value


def _rebuild(template: Any, leaves: dict[str, Any], prefix: str = "") -> Any:
    """The structure of `template` with its leaves taken from `leaves` by path."""
    if isinstance(template, tuple):
        keys = template._fields if hasattr(template, "_fields") else [str(i) for i in range(len(template))]
        items = [
            _rebuild(item, leaves, f"{prefix}.{key}" if prefix else key)
            for key, item in zip(keys, template, strict=True)
        ]
        return type(template)(*items) if hasattr(template, "_fields") else tuple(items)
    return leaves[prefix]


def _encode_tree(tree: Any) -> dict[str, Any]:
    return {path: encode(leaf) if isinstance(leaf, np.ndarray) else float(leaf) for path, leaf in _leaves(tree)}


def _decode_tree(template: Any, encoded: dict[str, Any], where: str) -> Any:
    """Decode every leaf of `template` from `encoded`, checking names, dtypes and shapes.

    Raises:
        SpecError: a missing, unexpected or misshapen entry.
    """
    expected = dict(_leaves(template))
    unexpected = sorted(set(encoded) - set(expected))
    if unexpected:
        raise SpecError.at(("body", where, unexpected[0]), "not part of this spec's state")
    leaves: dict[str, Any] = {}
    for path, leaf in expected.items():
        if path not in encoded:
            raise SpecError.at(("body", where, path), "missing")
        value = encoded[path]
        if isinstance(leaf, np.ndarray):
            if not isinstance(value, EncodedArray):
                raise SpecError.at(("body", where, path), "expected an array")
            array = decode(value, ("body", where, path))
            if array.shape != leaf.shape or array.dtype != leaf.dtype:  # float32 where the spec's dtype says
                raise SpecError.at(
                    ("body", where, path),
                    f"has shape {list(array.shape)} of {value.dtype}, "
                    f"the spec needs {list(leaf.shape)} of {leaf.dtype}",
                )
            leaves[path] = array
        else:
            if isinstance(value, EncodedArray):
                raise SpecError.at(("body", where, path), "expected a number")
            leaves[path] = float(value)
    return _rebuild(template, leaves)


# ----------------------------------------------------------------------------------------------
# Capture and restore


@dataclass(frozen=True)
class Frozen:
    """A run's state at one step, held by reference: cheap to take in the learner thread, encoded later.

    The Horde's and the world's states are immutable snapshots (the fast engine hands out copies, the
    numpy engine's pure functions return new arrays), so holding them costs no copy here.
    """

    spec: RunSpec
    status: RunStatus
    hz: float | None
    episode: int
    total_steps: int
    episode_return: float
    last_return: float
    rng: Mapping[str, Any]
    world: Any
    horde: Any
    stop_reference: list[np.ndarray] | None
    online: AdaptiveState | None = None


def freeze(
    sim: Source,
    spec: RunSpec,
    status: RunStatus,
    hz: float | None,
    stop_reference: list[np.ndarray] | None,
) -> Frozen:
    """The state `capture` encodes, taken without encoding it (call it from the thread that owns `sim`)."""
    rng = sim.rng.bit_generator.state
    if rng.get("bit_generator") != "PCG64":
        raise ValueError(f"snapshots support PCG64 generators only, not {rng.get('bit_generator')}")
    return Frozen(
        spec=spec,
        status=status,
        hz=hz,
        episode=sim.episode,
        total_steps=sim.total_steps,
        episode_return=sim.episode_return,
        last_return=sim.last_return,
        rng=rng,
        world=sim.world_state,
        horde=sim.horde_state,
        stop_reference=stop_reference,
        online=sim.learner_state() if sim.horde.keeps_learner_state else None,
    )


def encode_frozen(frozen: Frozen) -> Snapshot:
    """The snapshot document of frozen state (any thread)."""
    rng = frozen.rng
    return Snapshot(
        spec=frozen.spec,
        status=frozen.status,
        hz=frozen.hz,
        episode=frozen.episode,
        total_steps=frozen.total_steps,
        episode_return=frozen.episode_return,
        last_return=frozen.last_return,
        rng=RngState(
            state=str(rng["state"]["state"]),
            inc=str(rng["state"]["inc"]),
            has_uint32=int(rng["has_uint32"]),
            uinteger=int(rng["uinteger"]),
        ),
        world=_encode_tree(frozen.world),
        horde=_encode_tree(frozen.horde),
        stop_reference=[encode(a) for a in frozen.stop_reference] if frozen.stop_reference is not None else None,
        online={name: encode(a) for name, a in zip(AdaptiveState._fields, frozen.online, strict=True)}
        if frozen.online is not None
        else None,
    )


def capture(
    sim: Source,
    spec: RunSpec,
    status: RunStatus,
    hz: float | None,
    stop_reference: list[np.ndarray] | None,
) -> Snapshot:
    """Everything needed to resume `sim` exactly (call it from the thread that owns `sim`)."""
    return encode_frozen(freeze(sim, spec, status, hz, stop_reference))


def restore(snapshot: Snapshot) -> Restored:
    """Rebuild the simulation of a snapshot, every array checked before it reaches the engine (snapshot_checks).

    Raises:
        SpecError: the arrays do not fit the snapshot's spec, hold numbers out of range, or put the agent outside
            the world.
    """
    spec = snapshot.spec
    sim = new_simulation(spec)
    world_state = _decode_tree(sim.world_state, snapshot.world, "world")
    check_world(sim, world_state)
    horde_state = decode_horde(sim.horde, sim.horde_state, snapshot.horde)
    learner_state = None
    if snapshot.online is not None:
        learner_state = _decode_tree(sim.learner_state(), snapshot.online, "online")
        check_interleaved(horde_state, zip(AdaptiveState._fields, learner_state, strict=True), "online")
    reference = None
    if snapshot.stop_reference is not None:
        template = sim.thetas()
        reference = list(
            _decode_tree(tuple(template), {str(i): a for i, a in enumerate(snapshot.stop_reference)}, "stop_reference")
        )
        check_interleaved(horde_state, ((str(i), a) for i, a in enumerate(reference)), "stop_reference")
    sim.world_state = world_state
    sim.horde_state = horde_state
    if learner_state is not None:
        sim.load_learner_state(learner_state)
    sim.rng.bit_generator.state = {
        "bit_generator": "PCG64",
        "state": {"state": int(snapshot.rng.state), "inc": int(snapshot.rng.inc)},
        "has_uint32": snapshot.rng.has_uint32,
        "uinteger": snapshot.rng.uinteger,
    }
    sim.episode = snapshot.episode
    sim.total_steps = snapshot.total_steps
    sim.set_returns(snapshot.episode_return, snapshot.last_return)
    return Restored(sim, snapshot.status, snapshot.hz, reference)


def decode_horde(horde: Horde, template: HordeState, encoded: dict[str, Any]) -> HordeState:
    """A snapshot's Horde state, checked against the compiled spec (`check_horde`) before it reaches the engine.

    Raises:
        SpecError: naming the entry.
    """
    state: HordeState = _decode_tree(template, encoded, "horde")
    check_horde(horde, state)
    return state


def to_bytes(snapshot: Snapshot) -> bytes:
    """The compressed form kept in the store."""
    return zlib.compress(snapshot.model_dump_json(by_alias=True).encode(), level=1)


def from_bytes(data: bytes) -> Snapshot:
    return Snapshot.model_validate_json(zlib.decompress(data))
