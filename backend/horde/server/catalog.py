"""The scenarios the server offers, read-only from the scenario folder."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from horde.runs.errors import ConflictError, NotFoundError
from horde.scenarios import ScenarioError, Watch, find_scenario, load_watched, scenario_dir
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

    def entries(self) -> list[ScenarioEntry]:
        """Every *.toml file, by name; a file that does not load is listed with its error."""
        found = []
        for path in sorted(self.directory.glob("*.toml")):
            try:
                spec, watch = load_watched(path)
            except ScenarioError as exc:
                found.append(ScenarioEntry(path.stem, "", str(exc), Watch()))
            else:
                found.append(ScenarioEntry(path.stem, spec.description, None, watch))
        return found

    def get(self, name: str) -> RunSpec:
        """The spec of scenario `name`.

        Raises:
            NotFoundError: no such scenario.
            ConflictError: the file exists but does not load (the message says where and why).
        """
        try:
            return find_scenario(name, self.directory)
        except KeyError:
            raise NotFoundError(f"no scenario {name!r}") from None
        except ScenarioError as exc:
            raise ConflictError(f"scenario {name!r} does not load: {exc}") from None
