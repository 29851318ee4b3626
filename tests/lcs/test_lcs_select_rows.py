"""``H^0`` of a block of rows selected together (:mod:`verimono.lcs._select_rows`, branch example6) against each
row's own call (:meth:`LCSOperator._select`: Lemke, the rank certificate, the warm selection QP).

Tolerance: both answers are minimisers of the selection QP verified by ``kkt_residual`` to ``QP_RTOL`` in the
QP's equilibrated units, whose size is that of the data ``q = Cx + v`` and of ``c = BᵀAx``; ``H^0 = −Ax − Bλ*`` is
unique even where ``λ*`` is not, so the two agree to ``QP_RTOL`` times that size, times ``‖B‖∞`` (the map
from multipliers to ``H^0``) and a margin of 100 for the conditioning of these small systems:
``TOL_FACTOR·QP_RTOL·(1 + ‖C‖∞|x|∞ + |v|∞ + ‖A‖∞|x|∞)·(1 + ‖B‖∞)``.  Measured: at most 6e-6 of it on the random
systems below (3.7e-12 absolute on a rank-1 3×3 ``D`` at |x| ≈ 10, last bits elsewhere); a wrong face or a dropped
check gives errors of the data's size.
"""

from __future__ import annotations

import numpy as np
import pytest

import verimono.lcs._select_rows as sr
from verimono.core.errors import OutsideDomain
from verimono.core.tolerances import QP_RTOL
from verimono.lcs.relations import Complementarity, Relay
from verimono.lcs.system import LinearRelationSystem
from verimono.reference import lcs_example as ex

TOL_FACTOR = 100.0


def _tol(op, X, ts):
    s = op.system
    V = np.array([s.v(t) for t in ts])
    size = (1.0 + s._c_norm * np.abs(X).max(axis=1) + np.abs(V).max(axis=1)
            + np.abs(s.A).sum(axis=1).max() * np.abs(X).max(axis=1))
    return TOL_FACTOR * QP_RTOL * size * (1.0 + np.abs(s.B).sum(axis=1).max())


def _accepted(monkeypatch):
    """Count the rows the block selection accepts (so a test cannot pass with every row taken row by row)."""
    seen = [0, 0]
    orig = sr.select_rows

    def counting(*a):
        Z, ok = orig(*a)
        seen[0] += ok.size
        seen[1] += int(ok.sum())
        return Z, ok
    monkeypatch.setattr("verimono.lcs.system.select_rows", counting)
    return seen


def _psd_system(seed, n, m, relay=False, rank=None):
    """A passive LCS (``C = Bᵀ``, ``D = SᵀS + K``: ``S`` of rank ``rank``, ``K`` skew), ``v`` moving with ``t``."""
    rng = np.random.default_rng(seed)
    r = m if rank is None else rank
    S = rng.normal(size=(r, m))
    K = rng.normal(size=(m, m))
    D = S.T @ S + (K - K.T)
    A = rng.normal(size=(n, n)) * 0.5
    B = rng.normal(size=(n, m))
    w = rng.normal(size=m)
    return LinearRelationSystem(A, B, B.T.copy(), D, Relay() if relay else Complementarity(),
                                v=lambda t: w * np.sin(t + np.arange(m)), name=f"psd{seed}").operator()


