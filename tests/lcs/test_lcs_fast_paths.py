"""The small-problem fast paths of the LCS and QP hot path (issue 43 item 3, the paper's Example): each computes
what the code it replaces computed, bit for bit, or is the same verified computation with a check skipped only
where it cannot fire.  Each test compares against the reference computation (NumPy's or SciPy's own function,
the NumPy form of Lemke's pivoting) on random data chosen to hit ties, rank deficiency and all scales, so a
fast path that rounds differently or decides differently is caught; and a planted wrong pattern must still be
rejected by the box stepper's verification."""

import numpy as np
import pytest

import verimono.core.qp as qp
import verimono.lcs.lcp as lcp
from verimono.core._linalg import SMALL, absmax, eigvalsh_values, lstsq_solution, singular_values, svd_reduced
from verimono.lcs.relations import Complementarity, Relay


def _bits(a):
    return None if a is None else np.asarray(a).tobytes()


def _lcps(rng, count):
    """LCPs of size 1-6: PSD, skew (the Example's kind), general and integer ones (ties in the ratio test)."""
    for k in range(count):
        n = int(rng.integers(1, 7))
        A = rng.normal(size=(n, n))
        M = (A @ A.T, A - A.T, A, np.round(A))[k % 4] * 10.0 ** int(rng.integers(-6, 7))
        q = rng.normal(size=n) * 10.0 ** int(rng.integers(-4, 5))
        yield M, (np.round(q) if k % 3 == 0 else q)


def test_lemke_in_python_floats_is_the_numpy_pivoting_bit_for_bit(monkeypatch):
    """Lemke's pivots in Python floats give NumPy's ``(z, status)`` bit for bit, solved, ray-terminated or tied."""
    rng = np.random.default_rng(3)
    cases = list(_lcps(rng, 1500))
    fast = [lcp.lemke(M, q) for M, q in cases]
    monkeypatch.setattr(lcp, "LEMKE_SMALL", 0)           # the NumPy pivoting for every size
    slow = [lcp.lemke(M, q) for M, q in cases]
    statuses = {s for _, s in slow}
    assert statuses >= {"solved", "ray termination"}     # both outcomes are exercised
    assert [(s, _bits(z)) for z, s in fast] == [(s, _bits(z)) for z, s in slow]


def test_linalg_gufuncs_are_numpys_functions_bit_for_bit():
    """``lstsq_solution``, ``svd_reduced``, ``singular_values``: NumPy's answers bit for bit (rank-deficient and
    badly scaled matrices included) and NumPy's ``LinAlgError`` on data LAPACK cannot handle."""
    rng = np.random.default_rng(4)
    for k in range(1500):
        m, n = (int(v) for v in rng.integers(1, 8, 2))
        a = rng.normal(size=(m, n)) * 10.0 ** int(rng.integers(-8, 9))
        if k % 3 == 0 and n > 1:
            a[:, -1] = a[:, 0]                                          # rank deficient
        elif k % 3 == 1 and n > 1:
            a[:, -1] = a[:, 0] + 1e-13 * np.abs(a).max() * rng.normal(size=m)   # near it: rcond decides the rank
        b = rng.normal(size=m)
        assert _bits(lstsq_solution(a, b)) == _bits(np.linalg.lstsq(a, b, rcond=None)[0])
        assert [_bits(x) for x in svd_reduced(a)] == [_bits(x) for x in np.linalg.svd(a, full_matrices=False)]
        assert _bits(singular_values(a)) == _bits(np.linalg.svd(a, compute_uv=False))
    bad = np.full((2, 2), np.nan)
    for f in (lambda: lstsq_solution(bad, np.ones(2)), lambda: svd_reduced(bad), lambda: singular_values(bad)):
        with pytest.raises(np.linalg.LinAlgError):
            f()


