"""Stored worlds: GET|POST /api/worlds, GET|PUT|DELETE /api/worlds/{name}.

Runs copy their world when they are created (POST /api/runs {"world": "name", ...}), so changing or
deleting a stored world never changes a run. A world belongs to whoever stored it first: a student replaces
or deletes only their own (403 naming the owner otherwise).
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path, Response, status

from horde.runs.access import Access
from horde.runs.errors import ConflictError, NotFoundError, SpecError
from horde.runs.store import WorldRecord
from horde.server.convert import timestamp
from horde.server.deps import AccessDep, SettingsDep, StoreDep, WriterDep, write_router
from horde.server.responses import BAD_BODY, CONFLICT, NOT_FOUND, NOT_SAVED
from horde.server.schemas import WorldCreate, WorldOut
from horde.server.spec_builder import stored_world, world_of
from horde.spec import WorldSpec

router = APIRouter(prefix="/worlds", tags=["worlds"])
writes = write_router(router)

WorldName = Annotated[
    str,
    Path(min_length=1, max_length=64, pattern=r"^[A-Za-z_][A-Za-z0-9_.-]*$", description="the world's name"),
]


def _out(record: WorldRecord, world: WorldSpec, access: Access) -> WorldOut:
    return WorldOut(
        name=record.name,
        owner=access.owner_name("world", record.name),
        world=world,
        created_at=timestamp(record.created_at),
        updated_at=timestamp(record.updated_at),
    )


def _get(store: StoreDep, access: Access, name: str) -> WorldOut:
    return _out(*stored_world(store, name), access)


@router.get("", summary="List the stored worlds")
def list_worlds(store: StoreDep, access: AccessDep) -> list[WorldOut]:
    return [_out(r, world, access) for r in store.list_worlds() if (world := world_of(r)) is not None]


@writes.post(
    "",
    summary="Store a new world",
    status_code=status.HTTP_201_CREATED,
    responses={**BAD_BODY, **CONFLICT, **NOT_SAVED},
)
def create_world(
    world: WorldCreate, store: StoreDep, settings: SettingsDep, me: WriterDep, access: AccessDep
) -> WorldOut:
    """409 when a world of that name exists already, or the store holds as many worlds as allowed."""
    if store.get_world(world.name) is not None:
        raise ConflictError(f"a world named {world.name!r} exists already; PUT /api/worlds/{world.name} replaces it")
    if store.count_worlds() >= settings.max_worlds:
        raise ConflictError(f"the store holds at most {settings.max_worlds} worlds; delete one first")
    store.put_world(world.name, world.model_dump_json(by_alias=True))
    access.claim(me, "world", world.name)
    return _get(store, access, world.name)


@router.get("/{name}", summary="A stored world", responses={**NOT_FOUND})
def get_world(name: WorldName, store: StoreDep, access: AccessDep) -> WorldOut:
    return _get(store, access, name)


@writes.put(
    "/{name}",
    summary="Create or replace a stored world",
    responses={**BAD_BODY, **CONFLICT, **NOT_SAVED, 201: {"model": WorldOut, "description": "Created"}},
)
def put_world(
    name: WorldName,
    world: WorldSpec,
    store: StoreDep,
    settings: SettingsDep,
    response: Response,
    me: WriterDep,
    access: AccessDep,
) -> WorldOut:
    """200 when it replaced a world, 201 when it created one. The body's name, if given, must match."""
    if world.name is not None and world.name != name:
        raise SpecError.at(("body", "name"), f"the body names {world.name!r} but the path names {name!r}")
    exists = store.get_world(name) is not None
    if exists:
        access.check(me, "world", name)
    if not exists and store.count_worlds() >= settings.max_worlds:
        raise ConflictError(f"the store holds at most {settings.max_worlds} worlds; delete one first")
    created = store.put_world(name, world.model_copy(update={"name": name}).model_dump_json(by_alias=True))
    if created:
        access.claim(me, "world", name)
        response.status_code = status.HTTP_201_CREATED
    return _get(store, access, name)


@writes.delete(
    "/{name}",
    summary="Delete a stored world",
    status_code=status.HTTP_204_NO_CONTENT,
    responses={**NOT_FOUND, **NOT_SAVED},
)
def delete_world(name: WorldName, store: StoreDep, me: WriterDep, access: AccessDep) -> None:
    # A stored world that no longer reads can still be deleted (by its owner or the teacher).
    if store.get_world(name) is None:
        raise NotFoundError(f"no world {name!r}")
    access.check(me, "world", name)
    if not store.delete_world(name):
        raise NotFoundError(f"no world {name!r}")
    access.release("world", name)