def _domain_rows(op, seed, B=40):
    """Points of ``dom H(t_i)``: resolvents of random points at several scales (many land on the domain's
    faces, where the multipliers are not unique), and a few repeated rows and times."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(B, op.dim)) * np.repeat([1e-6, 0.1, 1.0, 10.0], B // 4)[:, None]
    ts = rng.uniform(0.0, 6.0, B)
    ts[1], X[1] = ts[0], X[0]
    return op.resolvent(X, 0.7, ts), ts


def _both(make, X, ts):
    """``min_norm`` of the block on one operator and row by row on a fresh one."""
    one, many = make(), make()
    rows = np.array([one.min_norm(x, t) for x, t in zip(X, ts.tolist())])
    return many.min_norm(X, ts), rows, many


SYSTEMS = [(0, 1, 1, False, None), (1, 2, 2, False, None), (2, 3, 2, False, 1), (3, 2, 3, False, None),
           (4, 3, 3, False, 1), (5, 1, 2, True, None), (6, 2, 2, True, 1)]


@pytest.mark.parametrize("seed,n,m,relay,rank", SYSTEMS)
def test_block_selection_agrees_with_each_rows_own_on_random_psd_systems(seed, n, m, relay, rank, monkeypatch):
    """Random monotone LCSs (complementarity and relay, ``D`` of full and deficient rank): the block's ``H^0``
    against each row's own call, within the stated tolerance; most rows are the block's own answers."""
    seen = _accepted(monkeypatch)
    make = lambda: _psd_system(seed, n, m, relay, rank)       # noqa: E731
    X, ts = _domain_rows(make(), seed)
    got, want, _ = _both(make, X, ts)
    tol = _tol(make(), X, ts)
    assert (np.abs(got - want).max(axis=1) <= tol).all(), np.abs(got - want).max(axis=1) / tol
    assert seen[1] >= 0.75 * seen[0] > 0, seen


def _example(v):
    return ex.example_system(v).operator()


SINE = lambda t: np.array([np.sin(t), 0.0])       # noqa: E731
RAMP = lambda t: np.array([-t, 0.0])              # noqa: E731


@pytest.mark.parametrize("v", [SINE, RAMP], ids=["sine", "ramp"])
def test_example_edge_rows_against_each_rows_own_and_the_closed_form(v, monkeypatch):
    """The Example's inputs on the edge ``x = −v2 = 0`` of ``dom H(t)`` (the multipliers a ray), rounding either
    side of it (``±1e-16``: the resolvent's outputs), at ``v1 = 0`` (a tie: ``max(−v1, 0)`` at its kink) and inside:
    ``H^0 = −max(−v1(t), 0)`` (the closed form), and each row's own call, within the stated tolerance."""
    seen = _accepted(monkeypatch)
    rng = np.random.default_rng(7)
    ts = np.concatenate([rng.uniform(0.0, 10.0, 30), [0.0, np.pi, 2 * np.pi, 1e-12, 2.0 ** -23]])
    X = np.zeros((ts.size, 1))
    X[10:15, 0] = 1e-16 * rng.random(5)
    X[15:20, 0] = rng.exponential(1.0, 5)
    X[20:23, 0] = [1e-300, 5e-324, 1e-9]
    got, want, _ = _both(lambda: _example(v), X, ts)
    closed = -np.maximum(-np.array([v(t)[0] for t in ts]), 0.0)
    tol = _tol(_example(v), X, ts)
    assert (np.abs(got[:, 0] - closed) <= tol).all()
    assert (np.abs(got - want).max(axis=1) <= tol).all()
    assert seen[1] >= 0.9 * seen[0] > 0, seen


def test_rows_outside_the_domain_and_non_finite_are_their_own_calls(monkeypatch):
    """A row outside ``dom H(t)`` raises :class:`OutsideDomain` from the block as from its own call (the block
    never accepts it); a row just outside by rounding (``−4e-16``) has an answer, as its own call does."""
    seen = _accepted(monkeypatch)
    op = _example(RAMP)
    with pytest.raises(OutsideDomain):
        op.min_norm(np.array([[1.0], [0.5], [-1.0], [2.0]]), np.array([0.1, 0.2, 0.3, 0.4]))
    got = op.min_norm(np.array([[-4e-16], [0.0]]), np.array([0.5, 0.25]))
    np.testing.assert_allclose(got, [[-0.5], [-0.25]], rtol=0, atol=_tol(op, np.zeros((2, 1)), [0.5, 0.25]).max())
    assert seen[1] >= 2


def test_block_selection_module_alone_accepts_only_minimisers():
    """:func:`select_rows` on the Example's ``LCP(q, D)`` with ``P = diag(0, 1)``: on the edge (``q2 = 0``)
    ``SOL = {0} × [max(−q1, 0), ∞)`` and the minimiser is ``(0, max(−q1, 0))``; inside (``q2 > 0``) it is the
    unique solution; the rows outside (``q2 < 0`` by a margin) are never accepted."""
    D = ex.D
    P = np.diag([0.0, 1.0])
    F = sr.Faces(D, P)
    q1 = np.array([-2.0, -0.5, 0.0, 0.3, 1e-9, -1e-9, -3.0, 2.0])
    q2 = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.5, -1.0])
    Q = np.stack([q1, q2], axis=1)
    Z, ok = sr.select_rows(F, Q, np.zeros((8, 2)), np.abs(Q).max(axis=1))
    assert ok[:7].all() and not ok[7]
    np.testing.assert_allclose(Z[:7, 1], np.maximum(-q1[:7], 0.0), rtol=0, atol=10 * QP_RTOL)
    np.testing.assert_allclose(Z[:6, 0], 0.0, rtol=0, atol=10 * QP_RTOL)     # w2 = q2 − z1 = −z1 ≥ 0 on the edge
    np.testing.assert_allclose(Z[6, 0], 1.5, rtol=0, atol=10 * QP_RTOL)      # z2 > 0 forces w2 = 1.5 − z1 = 0


