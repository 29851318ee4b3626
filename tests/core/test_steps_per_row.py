"""Issue 43: the catalog's operators take a step size per row — ``lam`` of shape ``(B,)`` beside ``x`` of shape
``(B, n)`` — in ``resolvent`` and ``yosida`` (with one time, or with a time per row where the operator takes times),
bit-identical to ``B`` separate calls, row ``i`` at ``λ_i``.  An operator that declares it (``_accepts_steps``) is
called once per block by the operator laws; one that does not (a user's, a subclass override, a member replaced on
the object) is called once per row with a float ``λ``.
"""

from __future__ import annotations

import numpy as np
import pytest

from verimono.core.errors import InvalidProblem
from verimono.core.operator_protocol import accepts_steps, operator_from_resolvent
from verimono.core.operators import Linear, NormalCone, NormSubdifferential, Shifted
from verimono.core.sets import Ball

from test_times_per_row import MEMBERS


def _points(n: int, seed: int = 2):
    """64 points from 10^-2 to 10^2, 64 step sizes from e^-9 to e^3 (every one distinct: the operator laws' λ
    designs span such decades) and 64 distinct times in [0, 2]."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(64, n)) * np.repeat([0.01, 1.0, 3.0, 100.0], 16)[:, None]
    return X, np.exp(rng.uniform(-9.0, 3.0, 64)), rng.uniform(0.0, 2.0, 64)


def _differences(op) -> list:
    """The members (with one time, or with a time per row) whose call with a step size per row differs, bit for
    bit, from separate calls with float steps."""
    X, ls, ts = _points(op.dim)
    bad = []
    for member in ("resolvent", "yosida"):
        f = getattr(op, member)
        for t in (0.7, ts):
            each = np.broadcast_to(t, ls.shape).tolist()
            together = f(X, ls, t)
            if not np.array_equal(together, np.array([f(x, lam, tt) for x, lam, tt in zip(X, ls.tolist(), each)])):
                bad.append((member, type(t).__name__))
    return bad


@pytest.mark.parametrize("name, op", MEMBERS, ids=[m[0] for m in MEMBERS])
def test_a_step_per_row_is_bit_identical_to_separate_calls(name, op):
    assert accepts_steps(op)
    assert _differences(op) == []


def test_the_comparison_sees_a_planted_bug(monkeypatch):
    """Block soft thresholding whose steps are taken in reverse order (row ``i`` at ``λ[B−1−i]``): the comparison
    sees the resolvent and the Yosida value differ, with one time and with a time per row."""
    op = NormSubdifferential(lambda t: 1.0 + t, dim=3)
    real = NormSubdifferential.resolvent

    def reversed_steps(self, x, lam, t=0.0):
        return real(self, x, lam[::-1] if type(lam) is np.ndarray else lam, t)
    monkeypatch.setattr(NormSubdifferential, "resolvent", reversed_steps)
    monkeypatch.setattr(NormSubdifferential, "_accepts_steps", lambda self: True)
    assert set(_differences(op)) == {(m, k) for m in ("resolvent", "yosida") for k in ("float", "ndarray")}


def test_the_comparison_sees_a_last_bit_difference(monkeypatch):
    """``Linear``'s rows as one ``(B, n) @ (n, n)`` product per step size against each row's ``(1, n) @ (n, n)``
    (the sums differ in the last bits somewhere for n = 9), and the Yosida value as ``(x - J)·(1/λ)`` per row."""
    op = Linear(np.eye(9) + np.triu(np.random.default_rng(0).normal(size=(9, 9)), 1) * 0.3)
    assert _differences(op) == []
    real = Linear.resolvent

    def product_per_step(self, x, lam, t=0.0):
        if type(lam) is not np.ndarray:
            return real(self, x, lam, t)
        return np.einsum("bi,bji->bj", x, np.array([np.linalg.inv(np.eye(9) + li * self._M(0.0)) for li in lam]))
    monkeypatch.setattr(Linear, "resolvent", product_per_step)
    monkeypatch.setattr(Linear, "_accepts_steps", lambda self: True)
    assert ("resolvent", "float") in _differences(op)
    monkeypatch.undo()
    from verimono.core.operator_protocol import Operator
    monkeypatch.setattr(Operator, "yosida", lambda self, x, lam, t=0.0: (x - self.resolvent(x, lam, t)) * (1.0 / lam[:, None])
                        if np.ndim(lam) else (x - self.resolvent(x, lam, t)) / lam)      # a reciprocal per row
    assert ("yosida", "float") in _differences(NormSubdifferential(0.3, dim=3))


def test_a_member_that_does_not_declare_it_is_called_per_row():
    """A user's operator, a subclass overriding the resolvent, a member replaced on the object: each is called once
    per row with a float ``λ`` (and its own float time) — ``yosida`` included — and gives the separate calls'
    values."""
    seen = []

    def res(x, lam, t):
        seen.append((type(lam), type(t)))
        return np.asarray(x) / (1.0 + lam)
    user = operator_from_resolvent(res, 2)
    X, ls, ts = _points(2)
    assert not accepts_steps(user)

    class Mine(NormSubdifferential):
        def resolvent(self, x, lam, t=0.0):
            assert not isinstance(lam, np.ndarray)
            return super().resolvent(x, lam, t)
    mine = Mine(lambda t: 1.0 + t, dim=2)
    assert not accepts_steps(mine)
    y = mine.yosida(X, ls, ts)
    assert np.array_equal(y, np.array([mine.yosida(x, lam, t) for x, lam, t in zip(X, ls.tolist(), ts.tolist())]))

    def float_only(member):
        def wrapped(x, lam, t=0.0):
            assert isinstance(lam, float), f"{member.__name__} called with λ of type {type(lam).__name__}"
            return member(x, lam, t)
        return wrapped
    for op in (NormalCone(Ball(lambda t: np.array([t, 0.0]), 1.0)), Shifted(NormSubdifferential(1.0, dim=2), [1.0, 0.0])):
        op.resolvent = float_only(op.resolvent)
        assert not accepts_steps(op)
        want = np.array([op.resolvent(x, lam, t) for x, lam, t in zip(X, ls.tolist(), ts.tolist())])
        assert np.array_equal(op.yosida(X, ls, ts), (X - want) / ls[:, None])      # the wrapper, once per row
    ns = NormSubdifferential(2.0, dim=2)
    ns.yosida = float_only(ns.yosida)
    assert not accepts_steps(ns)
    assert not accepts_steps(Shifted(Mine(1.0, dim=2), [1.0, 0.0]))       # its inner operator does not
    assert not accepts_steps(NormSubdifferential(np.array([1.0, 2.0]), dim=2))     # a batch of operators


def test_a_bad_step_in_the_block_raises_as_its_separate_call_does():
    """A step size ``≤ 0``, ``inf`` or NaN at one row: the error names it, as that row's own call does; a block of
    steps whose length is not the number of rows is refused."""
    X, ls, ts = _points(3)
    for bad in (0.0, -1.0, np.inf, np.nan):
        ls2 = ls.copy()
        ls2[7] = bad
        for op in (NormSubdifferential(1.0, dim=3), NormalCone(Ball(np.zeros(3), 1.0)), Linear(np.eye(3))):
            with pytest.raises(InvalidProblem, match=f"got {bad!r}"):
                op.resolvent(X, ls2, ts)
            with pytest.raises(InvalidProblem, match="step size"):
                op.yosida(X, ls2, 0.0)
    with pytest.raises(InvalidProblem, match="a step size per row"):
        NormSubdifferential(1.0, dim=3).resolvent(X[:3], ls, 0.0)
