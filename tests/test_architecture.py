"""The house keeps its plan: imports between the rooms go only the ways docs/architecture.md
allows (its table is the one place they are written), the files import each other in no
circle, functions stay short enough to hold, the runtime imports no sympy when imported and
generated/ imports neither the engine nor sympy.

Everything is read from the source with ``ast`` (imports at module level AND inside functions);
nothing of the project is imported except in the sympy check (a subprocess)."""

from __future__ import annotations

import ast
import fnmatch
import os
import re
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"
#: source folder -> the package it is
PACKAGES = {"runtime": "volerr", "derive": "volerr.derive", "generated": "volerr.generated"}
MAX_LINES = 90
#: the module's tests share its parsed trees: one worker runs them all
pytestmark = pytest.mark.xdist_group("architecture")

#: functions over MAX_LINES that are tables of printed equations, each with the reason; key:
#: (path relative to the repository, qualified name).  None today: every audit function that
#: was longer (dmu50.audit 245 lines ...) was a sequence of items, now one function per item.
TABLES_OF_PRINTED_EQUATIONS: dict = {}


# ---------------------------------------------------------------------------- the table
def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


@lru_cache(maxsize=1)
def rooms() -> list[tuple[str, list[str], set[str]]]:
    """The table of docs/architecture.md: (room, file patterns, rooms it may import), top
    first."""
    text = DOC.read_text(encoding="utf-8")
    section = text.split("## Rooms and what each may import", 1)[1].split("\n## ", 1)[0]
    out = []
    for line in section.splitlines():
        if not line.startswith("| `"):
            continue
        room, files, may, _ = _cells(line)
        out.append((room.strip("`"), re.findall(r"`([^`]+)`", files),
                    set(re.findall(r"`([^`]+)`", may))))
    assert out, "docs/architecture.md has no table of rooms"
    return out


def room_of(path: str) -> str | None:
    """The room of a file (path relative to the repository): the longest matching pattern."""
    best, best_len = None, -1
    for room, patterns, _ in rooms():
        for pat in patterns:
            if pat.endswith("/"):
                hit = path.startswith(pat)
            elif "*" in pat:
                hit = fnmatch.fnmatch(path, pat) and path.count("/") == pat.count("/")
            else:
                hit = path == pat
            if hit and len(pat) > best_len:
                best, best_len = room, len(pat)
    return best


# ---------------------------------------------------------------------------- the graph
@lru_cache(maxsize=None)
def tree(path: str) -> ast.Module:
    """The parsed source of a file (path relative to the repository)."""
    return ast.parse((ROOT / path).read_text(encoding="utf-8"), filename=path)


@lru_cache(maxsize=1)
def modules() -> dict[str, str]:
    """Module name -> path relative to the repository, for every .py of the three folders."""
    out = {}
    for folder, package in PACKAGES.items():
        for p in sorted((ROOT / folder).rglob("*.py")):
            rel = p.relative_to(ROOT)
            parts = [package, *rel.parts[1:]]
            parts[-1] = parts[-1][:-3]
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = rel.as_posix()
    return out


def import_statements(node) -> list:
    """Every ``import`` / ``from ... import`` statement under ``node``, at any depth (in
    functions, classes, if/try/with blocks); expressions are not walked (no import there)."""
    out, todo = [], [node]
    while todo:
        n = todo.pop()
        for field in ("body", "orelse", "finalbody", "handlers", "cases"):
            for child in getattr(n, field, None) or ():
                if isinstance(child, (ast.Import, ast.ImportFrom)):
                    out.append(child)
                elif isinstance(child, (ast.stmt, ast.excepthandler, ast.match_case)):
                    todo.append(child)
    return out


