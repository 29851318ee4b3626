"""The README's Python examples run as written: the "Verify your own solver" walk-through and the
solver-core example (their assertions are the walk-through's claims)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = (Path(__file__).resolve().parent.parent / "README.md").read_text()


def python_blocks(section: str) -> list[str]:
    match = re.search(rf"^## {re.escape(section)}\n(.*?)(?=^## |\Z)", README, re.S | re.M)
    assert match, f"README has no section {section!r}"
    return re.findall(r"```python\n(.*?)```", match.group(1), re.S)


@pytest.mark.parametrize("section", ["Verify your own solver", "The solver core"])
def test_readme_examples_run(section):
    blocks = python_blocks(section)
    assert blocks
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, f"README.md ({section})", "exec"), namespace)