def test_eigvalsh_values_is_numpys_eigvalsh_bit_for_bit():
    """``eigvalsh_values`` (``is_psd``'s eigenvalues, branch units9): ``np.linalg.eigvalsh``'s answer bit for bit on
    symmetric and non-symmetric matrices (only the lower triangle is read: ``UPLO="L"``), PSD ones on the edge, all
    scales, non-finite ones (NumPy's NaNs); NumPy's own function for other dtypes and empty matrices."""
    rng = np.random.default_rng(5)
    for k in range(1500):
        n = int(rng.integers(1, 9))
        a = rng.normal(size=(n, n)) * 10.0 ** int(rng.integers(-8, 9))
        a = (a + a.T, a @ a.T, a - a.T, a)[k % 4]                      # symmetric, PSD, skew, neither
        assert _bits(eigvalsh_values(a)) == _bits(np.linalg.eigvalsh(a)), k
    for a in (np.eye(3, dtype=int), np.zeros((0, 0)), np.eye(2, dtype=np.float32), np.full((2, 2), np.nan),
              np.array([[np.inf, 0.0], [0.0, 1.0]]), np.array([[1.0, np.nan], [0.0, 1.0]])):
        assert _bits(eigvalsh_values(a)) == _bits(np.linalg.eigvalsh(a))


@pytest.mark.parametrize("values", [[], [0.0], [-0.0, 0.0], [1.0, -3.0, 2.0], [np.inf, 1.0], [-np.inf],
                                    [1.0, np.nan, 5.0], [np.nan], [5.0, 1.0, np.nan]])
def test_absmax_is_numpys_max_of_abs(values):
    """``absmax`` is ``np.abs(a).max(initial=0.0)``: the same float, NaN wherever an entry is NaN."""
    for a in (np.array(values, dtype=float), np.array(values, dtype=float).reshape(-1, 1),
              np.resize(np.array(values or [0.0], dtype=float), SMALL + 3)):
        ref = float(np.abs(a).max(initial=0.0))
        got = absmax(a)
        assert (got == ref and np.signbit(got) == np.signbit(ref)) or (np.isnan(got) and np.isnan(ref))


def test_kkt_residual_and_equilibrate_with_their_shortcuts_are_the_plain_computation(monkeypatch):
    """``kkt_residual`` through SciPy's NNLS routine and ``equilibrate`` through the cached unit rows and the
    far-row shortcut report what the public ``nnls``, uncached rows and the far-row loop report, bit for bit,
    on random QPs with zero rows, far rows and repeated constraint matrices (the cache must not leak a row)."""
    rng = np.random.default_rng(5)
    cases = []
    G0 = rng.normal(size=(4, 3))
    for k in range(300):
        n, m = 3, 4
        P = rng.normal(size=(n, n)); P = P @ P.T
        G = G0.copy() if k % 2 else rng.normal(size=(m, n))
        h = rng.normal(size=m) * 10.0 ** int(rng.integers(-3, 4))
        if k % 5 == 0:
            G[1] = 0.0; h[1] = abs(h[1])                # a zero row, consistent
        if k % 7 == 0:
            h[2] = 1e30                                 # a far half-space
        cases.append((P, rng.normal(size=n), G, h, rng.normal(size=(1, n)), rng.normal(size=1), rng.normal(size=n)))

    def run():
        out = []
        for P, q, G, h, A, b, z in cases:
            S = qp.equilibrate(P, q, G, h, A, b, None)
            S.G[...] = -1.0 if S.G is not None else 0.0   # a caller writing into its rows must not reach the cache
            S = qp.equilibrate(P, q, G, h, A, b, None)
            rep = qp.kkt_residual(S.P, S.q, S.G, S.h, S.A, S.b, z / S.scale)
            out.append([_bits(x) for x in (S.P, S.q, S.G, S.h, S.A, S.b, S.G_far, S.h_far)]
                       + [S.scale, rep.primal, rep.dual, rep.comp, rep.ok])
        return out

    fast = run()
    real_far = qp._far

    def far_loop(h, core):      # the far-row loop with no shortcut
        far = np.zeros(h.shape, dtype=bool)
        size = core
        order = np.argsort(h)
        for pos, i in enumerate(order):
            if h[i] > qp.FAR * size:
                far[order[pos:]] = True
                break
            size = max(size, abs(float(h[i])))
        return far

    monkeypatch.setattr(qp, "_ROUTINES", (qp._nnls_routines()[0], None))     # the public nnls, no shortcut
    monkeypatch.setattr(qp, "_far", far_loop)
    qp._UNIT_ROWS.clear()
    monkeypatch.setattr(qp, "_UNIT_ROWS", type("NoCache", (dict,), {"__setitem__": lambda *a: None})())
    assert run() == fast
    assert real_far(np.array([1.0, np.nan, 1e30]), 1.0).tolist() == far_loop(np.array([1.0, np.nan, 1e30]), 1.0).tolist()


