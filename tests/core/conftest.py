"""Fixtures shared by the convergence tests of tests/core."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm

#: the linear part of the smooth manufactured problem
M = np.array([[1.0, 2.0], [-2.0, 0.5]])


@pytest.fixture(scope="module")
def manufactured():
    """x* = (I + M)^{-1} z(t) on the default figure eight: smooth (no kink), its input from finite differences."""
    return vm.manufactured_problem(vm.Linear(M), T=2 * math.pi, name="manufactured smooth linear")
