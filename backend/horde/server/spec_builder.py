"""A RunSpec from POST /api/runs's template form: a scenario and/or a stored world, plus overrides."""

from __future__ import annotations

from typing import Any

from pydantic import ValidationError

from horde.runs.errors import NotFoundError, SpecError
from horde.runs.store import Store
from horde.server.catalog import ScenarioCatalog
from horde.server.schemas import RunTemplateIn
from horde.spec import RunSpec, WorldSpec


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
        record = store.get_world(template.world)
        if record is None:
            raise NotFoundError(f"no world {template.world!r}")
        base["world"] = WorldSpec.model_validate_json(record.spec).model_dump(by_alias=True)
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
