"""The package's layout: a few parts at the top, and every module path of the flat layout still importable."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

import verimono

PACKAGE = Path(verimono.__file__).resolve().parent

#: the parts a newcomer can name: the facade, the command line and the pytest integration, and the folders
PARTS = {"__init__.py", "cli.py", "plugin.py", "testing.py",
         "core", "lcs", "strategies", "records", "execution", "checks", "run", "data"}


def test_the_top_level_is_the_parts():
    entries = {p.name for p in PACKAGE.iterdir() if not p.name.startswith((".", "__pycache__"))
               and (p.is_dir() or p.suffix == ".py")}
    assert entries == PARTS


@pytest.mark.parametrize("old", sorted(verimono.MOVED))
def test_an_earlier_module_path_is_the_same_module(old):
    new = f"verimono.{verimono.MOVED[old]}"
    module = importlib.import_module(f"verimono.{old}")
    assert module is importlib.import_module(new)
    assert module.__name__ == new and module.__spec__.name == new   # its own relative imports stay right
    assert getattr(verimono, old) is module


def test_earlier_paths_work_in_a_fresh_interpreter():
    """Before anything imported the new homes: ``from verimono.sets import Ball`` and submodules of moved packages."""
    code = ("from verimono.sets import Ball; import verimono.report.html as h; import verimono.stages.builtin as b; "
            "from verimono.runs import execute; import verimono; "
            "print(Ball.__module__, h.__name__, b.__name__, execute.__module__, verimono.timeouts.__name__)")
    out = subprocess.run([sys.executable, "-W", "error", "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["verimono.core.sets", "verimono.records.report.html", "verimono.run.stages.builtin",
                                  "verimono.run.execute", "verimono.execution.timeouts"]


def test_an_unknown_module_is_still_not_found():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("verimono.no_such_module")
    with pytest.raises(AttributeError):
        verimono.no_such_module
