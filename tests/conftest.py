"""Fixtures shared by the unit tests.

``shared_dir`` is the one way tests reach ``../shared`` (the paper, the Siconos references): with the
``CI`` variable set a missing folder fails loudly; elsewhere the test is skipped with the reason, and
pytest counts the skip.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

# `verimono run` uses every core by default (`--executor auto`); the many small in-process runs of the
# tests would each start worker processes (about 1.5 s of spawning and imports apiece), so the tests run
# serially unless a test asks otherwise (test_executors covers the default and process:N)
os.environ.setdefault("VERIMONO_EXECUTOR", "serial")


def locate_shared() -> Path | None:
    """``$VERIMONO_SHARED`` if set, else ``../shared`` beside the repository."""
    env = os.environ.get("VERIMONO_SHARED")
    candidate = Path(env) if env else REPO.parent / "shared"
    return candidate if candidate.is_dir() else None


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    path = locate_shared()
    if path is None:
        msg = "../shared (paper and Siconos reference data) not found beside the repository"
        if os.environ.get("CI"):
            pytest.fail(f"{msg}; CI must provide it", pytrace=False)
        pytest.skip(msg)
    return path


@pytest.fixture(scope="session")
def siconos_dir(shared_dir: Path) -> Path:
    path = shared_dir / "siconos"
    if not path.is_dir():
        pytest.fail(f"{path} is missing from the shared folder", pytrace=False)
    return path
