"""The warm-started QPs and the one-row infeasibility proof of :mod:`verimono.lcs._warm_qp`: the same answers as
:func:`verimono.core.qp.solve_qp` and the linear program they spare, on the paper's Example."""

import numpy as np
from pytest import approx

from verimono.core.qp import solve_qp
from verimono.core.tolerances import QP_RTOL
from verimono.lcs._warm_qp import INFEASIBLE_MARGIN, row_infeasible, solve_qp_warm
from verimono.lcs.lcp import _feasible
from verimono.reference.lcs_example import D, example_system


def _projection_qp(x, v):
    """The projection onto ``dom H = [−v2, ∞)`` of the Example as ``LCSOperator.project_domain`` poses it."""
    P = np.diag([1.0, 0.0, 0.0])
    G = np.block([[np.zeros((2, 1)), -np.eye(2)], [-np.array([[0.0], [1.0]]), -D]])
    return P, np.array([-x, 0.0, 0.0]), G, np.concatenate([np.zeros(2), v])


def test_warm_qp_is_solve_qp_on_the_example_projection():
    """``solve_qp``'s minimiser ``x' = max(x, −v2)`` at points on both sides of the domain's edge, and correct
    again after its memory is given a wrong active set (verified, so it falls back).  Only ``x'`` is unique
    (``P = diag(1, 0, 0)``: the multipliers of a point on the edge are not), so only ``x'`` is compared with
    ``solve_qp``'s, to the QPs' verification tolerance: ProxQP (the first back-end) and DAQP return different
    multipliers, and ``x'`` agreeing to 1.6e-12 (ProxQP) or bit for bit (DAQP, on the polished active set)."""
    memory: dict = {}
    rng = np.random.default_rng(0)
    for x, v1, v2 in zip(rng.uniform(-3, 1, 40), rng.uniform(-2, 2, 40), rng.uniform(-1, 1, 40)):
        args = _projection_qp(x, np.array([v1, v2]))
        z, ref = solve_qp_warm(memory, *args), solve_qp(*args)
        scale = 1 + abs(x) + abs(v1) + abs(v2)
        assert abs(z[0] - ref[0]) <= QP_RTOL * scale
        assert abs(z[0] - max(x, -v2)) <= QP_RTOL * scale
        assert z[1] >= -QP_RTOL * scale and z[2] >= -QP_RTOL * scale    # the multipliers are feasible
    assert memory and all(1 <= len(s) <= 4 for s in memory.values())
    for sets in memory.values():    # every remembered active set replaced by a wrong one: still the minimiser
        sets[:] = [np.zeros_like(sets[0])]
    args = _projection_qp(-2.0, np.array([1.0, 0.5]))
    assert abs(solve_qp_warm(memory, *args)[0] - (-0.5)) <= 1e-12


def test_row_infeasible_agrees_with_the_linear_program():
    """``FEA(η, D)`` of the Example, ``η = (v1, x + v2)``, is empty iff ``x + v2 < 0`` (row 2: ``−z1 + x + v2``):
    the one-row proof says so beyond its margin, leaves the band within it to the LP, never contradicts it."""
    for x in (-5.0, -1.0, -1e-3, -2e-5, -1e-9, 0.0, 1e-9, 1.0):
        q = np.array([-0.5, x])
        proof = row_infeasible(D, q)
        assert proof == (x < -INFEASIBLE_MARGIN * (1 + max(abs(x), 0.5) + 1))
        if proof:
            assert not _feasible(D, q)


def test_project_domain_and_min_norm_closed_forms():
    """``proj_dom H(t)(x) = max(x, −v2)`` and ``H^0(t, x) = −max(−v1, 0)`` on the domain (the closed forms of
    ``reference/lcs_example.py``), through the warm-started QPs, at points in, on the edge of and outside it."""
    H = example_system(lambda t: np.array([-t, 0.0])).operator()
    for t in np.linspace(0.0, 2.0, 9):
        for x in (-2.0, -1e-3, 0.0, 1e-6, 0.7):
            assert abs(H.project_domain(np.array([x]), t)[0] - max(x, 0.0)) <= QP_RTOL * (1 + abs(x) + t)
        for x in (0.0, 0.0, 1e-6, 0.7):
            assert abs(H.min_norm(np.array([x]), t)[0] + t) <= 1e-9 * (1 + t)


def test_resolvent_alternating_between_patterns_solves_twice_and_answers_the_closed_form():
    """Points alternately inside ``dom H`` and sent to its edge (two active patterns): the resolvent's stepper
    answers ``J = max(x + λ max(−v1, 0), −v2)`` (closed form) from its remembered patterns after one full solve
    per pattern, not one per change of pattern."""
    from verimono.reference.lcs_example import closed_form_resolvent

    op = example_system(lambda t: np.array([-t, 0.0])).operator()
    lam, t = 0.1, 0.5
    for k in range(20):
        x = np.array([0.4 + 0.01 * k if k % 2 else -0.4 - 0.01 * k])
        assert op.resolvent(x, lam, t) == approx(closed_form_resolvent(x, lam, -t, 0.0), abs=1e-14)
    assert op._mats[lam].step.full_solves == 2


def test_memo_answers_again_with_a_fresh_copy():
    """``H^0`` and ``proj_dom H`` asked again at the same ``(t, x)`` are the closed forms, computed once, and a
    caller writing into an answer does not change the next one."""
    H = example_system(lambda t: np.array([np.sin(t), 0.0])).operator()
    for _ in range(2):
        p = H.project_domain(np.array([-1.5]), 4.0)
        assert p[0] == approx(0.0, abs=1e-12)
        p[0] = 7.0
        f = H.min_norm(np.array([0.25]), 4.0)
        assert f[0] == approx(-max(-np.sin(4.0), 0.0), abs=1e-12)
        f[0] = 7.0
    assert len(H._memo) == 2