@pytest.mark.parametrize("relation", [Complementarity(), Relay(-1.0, 1.0)])
def test_box_stepper_rejects_a_planted_wrong_pattern(relation):
    """Every remembered pattern replaced by a wrong one before each call: the stepper's answer is still the
    relation's verified solution (a pattern is only a guess that the strict-complementarity test checks; the
    checks that test skips — an upper bound +∞, no row at a bound — are those that cannot fire).  Relay's finite
    upper bounds make the upper check fire: interior patterns there put a multiplier beyond the bound."""
    rng = np.random.default_rng(6)
    M = np.array([[2.0, 0.5], [-0.5, 1.0]])          # positive definite: one solution per q
    step = relation.stepper(M)
    patterns = [np.array(p, dtype=np.int8).tobytes() for p in ((1, 1), (0, 0), (1, 0), (0, 1), (2, 1), (1, 2), (2, 2))]
    for q in rng.normal(size=(60, 2)) * 3.0:
        ref = relation.solve(M, q)
        z, w = step(q)
        assert np.allclose(z, ref.z, rtol=1e-9, atol=1e-9) and np.allclose(w, ref.w, rtol=1e-9, atol=1e-9)
        wrong = [p for p in patterns if p != step.last and (relation.name == "Relay" or 2 not in p)]
        step.last, step.recent = wrong[0], wrong[1:]
        z, w = step(q)
        assert np.allclose(z, ref.z, rtol=1e-9, atol=1e-9) and np.allclose(w, ref.w, rtol=1e-9, atol=1e-9)


def _result_bits(r):
    return (_bits(r.z), _bits(r.w), r.residual, r.scale, r.backend, r.psd, r.unique, r.least_norm, r.reasons)


def test_unit_memo_returns_the_unit_solve_bit_for_bit(monkeypatch):
    """``solve_lcp`` with its memory of unit-scaled solves: the same ``LCPResult`` as without it, bit for bit,
    on LCPs repeated at many scales (``q·t``: the same unit data, as the Example's edge ``LCP((−t, 0), D)``);
    a caller writing into an answer does not reach the memory; a back-end replaced is a new key."""
    rng = np.random.default_rng(7)
    D = np.array([[0.0, 1.0], [-1.0, 0.0]])
    cases = [(D, np.array([-1.0, 0.0]) * t) for t in (1e-9, 0.5, 1.0, 3.0, 1e6)]
    for k in range(40):
        A = rng.normal(size=(3, 3))
        M = A @ A.T if k % 2 else A - A.T + 0.1 * np.eye(3)
        q = rng.normal(size=3)
        cases += [(M, q * t) for t in (1.0, 2.0 ** -7, 1e3)]

    def run():
        out = []
        for M, q in cases:
            r = lcp.solve_lcp(M, q, least_norm=bool(len(out) % 2), info=True)
            out.append(_result_bits(r))
            r.z[...] = np.nan; r.reasons.append("written by the caller")
        return out

    lcp._UNIT_MEMO.clear()
    fast = run()
    assert lcp._UNIT_MEMO          # the repeats were remembered
    monkeypatch.setattr(lcp, "_UNIT_MEMO", type("NoCache", (dict,), {"__setitem__": lambda *a: None})())
    assert run() == fast
    monkeypatch.undo()
    assert lcp.solve_lcp(D, np.array([-2.0, 0.0]), info=True).backend.startswith("lemke")
    monkeypatch.setitem(lcp.BACKENDS, "lemke", lambda M, q: (None, "no answer (replaced)"))
    assert lcp.solve_lcp(D, np.array([-2.0, 0.0]), info=True).backend.startswith("qp")


