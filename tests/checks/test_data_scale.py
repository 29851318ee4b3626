"""The operator's own scale in the one tolerance rule (verimono.core.tolerances, "the operator's own scale";
verimono.checks.engine.data_scale).

A correct projection onto a ball of radius ``r`` centred at ``c`` rounds at ``|c| + r`` whatever the point it is given:
judged at the points' magnitude alone, a float32 ball of radius 1e6 centred at 1e6·e_1 failed ``resolvent_identity``
by 12.9 times its slack, a float64 one at 1e12 four laws (measured on 0288656).  Stated, the scale decides; not stated,
a failure within the rounding of the scale inferred from the domain's extent is undecided — never a pass — and a
failure beyond it, or a non-finite one, stays failed."""

import numpy as np
import pytest

import verimono as vm
from verimono.checks.engine.data_scale import probe_extent
from verimono.core.tolerances import judged_at_scale, row_tolerances, tolerance

N = 5


def ball(dtype, S, *, bug=0.0, nan=False, stated=None):
    """The projection onto the ball of radius S centred at S·e_1 (the origin on its boundary), computed in ``dtype``;
    ``bug``: J + bug·x for |x| < 1 (a wrong resolvent near the origin); ``nan``: NaN there."""
    c = np.zeros(N)
    c[0] = S

    def J(x, lam, t):
        x = np.asarray(x, dtype=dtype)
        cc = c.astype(dtype)
        d = x - cc
        nd = np.linalg.norm(d)
        out = cc + d * min(dtype(1), dtype(S) / nd) if nd > 0 else x
        if np.linalg.norm(x) < 1:
            if nan:
                out = out * np.nan
            out = out + dtype(bug) * x
        return out

    return vm.operator_from_resolvent(J, N, project_domain=lambda x, t: J(x, 1.0, t),
                                      name=f"ball {np.dtype(dtype).name} at {S:g}", data_scale=stated)


def statuses(op, seed=0):
    rep = vm.check_operator(op, seed=seed, profile="ci")
    return {r.check: r for r in rep}


@pytest.mark.heavy       # a ci battery each (1-2 s): the tier CI runs after the default one
@pytest.mark.parametrize("dtype, S", [(np.float32, 1e6), (np.float64, 1e12)])
def test_correct_code_at_its_own_scale_is_never_failed(dtype, S):
    recs = statuses(ball(dtype, S))
    assert not [c for c, r in recs.items() if r.status == "failed"], {c: r.message for c, r in recs.items()
                                                                      if r.status == "failed"}
    undecided = [r for r in recs.values() if r.status == "undecided"]
    assert undecided, "the points' scale alone fails this correct code: the fallback must have been exercised"
    for r in undecided:       # the inferred scale is the domain's extent |c| + r = 2S, and the message says how to decide
        assert r.details["data_scale"]["inferred"] == pytest.approx(2 * S, rel=1e-6)
        assert "data_scale" in r.message and r.counterexample


@pytest.mark.heavy       # a ci battery each (1-2 s): the tier CI runs after the default one
@pytest.mark.parametrize("dtype, S", [(np.float32, 1e6), (np.float64, 1e12)])
def test_stated_scale_decides(dtype, S):
    recs = statuses(ball(dtype, S, stated=2 * S))
    assert {r.status for r in recs.values()} <= {"passed", "skipped"}
    assert any(r.status == "passed" for r in recs.values())
    assert all(r.details.get("data_scale") == {"stated": 2 * S} for r in recs.values() if r.status == "passed")


@pytest.mark.heavy       # a ci battery each (1-2 s): the tier CI runs after the default one
def test_a_violation_beyond_the_scale_stays_failed():
    # J + 0.1·x near the origin: 0.1·|x| exceeds rtol·(1 + 2e6) = 0.02 at |x| ≥ 0.2, so it fails at the inferred scale too
    recs = statuses(ball(np.float64, 1e6, bug=0.1))
    failed = [r for r in recs.values() if r.status == "failed"]
    assert failed
    assert any(r.details.get("data_scale", {}).get("fails_there_too") for r in failed)


