"""Issue 43: :class:`verimono.lcs.LCSOperator` takes a time per row (``_accepts_times``): ``resolvent``, ``yosida``,
``min_norm`` and ``project_domain`` of rows ``(B, n)`` at times ``(B,)`` give, bit for bit, what ``B`` separate
calls give, row ``i`` at ``t[i]`` — the operator's stepper and warm QPs are stateful, so each side is a fresh
operator and the rows are taken in their order.  The assumption laws then call the paper's Example once per block
of times; (A2)'s deep levels, where the Example's LCP is all but infeasible, fall back to one call per level when
the block raises :class:`verimono.UnverifiedSolution`."""

from __future__ import annotations

import numpy as np
import pytest

from verimono.checks import assumption_a2
from verimono.core.errors import OutsideDomain, UnverifiedSolution
from verimono.core.operator_protocol import Operator, accepts_times
from verimono.core.tolerances import QP_RTOL
from verimono.lcs.relations import Complementarity
from verimono.lcs.system import LinearRelationSystem
from verimono.reference.lcs_example import example_system

from assumption_records import assumption_records

LAM = 0.3


def _ramp():
    return example_system(lambda t: np.array([-t, 0.0])).operator()


def _sine():
    return example_system(lambda t: np.array([np.sin(t), 0.0])).operator()


def _psd2():
    """A system with n = m = 2, ``D`` PSD and not symmetric (a monotone LCS whose multipliers are not unique)."""
    A = np.array([[-0.5, 0.2], [0.1, -1.0]])
    B = np.array([[1.0, 0.0], [0.5, 1.0]])
    D = np.array([[0.0, 1.0], [-1.0, 0.5]])
    return LinearRelationSystem(A, B, B.T.copy(), D, Complementarity(),
                                v=lambda t: np.array([np.cos(3 * t), t - 1.0]), name="psd2").operator()


MAKERS = {"ramp": _ramp, "sine": _sine, "psd2": _psd2}


def _points(n: int, seed: int = 3):
    """24 points from 1e-9 to 1e3 in size, both signs (inside and outside the domains), a few exactly on the
    Example's edge ``x = 0``, and 24 times in [0, 3], two of them repeated."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(24, n)) * np.repeat([1e-9, 0.1, 1.0, 1e3], 6)[:, None]
    X[::5] = 0.0
    ts = rng.uniform(0.0, 3.0, 24)
    ts[5] = ts[4]
    return X, ts


def _same(a, b) -> bool:
    return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b)


@pytest.mark.parametrize("which", list(MAKERS))
def test_members_with_a_time_per_row_are_separate_calls_bit_for_bit(which):
    """Each member on a block of times against the same rows called one by one on a fresh operator (state
    included: the two operators then answer a further call alike)."""
    one, many = MAKERS[which](), MAKERS[which]()
    assert accepts_times(many)
    X, ts = _points(one.dim)
    for name, call in (("resolvent", lambda op, x, t: op.resolvent(x, LAM, t)),
                       ("yosida", lambda op, x, t: op.yosida(x, LAM, t))):
        rows = np.array([call(one, x, t) for x, t in zip(X, ts.tolist())])
        assert _same(call(many, X, ts), rows), name
    # project_domain of a block projects the rows proved outside together (branch example6,
    # tests/lcs/test_lcs_select_rows.py): the same projections to the QP's verification tolerance, QP_RTOL relative to
    # the data, and the rows inside the domain their own projection bit for bit
    rows = np.array([one.project_domain(x, t) for x, t in zip(X, ts.tolist())])
    got = many.project_domain(X, ts)
    assert got.shape == rows.shape
    np.testing.assert_allclose(got, rows, rtol=0, atol=100 * QP_RTOL * (1.0 + np.abs(X).max() + np.abs(rows).max()))
    same = (rows == X).all(axis=1)
    assert np.array_equal(got[same], rows[same])
    Z = one.resolvent(X, LAM, ts)      # in dom H(t_i): the minimal section exists at every row
    many.resolvent(X, LAM, ts)
    rows = np.array([one.min_norm(z, t) for z, t in zip(Z, ts.tolist())])
    # min_norm of a block selects the rows' multipliers together (branch example6, tests/lcs/test_lcs_select_rows.py):
    # the same H^0 to the selection QP's verification tolerance, QP_RTOL relative to the data, not bit for bit
    got = many.min_norm(Z, ts)
    assert got.shape == rows.shape
    np.testing.assert_allclose(got, rows, rtol=0, atol=100 * QP_RTOL * (1.0 + np.abs(Z).max() + np.abs(rows).max()))
    x, t = X[9] * 0.5, 1.25
    assert _same(one.resolvent(x, LAM, t), many.resolvent(x, LAM, t))   # the steppers left in the same state


def test_min_norm_with_a_row_outside_the_domain_raises():
    """``min_norm`` on a block raises :class:`OutsideDomain` when a row is outside ``dom H(t_i) = [0, ∞)``
    (the rows before it computed as separate calls would)."""
    op = _ramp()
    Z = np.array([[1.0], [0.5], [-1.0], [2.0]])
    with pytest.raises(OutsideDomain):
        op.min_norm(Z, np.array([0.1, 0.2, 0.3, 0.4]))
    assert _same(op.min_norm(Z[:2], np.array([0.1, 0.2])), np.array([[-0.1], [-0.2]]))   # H^0 = −max(−v1, 0)


def test_each_row_at_its_own_time_closed_form():
    """The block's rows each at their own time, against the closed form ``J = max(x + λ max(−v1(t), 0), −v2)``
    (``v = (−t, 0)``: ``x + λt`` on the domain) — not the first row's time for all."""
    op = _ramp()
    X = np.array([[0.0], [1.0], [2.0], [-0.5]])
    ts = np.array([0.0, 1.0, 2.0, 0.5])
    want = np.maximum(X[:, 0] + LAM * ts, 0.0)[:, None]
    np.testing.assert_allclose(op.resolvent(X, LAM, ts), want, rtol=1e-14, atol=1e-15)
    # the projection is a QP's minimiser, verified to QP_RTOL relative to the data (−0.5 → 1.4e-16)
    np.testing.assert_allclose(op.project_domain(X, ts), np.maximum(X, 0.0), rtol=0,
                               atol=QP_RTOL * (1.0 + np.abs(X).max()))


