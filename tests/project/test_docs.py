"""Every code block of the README and of docs/ is executed or checked, and every link resolves.

* ```` ```python ```` blocks run, in order, one namespace per page.  A block whose first line is ``# NAME.py`` is
  a file of the reader's (``mysolver.py``, ``test_mysolver.py``): it is written to a folder on ``sys.path``
  instead of run, so the blocks after it import it as the reader would.  ``print(...)  # claim`` on a line of its
  own asserts that the printed line is the claim: the pages quote what the code prints.  A page whose blocks
  need an optional dependency that is not installed (JAX, PyTorch, ...) is a skip naming it.
* ```` ```py ```` blocks quote the package: each must appear verbatim in the file it says it is from.
* ```` ```sh ```` blocks: each ``verimono`` command parses with the command line's own parser, and each ``pip
  install`` names extras that ``pyproject.toml`` declares.  The README's commands are run for real by CI (the
  quick start) and by ``tests/project/test_readme.py`` (the three ways in).
* Every relative link names a file of the repository, and its ``#anchor`` a heading of that file.
"""

from __future__ import annotations

import re
import shlex
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
IDS = [str(p.relative_to(REPO)) for p in PAGES]

#: optional dependencies a page may need: without them its blocks are a counted skip
OPTIONAL = {"jax", "jaxopt", "torch", "proxtorch", "pyproximal", "proxop", "prox_tv", "diffrax", "cvxpy", "dask",
            "distributed", "array_api_strict"}

BLOCK = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)
PRINTED = re.compile(r"^print\((?P<args>.*)\)\s+#\s*(?P<claim>.+?)\s*$")
FILE_BLOCK = re.compile(r"^# (?P<name>[\w/]+\.py)\s*$")


def blocks(page: Path, lang: str) -> list[str]:
    return [body for kind, body in BLOCK.findall(page.read_text(encoding="utf-8")) if kind == lang]


def with_claims_checked(block: str) -> str:
    """The block with every ``print(...)  # claim`` line turned into a call that prints and asserts the claim."""
    out = []
    for line in block.splitlines():
        m = PRINTED.match(line)
        out.append(f"_printed_as_claimed(({m['args']},), {m['claim']!r})" if m else line)
    return "\n".join(out)


def _printed_as_claimed(args: tuple, claim: str) -> None:
    text = " ".join(map(str, args))
    print(text)
    assert text == claim, f"the page claims {claim!r}, the code prints {text!r}"


def test_the_claim_checker_is_seen_failing():
    namespace = {"_printed_as_claimed": _printed_as_claimed}
    exec(with_claims_checked("print(1 + 1)  # 2"), namespace)
    with pytest.raises(AssertionError, match="claims '3', the code prints '2'"):
        exec(with_claims_checked("print(1 + 1)  # 3"), namespace)


def _with_python(pages: list[Path]) -> list[Path]:
    return [p for p in pages if blocks(p, "python")]


@pytest.mark.parametrize("page", _with_python(PAGES), ids=[str(p.relative_to(REPO)) for p in _with_python(PAGES)])
def test_python_blocks_run(page, tmp_path, monkeypatch):
    code = blocks(page, "python")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"_printed_as_claimed": _printed_as_claimed, "__name__": f"docs:{page.name}"}
    files = []
    try:
        for i, block in enumerate(code):
            first = block.splitlines()[0] if block.strip() else ""
            if (m := FILE_BLOCK.match(first)):
                (tmp_path / m["name"]).write_text(block)
                files.append(m["name"].removesuffix(".py"))
                continue
            exec(compile(with_claims_checked(block), f"{page.name} (python block {i + 1})", "exec"), namespace)
    except ModuleNotFoundError as e:
        if e.name and e.name.split(".")[0] in OPTIONAL:
            pytest.skip(f"{page.name} needs {e.name}, which is not installed")
        raise
    finally:
        for name in files:   # the reader's modules are the page's own: the next page writes its own
            sys.modules.pop(name, None)


