"""What a snapshot's decoded arrays must hold before they reach the engine: every import is untrusted input.

`snapshot._decode_tree` checks each array's name, dtype and shape against a fresh simulation of the
snapshot's spec. The compiled engine takes the rest on trust, so these check it:

- active-feature indices within their group's table, and indicator colours within their indicator's
  (both index arrays inside the compiled loop: out of range they read and write outside them);
- step counters not negative, generator words within 32 bits;
- every float finite, except where the engine itself leaves non-finite numbers: a state-value demon's
  action values (NaN by definition), and what belongs to a demon marked diverged (frozen and reported
  null, so its numbers are never read): its weights, error measures and readouts, the traces and policy
  of a class whose demons all diverged, and the adaptive learners' arrays (whose layout interleaves the
  demons) and the stopping rule's reference weights where any demon did.

Each check raises `SpecError` naming the entry as `body.<part>.<path>` (`body.horde.features.0`).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from horde.core.horde import Horde, HordeState
from horde.core.simulation import Simulation
from horde.core.source import Source
from horde.core.world import WorldState
from horde.runs.errors import SpecError
from horde.worlds.gym_simulation import GymWorldState

WORD = 2**32  # a generator word is 32 bits
MAX_COUNT = 2**63 - 1  # the largest count SQLite's INTEGER (signed 64-bit) holds

Loc = tuple[str | int, ...]


def _first(bad: np.ndarray) -> tuple[int, ...]:
    return tuple(int(i) for i in np.argwhere(bad)[0])


def check_finite(array: np.ndarray, loc: Loc, may_be_nonfinite: np.ndarray | bool = False) -> None:
    """Refuse a NaN or an infinity in a float array, except where `may_be_nonfinite` (broadcast to it) holds."""
    if array.dtype.kind != "f":
        return
    bad = ~np.isfinite(array) & ~np.asarray(may_be_nonfinite)
    if bad.any():
        at = _first(bad)
        raise SpecError.at(loc, f"holds {array[at]} at {list(at)}: every number must be finite")


def check_range(array: np.ndarray, loc: Loc, low: int, high: int, what: str) -> None:
    """Refuse an integer outside [low, high)."""
    bad = (array < low) | (array >= high)
    if bad.any():
        at = _first(bad)
        raise SpecError.at(loc, f"holds {int(array[at])} at {list(at)}: {what} must lie in [{low}, {high})")


def _per_row(mask: np.ndarray, array: np.ndarray) -> np.ndarray:
    """A [N] mask shaped to broadcast over an array of N rows."""
    return mask.reshape(-1, *[1] * (array.ndim - 1))


def check_horde(horde: Horde, state: HordeState) -> None:
    """The Horde's state of a snapshot (names, dtypes and shapes already match `horde`'s).

    Raises:
        SpecError: an active-feature index outside its table, or a non-finite number where the engine
            leaves none.
    """
    for g, (group, active) in enumerate(zip(horde.groups, state.features, strict=True)):
        check_range(active, ("body", "horde", f"features.{g}"), 0, group.coder.n, "active-feature indices")
    diverged = state.diverged  # [D] demon order
    slot_diverged = diverged[horde.slot_demon]  # [D] slot order
    class_dead = np.ones(horde.num_classes, dtype=bool)  # [C] every demon of the class diverged
    np.logical_and.at(class_dead, horde.slot_class, slot_diverged)
    for b, block in enumerate(horde.blocks):
        lo = int(horde.block_lo[b])
        columns = slot_diverged[lo : lo + block.size]  # [Db]
        for name in ("theta", "w", "h", "delta_e"):
            check_finite(getattr(state, name)[b], ("body", "horde", f"{name}.{b}"), columns[None, :])
        first_class = int(horde.slot_class[lo])
        classes = class_dead[first_class : first_class + state.e[b].shape[1]]  # [C_b]
        check_finite(state.e[b], ("body", "horde", f"e.{b}"), classes[None, :])
    for name in ("class_gamma", "class_pi"):
        array = getattr(state, name)
        check_finite(array, ("body", "horde", name), _per_row(class_dead, array))
    for name in ("delta_e_scale", "tau"):
        check_finite(getattr(state, name), ("body", "horde", name))
    for name in ("rupee_dot", "delta_stats", "pi", "prediction", "gamma", "delta", "cumulant"):
        array = getattr(state, name)
        check_finite(array, ("body", "horde", name), _per_row(diverged, array))
    state_values = ~horde.is_action_value  # [D] their action values are NaN
    check_finite(state.q, ("body", "horde", "q"), (diverged | state_values)[:, None])


def check_interleaved(state: HordeState, arrays: Iterable[tuple[str, np.ndarray]], where: str) -> None:
    """Arrays whose entries interleave the demons (the adaptive learners' state, the stopping rule's reference
    weights): finite, unless some demon diverged."""
    any_diverged = bool(state.diverged.any())
    for path, array in arrays:
        check_finite(array, ("body", where, path), any_diverged)


def check_world(sim: Source, state: WorldState | GymWorldState) -> None:
    """A world's state: the agent inside the world, counters not negative, colours and generator words within
    range, numbers finite.

    Raises:
        SpecError: naming the entry.
    """
    check_range(state.steps, ("body", "world", "steps"), 0, MAX_COUNT, "step counts")
    if isinstance(state, GymWorldState):
        check_finite(state.env_state, ("body", "world", "env_state"))
        check_finite(state.sensors, ("body", "world", "sensors"))
        check_range(state.env_rng, ("body", "world", "env_rng"), 0, WORD, "generator words")
        return
    assert isinstance(sim, Simulation)
    x, y = float(state.x[0]), float(state.y[0])
    if not sim.spec.grid.contains(x, y):  # NaN is never inside
        raise SpecError.at(("body", "world", "x"), f"the agent at ({x}, {y}) stands outside the world")
    for i, values in enumerate(sim.world.color_values):
        check_range(state.colors[:, i], ("body", "world", "colors"), 0, max(len(values), 1), f"indicator {i}'s colours")