def test_warm_qp_trial_memo_is_the_trial_bit_for_bit(monkeypatch):
    """The Example's minimal sections and projections (its selection and projection QPs, warm-started) with the
    memory of verified KKT trials: the same points, bit for bit, as without it, on the edge ``x = 0`` of
    ``dom H(t,·)`` (the same equilibrated QP at every ``t``), inside and outside it; a wrong active set planted
    in every warm memory is still refused (the trial is remembered with its verdict, not trusted)."""
    import verimono.lcs._warm_qp as W
    from verimono.reference.lcs_example import example_system

    ts = np.linspace(0.01, 2.0, 16)
    xs = [0.0, 0.0, 0.3, -0.2, 1e-9]

    def run(plant=False):
        op = example_system(lambda t: np.array([-np.sin(3 * t), 0.0])).operator()
        out = []
        for t in ts:
            if plant:
                for memory in (op._warm_select, op._warm_project):
                    for sets in memory.values():
                        sets.insert(0, ~sets[0])
            for x in xs:
                p = op.project_domain(np.array([x]), t)
                out.append((p.tobytes(), op.min_norm(p, t).tobytes()))
        return out

    W._TRIALS.clear()
    fast, planted = run(), run(plant=True)
    assert len(W._TRIALS) > 0
    monkeypatch.setattr(W, "_TRIALS", type("NoCache", (dict,), {"__setitem__": lambda *a: None})())
    assert run() == fast
    assert run(plant=True) == planted
    for (p, f0), t in zip(fast[::len(xs)], ts):      # x = 0: the edge, H^0 = −max(sin 3t, 0)
        assert np.frombuffer(f0)[0] == pytest.approx(-max(np.sin(3 * t), 0.0), abs=1e-12)


