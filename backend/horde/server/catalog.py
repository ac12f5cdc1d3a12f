"""The scenarios the server offers, read-only from the scenario folder.

Each file is read and validated once while it is unchanged (its modification time and size are the key): a
scenario of thousands of demons takes a second of validation, which a request should not pay each time.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from horde.runs.errors import ConflictError, NotFoundError
from horde.scenarios import ScenarioError, Watch, load_watched, scenario_dir, scenario_path
from horde.spec import RunSpec


@dataclass(frozen=True)
class ScenarioEntry:
    name: str
    description: str
    error: str | None  # why the file does not load, if it does not
    watch: Watch


class ScenarioCatalog:
    """Scenario files of one folder (default: `horde.scenarios.scenario_dir()`)."""

    def __init__(self, directory: Path | None = None) -> None:
        self.directory = directory or scenario_dir()
        self._loaded: dict[Path, tuple[tuple[float, int], tuple[RunSpec, Watch] | ScenarioError]] = {}
        self._dumps: dict[str, tuple[RunSpec, dict[str, Any]]] = {}
        self._lock = threading.Lock()

    def _load(self, path: Path) -> tuple[RunSpec, Watch]:
        """The file's spec and watch table, read again only when the file has changed.

        Raises:
            ScenarioError: the file does not load.
        """
        stat = path.stat()
        key = (stat.st_mtime, stat.st_size)
        with self._lock:
            cached = self._loaded.get(path)
        if cached is None or cached[0] != key:
            try:
                loaded: tuple[RunSpec, Watch] | ScenarioError = load_watched(path)
            except ScenarioError as exc:
                loaded = exc
            cached = (key, loaded)
            with self._lock:
                self._loaded[path] = cached
        if isinstance(cached[1], ScenarioError):
            raise cached[1]
        return cached[1]

    def entries(self) -> list[ScenarioEntry]:
        """Every *.toml file, by name; a file that does not load is listed with its error."""
        found = []
        for path in sorted(self.directory.glob("*.toml")):
            try:
                spec, watch = self._load(path)
            except ScenarioError as exc:
                found.append(ScenarioEntry(path.stem, "", str(exc), Watch()))
            else:
                found.append(ScenarioEntry(path.stem, spec.description, None, watch))
        return found

    def data(self, name: str) -> dict[str, Any]:
        """The spec of scenario `name` as plain data (the base a run template's overrides merge into); shared,
        never to be changed.

        Raises:
            NotFoundError, ConflictError: as `get`.
        """
        spec = self.get(name)
        with self._lock:
            cached = self._dumps.get(name)
        if cached is None or cached[0] is not spec:
            cached = (spec, spec.model_dump(by_alias=True))
            with self._lock:
                self._dumps[name] = cached
        return cached[1]

    def get(self, name: str) -> RunSpec:
        """The spec of scenario `name`.

        Raises:
            NotFoundError: no such scenario.
            ConflictError: the file exists but does not load (the message says where and why).
        """
        try:
            path = scenario_path(name, self.directory)
            spec, _ = self._load(path)
        except KeyError:
            raise NotFoundError(f"no scenario {name!r}") from None
        except ScenarioError as exc:
            raise ConflictError(f"scenario {name!r} does not load: {exc}") from None
        return spec
