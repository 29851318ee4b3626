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
import dataclasses
import functools
import sys
import tomllib
from pathlib import Path

import pytest


REPO = Path(__file__).resolve().parents[2]


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


@dataclasses.dataclass(frozen=True)
class Import:
    """One imported name: ``target`` (a module of the package, else ``None``), ``name`` (as written, made
    absolute), the line, and whether the statement sits inside a function (``local``)."""

    target: str | None
    name: str
    line: int
    local: bool


def import_statements(module: str, source: str, known: set[str], *, is_package: bool) -> list[Import]:
    """Every import in ``source``, module-level and function-local (``from __future__`` excepted).  Memoised on
    the arguments (the source text itself, so an edited file is read again): the tests here read the same ~170
    modules six times over, and parsing them was 1-2 s of CPU a test."""
    return list(_import_statements(module, source, frozenset(known), is_package))


@functools.lru_cache(maxsize=None)
def _import_statements(module: str, source: str, known: frozenset[str], is_package: bool) -> tuple[Import, ...]:
    found: list[Import] = []

    def visit(node: ast.AST, local: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inner = local or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.Import):
                names = [alias.name for alias in child.names]
            elif isinstance(child, ast.ImportFrom) and child.module != "__future__":
                base = _resolve(module, is_package, child.level, child.module)
                names = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in child.names]
            else:
                names = []
            for name in names:
                found.append(Import(_known(name, known), name, child.lineno, local))
            visit(child, inner)

    visit(ast.parse(source), False)
    return tuple(found)


def imports_of(module: str, source: str, known: set[str], *, is_package: bool) -> set[str]:
    """The package's modules that ``module`` imports anywhere in ``source`` (function-local imports included)."""
    return {i.target for i in import_statements(module, source, known, is_package=is_package)
            if i.target is not None and i.target != module}


def import_graph(repo: Path = REPO) -> dict[str, set[str]]:
    files = module_files(package_roots(repo))
    known = set(files)
    return {name: imports_of(name, path.read_text(encoding="utf-8"), known, is_package=path.name == "__init__.py")
            for name, path in files.items()}