@pytest.mark.heavy       # a ci battery each (1-2 s): the tier CI runs after the default one
def test_a_violation_within_the_scale_is_undecided_not_passed():
    # J + 1e-3·x near the origin is below rtol·(1 + 2e6) = 0.02 everywhere it acts: failed at the points' scale,
    # it cannot be told from rounding at the operator's own scale — undecided; at the unit ball's scale it fails
    recs = statuses(ball(np.float64, 1e6, bug=1e-3))
    assert not [r for r in recs.values() if r.status == "failed"]
    assert len([r for r in recs.values() if r.status == "undecided"]) >= 3
    unit = statuses(ball(np.float64, 1.0, bug=1e-3))
    assert len([r for r in unit.values() if r.status == "failed"]) >= 3


@pytest.mark.heavy       # a ci battery each (1-2 s): the tier CI runs after the default one
def test_a_non_finite_failure_is_never_rejudged():
    recs = statuses(ball(np.float64, 1e6, nan=True))
    failed = [r for r in recs.values() if r.status == "failed"]
    assert failed and not [r for r in recs.values() if r.status == "undecided"]
    assert all("data_scale" not in r.details for r in failed)


def test_probe_extent_sees_bounded_directions_only():
    op = ball(np.float64, 1e6)
    e, ev = probe_extent(op, N, 1.0, "float64")
    assert e == pytest.approx(2e6, rel=1e-9) and ev["calls"] > 0
    # the half-space {x_1 ≤ 3e4}: bounded towards +e_1 only
    half = vm.operator_from_resolvent(lambda x, lam, t: np.where(np.arange(N) == 0, np.minimum(x, 3e4), x), N)
    assert probe_extent(half, N, 1.0, "float64")[0] == pytest.approx(3e4)
    # full domains: a linear resolvent and a soft threshold grow with the radius: no extent
    A = np.diag(np.arange(1.0, N + 1))
    lin = vm.operator_from_resolvent(lambda x, lam, t: np.linalg.solve(np.eye(N) + lam * A, x), N)
    soft = vm.operator_from_resolvent(lambda x, lam, t: np.sign(x) * np.maximum(np.abs(x) - lam, 0.0), N)
    assert probe_extent(lin, N, 1.0, "float64")[0] == 0.0
    assert probe_extent(soft, N, 1.0, "float64")[0] == 0.0


def test_the_scale_is_one_more_magnitude_of_the_one_rule():
    x = np.array([1e-3, 2.0])
    assert tolerance(x) == pytest.approx(1e-8 * 3.0)
    with judged_at_scale(1e6):
        assert tolerance(x) == pytest.approx(1e-8 * (1 + 1e6))
        assert tolerance(np.array([5e6])) == pytest.approx(1e-8 * (1 + 5e6))
        np.testing.assert_allclose(row_tolerances(np.array([[1.0], [1e7]])), 1e-8 * (1 + np.array([1e6, 1e7])))
    assert tolerance(x) == pytest.approx(1e-8 * 3.0)
    with pytest.raises(ValueError):
        with judged_at_scale(-1.0):
            pass


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf"), True, "big", 10 ** 400])
def test_a_bad_stated_scale_is_a_typed_error(bad):
    with pytest.raises(vm.InvalidProblem):
        ball(np.float64, 1.0, stated=bad)
    with pytest.raises(vm.InvalidProblem):
        vm.operator_from_prox(lambda x, lam: x, shape=3, data_scale=bad)


def _failed(lhs, rhs, slack, worst=float("inf")):
    from verimono.records.verdicts import new_record
    return new_record("resolvent_firmly_nonexpansive", "ball", "failed", worst=worst, bound=1.0,
                      counterexample={"lhs": lhs, "rhs": rhs, "slack": slack}, message="violated",
                      details={"dtype": "float64"})


