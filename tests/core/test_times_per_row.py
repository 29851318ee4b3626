"""Issue 43: the catalog's sets and operators take a time per row — ``t`` of shape ``(B,)`` beside ``x`` of shape
``(B, n)`` — in the members the assumption laws call (``resolvent``, ``yosida``, ``min_norm``, ``project_domain``;
a set's ``project`` and ``contains``), bit-identical to ``B`` separate calls, each row at its own time.  A member
that declares it (``_accepts_times``) is called once per block of times; one that does not is called per row.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from verimono.core.errors import InvalidProblem, NotMonotone, OutsideDomain
from verimono.core.operator_protocol import accepts_times, operator_from_resolvent, resolvent_rows
from verimono.core.operators import (L1Subdifferential, Linear, LogBarrier, NormalCone, NormSubdifferential,
                                     Shifted)
from verimono.core.sets import Ball, Box, HalfSpace, Polyhedron, Translated
from verimono.reference import catalog

LAM = 0.3


def _members():
    """Every catalog operator of the twelve references (the paper Example's excepted: verimono/lcs) and a
    member of each kind of catalog set and operator with moving parameters."""
    for p in catalog():
        if not p.name.startswith("Example"):
            yield p.name, p.operator
    yield "Ball, moving radius", NormalCone(Ball([0.0, 1.0], lambda t: 1 + 0.5 * math.sin(t)))
    yield "Translated(Box)", NormalCone(Translated(Box([-1.0, -1.0], [1.0, 2.0]), lambda t: np.array([t, -t])))
    yield "Translated(Ball)", NormalCone(Translated(Ball([0.0, 0.0], 1.0), lambda t: np.array([math.cos(t), 0.0])))
    yield "Polyhedron", NormalCone(Polyhedron([[1.0, 1.0], [-1.0, 0.0]], lambda t: np.array([1.0 + t, 0.5])))
    yield "HalfSpace, moving normal", NormalCone(HalfSpace(lambda t: np.array([math.cos(t), math.sin(t)]), 0.3))
    yield "Box, one bound infinite", NormalCone(Box(lambda t: np.array([t - 1.0, -np.inf]), [1.5, 0.5]))
    yield "L1, moving weights", L1Subdifferential(lambda t: np.array([t, 2 * t]), dim=2)
    yield "L1, constant weight", L1Subdifferential(0.7, dim=3)
    yield "Linear, moving M", Linear(lambda t: np.array([[1.0, t], [-t, 1.0]]))
    yield "Shifted", Shifted(NormSubdifferential(lambda t: t, dim=2), lambda t: np.array([t, 1.0]))
    yield "LogBarrier, moving c", LogBarrier(lambda t: 1 + t, dim=2)
    yield "NormSubdifferential, constant c", NormSubdifferential(2.0, dim=4)


MEMBERS = list(_members())


def _points(n: int, seed: int = 1):
    """64 points from 10^-2 to 10^2 (inside and outside every set), and 64 times in [0, 2] (every one distinct)."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(64, n)) * np.repeat([0.01, 1.0, 3.0, 100.0], 16)[:, None]
    return X, rng.uniform(0.0, 2.0, 64)


def _differences(op) -> list:
    """The members of ``op`` whose call with a time per row differs, bit for bit, from separate calls."""
    X, ts = _points(op.dim)
    bad = []
    calls = {"resolvent": lambda x, t: op.resolvent(x, LAM, t), "yosida": lambda x, t: op.yosida(x, LAM, t),
             "project_domain": op.project_domain}
    Z = op.resolvent(X, LAM, ts)
    for name, f in calls.items():
        try:
            together = f(X, ts)
        except NotImplementedError:
            continue
        if not np.array_equal(together, np.array([f(x, t) for x, t in zip(X, ts.tolist())])):
            bad.append(name)
    try:        # F^0 at the resolvents (points of the domain at their own times)
        if not np.array_equal(op.min_norm(Z, ts), np.array([op.min_norm(z, t) for z, t in zip(Z, ts.tolist())])):
            bad.append("min_norm")
    except NotImplementedError:
        pass
    except OutsideDomain:       # the rows' resolvents are not in the domain at their own times
        bad.append("min_norm")
    S = getattr(op, "S", None)
    if S is not None:
        if not np.array_equal(S.project(X, ts), np.array([S.project(x, t) for x, t in zip(X, ts.tolist())])):
            bad.append("project")
        for P in (X, Z, Z + 1e-9):     # outside, inside, and within the default tolerance of the boundary
            inside = S.contains(P, ts)
            if inside.dtype != bool or inside.tolist() != [S.contains(p, t) for p, t in zip(P, ts.tolist())]:
                bad.append("contains")
    return bad


@pytest.mark.parametrize("name, op", MEMBERS, ids=[m[0] for m in MEMBERS])
def test_a_time_per_row_is_bit_identical_to_separate_calls(name, op):
    assert accepts_times(op)
    assert _differences(op) == []
    X, ts = _points(op.dim)
    assert np.array_equal(resolvent_rows(op, X, LAM, ts), op.resolvent(X, LAM, ts))


def test_the_comparison_sees_a_planted_bug(monkeypatch):
    """A moving ball whose times are taken in another order (row ``i`` at ``t[B−1−i]``): the comparison sees the
    resolvent, the Yosida value, the projections and the membership differ."""
    op = NormalCone(Ball(lambda t: np.array([t, 0.0]), 1.0))
    real = Ball._project

    def reversed_times(self, x, t, times=False):
        return real(self, x, t[::-1] if times else t, times)
    monkeypatch.setattr(Ball, "_project", reversed_times)
    assert set(_differences(op)) >= {"resolvent", "yosida", "project_domain", "project"}


def test_the_comparison_sees_a_last_bit_difference(monkeypatch):
    """(``Linear``'s min_norm over all rows as one ``(B, n) @ (n, n)`` product, against the stack of row products:
    the sums differ in the last bits somewhere for n = 9.)"""
    op = Linear(np.eye(9) + np.triu(np.random.default_rng(0).normal(size=(9, 9)), 1) * 0.3)
    assert _differences(op) == []
    monkeypatch.setattr(Linear, "min_norm", lambda self, x, t=0.0: np.asarray(x, dtype=float) @ self._M(0.0).T)
    monkeypatch.setattr(Linear, "_accepts_times", lambda self: True)
    assert "min_norm" in _differences(op)


def test_a_member_that_does_not_declare_it_is_called_per_row():
    """A user's operator (``operator_from_resolvent``) and a subclass overriding a member do not declare it:
    :func:`resolvent_rows` with a time per row calls them once per row, with a float time."""
    seen = []

    def res(x, lam, t):
        seen.append(type(t))
        return np.asarray(x) * 0.5
    user = operator_from_resolvent(res, 2)
    X, ts = _points(2)
    assert not accepts_times(user)
    assert np.array_equal(resolvent_rows(user, X, LAM, ts), X * 0.5) and seen == [float] * 64

    class Mine(Ball):
        def project(self, x, t=0.0):
            assert not isinstance(t, np.ndarray)
            return super().project(x, t)
    op = NormalCone(Mine(lambda t: np.array([t, 0.0]), 1.0))
    assert not accepts_times(op) and not accepts_times(op.S)
    assert np.array_equal(resolvent_rows(op, X, LAM, ts), np.array([op.resolvent(x, LAM, t) for x, t in zip(X, ts)]))
    assert np.array_equal(op.min_norm(op.resolvent(X, LAM, ts), ts), np.zeros_like(X))
    assert not accepts_times(NormSubdifferential(np.array([1.0, 2.0]), dim=2))     # a batch of operators


def test_a_member_wrapped_on_the_object_is_called_per_row():
    """A member replaced on the object itself (a user's instrumentation: ``op.resolvent = counting(op.resolvent)``,
    ``ball.project = ...``) is not the catalog's own: it is called once per row with a float time, as a subclass
    override is (found by the probe: the assumption laws called such a wrapper with an array of times)."""
    def float_only(member):
        def wrapped(x, *args):
            assert isinstance(args[-1], float), f"{member} called with t of type {type(args[-1]).__name__}"
            return getattr(type(member.__self__), member.__name__)(member.__self__, x, *args)
        return wrapped
    X, ts = _points(2)
    ball = Ball(lambda t: np.array([t, 0.0]), 1.0)
    ball.project = float_only(ball.project)
    assert not accepts_times(ball)
    op = NormalCone(ball)
    assert not accepts_times(op)
    assert np.array_equal(resolvent_rows(op, X, LAM, ts), np.array([op.resolvent(x, LAM, t) for x, t in zip(X, ts)]))
    ns = NormSubdifferential(lambda t: 1.0 + t, dim=2)
    ns.yosida = float_only(ns.yosida)
    assert not accepts_times(ns)
    nc = NormalCone(Box(-np.ones(2), lambda t: np.array([1.0 + t, 1.0])))
    nc.resolvent = float_only(nc.resolvent)
    assert not accepts_times(nc)
    assert np.array_equal(resolvent_rows(nc, X, LAM, ts), np.array([nc.resolvent(x, LAM, t) for x, t in zip(X, ts)]))


def test_a_parameter_invalid_at_one_time_raises_as_a_separate_call_does():
    """A radius, a weight, a box that goes wrong at one time of the block: the error names that time."""
    X, ts = _points(2)
    ts[5] = 7.0
    ball = Ball([0.0, 0.0], lambda t: 1.0 - t / 5.0)
    with pytest.raises(InvalidProblem, match="t = 7.0"):
        ball.project(X, ts)
    with pytest.raises(NotMonotone, match="t = 7.0"):
        NormSubdifferential(lambda t: 1.0 - t / 5.0, dim=2).resolvent(X, LAM, ts)
    with pytest.raises(InvalidProblem, match="t = 7.0"):
        Box(lambda t: np.array([t - 5.0, -1.0]), [1.0, 1.0]).project(X, ts)
    with pytest.raises(OutsideDomain):
        NormalCone(Ball([0.0, 0.0], 1.0)).min_norm(X, ts)
    with pytest.raises(InvalidProblem, match="a time per row"):
        ball.project(X[:3], ts)


def test_a_one_point_call_with_a_length_1_array_is_the_ordinary_call():
    """``x`` of shape ``(n,)`` with ``t`` or ``λ`` a length-1 array is not "a time (a step) per row": it is the
    ordinary call with ``t`` (``λ``) as given, as before times per row existed.  A constant operator's resolvent
    then equals the scalar call's; a time-dependent parameter of shape (1,) is, as always, a batch of one operator,
    whose typed error names it."""
    x = np.array([3.0, 0.5, -1.0])
    op = Linear(np.array([[2.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 3.0]]))
    assert np.array_equal(op.resolvent(x, 0.3, np.array([0.5])), op.resolvent(x, 0.3, 0.5))
    assert np.array_equal(op.yosida(x, 0.3, np.array([0.5])), op.yosida(x, 0.3, 0.5))
    ball = NormalCone(Ball(center=np.zeros(3), radius=lambda t: 1.0 + t))
    with pytest.raises(InvalidProblem, match="batch of 1 values"):
        ball.resolvent(x, 0.3, np.array([0.5]))


class TwiceNorm(NormSubdifferential):
    """∂(2c|·|) stated through the weight's read ``_c_at`` (NormSubdifferential's documented hook)."""

    def _c_at(self, t):
        return 2.0 * super()._c_at(t)


class TwiceBarrier(LogBarrier):
    """The log barrier of weight 2c stated through ``_c_at``."""

    def _c_at(self, t):
        return 2.0 * super()._c_at(t)


def test_a_subclass_reading_its_weight_its_own_way_is_called_per_row():
    """A subclass overriding the weight's read ``_c_at`` (NormSubdifferential's and LogBarrier's documented hook:
    here ``c(t)`` doubled) is not the catalog's own: a block with a time per row equals its separate calls, which
    read ``c`` through the override (found by probe2: the block read ``c`` from the parameter directly, the
    separate calls through ``_c_at``, so the engine's block pass judged an operator half as strong)."""
    X, ts = _points(2)
    for op in (TwiceNorm(lambda t: 1.0 + t, dim=2), TwiceBarrier(lambda t: 1.0 + t, dim=2)):
        sep = np.array([op.resolvent(x, LAM, t) for x, t in zip(X, ts.tolist())])
        assert np.array_equal(resolvent_rows(op, X, LAM, ts), sep), op.name
        assert np.array_equal(op.resolvent(X, LAM, ts), sep), op.name
        # against the weight written out: J x = max(1 - 2λc/|x|, 0) x for ∂(2c|·|)
        if isinstance(op, NormSubdifferential):
            c2 = 2.0 * (1.0 + ts)
            nrm = np.linalg.norm(X, axis=1)
            assert np.allclose(sep, X * np.maximum(1 - LAM * c2 / nrm, 0.0)[:, None], rtol=1e-14, atol=0.0)
            assert np.array_equal(op.min_norm(sep, ts), np.array([op.min_norm(z, t) for z, t in zip(sep, ts.tolist())]))


def test_a_subclass_reading_its_weight_its_own_way_gets_no_fast_kernel():
    """The steppers' kernel (:func:`resolvent_kernel`) of such a subclass is its resolvent, not the catalog's
    kernel reading ``c`` from the parameter (probe2: ``solve`` stepped ∂(c|·|) where the subclass states ∂(2c|·|))."""
    from verimono.core.operator_protocol import resolvent_kernel

    x = np.array([3.0, 4.0])
    for op in (TwiceNorm(lambda t: 1.0 + t, dim=2), TwiceNorm(1.5, dim=2), TwiceBarrier(1.5, dim=2)):
        assert np.array_equal(resolvent_kernel(op, x)(x, LAM, 0.5), op.resolvent(x, LAM, 0.5)), op.name
    # ∂(2·1.5|·|) at |x| = 5: J x = (1 - 0.3·3/5) x
    assert np.allclose(TwiceNorm(1.5, dim=2).resolvent(x, LAM, 0.5), 0.82 * x, rtol=1e-15)


def test_a_barrier_subclass_reading_its_weight_its_own_way_gets_its_own_min_norm():
    """``LogBarrier.min_norm`` (and ``contains``) read ``c`` through ``_c_at`` as its resolvent does: ``TwiceBarrier``
    states ``F(x) = -2c/x``, so ``F^0(t, x) = -2c(t)/x`` at one point and per row, and ``y ∈ F(x)`` holds for that
    ``y`` only (probe2: the parent's ``-c/x`` was returned; the resolvent's fixed point ``J x = x - λ F^0(J x)``
    ties the two together: ``J x + λ F^0(J x) = x`` within a few roundings)."""
    X, ts = _points(2)
    X = np.abs(X) + 0.5                                    # inside the orthant
    for c in (lambda t: 1.0 + t, 1.5):
        op, parent = TwiceBarrier(c, dim=2), LogBarrier(c, dim=2)
        for x, t in zip(X, ts.tolist()):
            want = -2.0 * parent._c_at(t) / x              # -2c(t)/x: the weight doubled, the same division
            assert np.array_equal(op.min_norm(x, t), want), (x, t)
            assert op.contains(x, want, t) and not op.contains(x, parent.min_norm(x, t), t), (x, t)
            p = op.resolvent(x, LAM, t)                    # J x + λ F^0(J x) = x
            assert np.allclose(p + LAM * op.min_norm(p, t), x, rtol=1e-13, atol=0.0), (x, t)   # a few roundings
        rows = np.array([op.min_norm(x, t) for x, t in zip(X, ts.tolist())])
        assert np.array_equal(op.min_norm(X, ts), rows)


def _twice_on_the_object(op):
    """``op`` with its weight's read ``_c_at`` doubled on the object itself (an instance attribute, not a subclass)."""
    cls = type(op)
    op._c_at = lambda t: 2.0 * cls._c_at(op, t)
    return op


@pytest.mark.parametrize("c", [lambda t: 1.0 + t, 1.5], ids=["moving", "constant"])
def test_a_weight_read_replaced_on_the_object_is_the_subclass_s(c):
    """An ``_c_at`` replaced on one object is honoured as a subclass's override is: every member of ∂(c|·|) (the
    one-point fast paths of catfast included), its steppers' kernel and a block with a time per row give, bit for
    bit, what ``TwiceNorm`` (the same operator written as a subclass) gives — and so for ``LogBarrier``.  Found by
    probe2: the one-point paths read ``c`` from the parameter when ``_c_at`` was the class's own, whatever the
    object said."""
    from verimono.core.operator_protocol import resolvent_kernel

    X, ts = _points(2)
    pairs = ((_twice_on_the_object(NormSubdifferential(c, dim=2)), TwiceNorm(c, dim=2), X),
             (_twice_on_the_object(LogBarrier(c, dim=2)), TwiceBarrier(c, dim=2), np.abs(X) + 0.5))
    for mine, sub, pts in pairs:
        for x, t in zip(pts[:8], ts[:8].tolist()):
            assert np.array_equal(mine.resolvent(x, LAM, t), sub.resolvent(x, LAM, t)), (mine.name, x, t)
            assert np.array_equal(mine.min_norm(x, t), sub.min_norm(x, t)), (mine.name, x, t)
            assert np.array_equal(resolvent_kernel(mine, x)(x, LAM, t), sub.resolvent(x, LAM, t)), (mine.name, x, t)
            y = sub.min_norm(x, t)
            assert mine.contains(x, y, t) and sub.contains(x, y, t), (mine.name, x, t)
            if isinstance(mine, NormSubdifferential):
                assert mine.value(x, t) == sub.value(x, t), (mine.name, x, t)
        assert np.array_equal(resolvent_rows(mine, pts, LAM, ts), resolvent_rows(sub, pts, LAM, ts)), mine.name
        assert np.array_equal(mine.resolvent(pts, LAM, ts), sub.resolvent(pts, LAM, ts)), mine.name
        assert np.array_equal(mine.min_norm(pts, ts), sub.min_norm(pts, ts)), mine.name
    # against the weight written out, at one point: ∂(2·c|·|) at |x| = 5, t = 0.5
    x = np.array([3.0, 4.0])
    assert np.allclose(pairs[0][0].resolvent(x, LAM, 0.5), (1 - LAM * 3.0 / 5.0) * x, rtol=1e-15)   # 2c(0.5) = 3
