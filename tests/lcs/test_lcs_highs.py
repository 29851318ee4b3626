"""HiGHS without ``linprog``'s wrapper (:mod:`verimono.lcs._highs`, issue 43 item 3): the same model, options and
acceptance test, so the same status, objective and point, bit for bit, as ``scipy.optimize.linprog(...,
method="highs")`` — on random LPs (optimal, infeasible, unbounded; ties, integer data, all scales), on the LPs of
``lcs.rel_int`` and of ``shorter_solution``; and the rel_int law's memo of ``t ↦ margin`` solves each LP once
and answers what the LP answers."""

import warnings

import numpy as np
from scipy.optimize import linprog

import verimono.checks.section7 as section7
import verimono.lcs.hypotheses as hyp
from verimono.lcs import Complementarity, LinearRelationSystem, Relay
from verimono.core._highs import linprog_highs
from verimono.reference.lcs_example import example_system


def _bits(a):
    return None if a is None else np.asarray(a, dtype=float).tobytes()


def _via_linprog(c, A_ub, b_ub, A_eq=None, b_eq=None, lb=None, ub=None):
    """The reference: ``linprog`` itself, its answer as ``linprog_highs`` returns it."""
    nv = len(c)
    lb = np.zeros(nv) if lb is None else lb
    ub = np.full(nv, np.inf) if ub is None else ub
    bounds = [(None if np.isinf(lo) else lo, None if np.isinf(hi) else hi) for lo, hi in zip(lb, ub)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # linprog warning about its options would be a different model
        r = linprog(c, A_ub=A_ub if len(b_ub) else None, b_ub=b_ub if len(b_ub) else None, A_eq=A_eq,
                    b_eq=b_eq, bounds=bounds, method="highs")
    return r.status, r.fun if r.x is not None else None, r.x


def _answer(out):
    status, fun, x = out
    return status, None if fun is None else float(fun).hex(), _bits(x)


def test_random_lps_are_linprogs_answers_bit_for_bit():
    rng = np.random.default_rng(7)
    statuses = set()
    for k in range(200):
        nv, nr, ne = int(rng.integers(1, 8)), int(rng.integers(0, 8)), int(rng.integers(0, 3))
        A = rng.normal(size=(nr, nv)) * (rng.random((nr, nv)) < 0.6)          # sparse: zeros dropped by CSC
        if k % 3 == 0:
            A = np.round(A)                                                     # ties in the ratio tests
        b = rng.normal(size=nr) * 10.0 ** rng.uniform(-8, 3)
        Ae, be = rng.normal(size=(ne, nv)), rng.normal(size=ne)
        c = rng.normal(size=nv) * (rng.random(nv) < 0.8)
        lb = np.where(rng.random(nv) < 0.5, -np.inf, rng.normal(size=nv) - 1)
        ub = np.maximum(np.where(rng.random(nv) < 0.5, np.inf, rng.normal(size=nv) + 1), lb)
        eq = (Ae, be) if ne else (None, None)
        want = _answer(_via_linprog(c, A, b, *eq, lb, ub))
        statuses.add(want[0])
        assert _answer(linprog_highs(c, A, b, *eq, lb, ub)) == want, k
    assert statuses >= {0, 2, 3}                # optimal, infeasible and unbounded LPs all compared


def _systems():
    rng = np.random.default_rng(11)
    yield example_system(lambda t: np.array([-t, 0.0]))
    yield example_system(lambda t: np.array([np.sin(t), 0.0]))
    for k in range(6):
        n, m = 2, 2 + k % 2
        R = rng.normal(size=(m, m))
        D = R @ R.T * (k % 3 != 0) + (R - R.T)                     # PSD, some singular (skew only)
        rel = Complementarity() if k % 2 else Relay(-1.0, 1.0 + k)
        w = rng.normal(size=m)
        yield LinearRelationSystem(-np.eye(n), rng.normal(size=(n, m)), rng.normal(size=(m, n)), D, rel,
                                   v=lambda t, w=w: w * np.cos(3 * t) - 0.5)


def test_rel_int_margin_and_shorter_solution_are_linprogs_bit_for_bit(monkeypatch):
    systems = list(_systems())
    ts = [0.0, 1e-12, 0.25, 1.0, 1.7, 2.0]
    fast = [hyp.rel_int_margin(s, t) for s in systems for t in ts]
    rng = np.random.default_rng(2)
    D = np.array([[0.0, 1.0], [-1.0, 0.0]])                        # the Example's D: SOL not a singleton
    lcps = [(D, q, z) for q, z in ((np.array([1.0, 0.0]), np.array([0.0, 2.0])),
                                   (np.array([0.5, 0.0]), np.array([0.0, 1.0])))]
    for _ in range(20):
        R = rng.normal(size=(3, 3)) * (rng.random((3, 3)) < 0.5)
        M = R @ R.T
        z = np.abs(rng.normal(size=3)) * (rng.random(3) < 0.6)
        lcps.append((M, np.maximum(-(M @ z), 0.0) - M @ z + np.where(z > 0, 0.0, 1.0), z))
    fast_short = [_bits(hyp.shorter_solution(M, q, z)) for M, q, z in lcps]
    monkeypatch.setattr(hyp, "linprog_highs", _via_linprog)
    assert [m.hex() for m in fast] == [hyp.rel_int_margin(s, t).hex() for s in systems for t in ts]
    assert fast_short == [_bits(hyp.shorter_solution(M, q, z)) for M, q, z in lcps]
    assert fast_short[0] is not None                                # a shorter solution found and compared


def test_rel_int_memo_solves_each_lp_once_and_answers_the_lp(monkeypatch):
    solved, answers = [], []

    def margin(system, t):
        solved.append(t)
        answers.append(hyp.rel_int_margin(system, t))
        return answers[-1]

    monkeypatch.setattr(section7, "rel_int_margin", margin)
    system = example_system(lambda t: np.array([np.sin(3 * t) - 0.2, 0.0]))
    out = section7.check_rel_int(system, 2.0, samples=17, seed=0)
    assert len(solved) == len(set(solved))                          # each t's LP once
    assert set(np.linspace(0.0, 2.0, 17).tolist()) <= set(solved)   # the grid among them, and searched beyond
    assert len(solved) > 17
    # what the law reports is what the LPs say: its grid margins, its search's least margin the LP's at the time
    # the search names, and its worst the least of all solved
    assert out.details["margins"] == [hyp.rel_int_margin(system, t) for t in out.details["t"]]
    found = out.details["min_search"]
    assert -found["sup"] == hyp.rel_int_margin(system, found["t"])
    assert -out.worst == min(answers)


def test_lcp_feasibility_and_infeasibility_certificate_are_linprogs(monkeypatch):
    """``lcp._feasible`` and ``lcp._infeasibility_certificate`` (the LPs behind ``dom H`` and the infeasible-step
    message) answer as through ``linprog``, bit for bit, on feasible and infeasible LCPs of PSD and skew ``M``."""
    import verimono.lcs.lcp as lcp

    rng = np.random.default_rng(3)
    cases = []
    for k in range(40):
        R = rng.normal(size=(3, 3))
        M = (R @ R.T * (rng.random((3, 3)) < 0.7), R - R.T, np.diag([1.0, 0.0, 0.0]))[k % 3]
        cases.append((M, rng.normal(size=3) * 10.0 ** rng.uniform(-3, 3)))
    fast = [(lcp._feasible(M, q), _bits(lcp._infeasibility_certificate(M, q))) for M, q in cases]
    monkeypatch.setattr(lcp, "linprog_highs", _via_linprog)
    assert fast == [(lcp._feasible(M, q), _bits(lcp._infeasibility_certificate(M, q))) for M, q in cases]
    assert {f for f, _ in fast} == {True, False} and any(c is not None for _, c in fast)


def test_without_scipys_private_highs_modules_linprog_itself_answers(monkeypatch):
    """Another SciPy, whose private HiGHS modules are not the ones ``_highs`` reads: ``linprog`` is called, and
    answers as the direct path does."""
    import verimono.core._highs as highs

    rng = np.random.default_rng(4)
    cases = []
    for _ in range(30):
        A, b = rng.normal(size=(4, 3)), rng.normal(size=4)
        cases.append((rng.normal(size=3), A, b, None, None, np.full(3, -2.0), np.full(3, np.inf)))
    direct = [_answer(linprog_highs(*case)) for case in cases]
    monkeypatch.setattr(highs, "_state", {"h": None})
    assert [_answer(linprog_highs(*case)) for case in cases] == direct
    assert {s for s, _, _ in direct} >= {0}


def test_models_kept_by_their_fixed_arrays_answer_each_lp_as_linprog():
    """``linprog_highs`` keeps each model's part that does not depend on ``b_ub`` (branch units9): LPs that differ
    from a kept one in any one other array (``c``, ``A_ub``, ``A_eq``, ``b_eq``, ``lb``, ``ub``, the rows' count) or
    in ``b_ub`` alone, asked one after the other, each get ``linprog``'s own answer bit for bit — each change
    chosen to move the optimum, so a model kept under a key that misses it answers another LP."""
    base = dict(c=np.array([1.0, -1.0, 0.5]), A_ub=np.array([[1.0, 1.0, 0.0], [-1.0, 2.0, 1.0]]),
                b_ub=np.array([4.0, 3.0]), A_eq=np.array([[1.0, -1.0, 1.0]]), b_eq=np.array([0.5]),
                lb=np.array([-1.0, -2.0, -np.inf]), ub=np.array([3.0, np.inf, 2.0]))
    moved = {"c": (0, 0.25), "A_ub": (3, 0.25), "b_ub": (1, 0.25), "A_eq": (0, 0.25), "b_eq": (0, 0.25),
             "lb": (0, 0.25), "ub": (2, -0.5)}                 # (flat index, change) of one entry
    variants = [dict(base)]
    for k, (i, d) in moved.items():
        w = base[k].copy()
        w.flat[i] += d
        variants.append(dict(base, **{k: w}))
    variants.append(dict(base, A_ub=np.vstack([base["A_ub"], [0.0, 1.0, 1.0]]), b_ub=np.array([4.0, 3.0, 1.0])))
    first = _answer(_via_linprog(**base))
    for _ in range(2):                                      # the second pass reads every kept model
        for k, v in enumerate(variants):
            want = _answer(_via_linprog(**v))
            assert want[0] == 0 and (k == 0 or want != first), k    # optimal, and another optimum than base's
            assert _answer(linprog_highs(**v)) == want, k


def _random_lps(seed: int, count: int):
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        nv, nr, ne = int(rng.integers(1, 8)), int(rng.integers(0, 8)), int(rng.integers(0, 3))
        A = rng.normal(size=(nr, nv)) * (rng.random((nr, nv)) < 0.6)
        if k % 3 == 0:
            A = np.round(A)
        b = rng.normal(size=nr) * 10.0 ** rng.uniform(-8, 3)
        Ae, be = rng.normal(size=(ne, nv)), rng.normal(size=ne)
        c = rng.normal(size=nv) * (rng.random(nv) < 0.8)
        lb = np.where(rng.random(nv) < 0.5, -np.inf, rng.normal(size=nv) - 1)
        ub = np.maximum(np.where(rng.random(nv) < 0.5, np.inf, rng.normal(size=nv) + 1), lb)
        out.append((c, A, b, *((Ae, be) if ne else (None, None)), lb, ub))
    return out


def test_the_kept_highs_instance_answers_as_a_fresh_one_in_any_order():
    """``linprog_highs`` keeps one HiGHS instance per thread, ``clear()``-ed before each LP (branch perf10: making
    one was half of a margin LP's call): an LP's answer does not depend on what the instance solved before it —
    each of 150 random LPs (optimal, infeasible, unbounded, degenerate) and the Example's margin LPs, solved after
    others in a shuffled order, gives its answer on a new instance bit for bit."""
    from verimono.core import _highs
    from verimono.lcs.hypotheses import _margin_lp

    system = example_system(lambda t: np.array([-t, 0.0]))
    c, A_ub, head, tail, A_eq, b_eq, lb, ub = _margin_lp(system, system.relation)
    cases = _random_lps(11, 150) + [(c, A_ub, np.concatenate([head + np.array([-t, 0.0]), tail]), A_eq, b_eq, lb, ub)
                                    for t in np.linspace(0.0, 2.0, 30)]

    def fresh(case):
        _highs._LOCAL.highs = None          # a new instance for this LP alone
        return _answer(linprog_highs(*case))

    alone = [fresh(case) for case in cases]
    order = np.random.default_rng(3).permutation(len(cases)).tolist()
    _highs._LOCAL.highs = None
    for i in order + order[::-1]:
        assert _answer(linprog_highs(*cases[i])) == alone[i], i
    assert {a[0] for a in alone} >= {0, 2, 3}
