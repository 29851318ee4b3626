"""The scheme's stepping loops (``core.stepping._plain_steps``, ``_drift_steps``: small functions of their own, for
tracemalloc's line lookups): a resolvent value of the wrong shape, a list or a float at a later step is reported at
that step, with and without a field; an ``AttributeError`` raised by the resolvent itself is the user's, untouched;
and the states are those of the loop written out (x_{k+1} = J(x_k + h f(x_k)))."""

from __future__ import annotations

import re

import numpy as np
import pytest

import verimono as vm
import verimono.core.stepping as stepping
from verimono.core.errors import SolverFailure


def _kernel_failing_at(call: int, bad):
    def make(op, x0):
        calls = {"n": 0}

        def step(x, lam, t):
            calls["n"] += 1
            return bad(x) if calls["n"] == call else x * (1.0 / (1.0 + lam * (1.0 + t)))
        return step
    return make


@pytest.mark.parametrize("field", [None, lambda x: -0.5 * x], ids=["plain", "field"])
@pytest.mark.parametrize("bad, what", [(lambda x: x[:1], "shape (1,)"), (list, "a list"), (lambda x: 3.0, "a float")])
def test_a_bad_value_at_a_later_step_is_reported_at_that_step(monkeypatch, field, bad, what):
    monkeypatch.setattr(stepping, "resolvent_kernel", _kernel_failing_at(7, bad))
    p = vm.Problem(vm.NormSubdifferential(1.0, dim=2), np.array([1.0, 2.0]), 1.0, f=field)
    with pytest.raises(SolverFailure, match=rf"returned {re.escape(what)} for a point of shape \(2,\) at step 7 \(t = 0\.7\)"):
        vm.solve(p, np.linspace(0.0, 1.0, 11))


def test_the_resolvents_own_attribute_error_is_raised_as_it_is(monkeypatch):
    def boom(x):
        raise AttributeError("the user's own")
    monkeypatch.setattr(stepping, "resolvent_kernel", _kernel_failing_at(4, boom))
    p = vm.Problem(vm.NormSubdifferential(1.0, dim=2), np.array([1.0, 2.0]), 1.0)
    with pytest.raises(AttributeError, match="the user's own"):
        vm.solve(p, np.linspace(0.0, 1.0, 11))


@pytest.mark.parametrize("field", [None, lambda x: -0.5 * x], ids=["plain", "field"])
def test_the_loops_states_are_the_schemes(monkeypatch, field):
    monkeypatch.setattr(stepping, "resolvent_kernel", _kernel_failing_at(-1, None))
    t = np.linspace(0.0, 1.0, 21) ** 2
    x0 = np.array([1.0, -2.0])
    x = vm.solve(vm.Problem(vm.NormSubdifferential(1.0, dim=2), x0, 1.0, f=field), t)
    want = [x0]
    for k in range(20):
        h = t[k + 1] - t[k]
        z = want[-1] if field is None else want[-1] + h * field(want[-1])
        want.append(z * (1.0 / (1.0 + h * (1.0 + t[k + 1]))))
    assert np.array_equal(np.asarray(x), np.array(want))