def test_an_override_is_not_assumed_to_take_times():
    """A subclass overriding a member, or one replaced on the object, is called once per time."""
    class Mine(type(_ramp())):
        def min_norm(self, x, t=0.0):
            return super().min_norm(x, t)

    op = _ramp()
    op.resolvent = lambda x, lam, t=0.0: x
    assert not accepts_times(op)
    assert not accepts_times(Mine(example_system(np.zeros(2))))
    with pytest.raises(Exception):
        _ramp().resolvent(np.zeros((3, 1)), LAM, np.zeros(2))    # a time per row needs a row per time


class _Unverified(Operator):
    """``J_λ(t) x = x + λt``, taking a time per row, unverified at the levels ``t`` of ``bad``."""

    def __init__(self, bad):
        super().__init__(1, "unverified at some levels")
        self.bad, self.calls = bad, []

    def _accepts_times(self):
        return True

    def resolvent(self, x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        self.calls.append(np.size(t))
        if np.any(np.isin(np.atleast_1d(t), self.bad)):
            raise UnverifiedSolution("level not verified")
        return x + lam * np.asarray(t, dtype=float).reshape(-1, 1)[: len(np.atleast_2d(x))].reshape(x.shape)


class _S:
    def __init__(self, op):
        self.op, self.T = op, 2.0


def test_a2_deep_levels_fall_back_to_one_call_per_level():
    """(A2)'s deep levels of an operator that takes times: a block that raises UnverifiedSolution at a level
    (not one of the last four) is taken again level by level, that level left out — what the per-level path
    gives (before, the block's exception ended the law's record as undecided)."""
    p, lam, t = np.array([0.25]), 0.5, 0.5
    dd = (2.0 - t) * assumption_a2.A2_RATIO ** np.arange(assumption_a2.A2_LEVELS + 1, assumption_a2.A2_DEEP_LEVELS + 1)
    bad = t + dd[1]
    op = _Unverified([bad])
    got = assumption_a2._deep(_S(op), p, lam, t)
    assert got is not None and len(op.calls) == 1 + len(dd)     # the block, then each level alone
    assert bad - t not in got[0] and len(got[0]) == len(dd) - 1
    np.testing.assert_array_equal(got[1][:, 0], p[0] + lam * (t + got[0]))
    good = assumption_a2._deep(_S(_Unverified([])), p, lam, t)
    assert len(good[0]) == len(dd)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["example-ramp", "example-sine"])
