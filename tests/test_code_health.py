"""Length bounds (issue 15, must-hold 2): no function longer than about 60 lines and no module of
backend/horde longer than about 400 lines without a reason in its docstring.

A reason is a sentence of the docstring that starts with "Why" and names the length ("Why one module of
about 850 lines: ...", "Why 70 lines: ..."). When it names a number of lines, the code may not have grown
past it by more than a quarter: a reason that has gone stale fails like a missing one. The compiled
kernels (functions decorated with numba's `njit`/`jit`) are exempt: numba compiles one function into one
kernel, and their length is REVIEW item 2's business (issue "One engine, at Horde scale").

Functions are checked in backend/horde and tests/; modules in backend/horde.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "backend" / "horde"
MAX_FUNCTION_LINES = 60
MAX_MODULE_LINES = 400
STALE = 1.25  # a reason's "about N lines" holds up to this many times N
WHY = re.compile(r"\bWhy\b[^.:]*")  # the reason's first clause: "Why one module of about 850 lines"
NAMES_LENGTH = re.compile(r"\d[\d,]* lines|\blong\b|\bone (?:module|function)\b", re.IGNORECASE)
LINES = re.compile(r"(\d[\d,]*) lines")


@dataclass(frozen=True)
class Place:
    key: str  # "path" for a module, "path::Qualified.name" for a function
    lines: int
    bound: int
    docstring: str | None

    def problem(self) -> str | None:
        """Why this place breaks its bound, or None when it keeps it."""
        if self.lines <= self.bound:
            return None
        reason = next((w for w in WHY.findall(self.docstring or "") if NAMES_LENGTH.search(w)), None)
        if reason is None:
            return f"{self.key}: {self.lines} lines (bound {self.bound}) and no 'Why ...' reason in its docstring"
        stated = LINES.search(reason)
        if stated and self.lines > STALE * int(stated.group(1).replace(",", "")):
            return f"{self.key}: {self.lines} lines, but its reason says about {stated.group(1)}: update the reason"
        return None


def _compiled(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    return any(re.search(r"\b(njit|jit)\b", ast.unparse(d)) for d in node.decorator_list)


def _functions(tree: ast.AST, prefix: str = "") -> list[tuple[str, ast.FunctionDef | ast.AsyncFunctionDef]]:
    found = []
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found.append((prefix + node.name, node))
            found += _functions(node, f"{prefix}{node.name}.")
        elif isinstance(node, ast.ClassDef):
            found += _functions(node, f"{prefix}{node.name}.")
    return found


def places(files: list[Path], modules: bool, root: Path = ROOT) -> list[Place]:
    """Every module (when `modules`) and every function of `files` that is not a compiled kernel, named from `root`."""
    found = []
    for path in files:
        source = path.read_text()
        tree = ast.parse(source)
        name = path.relative_to(root).as_posix()
        if modules:
            found.append(Place(name, len(source.splitlines()), MAX_MODULE_LINES, ast.get_docstring(tree)))
        for qualified, node in _functions(tree):
            if not _compiled(node):
                lines = node.end_lineno - node.lineno + 1  # type: ignore[operator]
                found.append(Place(f"{name}::{qualified}", lines, MAX_FUNCTION_LINES, ast.get_docstring(node)))
    return found


def all_places() -> list[Place]:
    return places(sorted(PACKAGE.rglob("*.py")), modules=True) + places(
        sorted((ROOT / "tests").rglob("*.py")), modules=False
    )


def test_no_function_or_module_is_too_long_without_a_reason() -> None:
    problems = [p for place in all_places() if (p := place.problem())]
    assert problems == [], "\n".join(problems)


@pytest.mark.parametrize(
    ("source", "problem"),
    [
        ("def f():\n" + "    x = 1\n" * 61, "no 'Why ...' reason"),
        ('def f():\n    """Why 62 lines: a table."""\n' + "    x = 1\n" * 60, None),
        ('def f():\n    """Why 40 lines: it was short once."""\n' + "    x = 1\n" * 61, "update the reason"),
        ("@njit(cache=True)\ndef f():\n" + "    x = 1\n" * 80, None),
        ("class A:\n    def f(self):\n" + "        x = 1\n" * 61, "::A.f: 62 lines"),
    ],
)
def test_the_check_reads_lengths_reasons_and_kernels(tmp_path: Path, source: str, problem: str | None) -> None:
    path = tmp_path / "probe.py"
    path.write_text(source)
    found = [p for place in places([path], modules=False, root=tmp_path) if (p := place.problem())]
    if problem is None:
        assert found == []
    else:
        assert len(found) == 1 and problem in found[0], found
