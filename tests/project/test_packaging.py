"""Packaging: the wheel ships reference/ and properties/ as verimono.reference and verimono.properties,
and the README's quick start is what CI runs."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(REPO)],
                   check=True, capture_output=True)
    (path,) = out.glob("verimono-*.whl")
    return path


@pytest.mark.slow
def test_wheel_contains_the_mapped_packages(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    for init in (REPO / "verimono").rglob("__init__.py"):  # every subpackage of the source tree ships
        assert init.relative_to(REPO).as_posix() in names, f"{init} is missing from the wheel"
    for required in ("verimono/__init__.py", "verimono/reference/__init__.py", "verimono/reference/sweeping.py",
                     "verimono/properties/__init__.py"):
        assert required in names, required


@pytest.mark.slow
def test_reference_catalog_imports_from_the_installed_wheel(wheel, tmp_path):
    zipfile.ZipFile(wheel).extractall(tmp_path)
    code = ("import verimono.reference as r, verimono; from verimono.reference import catalog; "
            "print(r.__file__); print(len(catalog()))")
    env = dict(os.environ, PYTHONPATH=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, check=True,
                         capture_output=True, text=True).stdout.split()
    assert out[0].startswith(str(tmp_path)) and int(out[1]) >= 12


def test_wheel_ships_the_siconos_data_and_reads_them_from_a_bare_directory(wheel, tmp_path):
    """The Siconos reference data are package data: every file of verimono/data/siconos is in the wheel, and
    the installed package's check_siconos finds them with nothing beside it (29 records, all passing)."""
    names = set(zipfile.ZipFile(wheel).namelist())
    data = [f.relative_to(REPO).as_posix() for f in (REPO / "verimono" / "data" / "siconos").rglob("*") if f.is_file()]
    assert len(data) == 33 and not set(data) - names, sorted(set(data) - names)
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    code = ("from verimono.lcs import check_siconos; from verimono.lcs.siconos import PACKAGED_DATA; "
            "r = check_siconos(); print(PACKAGED_DATA); print(len(r), r.ok)")
    env = {k: v for k, v in os.environ.items() if k != "VERIMONO_SHARED"} | {"PYTHONPATH": str(site)}
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, check=True,
                         capture_output=True, text=True).stdout.split()
    assert out == [str(site / "verimono" / "data"), "29", "True"]


def quick_start_commands() -> list[str]:
    text = (REPO / "README.md").read_text()
    assert text.lstrip().startswith("#"), "README must start with a heading"
    block = re.search(r"^## Quick start\s*\n+```sh\n(.*?)```", text, re.S | re.M)
    assert block, "README needs a '## Quick start' heading followed by a sh block"
    return [ln for ln in block.group(1).splitlines() if ln.strip() and not ln.startswith("#")]


def test_readme_quick_start_has_two_commands_and_ci_runs_them():
    cmds = quick_start_commands()
    assert len(cmds) == 2
    assert "verimono run" in cmds[0] and "pytest" in cmds[1]
    ci = (REPO / ".ci" / "run").read_text()
    for cmd in cmds:
        assert cmd in ci.splitlines(), f"CI does not run the README command {cmd!r}"