def _imported(module: str, path: str, node) -> list[str]:
    """Modules of the project an import statement names (the longest known prefix of each)."""
    mods = modules()
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        base = module.split(".")
        if node.level:
            if not path.endswith("__init__.py"):
                base = base[:-1]
            base = base[:len(base) - (node.level - 1)]
            prefix = ".".join(base + ([node.module] if node.module else []))
        else:
            prefix = node.module or ""
        names = [f"{prefix}.{a.name}" if f"{prefix}.{a.name}" in mods else prefix
                 for a in node.names]
    out = []
    for name in names:
        while name and name not in mods:
            name = name.rpartition(".")[0]
        if name and name != module:
            out.append(name)
    return out


@lru_cache(maxsize=1)
def imports() -> dict[str, dict[str, int]]:
    """path -> {imported path: line of the first such import}, every import of the file."""
    mods = modules()
    graph: dict = {}
    for module, path in mods.items():
        edges: dict = {}
        for node in import_statements(tree(path)):
            for target in _imported(module, path, node):
                edges.setdefault(mods[target], node.lineno)
        graph[path] = edges
    return graph


def circles(graph: dict) -> list[list[str]]:
    """Strongly connected components of more than one file (Tarjan, iterative)."""
    index: dict = {}
    low: dict = {}
    on_stack: set = set()
    stack: list = []
    found = []
    counter = 0
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(graph[start]))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(graph[w])))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        found.append(sorted(comp))
    return found


# ---------------------------------------------------------------------------- the tests
def test_the_table_is_a_layering():
    """Every room named once; a room may import only rooms BELOW it in the table, so the
    rooms cannot import each other in a circle."""
    table = rooms()
    names = [r for r, _, _ in table]
    assert len(names) == len(set(names)), "a room named twice in docs/architecture.md"
    for i, (room, _, may) in enumerate(table):
        below = set(names[i + 1:])
        assert may <= below, f"room {room} may import {sorted(may - below)}, not below it"


def test_every_file_has_a_room():
    lost = [p for p in modules().values() if room_of(p) is None]
    assert not lost, f"files in no room of docs/architecture.md: {lost}"


def folder_gaps(patterns, folders) -> tuple[list, list]:
    """(package folders no pattern names, patterns naming a folder or file that is not
    there).  A folder is named by ``dir/`` or ``dir/*.py``; ``folders`` end in ``/``."""
    named = {pat if pat.endswith("/") else pat.rsplit("/", 1)[0] + "/"
             for pat in patterns if pat.endswith("/") or pat.endswith("/*.py")}
    files = [pat for pat in patterns if not pat.endswith("/") and "*" not in pat]
    missing = sorted(set(folders) - named)
    stale = sorted(named - set(folders)) + sorted(f for f in files if not (ROOT / f).is_file())
    return missing, stale


def package_folders() -> set[str]:
    """Every folder of runtime/, derive/ and generated/ that holds Python files."""
    return {p.rsplit("/", 1)[0] + "/" for p in modules().values()}


def test_the_room_list_names_every_package_folder_and_no_other():
    """issue 42 item 6: the table of docs/architecture.md is the tree as it is -- every folder
    with Python files is a room's ``dir/`` or ``dir/*.py``, and every folder or file the
    table names exists."""
    patterns = [pat for _, pats, _ in rooms() for pat in pats]
    missing, stale = folder_gaps(patterns, package_folders())
    assert not missing, f"package folders docs/architecture.md does not name: {missing}"
    assert not stale, f"docs/architecture.md names what is not there: {stale}"


def test_folder_gaps_finds_a_missing_and_a_stale_room():
    folders = {"runtime/", "runtime/cli/", "runtime/new/"}
    patterns = ["runtime/*.py", "runtime/cli/", "runtime/gone/", "runtime/cli/nothere.py"]
    missing, stale = folder_gaps(patterns, folders)
    assert missing == ["runtime/new/"]
    assert stale == ["runtime/gone/", "runtime/cli/nothere.py"]
    assert folder_gaps(["runtime/*.py", "runtime/cli/", "runtime/new/"], folders) == ([], [])


