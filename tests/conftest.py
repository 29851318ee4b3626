"""Fixtures shared by the unit tests.

``siconos_dir`` is the Siconos reference data shipped in the package (``verimono/data/siconos``): the
tests need nothing beside the repository.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# `verimono run` uses every core by default (`--executor auto`); the many small in-process runs of the
# tests would each start worker processes (about 1.5 s of spawning and imports apiece), so the tests run
# serially unless a test asks otherwise (test_executors covers the default and process:N)
os.environ.setdefault("VERIMONO_EXECUTOR", "serial")


@pytest.fixture(scope="session")
def siconos_dir() -> Path:
    """The packaged Siconos data folder (holds ``refs/`` and ``lcp/``)."""
    from verimono.lcs.siconos import PACKAGED_DATA, siconos_root

    return siconos_root(PACKAGED_DATA)


def pytest_collection_modifyitems(config, items):
    """Tests marked ``slow`` (minutes long) run only with ``VERIMONO_SLOW=1`` or when ``-m`` names them."""
    if os.environ.get("VERIMONO_SLOW") == "1" or "slow" in (config.getoption("-m") or ""):
        return
    skip = pytest.mark.skip(reason="slow: set VERIMONO_SLOW=1 (or -m slow) to run it")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