def test_a_finite_violation_with_a_negative_bound_is_rejudged():
    # probe7: a correct float64 ball of radius 1e12 centred at 1e12·e_1, n = 3, seed 0: firm nonexpansiveness at two
    # points near its boundary, lhs 1e-10 > rhs -9.99e-08 + slack 4.04e-10 — finite sides whose bound rhs + slack < 0
    # give the ratio inf by convention; it stayed failed (a non-finite ratio was never re-judged).  Its sides are
    # finite: it is re-judged at the inferred scale like any finite violation, undecided where the law holds there
    from verimono.checks.engine.data_scale import finite_failure, judged_at_data_scale
    from verimono.records.verdicts import new_record
    op = ball(np.float64, 1e12)
    rec = _failed(1e-10, -9.99e-08, 4.04e-10)
    assert finite_failure(rec)
    out = judged_at_data_scale(rec, op, 1.0, lambda: new_record("resolvent_firmly_nonexpansive", "ball", "passed",
                                                                worst=0.5, bound=1.0, message="held"))
    assert out.status == "undecided"
    assert out.details["data_scale"]["inferred"] == pytest.approx(2e12, rel=1e-6)
    # a non-finite side (a NaN, an infinity) stays failed, never re-judged
    for sides in [(float("nan"), 0.0, 1e-8), (1.0, float("inf"), 1e-8), (0.0, 0.0, float("inf"))]:
        rec = _failed(*sides)
        assert not finite_failure(rec)
        assert judged_at_data_scale(rec, op, 1.0, lambda: pytest.fail("re-judged")).status == "failed"
    assert not finite_failure(new_record("x", "y", "failed", worst=float("inf"), bound=1.0, message="raised"))


@pytest.mark.heavy       # a ci battery each (1-2 s): the tier CI runs after the default one
@pytest.mark.parametrize("dtype, S", [(np.float32, 1e6), (np.float64, 1e12)])
def test_correct_code_at_its_own_scale_is_never_failed_in_three_dimensions(dtype, S):
    # probe7: the ball in R^3 given by its projection alone (no project_domain), ci seeds 0 and 1: firm
    # nonexpansiveness failed on this correct code with a bound rhs + slack < 0 (float32 at 1e6, float64 at 1e12)
    c = np.array([S, 0.0, 0.0], dtype=dtype)

    def J(x, lam, t):
        x = np.asarray(x, dtype=dtype)
        d = x - c
        nd = np.linalg.norm(d)
        return x if nd <= dtype(S) else c + d * (dtype(S) / nd)

    op = vm.operator_from_resolvent(J, 3, name=f"ball3 {np.dtype(dtype).name} at {S:g}")
    for seed in (0, 1):
        recs = statuses(op, seed=seed)
        assert not [c for c, r in recs.items() if r.status == "failed"], (
            seed, {c: r.message for c, r in recs.items() if r.status == "failed"})


def test_the_laws_own_overflow_is_no_verdict():
    """A violation whose left side (the subject's values) is finite while the law's own slack overflowed judges
    nothing: inconclusive, never failed; a non-finite left side still fails (engine/search.own_overflow)."""
    from verimono.checks.core import Outcome
    from verimono.checks.engine.search import own_overflow

    assert "overflowed" in own_overflow(Outcome.compare(0.0, 0.0, float("inf"), "J_λx = J_μ(...)"))
    assert own_overflow(Outcome.compare(float("nan"), 0.0, 1.0, "x")) is None
    assert own_overflow(Outcome.compare(float("inf"), 1.0, float("inf"), "x")) is None
    assert own_overflow(Outcome.compare(2.0, 0.0, 1.0, "x")) is None        # an ordinary violation: judged


@pytest.mark.heavy       # a ci battery each (1-2 s): the tier CI runs after the default one
@pytest.mark.parametrize("seed", [0, 2])
def test_a_far_half_space_is_not_failed_by_the_laws_own_overflow(seed):
    # measured on 357ebca (probe7): x_1 ≤ -1e12 failed resolvent_identity at λ = 1e-153 with "slack inf" (z ≈ 1e165)
    half = vm.operator_from_resolvent(lambda x, lam, t: np.where(np.arange(3) == 0, np.minimum(x, -1e12), x), 3,
                                      name="half-space x_1 ≤ -1e12")
    recs = statuses(half, seed)
    assert not [r for r in recs.values() if r.status in ("failed", "undecided")], \
        {c: r.message for c, r in recs.items() if r.status in ("failed", "undecided")}
