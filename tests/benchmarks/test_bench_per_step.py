"""Issue 6, target 1: per-step overhead of ``verimono.solve`` on closed-form resolvents.

``solve`` on t|x| (``c(t) = t``), a box and a ball (``NormalCone``), ``n = 1, 3, 10``, 10^5 steps, within
1.5× a bare NumPy loop doing the same arithmetic (preallocated output, steps as Python floats, the same
operations in the same order — hence the same bits, which is asserted).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.sets import Ball, Box

TARGET = 1.5
TINY = 5e-324


def bare_t_norm(x0, t):
    hs, ts = np.diff(t).tolist(), t[1:].tolist()
    x = np.empty((len(t),) + x0.shape)
    x[0] = xk = x0
    for k in range(len(hs)):
        nrm = math.sqrt(xk.dot(xk))
        xk = xk * (max(nrm - hs[k] * ts[k], 0.0) / max(nrm, TINY))
        x[k + 1] = xk
    return x


def bare_box(x0, t, lo, hi):
    mn, mx = np.minimum, np.maximum
    x = np.empty((len(t),) + x0.shape)
    x[0] = xk = x0
    for k in range(len(t) - 1):
        xk = mn(mx(xk, lo), hi)
        x[k + 1] = xk
    return x


def bare_ball(x0, t, c, r):
    x = np.empty((len(t),) + x0.shape)
    x[0] = xk = x0
    for k in range(len(t) - 1):
        d = xk - c
        nrm = math.sqrt(d.dot(d))
        if nrm > r:
            xk = c + d * (r / nrm)
        x[k + 1] = xk
    return x


def make(kind, n):
    x0 = np.linspace(0.5, 1.0, n)
    x0 /= np.linalg.norm(x0)
    if kind == "t|x|":
        return vm.Problem(vm.NormSubdifferential(lambda s: s, dim=n), x0, 2.0), lambda t: bare_t_norm(x0, t)
    if kind == "box":
        lo, hi = -0.3 * np.ones(n), 0.4 * np.ones(n)
        return (vm.Problem(vm.NormalCone(Box(lo, hi)), x0, 2.0, initial_jump=True),
                lambda t: bare_box(x0, t, lo, hi))
    c = np.zeros(n)
    return (vm.Problem(vm.NormalCone(Ball(c, 0.5)), x0, 2.0, initial_jump=True),
            lambda t: bare_ball(x0, t, c, 0.5))


@pytest.mark.parametrize("n", [1, 3, 10])
@pytest.mark.parametrize("kind", ["t|x|", "box", "ball"])
def test_per_step_overhead_vs_bare_numpy_loop(gate, kind, n):
    problem, bare = make(kind, n)
    t = vm.uniform_grid(2.0, steps=gate.size(100_000, 20_000))
    assert np.array_equal(vm.solve(problem, t).x, bare(t))  # the same arithmetic, bit for bit
    gate.benchmark.extra_info.update({"steps": len(t) - 1, "n": n, "operator": kind})
    gate.measure(lambda: vm.solve(problem, t), lambda: bare(t), target=TARGET)