def _source_files() -> list[Path]:
    return [p for folder in ("verimono", "reference", "properties") for p in (REPO / folder).rglob("*.py")]


@pytest.mark.parametrize("page", PAGES, ids=IDS)
def test_quoted_code_is_the_packages(page):
    sources = {p: p.read_text(encoding="utf-8") for p in _source_files()}
    for block in blocks(page, "py"):
        quoted = textwrap.dedent(block).strip()
        assert any(quoted in text for text in sources.values()), (
            f"{page.name} quotes code that is in no file of the package:\n{quoted[:400]}")


def _verimono_parser():
    from verimono.cli import build_parser

    return build_parser()


def _declared_extras() -> set[str]:
    return set(tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["optional-dependencies"])


def commands(page: Path) -> list[str]:
    """The commands of a page's sh blocks, one per line (``&&`` and ``&`` split, comments and prompts dropped)."""
    out = []
    for block in blocks(page, "sh"):
        for line in block.splitlines():
            line = line.split(" #")[0].strip().removeprefix("$ ")
            if not line or line.startswith("#"):
                continue
            out += [part.strip() for part in re.split(r"&&|(?<!&)&(?!&)", line) if part.strip()]
    return out


@pytest.mark.parametrize("page", PAGES, ids=IDS)
def test_commands_parse(page):
    parser = _verimono_parser()
    extras = _declared_extras()
    for command in commands(page):
        words = shlex.split(command)
        if words[0] == "verimono":
            try:
                parser.parse_args(words[1:])
            except SystemExit as e:
                raise AssertionError(f"{page.name}: `{command}` does not parse") from e
        elif words[:2] == ["pip", "install"]:
            for word in words[2:]:
                if (m := re.search(r"\[([\w,-]+)\]", word)):
                    unknown = set(m[1].split(",")) - extras
                    assert not unknown, f"{page.name}: `{command}` names extras {unknown} pyproject does not declare"


def test_the_command_checker_is_seen_failing(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("```sh\nverimono run --no-such-option\n```\n")
    with pytest.raises(AssertionError, match="does not parse"):
        test_commands_parse(page)
    page.write_text("```sh\npip install -e \".[nonexistent]\"\n```\n")
    with pytest.raises(AssertionError, match="nonexistent"):
        test_commands_parse(page)


LINK = re.compile(r"\]\((?P<target>[^)\s]+)\)")


def anchors(page: Path) -> set[str]:
    """GitHub's anchors of a page's headings: lower case, punctuation dropped, spaces as hyphens."""
    out = set()
    for line in page.read_text(encoding="utf-8").splitlines():
        if (m := re.match(r"^#+\s+(.*)", line)):
            out.add(re.sub(r"[^\w\- ]", "", m[1].strip().lower()).replace(" ", "-"))
    return out


@pytest.mark.parametrize("page", PAGES, ids=IDS)
def test_links_resolve(page):
    text = BLOCK.sub("", page.read_text(encoding="utf-8"))
    for target in LINK.findall(text):
        if re.match(r"\w+://|mailto:", target):
            continue
        path, _, anchor = target.partition("#")
        file = (page.parent / path).resolve() if path else page
        assert file.exists(), f"{page.name} links to {target}, which does not exist"
        if anchor and file.suffix == ".md":
            assert anchor in anchors(file), f"{page.name} links to {target}: no such heading in {file.name}"


def test_every_registered_law_has_its_row_in_the_paper_map():
    """Adding a law is its evaluator, a zoo member and a row of docs/paper.md: the row is asked for here."""
    from verimono.checks import REGISTRY

    paper = (REPO / "docs" / "paper.md").read_text(encoding="utf-8")
    missing = [f"{kind}: {name}" for kind, laws in REGISTRY.items() for name in laws if f"`{name}`" not in paper]
    assert not missing, "laws without a row in docs/paper.md:\n" + "\n".join(missing)
