"""TOML scenario files -> RunSpec, with errors that name the file and the line.

A scenario is a RunSpec written in TOML (see scenarios/*.toml), plus an optional `[watch]` table that is no
part of the run: the speed it is best watched at live (`hz`, steps per second; absent: full speed) and a `note`
saying why and what to watch for. Its name is the file's stem.
"""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from horde.spec import Hz, RunSpec
from horde.worlds.gym_spaces import resolve_world


class ScenarioError(ValueError):
    """A scenario file that cannot be read or does not validate; the message names file and line."""


class Watch(BaseModel):
    """A scenario's `[watch]` table: how to watch it live (the dashboard launches it at this speed)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    hz: Hz | None = Field(default=None, description="steps per second to watch at; absent: full speed")
    note: str = Field(default="", max_length=500, description="why this speed, what to watch for")


def file_dir(variable: str, folder: str) -> Path:
    """The environment variable `variable`, else the repository's `folder`/ (beside backend/), else ./`folder`."""
    env = os.environ.get(variable)
    if env:
        return Path(env)
    repo = Path(__file__).resolve().parents[2] / folder
    return repo if repo.is_dir() else Path.cwd() / folder


def scenario_dir() -> Path:
    """`HORDE_SCENARIOS`, else the repository's scenarios/ folder, else ./scenarios."""
    return file_dir("HORDE_SCENARIOS", "scenarios")


def _line_of(text: str, loc: tuple[int | str, ...]) -> int | None:
    """Best guess of the line that holds the last named key of a validation error's location."""
    keys = [str(part) for part in loc if isinstance(part, str) and not part.startswith(("function-", "is-"))]
    lines = text.splitlines()
    for key in reversed(keys):
        pattern = re.compile(rf"(^|[\s{{,.\[])\"?{re.escape(key)}\"?\s*=|^\s*\[\[?{re.escape(key)}\]\]?")
        for number, line in enumerate(lines, start=1):
            if pattern.search(line.split("#", 1)[0]):
                return number
    return None


line_of = _line_of  # public: study files (horde.studies.files) locate their problems the same way


MAX_TOML_DEPTH = 100  # arrays and tables inside each other: where a deep document is said to go too deep


def _too_deep_line(text: str) -> int:
    """The line where brackets and braces first nest MAX_TOML_DEPTH deep (counted plainly, strings and all)."""
    depth = 0
    for number, line in enumerate(text.splitlines(), start=1):
        for char in line:
            depth += 1 if char in "[{" else -1 if char in "]}" else 0
            if depth >= MAX_TOML_DEPTH:
                return number
    return 1


def load_toml(text: str, source: str) -> dict[str, Any]:
    """Parse TOML text (a scenario or a study file).

    Raises:
        ScenarioError: "source:line: invalid TOML: ..." for malformed text, or for arrays nested so deep that the
            parser (recursive) cannot read them.
    """
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        message = str(exc)
        found = re.search(r"\(at line (\d+), column \d+\)", message)
        number = int(found.group(1)) if found else max(len(text.splitlines()), 1)
        raise ScenarioError(f"{source}:{number}: invalid TOML: {message}") from None
    except RecursionError:
        line = _too_deep_line(text)
        raise ScenarioError(f"{source}:{line}: invalid TOML: arrays or tables nested too deep to read") from None


def parse_scenario(text: str, source: str = "<scenario>") -> RunSpec:
    """Validate TOML text as a RunSpec (a `[watch]` table is checked and left out: see `parse_watched`).

    Raises:
        ScenarioError: "source:line: field: message" for every problem found.
    """
    return parse_watched(text, source)[0]


def parse_watched(text: str, source: str = "<scenario>") -> tuple[RunSpec, Watch]:
    """Validate TOML text as a RunSpec and its `[watch]` table.

    Raises:
        ScenarioError: "source:line: field: message" for every problem found.
    """
    data = load_toml(text, source)
    watch_table = data.pop("watch", {})
    messages = []
    try:
        watch = Watch.model_validate(watch_table)
    except ValidationError as exc:
        messages += _located(exc, text, source, ("watch",))
    try:
        spec = resolve_world(RunSpec.model_validate(data))  # a Gymnasium world: its sensors checked too
    except ValidationError as exc:
        messages += _located(exc, text, source, ())
    if messages:
        raise ScenarioError("\n".join(messages))
    return spec, watch


def _located(exc: ValidationError, text: str, source: str, prefix: tuple[str, ...]) -> list[str]:
    """ "source:line: field: message" for every problem of a validation error, its fields under `prefix`."""
    messages = []
    for error in exc.errors():
        loc = (*prefix, *error["loc"])
        field = ".".join(str(p) for p in loc) or "(top level)"
        line = _line_of(text, loc)
        where = f"{source}:{line}" if line else source
        messages.append(f"{where}: {field}: {error['msg']}")
    return messages


def load_scenario(path: str | Path) -> RunSpec:
    """Read and validate one scenario file; a missing `name` becomes the file's stem."""
    return load_watched(path)[0]


def load_watched(path: str | Path) -> tuple[RunSpec, Watch]:
    """Read and validate one scenario file and its `[watch]` table; a missing `name` becomes the file's stem."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read: {exc.strerror}") from None
    spec, watch = parse_watched(text, str(path))
    return (spec if spec.name else spec.model_copy(update={"name": path.stem})), watch


@dataclass(frozen=True)
class ScenarioInfo:
    name: str
    description: str
    path: Path
    watch: Watch


def list_scenarios(directory: Path | None = None) -> list[ScenarioInfo]:
    """Every valid scenario in the folder, by name (invalid files raise: scenarios ship tested)."""
    directory = directory or scenario_dir()
    found = []
    for path in sorted(directory.glob("*.toml")):
        spec, watch = load_watched(path)
        found.append(ScenarioInfo(path.stem, spec.description, path, watch))
    return found


def scenario_path(name: str, directory: Path | None = None) -> Path:
    """The file of scenario `name` (a file stem) in the folder.

    Raises:
        KeyError: no such scenario.
    """
    directory = directory or scenario_dir()
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name) or name.startswith("."):
        raise KeyError(name)
    path = directory / f"{name}.toml"
    if not path.is_file():
        raise KeyError(name)
    return path


def find_scenario(name: str, directory: Path | None = None) -> RunSpec:
    """Load scenario `name` (a file stem) from the folder.

    Raises:
        KeyError: no such scenario.
    """
    return load_scenario(scenario_path(name, directory))