def _resolvent_run(op, rng):
    """Resolvents of ``op`` over 20 step sizes cycled (more than the 16 live steppers: each is made again) at
    points inside ``dom H``, at its edge and beyond it, several times: their bits, and the full solves counted
    by the relation."""
    rel = op.system.relation
    full = []
    solve = rel.solve
    rel.solve = lambda *a, **k: (full.append(1), solve(*a, **k))[1]
    lams = 10.0 ** rng.uniform(-6, 2, 20)
    out = []
    for k in range(240):            # runs of 6 calls per λ (patterns alternate within a run), 20 λ cycled twice
        lam = float(lams[(k // 6) % 20])
        x = rng.normal(size=op.dim) * 10.0 ** rng.uniform(-3, 2)
        out.append(op.resolvent(x, lam, float(rng.uniform(0, 2))).tobytes())
    del rel.solve
    return out, len(full)


def test_step_matrices_made_once_answer_as_new_ones_bit_for_bit(monkeypatch):
    """``LCSOperator._sm`` makes each step size's matrices once and a fresh stepper from them when a live one
    was forgotten: the same resolvents, bit for bit, and the same full solves (a fresh stepper remembers no
    pattern) as a new ``StepMatrices`` each time; and the kept matrices are bit for bit new ones."""
    from verimono.lcs import Complementarity, LinearRelationSystem, Relay
    from verimono.lcs.relations import _BoxStepper
    from verimono.execution.workers import blas_limited
    from verimono.reference.lcs_example import example_system

    with blas_limited():    # one BLAS thread, as the run holds it: OpenBLAS's threads cost 5-15 ms a 1x1 solve here
        rng = np.random.default_rng(5)
        C = rng.normal(size=(2, 2))
        S = rng.normal(size=(2, 2))
        # B = Cᵀ, A = −I: M = D + λ/(1+λ) C Cᵀ, positive definite (complementarity) or PSD (a bounded box): solvable
        systems = [lambda: example_system(lambda t: np.array([np.sin(t), 0.0])),
                   lambda: LinearRelationSystem(-np.eye(2), C.T, C, S @ S.T + np.eye(2),
                                                Complementarity(), v=lambda t: np.array([np.cos(t), -0.5])),
                   lambda: LinearRelationSystem(-np.eye(2), C.T, C, S - S.T, Relay(-1.0, 2.0),
                                                v=lambda t: np.array([np.cos(t), t]))]
        fast = []
        for make in systems:
            op = make().operator()
            fast.append(_resolvent_run(op, np.random.default_rng(1)))
            assert len(op._templates) == 20
            for key, tpl in op._templates.items():
                new = op.system.step_matrices(float.fromhex(key), 1.0, None)
                assert [_bits(a) for a in (tpl.E, tpl.G, tpl.M, *tpl.lu)] == \
                    [_bits(a) for a in (new.E, new.G, new.M, *new.lu)]
        assert all(n > 0 for _, n in fast)                   # full solves happen, and are compared
        monkeypatch.setattr(_BoxStepper, "fresh", lambda self: _BoxStepper(self.rel, self.M))    # new each time
        assert [_resolvent_run(make().operator(), np.random.default_rng(1)) for make in systems] == fast


def test_batched_resolvent_rows_are_the_point_resolvents_bit_for_bit():
    """``LCSOperator.resolvent`` of a batch (``_rows``: the step matrices and ``v(t)`` looked up once) answers
    each row as the one-point resolvent does, bit for bit, and leaves its stepper as the rows one by one would
    (the same full solves, last and recent patterns): rows inside ``dom H``, at its edge and beyond, in runs."""
    from verimono.execution.workers import blas_limited
    from verimono.lcs import LinearRelationSystem, Relay
    from verimono.reference.lcs_example import example_system

    rng = np.random.default_rng(8)
    S = rng.normal(size=(2, 2))
    C = rng.normal(size=(2, 2))
    makes = [lambda: example_system(lambda t: np.array([np.sin(t), 0.0])),
             lambda: LinearRelationSystem(-np.eye(2), C.T, C, S - S.T, Relay(-1.0, 2.0),
                                          v=lambda t: np.array([np.cos(t), t]))]
    with blas_limited():
        for make in makes:
            batched, single = make().operator(), make().operator()
            for k in range(30):
                lam, t = float(10.0 ** rng.uniform(-4, 1)), float(rng.uniform(0, 2))
                X = rng.normal(size=(int(rng.integers(1, 12)), batched.dim)) * 10.0 ** rng.uniform(-3, 1)
                X[::3] = np.abs(X[::3]) * (k % 2)       # runs of the domain's edge and inside it
                got = batched.resolvent(X, lam, t)
                want = np.array([single.resolvent(x, lam, t) for x in X])
                assert got.shape == want.shape and _bits(got) == _bits(want)
                a, b = batched._mats[lam].step, single._mats[lam].step
                assert (a.full_solves, a.last, a.recent) == (b.full_solves, b.last, b.recent)


def test_pattern_sets_are_each_patterns_own_index_sets_and_read_only():
    """``relations._pattern_sets`` (branch units9: a pattern's index sets made once, shared by the steppers of every
    step size): for every pattern of ``m ≤ 4`` multipliers, the sets ``_BoxStepper._entry`` made per stepper —
    rows at the upper bound, inner, at the lower bound — and whether each is nonempty; asked again, the same
    arrays, which refuse writes."""
    import itertools

    from verimono.lcs.relations import _pattern_sets

    for m in range(1, 5):
        for labels in itertools.product((0, 1, 2), repeat=m):
            s = np.array(labels, dtype=np.int8)
            pat = s.tobytes()
            two, I, lo, hi, inner, lower, upper = _pattern_sets(pat)
            assert two.tolist() == (s == 2).tolist()
            assert (I.tolist(), lo.tolist(), hi.tolist()) == tuple(np.flatnonzero(s == k).tolist() for k in (1, 0, 2))
            assert (inner, lower, upper) == (bool((s == 1).any()), bool((s == 0).any()), bool((s == 2).any()))
            assert _pattern_sets(pat)[1] is I
            with pytest.raises(ValueError):
                I[...] = 0
