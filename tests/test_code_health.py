"""Length bounds (issue 15, must-hold 2): no function longer than about 60 lines and no module of
backend/horde longer than about 400 lines without a reason in its docstring.

A reason is a sentence of the docstring that starts with "Why" and names the length ("Why one module of
about 850 lines: ...", "Why 70 lines: ..."). When it names a number of lines, the code may not have grown
past it by more than a quarter: a reason that has gone stale fails like a missing one. The compiled
kernels (functions decorated with numba's `njit`/`jit`) are exempt: numba compiles one function into one
kernel, and their length is REVIEW item 2's business (issue "One engine, at Horde scale").

Functions are checked in backend/horde and tests/; modules in backend/horde.

The engine (issue 29): no module of backend/horde/core over 600 lines, no function there (compiled kernels
included) with more than 12 parameters: kernels take a few named tuples, not dozens of arrays.

No import circles (issue 29): the graph of which module of backend/horde imports which, imports inside
functions included, has no cycle (`import_cycles`), and the layers' arrows point one way (DESIGN section 1):
the spec imports nothing of the package above it, the core nothing but the spec.
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


CORE = PACKAGE / "core"
MAX_CORE_MODULE_LINES = 600
MAX_PARAMETERS = 12


def parameter_count(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """A function's parameters (self and cls left out; *args and **kwargs count one each)."""
    args = node.args
    names = [a.arg for a in (*args.posonlyargs, *args.args, *args.kwonlyargs)]
    return len([n for n in names if n not in ("self", "cls")]) + (args.vararg is not None) + (args.kwarg is not None)


def engine_problems(files: list[Path], root: Path = ROOT) -> list[str]:
    """Modules over MAX_CORE_MODULE_LINES and functions over MAX_PARAMETERS parameters among `files`."""
    problems = []
    for path in files:
        source = path.read_text()
        name = path.relative_to(root).as_posix()
        if len(source.splitlines()) > MAX_CORE_MODULE_LINES:
            problems.append(f"{name}: {len(source.splitlines())} lines (at most {MAX_CORE_MODULE_LINES})")
        for qualified, node in _functions(ast.parse(source)):
            if parameter_count(node) > MAX_PARAMETERS:
                problems.append(f"{name}::{qualified}: {parameter_count(node)} parameters (at most {MAX_PARAMETERS})")
    return problems


def test_the_engine_has_small_modules_and_short_parameter_lists() -> None:
    files = sorted(CORE.rglob("*.py"))
    assert len(files) > 20 and (CORE / "engine" / "step.py") in files  # the tree is read
    assert engine_problems(files) == []


def test_the_engine_check_counts_lines_and_parameters(tmp_path: Path) -> None:
    path = tmp_path / "probe.py"
    path.write_text("def f(self, a, b, c, d, e, f, g, h, i, j, k, l, *m):\n    pass\n" + "x = 1\n" * 600)
    found = engine_problems([path], root=tmp_path)
    assert found == ["probe.py: 602 lines (at most 600)", "probe.py::f: 13 parameters (at most 12)"], found


def import_graph(package: Path) -> dict[str, set[str]]:
    """Each module of `package` (dotted, from the package's parent) -> the package's modules it imports.

    Imports anywhere in the file count, inside functions too. `from pkg import sub` is an import of the
    submodule `sub` when there is one, else of `pkg`.
    """
    modules: dict[str, tuple[Path, bool]] = {}
    for path in package.rglob("*.py"):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        modules[".".join(parts[:-1] if is_package else parts)] = (path, is_package)
    graph: dict[str, set[str]] = {}
    for name, (path, is_package) in modules.items():
        here = name.split(".") if is_package else name.split(".")[:-1]
        imported: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                imported.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = ".".join([*here[: len(here) - node.level + 1], node.module or ""]) if node.level else node.module
                base = (base or "").strip(".")
                imported.update(f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names)
        graph[name] = {m for m in imported if m in modules and m != name}
    return graph


def import_cycles(graph: dict[str, set[str]]) -> list[tuple[str, ...]]:
    """The strongly connected components of more than one module (Tarjan's algorithm), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[tuple[str, ...]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = [stack.pop()]
            while component[-1] != v:
                component.append(stack.pop())
            if len(component) > 1:
                cycles.append(tuple(sorted(component)))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(cycles)


def test_the_package_has_no_import_cycles() -> None:
    graph = import_graph(PACKAGE)
    assert "horde.core.check" in graph and "horde.spec" in graph["horde.core.check"]  # the graph is read
    cycles = import_cycles(graph)
    assert cycles == [], "import cycles: " + "; ".join(" <-> ".join(c) for c in cycles)


def layer_breaches(graph: dict[str, set[str]], layer: str, allowed: tuple[str, ...]) -> list[str]:
    """Imports of modules of `layer` (dotted prefix) that reach outside it and `allowed` (dotted prefixes)."""
    inside = (layer, *allowed)
    return sorted(
        f"{module} imports {target}"
        for module, targets in graph.items()
        if module == layer or module.startswith(layer + ".")
        for target in targets
        if not any(target == p or target.startswith(p + ".") for p in inside)
    )


def test_the_spec_imports_nothing_above_it_and_the_core_nothing_but_the_spec() -> None:
    graph = import_graph(PACKAGE)
    assert layer_breaches(graph, "horde.spec", ()) == []
    assert layer_breaches(graph, "horde.core", ("horde.spec",)) == []
    # the check finds a breach where there is one
    assert layer_breaches({"horde.core.a": {"horde.worlds.b"}, "horde.worlds.b": set()}, "horde.core", ()) == [
        "horde.core.a imports horde.worlds.b"
    ]


@pytest.mark.parametrize(
    ("files", "cycles"),
    [
        (
            {"a.py": "from p import b", "b.py": "def f():\n    from p.c import g", "c.py": "from . import a"},
            [("p.a", "p.b", "p.c")],
        ),
        ({"a.py": "import p.b", "b.py": "from p import c", "c.py": "import os"}, []),
        ({"__init__.py": "from p.a import x", "a.py": "from p import b", "b.py": "x = 2"}, []),
        (
            {
                "__init__.py": "from p.a import x",
                "a.py": "x = 1",
                "q/__init__.py": "",
                "q/m.py": "from ..a import x\nfrom p.q import n",
                "q/n.py": "from p.q.m import y",
            },
            [("p.q.m", "p.q.n")],
        ),
    ],
)
def test_the_cycle_check_reads_every_import(
    tmp_path: Path, files: dict[str, str], cycles: list[tuple[str, ...]]
) -> None:
    for name, source in files.items():
        (tmp_path / "p" / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "p" / name).write_text(source)
    (tmp_path / "p" / "__init__.py").touch()
    assert import_cycles(import_graph(tmp_path / "p")) == cycles
