"""Demon families: one entry that expands into the product of its lists (Horde scale that a user can write)."""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Iterator
from functools import partial
from typing import Annotated, Any

from pydantic import Field, PrivateAttr, ValidationError, ValidationInfo, field_validator, model_validator

from horde.spec.base import MAX_DEMONS, NAME, NAME_MAX, NAME_RULE, Finite, Model, Name
from horde.spec.demons import DemonSpec

MAX_FAMILIES = 64
_PLACEHOLDER = re.compile(r"\{([A-Za-z_][A-Za-z0-9_]*)\}")


def _fill(template: Any, env: dict[str, str | float]) -> Any:
    """The template with every "{var}" replaced: a string that is only "{var}" becomes the value itself."""
    if isinstance(template, str):
        whole = _PLACEHOLDER.fullmatch(template)
        if whole and whole.group(1) in env:
            return env[whole.group(1)]
        return _PLACEHOLDER.sub(lambda m: str(env[m.group(1)]) if m.group(1) in env else m.group(0), template)
    if isinstance(template, dict):
        return {key: _fill(value, env) for key, value in template.items()}
    if isinstance(template, list):
        return [_fill(value, env) for value in template]
    return template


def _part(parts: dict[str, str], match: re.Match[str]) -> str:
    return parts[match.group(1)]


class DemonFamily(Model):
    """One entry that expands into a demon for every combination of its lists (their product).

    `demon` is a demon written as usual, in which any "{var}" stands for the values of the list `var`
    of `over`; `name` is the pattern of the demons' names, such as "{sensor}_g{gamma}" (characters a
    name cannot hold, such as the colon of "in:zone1", become "_"). A 422 about a family names the field
    and the rule, never the pattern or a demon name made of it (they are input).
    """

    over: dict[Name, Annotated[list[Annotated[str, Field(max_length=80)] | Finite], Field(min_length=1)]] = Field(
        min_length=1, max_length=8, description="the lists whose product the family expands into"
    )
    name: str = Field(min_length=1, max_length=64, description='the name pattern, e.g. "{sensor}_g{gamma}"')
    demon: dict[str, Any] = Field(description='a demon without its name; "{var}" in any string takes the values')
    _demons: list[DemonSpec] = PrivateAttr(default_factory=list)

    @field_validator("over")
    @classmethod
    def _bounded(cls, over: dict[str, list[str | float]]) -> dict[str, list[str | float]]:
        count = math.prod(len(values) for values in over.values())
        if count > MAX_DEMONS:
            raise ValueError(f"the lists expand into {count} demons, more than {MAX_DEMONS}")
        return over

    @field_validator("name")
    @classmethod
    def _pattern_fits_over(cls, name: str, info: ValidationInfo) -> str:
        over = info.data.get("over")
        if over is None:  # over is invalid itself, and its own error says so
            return name
        used = set(_PLACEHOLDER.findall(name))
        unknown = sorted(used - set(over))
        if unknown:  # placeholders are identifiers ([A-Za-z_][A-Za-z0-9_]*): naming them echoes no markup
            raise ValueError(f"every {{placeholder}} must be a list of over ({', '.join(unknown)} is not)")
        missing = sorted(set(over) - used)
        if missing:
            raise ValueError(f"must use every list of over as a {{placeholder}} (missing: {', '.join(missing)})")
        for i, (_, demon_name) in enumerate(_combinations(name, over)):
            if not (len(demon_name) <= NAME_MAX and NAME.fullmatch(demon_name)):
                raise ValueError(f"must make demon names of {NAME_RULE}; combination {i + 1} of over does not")
        return name

    @model_validator(mode="after")
    def _names(self) -> DemonFamily:
        if "name" in self.demon:
            raise ValueError("the demon template takes its name from the family's name pattern")
        self._demons = self._expand()
        return self

    def size(self) -> int:
        return math.prod(len(values) for values in self.over.values())

    def expand(self) -> list[DemonSpec]:
        """The family's demons, in the order of the product of its lists (the last list varies fastest)."""
        return list(self._demons)

    def _expand(self) -> list[DemonSpec]:
        """The demons of `expand`, validated.

        Raises:
            ValueError: naming the first combination whose filled-in template is not a valid demon, and the field.
        """
        demons = []
        for i, (env, name) in enumerate(_combinations(self.name, self.over)):
            try:
                demons.append(DemonSpec.model_validate({**_fill(self.demon, env), "name": name}))
            except ValidationError as exc:
                error = exc.errors()[0]
                where = ".".join(str(part) for part in error["loc"])
                raise ValueError(f"demon: combination {i + 1} of over: {where}: {error['msg']}") from None
        return demons


def _combinations(pattern: str, over: dict[str, list[str | float]]) -> Iterator[tuple[dict[str, str | float], str]]:
    """(values, demon name) of every combination of `over`'s lists, the last list varying fastest."""
    keys = list(over)
    for values in itertools.product(*(over[key] for key in keys)):
        env = dict(zip(keys, values, strict=True))
        parts = {key: re.sub(r"[^A-Za-z0-9_.-]", "_", str(value)) for key, value in env.items()}
        yield env, _PLACEHOLDER.sub(partial(_part, parts), pattern)
