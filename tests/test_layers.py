"""One-way layers: the import graph of ``verimono`` has no cycle.

The graph is read from the source with :mod:`ast`, so it holds every ``import`` statement, the ones inside
functions included: a function-local import cannot hide a cycle, it is an edge like any other.  Packages are
mapped to folders by ``[tool.setuptools.package-dir]`` of ``pyproject.toml`` (``verimono.reference`` is
``reference/``, ``verimono.properties`` is ``properties/``).  An edge ``A → B`` means "A imports B"; ``from P
import name`` is an edge to ``P.name`` when that is a module, else to ``P``.  Imports of a package's parents
(``verimono`` when importing ``verimono.checks.orders``) are not edges: Python runs them, but they only
re-export, and counting them would make every re-exporting ``__init__`` a cycle.
"""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


def package_roots(repo: Path = REPO) -> dict[str, Path]:
    """``{package: folder}`` for the ``verimono`` packages whose folder is stated in pyproject's package-dir."""
    config = tomllib.loads((repo / "pyproject.toml").read_text())["tool"]["setuptools"]
    dirs = config.get("package-dir", {})
    return {name: repo / folder for name, folder in dirs.items() if name.split(".")[0] == "verimono"}


def module_files(roots: dict[str, Path]) -> dict[str, Path]:
    """``{module name: file}`` of every Python module under the roots (a package is its ``__init__.py``)."""
    files: dict[str, Path] = {}
    for package, folder in roots.items():
        for path in sorted(folder.rglob("*.py")):
            parts = list(path.relative_to(folder).with_suffix("").parts)
            if any(p.startswith(".") or p == "__pycache__" for p in parts):
                continue
            if parts[-1] == "__init__":
                parts = parts[:-1]
            name = ".".join([package, *parts])
            files.setdefault(name, path)  # a mapped folder (verimono.reference) wins over a same-named subfolder
    return files


def _resolve(module: str, is_package: bool, level: int, target: str | None) -> str:
    """The absolute name of ``from <level dots><target> import ...`` written in ``module``."""
    if level == 0:
        return target or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join([*base, target] if target else base)


def _known(name: str, known: set[str]) -> str | None:
    """The longest prefix of ``name`` that is a module of the package, or ``None`` (an external module)."""
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        candidate = ".".join(parts[:k])
        if candidate in known:
            return candidate
    return None


def imports_of(module: str, source: str, known: set[str], *, is_package: bool) -> set[str]:
    """The package's modules that ``module`` imports anywhere in ``source`` (function-local imports included)."""
    edges: set[str] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(module, is_package, node.level, node.module)
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base for alias in node.names]
        else:
            continue
        for target in targets:
            hit = _known(target, known)
            if hit is not None and hit != module:
                edges.add(hit)
    return edges


def import_graph(repo: Path = REPO) -> dict[str, set[str]]:
    files = module_files(package_roots(repo))
    known = set(files)
    return {name: imports_of(name, path.read_text(encoding="utf-8"), known, is_package=path.name == "__init__.py")
            for name, path in files.items()}


def layers(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """The graph between the package's layers: each subpackage of ``verimono`` (``verimono.report``,
    ``verimono.checks``, ...) collapsed to one node, each top-level module and the package itself one node
    each.  A cycle here (``report`` → ``gate`` → ``report.schema``) is one between layers even when no two
    modules import each other."""
    def layer(module: str) -> str:
        return ".".join(module.split(".")[:2])
    out: dict[str, set[str]] = {}
    for v, targets in graph.items():
        out.setdefault(layer(v), set()).update(layer(w) for w in targets if layer(w) != layer(v))
    return out


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan), each sorted; ``[]`` when acyclic."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = 0

    def visit(v: str) -> None:
        nonlocal counter
        index[v] = low[v] = counter
        counter += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1 or v in graph.get(v, ()):
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def cycle_path(graph: dict[str, set[str]], component: list[str]) -> list[str]:
    """One closed path ``a → b → ... → a`` inside a strongly connected component, for the failure message."""
    members = set(component)
    start = component[0]
    path, seen = [start], {start}
    while True:
        nxt = sorted(w for w in graph[path[-1]] if w in members)
        back = [w for w in nxt if w in seen]
        if back:
            return path[path.index(back[0]):] + [back[0]]
        path.append(nxt[0])
        seen.add(nxt[0])


# -- the finder itself is seen failing -----------------------------------------------------------------------


def test_cycle_finder_finds_a_synthetic_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert cycles(graph) == [["a", "b", "c"]]
    path = cycle_path(graph, ["a", "b", "c"])
    assert path[0] == path[-1] and len(path) == 4
    assert cycles({"a": {"a"}}) == [["a"]]
    assert cycles({"a": {"b"}, "b": {"c"}, "c": set(), "d": {"b", "c"}}) == []


def test_graph_reader_sees_function_local_and_relative_imports(tmp_path):
    (tmp_path / "pyproject.toml").write_text(
        '[tool.setuptools.package-dir]\n"verimono" = "pkg"\n"verimono.reference" = "ref"\n')
    (tmp_path / "pkg" / "sub").mkdir(parents=True)
    (tmp_path / "ref").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text("from .a import f\n")
    (tmp_path / "pkg" / "a.py").write_text("import numpy\n\ndef f():\n    from .sub import b\n    return b\n")
    (tmp_path / "pkg" / "sub" / "__init__.py").write_text("")
    (tmp_path / "pkg" / "sub" / "b.py").write_text("def g():\n    from ..a import f\n    from verimono.reference import r\n")
    (tmp_path / "ref" / "__init__.py").write_text("")
    (tmp_path / "ref" / "r.py").write_text("import verimono.a as a\n")
    graph = import_graph(tmp_path)
    assert graph["verimono"] == {"verimono.a"}
    assert graph["verimono.a"] == {"verimono.sub.b"}
    assert graph["verimono.sub.b"] == {"verimono.a", "verimono.reference.r"}
    assert graph["verimono.reference.r"] == {"verimono.a"}
    assert cycles(graph) == [["verimono.a", "verimono.reference.r", "verimono.sub.b"]]
    # no module cycle, but the layer `sub` uses `a`, which uses `sub` (through another module of it)
    between = {"verimono.a": {"verimono.sub.c"}, "verimono.sub.b": {"verimono.a"}, "verimono.sub.c": set()}
    assert cycles(between) == []
    assert cycles(layers(between)) == [["verimono.a", "verimono.sub"]]


# -- the package ---------------------------------------------------------------------------------------------


def test_graph_covers_the_mapped_packages():
    graph = import_graph()
    assert {"verimono", "verimono.reference", "verimono.properties", "verimono.checks"} <= set(graph)
    assert "verimono.reference.sweeping" in graph and "verimono.results" in graph["verimono"]


def test_import_graph_has_no_cycle():
    graph = import_graph()
    found = cycles(graph)
    assert not found, "import cycles (function-local imports count):\n" + "\n".join(
        " → ".join(cycle_path(graph, c)) for c in found)


def test_layers_have_no_cycle():
    graph = layers(import_graph())
    found = cycles(graph)
    assert not found, "import cycles between subpackages (function-local imports count):\n" + "\n".join(
        " → ".join(cycle_path(graph, c)) for c in found)


if __name__ == "__main__":  # pragma: no cover - a listing for whoever is untangling a cycle
    for g in (import_graph(), layers(import_graph())):
        for c in cycles(g):
            print(" → ".join(cycle_path(g, c)), f"  ({len(c)} modules: {', '.join(c)})")
