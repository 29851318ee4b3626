"""Issue 43: the operator laws' calls of ``min_norm`` and ``project_domain`` over rows
(:func:`verimono.checks.engine.batches.row_member`) made as one subject call per block when the catalog operator
takes a time per row (``accepts_times``) — the same values and the same rows judged bad as the calls per row,
bit for bit; a block that raises (a row outside the domain) is judged row by row, and users' members and members
replaced on the object are called per row with a float time."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.checks import operator_laws  # noqa: F401 - the laws and their vectorised forms register
from verimono.checks.engine import batches
from verimono.checks.engine.batches import row_member
from verimono.checks.engine.search import run_law
from verimono.core.operators import L1Subdifferential, Linear, LogBarrier, NormalCone, NormSubdifferential, Shifted
from verimono.core.sets import Ball, Box, HalfSpace, Polyhedron, Translated

OPS = {
    "ball": lambda: NormalCone(Ball(np.zeros(3), 1.0)),
    "ball, moving radius": lambda: NormalCone(Ball([0.0, 1.0, 0.0], lambda t: 1 + 0.5 * math.sin(t))),
    "moving box": lambda: NormalCone(Box(lambda t: np.array([t - 1.0, -1.0, -2.0]), [1.5, 0.5, 1.0])),
    "Translated(Box)": lambda: NormalCone(Translated(Box([-1.0, -1.0, -1.0], [1.0, 2.0, 1.0]),
                                                     lambda t: np.array([t, -t, 0.0]))),
    "Polyhedron": lambda: NormalCone(Polyhedron([[1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]],
                                                lambda t: np.array([1.0 + t, 0.5]))),
    "HalfSpace, moving normal": lambda: NormalCone(HalfSpace(lambda t: np.array([math.cos(t), math.sin(t), 0.0]),
                                                             0.3)),
    "t|x|": lambda: NormSubdifferential(lambda t: t, dim=3),
    "L1, moving weights": lambda: L1Subdifferential(lambda t: np.array([t, 2 * t, 0.5]), dim=3),
    "Linear": lambda: Linear(np.array([[2.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.5]])),
    "Linear, moving M": lambda: Linear(lambda t: np.array([[1.0, t, 0.0], [-t, 1.0, 0.0], [0.0, 0.0, 2.0]])),
    "Shifted": lambda: Shifted(NormSubdifferential(lambda t: t, dim=3), lambda t: np.array([t, 1.0, 0.0])),
    "LogBarrier, moving c": lambda: LogBarrier(lambda t: 1 + t, dim=3),
}


def _rows(op, seed: int = 5, B: int = 48):
    """48 points from 10^-2 to 10^2 mapped into the domain (``J_ν x`` at their times, as the laws' domain pairs
    are), and 48 distinct times in [0, 2]; the raw points too (outside the sets' domains for some)."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(B, 3)) * np.repeat([0.01, 1.0, 100.0], B // 3)[:, None]
    if isinstance(op, LogBarrier):
        X = np.abs(X) + 1e-3
    ts = rng.uniform(0.0, 2.0, B)
    return np.array([op.resolvent(x, 0.5, t) for x, t in zip(X, ts.tolist())]), X, ts


def _per_row(member, X, ts, ok):
    """``row_member`` as it calls a member that takes no time per row (one call per row)."""
    real = batches._member_takes_times
    batches._member_takes_times = lambda m: False
    try:
        return row_member(member, X, ts, ok)
    finally:
        batches._member_takes_times = real


def _counting(monkeypatch, cls, name):
    calls = []
    real = getattr(cls, name)

    def counting(self, x, t=0.0):
        calls.append((np.shape(x), np.shape(t), type(t)))
        return real(self, x, t)
    monkeypatch.setattr(cls, name, counting)
    return calls


@pytest.mark.parametrize("name", sorted(OPS))
@pytest.mark.parametrize("member", ["min_norm", "project_domain"])
def test_one_call_per_block_gives_the_calls_per_row_values(name, member, monkeypatch):
    op = OPS[name]()
    Z, _, ts = _rows(op)
    calls = _counting(monkeypatch, type(op), member)
    ok = np.ones(len(Z), dtype=bool)
    ok[[3, 17]] = False        # rows already judged bad are not called
    got = row_member(getattr(op, member), Z, ts, ok)
    # one call from the engine, a time per row (a moving M's min_norm then calls itself per row: the catalog's own)
    assert calls[0] == ((46, 3), (46,), np.ndarray) and all(c[0] == (3,) for c in calls[1:])
    calls.clear()
    ok_want = np.ones(len(Z), dtype=bool)
    ok_want[[3, 17]] = False
    want = _per_row(getattr(op, member), Z, ts, ok_want)
    assert len(calls) == 46 and {c[2] for c in calls} == {float}
    assert np.array_equal(got, want) and np.array_equal(ok, ok_want) and ok.sum() == 46


def test_the_comparison_sees_times_taken_in_another_order(monkeypatch):
    """A ``min_norm`` that declares times per row but takes them reversed in the block: its rows differ from the
    calls per row (the values test above would fail on it)."""
    op = OPS["t|x|"]()
    Z, _, ts = _rows(op)
    real = NormSubdifferential.min_norm

    def reversed_times(self, x, t=0.0):
        return real(self, x, t[::-1] if type(t) is np.ndarray else t)
    monkeypatch.setattr(NormSubdifferential, "min_norm", reversed_times)
    got = row_member(op.min_norm, Z, ts, np.ones(len(Z), dtype=bool))
    want = _per_row(op.min_norm, Z, ts, np.ones(len(Z), dtype=bool))
    assert not np.array_equal(got, want)


def test_a_block_with_a_row_outside_the_domain_is_judged_row_by_row():
    """Points of which some are outside the moving box: the block's ``min_norm`` raises ``OutsideDomain``; the calls
    per row mark exactly the rows outside, as they did."""
    op = OPS["moving box"]()
    Z, X, ts = _rows(op)
    Z[[5, 30]] = X[[5, 30]] * 0 + 50.0            # two rows outside the box
    ok = np.ones(len(Z), dtype=bool)
    got = row_member(op.min_norm, Z, ts, ok)
    ok_want = np.ones(len(Z), dtype=bool)
    want = _per_row(op.min_norm, Z, ts, ok_want)
    assert np.flatnonzero(~ok).tolist() == [5, 30] and np.array_equal(ok, ok_want) and np.array_equal(got, want)


def test_a_block_answering_another_shape_is_judged_row_by_row(monkeypatch):
    """A block answer of the wrong shape is no answer: the rows are called one by one."""
    op = OPS["t|x|"]()
    Z, _, ts = _rows(op)
    real = NormSubdifferential.min_norm

    def flat(self, x, t=0.0):
        p = real(self, x, t)
        return p.ravel() if np.ndim(x) == 2 else p
    monkeypatch.setattr(NormSubdifferential, "min_norm", flat)
    ok = np.ones(len(Z), dtype=bool)
    got = row_member(op.min_norm, Z, ts, ok)
    assert ok.all() and np.array_equal(got, np.array([real(op, z, t) for z, t in zip(Z, ts.tolist())]))


def test_users_and_wrapped_members_are_called_per_row_with_floats():
    """A user's operator and a catalog member replaced on the object get a float time per call."""
    seen = []

    def min_norm(x, t):
        seen.append(type(t))
        return np.asarray(x) * 0.0
    user = vm.operator_from_resolvent(lambda x, lam, t: np.asarray(x) * 0.5, 3, min_norm=min_norm)
    Z, _, ts = _rows(OPS["ball"]())
    row_member(user.min_norm, Z, ts, np.ones(len(Z), dtype=bool))
    assert seen == [float] * 48
    op, seen[:] = OPS["ball"](), []
    real = op.project_domain

    def wrapped(x, t=0.0):
        seen.append(type(t))
        return real(x, t)
    op.project_domain = wrapped
    row_member(op.project_domain, Z, ts, np.ones(len(Z), dtype=bool))
    assert seen == [float] * 48


def test_the_one_call_is_timed_as_one_subject_call():
    class State:
        in_flight, slowest = None, 0.0
    st = State()
    op = OPS["ball"]()
    Z, _, ts = _rows(op)
    batches.CLOCK.append(st)
    try:
        row_member(op.min_norm, Z, ts, np.ones(len(Z), dtype=bool))
        first = st.in_flight
        row_member(op.project_domain, Z, ts, np.ones(len(Z), dtype=bool))
    finally:
        batches.CLOCK.pop()
    assert first is not None and st.in_flight > first


def _fields(r):
    return (r.status, r.worst, repr(r.counterexample), r.details.get("evaluations"))


def _record_per_row(law, op):
    real = batches._member_takes_times
    batches._member_takes_times = lambda m: False
    try:
        return run_law(law, OPS[op](), seed=1, examples=8)
    finally:
        batches._member_takes_times = real


@pytest.mark.parametrize("law, op", [
    ("yosida_limit", "moving box"), ("resolvent_in_domain", "moving box"), ("min_norm_in_graph", "Shifted"),
    pytest.param("min_norm_least", "t|x|", marks=pytest.mark.slow),             # ~0.3 s a search
    pytest.param("yosida_bounded_by_min_norm", "L1, moving weights", marks=pytest.mark.slow)])
def test_the_records_are_the_calls_per_row_records(law, op):
    """The laws that call ``min_norm`` or ``project_domain`` over rows: the record with one call per block equals
    the one with a call per row — status, worst, counterexample, evaluations."""
    assert _fields(run_law(law, OPS[op](), seed=1, examples=8)) == _fields(_record_per_row(law, op))


@pytest.mark.slow
def test_the_records_see_times_taken_in_another_order(monkeypatch):
    """The law's record sees a ``min_norm`` taking the block's times reversed (Yosida's bound by F^0 on t|x|): the
    laws' searches use the one call."""
    before = run_law("yosida_bounded_by_min_norm", OPS["t|x|"](), seed=1, examples=8)
    real = NormSubdifferential.min_norm

    def reversed_times(self, x, t=0.0):
        return real(self, x, t[::-1] if type(t) is np.ndarray else t)
    monkeypatch.setattr(NormSubdifferential, "min_norm", reversed_times)
    after = run_law("yosida_bounded_by_min_norm", OPS["t|x|"](), seed=1, examples=8)
    assert _fields(after) != _fields(before)