def test_the_example_records_with_a_time_per_row_equal_time_by_time(name, monkeypatch):
    """The Example's five assumption records (a tiny time budget, every path taken) with the operator called
    once per block of times against the per-time path (~1.7 s each): equal field by field but for what the
    block selection of ``H^0`` moves (branch example6: the same ``H^0`` to the selection QP's verification
    tolerance, not bit for bit) — the worst ratio to 1e-9 relative (RTOL/10) and the details the searches steer."""
    got = _records(name, monkeypatch)
    want = _records(name, monkeypatch, accepts_times=lambda op: False)
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert {k: v for k, v in g.items() if k not in ("worst", "details", "message")} == \
            {k: v for k, v in w.items() if k not in ("worst", "details", "message")}
        assert (g["worst"] is None) == (w["worst"] is None)
        if g["worst"] is not None:
            assert abs(g["worst"] - w["worst"]) <= 1e-9 * (1.0 + abs(w["worst"]))


def _records(name, monkeypatch, **patches):
    """The five assumption records of reference ``name`` (time budget 4, 8 points) as dicts without ``duration``,
    with ``patches`` set on every module that asks ``accepts_times`` (tests/assumption_records.py)."""
    return assumption_records(name, monkeypatch, 4, **patches)


# -- project_domain of a block: rows proved inside dom H(t_i) at once -------------------------------------------

def _psd3(seed: int = 0):
    """n = m = 3 with a random PSD, non-symmetric ``D`` (``S + K``, ``S`` PSD of rank 2, ``K`` skew): 8 patterns,
    some of them singular."""
    rng = np.random.default_rng(seed)
    R = rng.normal(size=(3, 2))
    K = rng.normal(size=(3, 3))
    D = R @ R.T + (K - K.T)
    C = rng.normal(size=(3, 3))
    return LinearRelationSystem(-np.eye(3), C.T.copy(), C, D, Complementarity(),
                                v=lambda t: np.array([np.sin(t), t - 1.0, 0.5 - t]), name="psd3").operator()


def _exact_inside(op, x, t) -> bool:
    """What :meth:`LCSOperator._project_domain` proves: ``x ∈ dom H(t)`` (no row infeasible, and Lemke's solution
    or the linear program)."""
    from verimono.lcs._warm_qp import row_infeasible
    from verimono.lcs.lcp import _feasible, proved_solvable
    s = op.system
    q = s.C @ x + s.v(t)
    return not row_infeasible(s.D, q) and (proved_solvable(s.D, q, s.q_scale(x, s.v(t))) or _feasible(s.D, q))


def _edge_points(op, seed: int = 5):
    """Points at every scale, and the Example's kind of degenerate ones: on the edge ``x = −v2`` exactly, and
    ``1e-13``, ``1e-10`` and ``1e-7`` (relative) either side of it; times where ``v1`` vanishes (``t = 0``, ``π``)."""
    rng = np.random.default_rng(seed)
    n = op.dim
    X = rng.normal(size=(60, n)) * np.repeat([1e-8, 1.0, 1e4], 20)[:, None]
    ts = rng.uniform(0.0, 4.0, 60)
    ts[:6] = [0.0, 0.0, np.pi, np.pi, 1.0, 2.0]
    if n == 1:
        X[:6, 0] = 0.0
        X[40:60, 0] = np.repeat([0.0, 1e-13, -1e-13, 1e-10, -1e-10, 1e-7, -1e-7, 5e-9, -5e-9, 2.0], 2) * \
            np.tile([1.0, 3.0], 10)
    return X, ts


@pytest.mark.parametrize("which", ["ramp", "sine", "psd2", "psd3"])
def test_rows_proved_inside_are_inside_by_the_exact_proof(which):
    """Every row the block proves inside, the row's own proof (Lemke or the linear program) proves inside too,
    and the block proves a good share of the rows inside (the test is not vacuous; the two PSD systems have every
    row inside, the Example leaves those outside and on its edge); the block's projections are
    the separate calls' bit for bit."""
    make = _psd3 if which == "psd3" else MAKERS[which]
    op = make()
    X, ts = _edge_points(op)
    inside = op._inside_rows(X, ts)
    assert inside is not None and inside.sum() >= 10
    if which in ("ramp", "sine"):     # dom H(t) = [0, ∞): the points outside and on the edge are left
        assert inside.sum() <= len(X) - 20
    for x, t, ok in zip(X, ts.tolist(), inside.tolist()):
        if ok:
            assert _exact_inside(op, x, t), (x, t)
    one = make()
    rows = np.array([one.project_domain(x, t) for x, t in zip(X, ts.tolist())])
    got = op.project_domain(X, ts)
    # the rows proved outside are projected together (branch example6): to QP_RTOL of the data, not bit for bit
    np.testing.assert_allclose(got, rows, rtol=0, atol=100 * QP_RTOL * (1.0 + np.abs(X).max() + np.abs(rows).max()))
    same = (rows == X).all(axis=1)
    assert np.array_equal(got[same], rows[same])