def test_imports_go_only_the_allowed_ways():
    allowed = {room: may for room, _, may in rooms()}
    wrong = []
    for path, edges in imports().items():
        here = room_of(path)
        for target, line in edges.items():
            there = room_of(target)
            if there != here and there not in allowed[here]:
                wrong.append(f"{path}:{line} ({here}) imports {target} ({there})")
    assert not wrong, "imports the table of docs/architecture.md does not allow:\n" + \
        "\n".join(wrong)


def test_no_import_circle_between_files():
    found = circles(imports())
    assert not found, "files that import each other in a circle:\n" + "\n".join(
        " -> ".join(c) for c in found)


def test_circle_finder_finds_a_circle():
    """The finder itself (so that an empty answer means something)."""
    graph = {"a": {"b": 1}, "b": {"c": 1}, "c": {"a": 1}, "d": {"a": 1}, "e": {}}
    assert circles(graph) == [["a", "b", "c"]]
    assert circles({"a": {"b": 1}, "b": {}}) == []


@lru_cache(maxsize=None)
def long_functions(limit: int = MAX_LINES) -> list[tuple[str, str, int]]:
    """(path, qualified name, lines) of every function of runtime/ and derive/ over ``limit``
    lines (decorators excluded, docstring included)."""
    out = []
    for folder in ("runtime", "derive"):
        for p in sorted((ROOT / folder).rglob("*.py")):
            path = p.relative_to(ROOT).as_posix()
            todo = [(tree(path), "")]
            while todo:
                node, prefix = todo.pop()
                for child in ast.iter_child_nodes(node):
                    if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                        name = prefix + child.name
                        if not isinstance(child, ast.ClassDef):
                            n = child.end_lineno - child.lineno + 1
                            if n > limit:
                                out.append((path, name, n))
                        todo.append((child, name + "."))
    return out


def _excused(path: str, name: str) -> bool:
    return (path, name) in TABLES_OF_PRINTED_EQUATIONS


def test_functions_a_reader_can_hold():
    too_long = [f"{p} {n}: {k} lines" for p, n, k in long_functions() if not _excused(p, n)]
    assert not too_long, f"functions over {MAX_LINES} lines:\n" + "\n".join(too_long)


def test_exceptions_are_still_needed():
    """An allow-listed function that is gone or short again is struck from its list."""
    long = {(p, n) for p, n, _ in long_functions()}
    stale = [k for k in TABLES_OF_PRINTED_EQUATIONS if k not in long]
    assert not stale, f"no longer over {MAX_LINES} lines (strike them): {stale}"


def test_generated_imports_neither_the_engine_nor_sympy():
    for path in (p for p in modules().values() if p.startswith("generated/")):
        for node in import_statements(tree(path)):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                names = [node.module or ""] if not node.level else ["(relative)"]
            for name in names:
                assert name.split(".")[0] not in ("sympy", "volerr", "(relative)"), \
                    f"{path}:{node.lineno} imports {name}"


def test_import_statements_are_found_at_any_depth():
    """The statement walk finds imports in functions, methods, branches and handlers."""
    src = ("import a\n"
           "def f():\n    if x:\n        from b import c\n"
           "class K:\n    def m(self):\n        try:\n            pass\n"
           "        except E:\n            import d\n"
           "        finally:\n            import e\n")
    found = sorted(getattr(n, "module", None) or n.names[0].name
                   for n in import_statements(ast.parse(src)))
    assert found == ["a", "b", "d", "e"]


def test_runtime_imports_no_sympy_when_imported():
    """Every module of runtime/ (and of generated/) imported in a fresh interpreter: sympy is
    not loaded (it is imported only where a derivation or the audit runs)."""
    names = [m for m, p in modules().items()
             if p.startswith(("runtime/", "generated/")) and not p.endswith("__main__.py")]
    code = ("import sys, importlib\n"
            f"for name in {names!r}:\n"
            "    importlib.import_module(name)\n"
            "bad = sorted(m for m in sys.modules if m == 'sympy' or m.startswith('volerr.derive.')"
            " and m != 'volerr.derive.audit')\n"
            "print(' '.join(bad))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                       env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "", f"imported when the runtime is imported: {r.stdout.strip()}"