def layers(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """The graph between the package's layers: each subpackage of ``verimono`` (``verimono.records.report``,
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
    assert "verimono.reference.sweeping" in graph and "verimono.records.results" in graph["verimono"]


def test_import_graph_has_no_cycle():
    graph = import_graph()
    found = cycles(graph)
    assert not found, "import cycles (function-local imports count):\n" + "\n".join(
        " → ".join(cycle_path(graph, c)) for c in found)


def facades(repo: Path = REPO) -> set[str]:
    """The packages' ``__init__`` modules: they re-export their package's names (some on first use)."""
    return {m for m, path in module_files(package_roots(repo)).items() if path.name == "__init__.py"}


def test_layers_have_no_cycle():
    """Between subpackages; a facade's re-export of a name defined in another layer
    (``verimono.lcs.check_hypotheses``, from :mod:`verimono.checks.section7`) is not an edge of its package."""
    inner = facades()
    graph = layers({m: set() if m in inner else targets for m, targets in import_graph().items()})
    found = cycles(graph)
    assert not found, "import cycles between subpackages (function-local imports count):\n" + "\n".join(
        " → ".join(cycle_path(graph, c)) for c in found)


if __name__ == "__main__":  # pragma: no cover - a listing for whoever is untangling a cycle
    for g in (import_graph(), layers(import_graph())):
        for c in cycles(g):
            print(" → ".join(cycle_path(g, c)), f"  ({len(c)} modules: {', '.join(c)})")


#: modules `import verimono` must not load: the heavy ones (SciPy's statistics and optimizers, hypothesis,
#: matplotlib, the QP back-ends: together about 1 s of the 1.2-1.5 s the import took) and the layers that
#: pull them in; each is imported where it is used (the first order fit, the first check, ...)
#: (``verimono.core.qp`` left the list when it stopped importing ``scipy.optimize`` at its top; ``core.sets`` imports it)
NOT_AT_IMPORT = ("scipy.stats", "scipy.optimize", "hypothesis", "matplotlib", "qpsolvers", "proxsuite",
                 "verimono.checks", "verimono.strategies", "verimono.lcs", "verimono.records.report")


@pytest.mark.slow
def test_import_verimono_loads_only_the_core():
    import subprocess
    import sys

    code = ("import sys, verimono; "
            f"print(' '.join(m for m in {NOT_AT_IMPORT!r} if m in sys.modules)); "
            "from verimono import check_stepper, check_assumptions, lcs, strategies; "  # still importable
            "print(check_stepper.__module__, lcs.__name__, strategies.grids.__module__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    loaded, names = out.splitlines()
    assert loaded == "", f"`import verimono` loads {loaded}"
    assert names == "verimono.checks.stepper_battery verimono.lcs verimono.strategies.partitions"


# -- function-local imports: only for what is optional or heavy ---------------------------------------------

#: modules that must stay cheap to import and load the rest where it is used: the facade, the command line
#: and the pytest plugin (which every pytest session loads), and ``verimono.testing``, which the plugin imports in
#: every session too (its batteries' counter): loading the stepper battery at its top cost 0.055 s a session
ENTRY_POINTS = frozenset({"verimono", "verimono.cli", "verimono.plugin", "verimono.testing"})


def heavy_modules(repo: Path = REPO) -> dict[str, list[str]]:
    """``{module: third-party modules besides NumPy that importing it loads}`` (module-level imports, its own
    and transitively those of the package's modules it imports, parent packages included: importing
    ``verimono.checks.orders`` runs ``verimono/checks/__init__.py``).  Empty: a light module."""
    files = module_files(package_roots(repo))
    known = set(files)
    stmts = {m: import_statements(m, p.read_text(encoding="utf-8"), known, is_package=p.name == "__init__.py")
             for m, p in files.items()}
    light = set(sys.stdlib_module_names) | {"numpy"}

    def closure(module: str, seen: set[str]) -> set[str]:
        if module in seen:
            return set()
        seen.add(module)
        parts = module.split(".")
        out: set[str] = set()
        for k in range(1, len(parts)):
            if ".".join(parts[:k]) in stmts:
                out |= closure(".".join(parts[:k]), seen)
        for i in stmts[module]:
            if i.local:
                continue
            if i.target is None:
                out.add(i.name)
            elif i.target != module:
                out |= closure(i.target, seen)
        return out

    return {m: sorted(e for e in closure(m, set()) if e.split(".")[0] not in light) for m in files}


def misplaced_local_imports(repo: Path = REPO) -> list[str]:
    """Function-local imports of a light module of the package outside the entry points (``where → target``):
    with the import graph acyclic such an import only hides an edge."""
    files = module_files(package_roots(repo))
    known = set(files)
    heavy = heavy_modules(repo)
    out = []
    for module, path in files.items():
        if module in ENTRY_POINTS or path.name == "__init__.py":   # a facade loads its names on first use
            continue
        for i in import_statements(module, path.read_text(encoding="utf-8"), known,
                                   is_package=path.name == "__init__.py"):
            if i.local and i.target is not None and not heavy[i.target]:
                out.append(f"{module}:{i.line} → {i.target}")
    return sorted(set(out))


def test_the_local_import_rule_is_seen_failing(tmp_path):
    (tmp_path / "pyproject.toml").write_text('[tool.setuptools.package-dir]\n"verimono" = "pkg"\n')
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text("")
    (tmp_path / "pkg" / "light.py").write_text("import math\nimport numpy\n")
    (tmp_path / "pkg" / "heavy.py").write_text("from .light import math\nimport hypothesis\n")
    (tmp_path / "pkg" / "user.py").write_text("def f():\n    from . import heavy\n    from .light import numpy\n"
                                               "    import cvxpy\n")
    assert heavy_modules(tmp_path)["verimono.heavy"] == ["hypothesis"]
    assert heavy_modules(tmp_path)["verimono.light"] == []
    assert misplaced_local_imports(tmp_path) == ["verimono.user:3 → verimono.light"]


def test_function_local_imports_are_for_optional_or_heavy_modules():
    """A function-local import names a third-party module (optional: cvxpy, dask, matplotlib...; or heavy:
    hypothesis, SciPy's optimizers) or a module of the package that loads one; a light module of the
    package is imported at the top (the entry points excepted: they load everything where it is used)."""
    found = misplaced_local_imports()
    assert not found, "function-local imports of light modules (import them at the top):\n" + "\n".join(found)


# -- the order of the layers -----------------------------------------------------------------------------------

#: the layers, bottom up: a module imports only from its own layer and the ones below it.  A module belongs to
#: the first layer one of whose prefixes names it (``verimono.checks`` covers ``verimono.checks.core``, ...)
LAYERS = (
    ("core", ("verimono.core",)),
    ("models", ("verimono.lcs", "verimono.reference", "verimono.strategies", "verimono.data")),
    ("records", ("verimono.records",)),
    # what a check runs under (profiles, budgets, the watchdog, workers, calibration): the batteries use it
    ("execution", ("verimono.execution",)),
    ("checks", ("verimono.checks",)),
    ("run", ("verimono.run",)),
    ("entry points", ("verimono.cli", "verimono.plugin", "verimono.testing", "verimono.properties", "verimono")),
)


def layer_of(module: str) -> int:
    """The index of ``module``'s layer in :data:`LAYERS`."""
    for i, (_, prefixes) in enumerate(LAYERS):   # "verimono" names the top package (the facade) only
        if any(module == p or (p != "verimono" and module.startswith(p + ".")) for p in prefixes):
            return i
    raise KeyError(f"{module} is in no layer of LAYERS: add it where it belongs")


def upward_imports(repo: Path = REPO) -> list[str]:
    """Imports of a module of a higher layer (``where → target``).  A package's ``__init__`` only re-exports
    (``verimono.lcs.check_hypotheses``): it is a facade of its package, outside the order (cycles still count)."""
    files = module_files(package_roots(repo))
    graph = import_graph(repo)
    return sorted(f"{m} ({LAYERS[layer_of(m)][0]}) → {t} ({LAYERS[layer_of(t)][0]})"
                  for m, targets in graph.items() if files[m].name != "__init__.py"
                  for t in targets if layer_of(t) > layer_of(m))


def test_the_layer_order_is_seen_failing(tmp_path):
    """A core module reaching up to the execution machinery or the checks, even inside a function, is found."""
    (tmp_path / "pyproject.toml").write_text('[tool.setuptools.package-dir]\n"verimono" = "pkg"\n')
    for folder in ("core", "execution", "checks"):
        (tmp_path / "pkg" / folder).mkdir(parents=True)
        (tmp_path / "pkg" / folder / "__init__.py").write_text("")
    (tmp_path / "pkg" / "__init__.py").write_text("from .cli import main\n")
    (tmp_path / "pkg" / "core" / "stepping.py").write_text(
        "from .errors import E\n\ndef solve():\n    from ..execution.timeouts import budget\n")
    (tmp_path / "pkg" / "core" / "problem.py").write_text("from ..checks import core\n")
    (tmp_path / "pkg" / "core" / "errors.py").write_text("class E(Exception):\n    pass\n")
    (tmp_path / "pkg" / "execution" / "timeouts.py").write_text("from ..core.errors import E\n")
    (tmp_path / "pkg" / "checks" / "core.py").write_text("from ..execution.timeouts import budget\n")
    (tmp_path / "pkg" / "cli.py").write_text("from .checks.core import budget\n")
    assert upward_imports(tmp_path) == [
        "verimono.core.problem (core) → verimono.checks.core (checks)",
        "verimono.core.stepping (core) → verimono.execution.timeouts (execution)"]
    (tmp_path / "pkg" / "newcomer.py").write_text("from .core.errors import E\n")
    with pytest.raises(KeyError, match="verimono.newcomer is in no layer"):
        upward_imports(tmp_path)


def test_every_module_imports_only_its_layer_and_the_ones_below():
    """numerics, then records, then checks, then runs, then entry points (:data:`LAYERS`)."""
    found = upward_imports()
    assert not found, "imports against the layer order:\n" + "\n".join(found)


#: what a problem built and solved through the facade, and the command line's parser, must not load (the
#: heavy third-party modules and the layers that import them: the checks, the LCS tools, the strategies)
#: (``verimono.core.qp`` left it when it stopped importing ``scipy.optimize`` at its top: ``core.sets`` imports it)
NOT_FOR_A_PROBLEM = ("scipy", "hypothesis", "matplotlib", "qpsolvers", "proxsuite", "verimono.checks",
                     "verimono.strategies", "verimono.lcs")


@pytest.mark.slow
def test_a_problem_and_the_parser_load_none_of_the_heavy_modules():
    """``import verimono``, a problem with ``f`` and ``u`` built and solved, then the command line's parser
    (``verimono gate``/``baseline``/``--version`` need no stage: the stages' names are read on first use), in a
    fresh interpreter; then ``--stage`` of ``verimono run`` is checked, which loads the stages (and SciPy)."""
    import subprocess
    import sys

    code = ("import sys, numpy as np, verimono as vm\n"
            "loaded = lambda: ' '.join(m for m in sorted(sys.modules) if m in %r or m.startswith(tuple(x + '.' for x in %r)))\n"
            "p = vm.Problem(operator=vm.NormalCone(vm.sets.Ball(np.zeros(2), 1.0)), x0=np.array([0.5, 0.0]), T=1.0,\n"
            "               f=lambda x: -x, u=lambda t: np.array([np.sin(t), 0.0]))\n"
            "x = vm.solve(p, vm.uniform_grid(1.0, steps=8)).x\n"
            "print(x.shape, loaded() or '-')\n"
            "from verimono.cli import build_parser\n"
            "build_parser().parse_args(['gate', '--baseline', 'b.json', '--results', 'r.json'])\n"
            "print(loaded() or '-')\n"
            "build_parser().parse_args(['run', '--stage', 'siconos'])\n"
            # the stages without scipy.optimize (0.15-0.5 s): the stages whose units use it import it before the
            # workers fork (their ``prepare``), a stepper's check in the worker that builds the paper's Example
            "print('verimono.lcs' in sys.modules, 'scipy.optimize' in sys.modules)\n"
            # the stages without scipy.integrate: the a-priori bounds integrate by their own quadrature
            "print('verimono.checks.bounds' in sys.modules, 'scipy.integrate' in sys.modules)\n") % (
                NOT_FOR_A_PROBLEM, NOT_FOR_A_PROBLEM)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == ["(9, 2) -", "-", "True False", "True False"], out
