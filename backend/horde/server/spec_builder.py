"""A RunSpec from POST /api/runs's template form: a scenario and/or a stored world, plus overrides."""

from __future__ import annotations

import logging
from typing import Any

from pydantic import ValidationError

from horde.runs.errors import NotFoundError, SpecError
from horde.runs.store import Store, WorldRecord
from horde.server.catalog import ScenarioCatalog
from horde.server.schemas import RunTemplateIn
from horde.spec import RunSpec, WorldSpec

log = logging.getLogger(__name__)


def world_of(record: WorldRecord) -> WorldSpec | None:
    """A stored world's spec, or None (logged) when it no longer reads: written by an older version, or by hand."""
    try:
        return WorldSpec.model_validate_json(record.spec)
    except ValidationError as exc:
        log.error("world %r left out: its stored spec cannot be read: %s", record.name, exc)
        return None


def stored_world(store: Store, name: str) -> tuple[WorldRecord, WorldSpec]:
    """The stored world `name` and its spec.

    Raises:
        NotFoundError: no such world, or one whose stored spec no longer reads (PUT replaces it).
    """
    record = store.get_world(name)
    if record is None:
        raise NotFoundError(f"no world {name!r}")
    world = world_of(record)
    if world is None:
        raise NotFoundError(f"world {name!r} is stored but no longer reads as a world; PUT /api/worlds/{name} mends it")
    return record, world


def merge(base: Any, override: Any) -> Any:
    """`override` merged into `base`: objects key by key (recursively), anything else replaced."""
    if isinstance(base, dict) and isinstance(override, dict):
        merged = dict(base)
        for key, value in override.items():
            merged[key] = merge(base.get(key), value)
        return merged
    return override


def template_data(template: RunTemplateIn, catalog: ScenarioCatalog, store: Store) -> dict[str, Any]:
    """Resolve the scenario and the world and merge the overrides into them: the RunSpec's data, not validated.

    Raises:
        NotFoundError: an unknown scenario or stored world.
    """
    base: dict[str, Any] = dict(catalog.data(template.scenario)) if template.scenario else {}
    overrides = template.model_dump(exclude_unset=True, exclude={"scenario", "world"})
    if isinstance(template.world, str):
        base["world"] = stored_world(store, template.world)[1].model_dump(by_alias=True)
    elif template.world is not None:
        overrides["world"] = template.world
    merged: dict[str, Any] = merge(base, overrides)
    return merged


def build_spec(template: RunTemplateIn, catalog: ScenarioCatalog, store: Store) -> RunSpec:
    """Resolve the scenario and the world, merge the overrides, and validate the result.

    Raises:
        NotFoundError: an unknown scenario or stored world.
        SpecError: the merged spec is invalid (locations are the RunSpec's fields, under "body").
    """
    data = template_data(template, catalog, store)
    try:
        return RunSpec.model_validate(data)
    except ValidationError as exc:
        raise SpecError.from_validation(exc, ("body",)) from None