def test_rows_within_rounding_of_the_edge_are_left_to_their_own_call():
    """The Example at ``v = (−t, 0)``: ``dom H(t) = [0, ∞)``; a row ``1e-13`` inside the edge, on it, or outside is
    not proved inside by the block (the margin is 1e-9 of the data); ``1e-7`` inside is."""
    op = _ramp()
    X = np.array([[0.0], [1e-13], [-1e-13], [-1e-7], [1e-7], [3.0]])
    ts = np.full(6, 0.5)
    assert op._inside_rows(X, ts).tolist() == [False, False, False, False, True, True]
    assert op._inside_rows(X, np.zeros(6)).tolist() == [False] * 6     # v1 = 0: no strict pattern


def test_not_applicable_to_a_relay_or_a_broken_v():
    """A relay (bounded box: ``dom H = R^n``, the row's own call answers at once) and a ``v`` that raises: no
    block proof, each row its own call (which raises in its turn)."""
    from verimono.lcs.relations import Relay
    relay = LinearRelationSystem(np.zeros((1, 1)), np.array([[1.0]]), np.array([[1.0]]), np.array([[1.0]]),
                                 Relay(), v=np.zeros(1), name="relay").operator()
    assert relay._inside_rows(np.ones((3, 1)), np.zeros(3)) is None

    def v(t):
        if t > 1:
            raise ZeroDivisionError("v")
        return np.array([-t, 0.0])
    bad = example_system(v).operator()
    assert bad._inside_rows(np.ones((3, 1)), np.array([0.5, 2.0, 0.5])) is None
    with pytest.raises(ZeroDivisionError):
        bad.project_domain(np.ones((3, 1)), np.array([0.5, 2.0, 0.5]))


def test_non_finite_rows_are_left_to_their_own_call():
    """A NaN or infinite row is never proved inside (its own call says what it is)."""
    op = _ramp()
    X = np.array([[np.nan], [np.inf], [1.0], [-np.inf]])
    assert op._inside_rows(X, np.full(4, 0.5)).tolist() == [False, False, True, False]


def test_v_once_per_run_of_equal_times_and_zeros_of_both_signs_apart():
    """A block's ``v(t_i)`` is called once per run of equal times (branch perf10: the assumption laws' blocks are
    their points repeated at each time) and stacked once for ``project_domain``'s block members; times are equal by
    their bits, so ``-0.0`` and ``0.0`` are two (a ``v`` that reads the sign answers differently) — each member of
    the block still gives what the calls per row give, bit for bit (points inside the domain and on its edge: the
    block's projection of a point outside agrees with its own call's to the QP's tolerance only, before as now)."""
    calls = []

    def v(t):
        calls.append(t)
        return np.array([-np.copysign(1.0, t) * (0.25 + abs(t)), 0.0])

    X = np.array([[0.0], [0.3], [2.0], [5.0]])
    ts = np.repeat([0.0, -0.0, 0.5, 0.5, 1.25, -0.0], len(X))     # time-major: the points repeated at each time
    XX = np.tile(X, (6, 1))
    for member, args in (("resolvent", (LAM,)), ("project_domain", ()), ("min_norm", ())):
        if member == "min_norm":    # its memo takes 0.0 and -0.0 for one time (before as now): positive times
            ts = np.repeat([0.0, 0.5, 0.5, 1.25], len(X))
            XX = np.tile(X, (4, 1))
        block, own = example_system(v).operator(), example_system(v).operator()
        want = np.array([getattr(own, member)(x, *args, t) for x, t in zip(XX, ts.tolist())])
        calls.clear()
        got = getattr(block, member)(XX, *args, ts)
        assert _same(got, want), member
        if member != "min_norm":     # runs 0.0 | -0.0 | 0.5 (two times over) | 1.25 | -0.0, each asked once
            assert [np.copysign(1.0, t) for t in calls] == [1.0, -1.0, 1.0, 1.0, -1.0], (member, calls)
