"""Study TOML files (studies/*.toml) -> StudySpec and base RunSpec, with errors naming file and line."""

from __future__ import annotations

import re
from pathlib import Path

from pydantic import ValidationError

from horde.runs.errors import SpecError
from horde.scenarios import ScenarioError, file_dir, find_scenario, line_of, load_toml
from horde.spec import RunSpec
from horde.studies.spec import Configuration, StudySpec, expand


def study_dir() -> Path:
    """`HORDE_STUDIES`, else the repository's studies/ folder, else ./studies."""
    return file_dir("HORDE_STUDIES", "studies")


def _axis_line(text: str, loc: tuple[str | int, ...], study: StudySpec | None) -> int | None:
    """The line of the axis (or its value) that a problem's location names."""
    if study is not None and len(loc) >= 2 and loc[0] == "axes" and isinstance(loc[1], int):
        path = study.axes[loc[1]].path
        lines = text.splitlines()
        for number, line in enumerate(lines, start=1):
            if re.search(rf"path\s*=\s*[\"']{re.escape(path)}[\"']", line):
                if "values" in loc:  # the axis' values: the next `values =` from its path on
                    found = next((n for n in range(number, len(lines) + 1) if "values" in lines[n - 1]), None)
                    return found or number
                return number
    return line_of(text, loc)


def parse_study(text: str, source: str = "<study>") -> tuple[StudySpec, RunSpec, list[Configuration]]:
    """Validate a study's TOML text, load its base scenario and expand it (before any task starts).

    Raises:
        ScenarioError: "source:line: field: message" for every problem (an axis' problems name its path).
    """
    data = load_toml(text, source)
    try:
        study = StudySpec.model_validate(data)
    except ValidationError as exc:
        messages = []
        for error in exc.errors():
            field = ".".join(str(p) for p in error["loc"]) or "(top level)"
            line = _axis_line(text, tuple(error["loc"]), None)
            messages.append(f"{source}:{line or 1}: {field}: {error['msg']}")
        raise ScenarioError("\n".join(messages)) from None
    if study.base is not None:
        base = study.base
    else:
        assert study.scenario is not None
        try:
            base = find_scenario(study.scenario)
        except KeyError:
            line = line_of(text, ("scenario",)) or 1
            raise ScenarioError(f"{source}:{line}: scenario: no scenario named {study.scenario!r}") from None
    try:
        configurations = expand(study, base)
    except SpecError as exc:
        messages = []
        for problem in exc.problems:
            line = _axis_line(text, problem.loc, study) or 1
            messages.append(f"{source}:{line}: {'.'.join(map(str, problem.loc))}: {problem.msg}")
        raise ScenarioError("\n".join(messages)) from None
    if study.name is None:
        study = study.model_copy(update={"name": Path(source).stem if source != "<study>" else base.name})
    return study, base, configurations


def load_study_file(path: str | Path) -> tuple[StudySpec, RunSpec, list[Configuration]]:
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read: {exc.strerror}") from None
    return parse_study(text, str(path))