def test_block_selection_checks_optimality_not_only_membership():
    """Rows where a face's candidate lies in ``SOL`` but is not the minimiser: the Example's ``LCP(q, D)`` at
    ``q = (0, 1)`` has ``SOL = [0, 1] × {0}``; with ``P = I`` the minimiser is ``0`` and the vertex ``(1, 0)`` (the
    face ``w2 = 0``) is a member of higher objective.  With ``P = 0``, ``c = (0, −1)`` on the edge ``q = (−2, 0)``
    the objective is unbounded below over ``SOL = {0} × [2, ∞)``: no candidate may be accepted (the vertex
    ``(0, 2)`` is in ``SOL`` and passes the residual check; only the KKT check's multiplier sign rejects it),
    while ``c = (0, 1)`` makes it the minimiser."""
    D = ex.D
    Z, ok = sr.select_rows(sr.Faces(D, np.eye(2)), np.array([[0.0, 1.0], [0.0, 3.0]]), np.zeros((2, 2)),
                           np.array([1.0, 3.0]))
    assert ok.all()
    np.testing.assert_allclose(Z, 0.0, rtol=0, atol=10 * QP_RTOL)
    F0 = sr.Faces(D, np.zeros((2, 2)))
    Q = np.array([[-2.0, 0.0], [-2.0, 0.0]])
    Z, ok = sr.select_rows(F0, Q, np.array([[0.0, -1.0], [0.0, 1.0]]), np.array([2.0, 2.0]))
    assert not ok[0] and ok[1]
    np.testing.assert_allclose(Z[1], [0.0, 2.0], rtol=0, atol=10 * QP_RTOL)


def _edge_and_outside_rows(op, seed, B=40):
    """Resolvent outputs (on the domain's faces), the same nudged by ±1e-16·scale, and random points (many outside
    the domain), at random times."""
    rng = np.random.default_rng(seed)
    X, ts = _domain_rows(op, seed, B)
    X[::4] += 1e-16 * rng.normal(size=X[::4].shape) * (1.0 + np.abs(X[::4]))
    X[1::4] = rng.normal(size=X[1::4].shape) * 2.0
    return X, ts


@pytest.mark.parametrize("seed,n,m,relay,rank", SYSTEMS[:5])
def test_block_projection_is_each_rows_own(seed, n, m, relay, rank, monkeypatch):
    """``project_domain`` of a block, whose rows on the domain's edge are proved inside by a face's verified
    multiplier (:func:`verimono.lcs._select_rows.solvable_rows`) and whose rows proved outside are projected
    together (:func:`verimono.lcs._select_rows.project_rows`), against each row's own call, on random passive LCSs
    and the Example's two inputs: the rows inside bit for bit (a row proved inside is its own projection, what
    its own call returns after Lemke's proof), the projections within ``TOL_FACTOR·QP_RTOL`` of the data's size
    (both sides are QP minimisers verified to ``QP_RTOL``; measured ≤ 0.006·QP_RTOL)."""
    seen = []
    orig = sr.project_rows

    def counting(F, c, h):
        Y, ok = orig(F, c, h)
        seen.append(int(ok.sum()))
        return Y, ok
    monkeypatch.setattr("verimono.lcs.system.project_rows", counting)
    for make in (lambda: _psd_system(seed, n, m, relay, rank), lambda: _example(SINE), lambda: _example(RAMP)):
        X, ts = _edge_and_outside_rows(make(), seed)
        one, many = make(), make()
        rows = np.array([one.project_domain(x, t) for x, t in zip(X, ts.tolist())])
        got = many.project_domain(X, ts)
        assert got.shape == rows.shape
        size = 1.0 + np.abs(X).max(axis=1) + np.abs(rows).max(axis=1)
        assert (np.abs(got - rows).max(axis=1) <= TOL_FACTOR * QP_RTOL * size).all()
        inside = (rows == X).all(axis=1)
        assert np.array_equal(got[inside], rows[inside])
    assert sum(seen) >= 8       # the Example's rows outside by a margin: projected by the block


