"""The README's Python examples run as written: the "Verify your own solver" walk-through, the
"Checking your own problem" example, the "How a check is built" example and the solver-core example (their assertions are the walk-through's claims)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = (Path(__file__).resolve().parents[2] / "README.md").read_text()


def python_blocks(section: str) -> list[str]:
    match = re.search(rf"^## {re.escape(section)}\n(.*?)(?=^## |\Z)", README, re.S | re.M)
    assert match, f"README has no section {section!r}"
    return re.findall(r"```python\n(.*?)```", match.group(1), re.S)


#: ``print(...)  # what it prints`` on a line of its own: the comment is a claim about the output
PRINTED = re.compile(r"^print\((?P<args>.*)\)\s+#\s*(?P<claim>.+?)\s*$")


def with_claims_checked(block: str) -> str:
    """The block with every ``print(...)  # claim`` line turned into a call that prints and asserts that the
    printed line is the claim (the README's quoted output stays what the code prints)."""
    out = []
    for line in block.splitlines():
        m = PRINTED.match(line)
        out.append(f"_printed_as_claimed(({m['args']},), {m['claim']!r})" if m else line)
    return "\n".join(out)


def _printed_as_claimed(args: tuple, claim: str) -> None:
    text = " ".join(map(str, args))
    print(text)
    assert text == claim, f"README claims {claim!r}, the code prints {text!r}"


@pytest.mark.parametrize("section", ["Verify your own solver", "Checking your own problem", "How a check is built",
                                     "The solver core"])
def test_readme_examples_run(section):
    blocks = python_blocks(section)
    assert blocks
    namespace: dict = {"_printed_as_claimed": _printed_as_claimed}
    claims = sum(bool(PRINTED.match(line)) for block in blocks for line in block.splitlines())
    for block in blocks:
        exec(compile(with_claims_checked(block), f"README.md ({section})", "exec"), namespace)
    assert section != "Verify your own solver" or claims >= 3
