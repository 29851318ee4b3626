"""The three manufactured examples, built once per test session (a few seconds each: thousands of resolvents)."""

from __future__ import annotations

import pytest

from verimono import manufactured as mf


@pytest.fixture(scope="session")
def box():
    return mf.moving_box()


@pytest.fixture(scope="session")
def norm():
    return mf.norm_subdifferential()


@pytest.fixture(scope="session")
def lcs():
    return mf.complementarity()