def test_block_projection_proves_the_example_edge_rows(monkeypatch):
    """The Example's edge rows ``x = −v2(t) = 0`` (and 1e-16 either side) are proved inside by the block, not left
    to Lemke one row at a time; rows outside by more than rounding are not."""
    calls = []
    orig = sr.solvable_rows

    def counting(F, Q, scales):
        got = orig(F, Q, scales)
        calls.append((Q.copy(), got.copy()))
        return got
    monkeypatch.setattr("verimono.lcs.system.solvable_rows", counting)
    op = _example(SINE)
    ts = np.linspace(0.1, 9.0, 12)
    X = np.array([[0.0], [1e-16], [-1e-16], [-1e-3]] * 3)
    got = op.project_domain(X, ts)
    Q, proved = calls[-1]
    assert proved[:3].all() and proved[4:7].all() and proved[8:11].all()
    assert not proved[[3, 7, 11]].any()
    np.testing.assert_array_equal(got[[0, 1, 2]], X[[0, 1, 2]])
    np.testing.assert_allclose(got[[3, 7, 11]], 0.0, rtol=0, atol=10 * QP_RTOL)


def test_block_projection_at_each_rows_own_time_on_a_moving_domain():
    """``v = (−1, t − 1)``: ``dom H(t) = [1 − t, ∞)`` moves; rows on and 1e-3 below their own time's edge, the times
    decreasing (each row inside at the first row's time), and rows at ``−3`` (outside at every time): each row's own
    projection, ``max(x, 1 − t_i)`` (data of
    size ≤ 2: the tolerance ``TOL_FACTOR·QP_RTOL·3``)."""
    make = lambda: ex.example_system(lambda t: np.array([-1.0, t - 1.0])).operator()     # noqa: E731
    ts = np.linspace(2.0, 0.0, 9)
    X = (1.0 - ts - np.tile([0.0, 1e-3, 0.0], 3))[:, None]
    X[2::3] = -3.0      # outside at every time: each row's projection its own time's edge
    one, many = make(), make()
    rows = np.array([one.project_domain(x, t) for x, t in zip(X, ts.tolist())])
    got = many.project_domain(X, ts)
    np.testing.assert_allclose(got, rows, rtol=0, atol=TOL_FACTOR * QP_RTOL * 3.0)
    np.testing.assert_allclose(got[:, 0], 1.0 - ts, rtol=0, atol=TOL_FACTOR * QP_RTOL * 3.0)


def test_block_projection_module_alone_takes_the_minimiser():
    """:func:`project_rows` on ``min ½|y − x|²`` over ``y ∈ [−1, 1]`` (``G = (1, −1)ᵀ``, ``h = (1, 1)``): ``x = −2``
    projects to ``−1`` — the active set ``{y ≤ 1}`` comes first in the enumeration and its point ``y = 1`` is
    feasible, but its multiplier is ``−3``: never accepted; ``x = 0.5`` is its own projection, ``x = 5`` goes to 1.
    ``x = 0`` (``c = 0``: every half-space *far* by ``equilibrate``'s rule) is left to its own call."""
    F = sr.ProjectionFaces(np.eye(1), np.array([[1.0], [-1.0]]))
    x = np.array([[-2.0], [0.5], [5.0], [0.0]])
    Y, ok = sr.project_rows(F, -x, np.ones((4, 2)))
    assert ok[:3].all() and not ok[3]
    np.testing.assert_allclose(Y[:3, 0], [-1.0, 0.5, 1.0], rtol=0, atol=10 * QP_RTOL)
