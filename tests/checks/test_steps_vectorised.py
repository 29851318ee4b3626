"""Issue 43: the operator laws' designs over the step size λ (and the time t) evaluated in one subject call per block
(:func:`verimono.checks.engine.batches.row_resolvents`) when the operator takes a step size per row
(``accepts_steps``) and a time per row (``accepts_times``) — the same values, the same rows judged bad and the same
records as the calls per distinct ``(λ, t)``; an operator that does not declare it is called per ``(λ, t)`` with
floats."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks import operator_laws  # noqa: F401 - the laws and their vectorised forms register
from verimono.checks.engine import batches
from verimono.checks.engine.batches import row_resolvents
from verimono.checks.engine.search import run_law
from verimono.core.operators import Linear, NormalCone, NormSubdifferential
from verimono.core.sets import Ball, Box

OPS = {
    "ball": lambda: NormalCone(Ball(np.zeros(3), 1.0)),
    "moving box": lambda: NormalCone(Box(lambda t: np.array([t - 1.0, -1.0, -2.0]), [1.5, 0.5, 1.0])),
    "t|x|": lambda: NormSubdifferential(lambda t: t, dim=3),
    "Linear": lambda: Linear(np.array([[2.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.5]])),
}


def _rows(seed: int = 4, B: int = 48):
    """48 points from 10^-2 to 10^2, step sizes over 12 decades and times in [0, 2], each distinct, and the first
    eight rows sharing one (λ, t) (a block with a repeated group)."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(B, 3)) * np.repeat([0.01, 1.0, 100.0], B // 3)[:, None]
    ls, ts = np.exp(rng.uniform(-9.0, 3.0, B)), rng.uniform(0.0, 2.0, B)
    ls[:8], ts[:8] = ls[0], ts[0]
    return X, ls, ts


def _per_group(op, X, ls, ts):
    """``row_resolvents`` as it calls an operator that does not declare steps per row (one call per (λ, t))."""
    ok = np.ones(len(X), dtype=bool)
    cls = type(op)
    real = cls._accepts_steps
    cls._accepts_steps = lambda self: False
    try:
        return row_resolvents(op, X, ls, ts, ok), ok
    finally:
        cls._accepts_steps = real


def _counted(op):
    calls = []
    real = type(op).resolvent

    def counting(self, x, lam, t=0.0):
        calls.append((np.shape(lam), np.shape(t)))
        return real(self, x, lam, t)
    return calls, counting


@pytest.mark.parametrize("name", sorted(OPS))
def test_one_call_per_block_gives_the_calls_per_step_values(name, monkeypatch):
    op = OPS[name]()
    X, ls, ts = _rows()
    calls, counting = _counted(op)
    monkeypatch.setattr(type(op), "resolvent", counting)
    for t in (ts, np.full_like(ts, 0.7)):
        ok = np.ones(len(X), dtype=bool)
        calls.clear()
        J = row_resolvents(op, X, ls, t, ok)
        assert calls == [((48,), (48,) if t is ts else ())]        # one call, a step per row
        want, ok_want = _per_group(op, X, ls, t)
        assert len(calls) == 1 + 41       # and the calls per (λ, t): 40 distinct rows and one group of eight
        assert np.array_equal(J, want) and np.array_equal(ok, ok_want) and ok.all()


def _reversed_steps(monkeypatch):
    """t|x| declaring steps per row but taking them reversed in the block."""
    real = NormSubdifferential.resolvent

    def reversed_steps(self, x, lam, t=0.0):
        return real(self, x, lam[::-1] if type(lam) is np.ndarray else lam, t)
    monkeypatch.setattr(NormSubdifferential, "resolvent", reversed_steps)


def test_the_comparison_sees_steps_taken_in_another_order(monkeypatch):
    """An operator that declares steps per row but takes them reversed in the block: its rows differ from the
    calls per (λ, t)."""
    op = OPS["t|x|"]()
    X, ls, ts = _rows()
    _reversed_steps(monkeypatch)
    J = row_resolvents(op, X, ls, ts, np.ones(len(X), dtype=bool))
    want, _ = _per_group(op, X, ls, ts)
    assert not np.array_equal(J, want)


