"""Fixtures shared by the unit tests.

``siconos_dir`` is the Siconos reference data shipped in the package (``verimono/data/siconos``): the
tests need nothing beside the repository.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

# the tests mirror the package's folders (tests/core, tests/checks, ...); the broken subjects they share, the
# zoo (zoo.py, zoo_steppers.py, ...), stay here, importable from every folder
sys.path.insert(0, str(Path(__file__).resolve().parent))

# `verimono run` uses every core by default (`--executor auto`); the many small in-process runs of the
# tests would each start worker processes (about 1.5 s of spawning and imports apiece), so the tests run
# serially unless a test asks otherwise (test_executors covers the default and process:N)
os.environ.setdefault("VERIMONO_EXECUTOR", "serial")


@pytest.fixture(scope="session")
def siconos_dir() -> Path:
    """The packaged Siconos data folder (holds ``refs/`` and ``lcp/``)."""
    from verimono.lcs.siconos import PACKAGED_DATA, siconos_root

    return siconos_root(PACKAGED_DATA)


def _node_ids(name: str) -> set[str]:
    """The node ids listed in ``tests/<name>`` (one a line; after '#', the measured seconds)."""
    return {line.split("  #")[0].strip() for line in
            (Path(__file__).resolve().parent / name).read_text(encoding="utf-8").splitlines()
            if line.strip() and not line.startswith("#")}


#: fast-tier tests measured at 2 s or more: marked ``slow`` here (tests/slow_tests.txt says when and how measured)
_MEASURED_SLOW = _node_ids("slow_tests.txt")
#: fast-tier tests measured at 0.3 s or more: marked ``heavy``, the tier CI runs right after the default one
#: (tests/heavy_tests.txt says when and how measured)
_MEASURED_HEAVY = _node_ids("heavy_tests.txt")


@pytest.hookimpl(tryfirst=True)       # before `-m` deselects: the marker must be there when it looks
def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.nodeid in _MEASURED_SLOW:
            item.add_marker(pytest.mark.slow)
        elif item.nodeid in _MEASURED_HEAVY:
            item.add_marker(pytest.mark.heavy)