@pytest.mark.slow       # two searches: ~1 s
def test_the_laws_searches_use_the_one_call_and_stay_right_when_it_is_wrong(monkeypatch):
    """Yosida's limit on t|x| (one seed) calls the resolvent with a step per row (the one call per block); with the
    steps taken reversed in the block, the block's rows are no longer accepted and the law's own evaluator (a call
    per sample, a float λ) decides them: the same record.  (Until the block form left every row not clearly inside
    the bound to the evaluator, the record changed instead; it was asserted so, and failed since before 0288656.)"""
    real = NormSubdifferential.resolvent
    blocks = []

    def counting(self, x, lam, t=0.0):
        if type(lam) is np.ndarray:
            blocks.append(lam.size)
        return real(self, x, lam, t)
    monkeypatch.setattr(NormSubdifferential, "resolvent", counting)
    before = run_law("yosida_limit", OPS["t|x|"](), seed=0, examples=8)
    assert blocks and max(blocks) > 1
    _reversed_steps(monkeypatch)
    after = run_law("yosida_limit", OPS["t|x|"](), seed=0, examples=8)
    assert (after.status, after.worst, after.details.get("evaluations")) == \
        (before.status, before.worst, before.details.get("evaluations"))


def test_the_records_are_the_calls_per_steps_records():
    """A law whose vectorised form moves λ per row (Yosida's limit, the resolvent's Lipschitz bound), on t|x|: the
    record with one call per block equals the one with a call per (λ, t) — status, worst, counterexample,
    evaluations."""
    def fields(r):
        return (r.status, r.worst, repr(r.counterexample), r.details.get("evaluations"))
    for law in ("yosida_limit", "resolvent_nonexpansive"):
        one = run_law(law, OPS["t|x|"](), seed=1, examples=8)
        real = NormSubdifferential._accepts_steps
        NormSubdifferential._accepts_steps = lambda self: False
        try:
            each = run_law(law, OPS["t|x|"](), seed=1, examples=8)
        finally:
            NormSubdifferential._accepts_steps = real
        assert fields(one) == fields(each)


def test_an_undeclared_or_wrapped_resolvent_is_called_per_step_with_floats():
    """A user's operator and a catalog resolvent replaced on the object get a float λ and t per call."""
    seen = []

    def res(x, lam, t):
        seen.append((type(lam), type(t)))
        return np.asarray(x) * 0.5
    X, ls, ts = _rows()
    user = vm.operator_from_resolvent(res, 3)
    row_resolvents(user, X, ls, ts, np.ones(len(X), dtype=bool))
    assert set(seen) == {(float, float)} and len(seen) == 48
    op = OPS["ball"]()
    real, seen[:] = op.resolvent, []

    def wrapped(x, lam, t=0.0):
        seen.append((type(lam), type(t)))
        return real(x, lam, t)
    op.resolvent = wrapped
    row_resolvents(op, X, ls, ts, np.ones(len(X), dtype=bool))
    assert set(seen) == {(float, float)} and len(seen) == 48


def test_a_block_that_raises_is_judged_row_by_row():
    """A weight invalid at one row's time: the block call raises, the calls per (λ, t) mark that row alone."""
    op = NormSubdifferential(lambda t: 1.0 - t / 5.0, dim=3)
    X, ls, ts = _rows()
    ts[20] = 7.0
    ok = np.ones(len(X), dtype=bool)
    J = row_resolvents(op, X, ls, ts, ok)
    assert np.flatnonzero(~ok).tolist() == [20]
    assert np.array_equal(J[ok], np.array([op.resolvent(x, lam, t) for x, lam, t in
                                           zip(X[ok], ls[ok].tolist(), ts[ok].tolist())]))


def test_the_one_call_is_timed_as_one_subject_call():
    """The running search's clock sees the block as one call (its start set once)."""
    class State:
        in_flight, slowest = None, 0.0
    st = State()
    batches.CLOCK.append(st)
    try:
        X, ls, ts = _rows()
        row_resolvents(OPS["ball"](), X, ls, ts, np.ones(len(X), dtype=bool))
    finally:
        batches.CLOCK.pop()
    assert st.in_flight is not None and st.slowest == 0.0
