"""The operator laws fail on the broken zoo (with a reproducing, shrunk counterexample) and pass on every
correct catalog operator over several seeds; skips are counted, never passed."""

from __future__ import annotations

import numpy as np
import pytest

import zoo
import zoo_prox
import verimono as vm
from verimono import Report, operator_from_resolvent
from verimono.checks import LAWS, OPERATOR_CHECKS, check_operator, operator_checks, run_law
from verimono.strategies import catalog

ZOO_CASES = [(member, law) for member, laws in zoo.BREAKS.items() for law in laws]


#: the value laws are seen failing on the zoo of lawful prox bugs (tests/zoo_prox.py, tests/core/test_prox.py)
VALUE_LAWS = {"prox_inequality", "prox_optimal", "prox_minimiser", "moreau_envelope"}


def test_every_law_is_broken_by_some_zoo_member():
    broken = {law for _, law in ZOO_CASES} | VALUE_LAWS
    assert broken == set(LAWS), set(LAWS) - broken
    assert zoo_prox.LAWFUL


@pytest.mark.parametrize("member,law", ZOO_CASES, ids=[f"{m}-{lw}" for m, lw in ZOO_CASES])
def test_law_fails_on_zoo_member(member, law):
    op = zoo.build(member)
    r = OPERATOR_CHECKS[law](op, seed=0, examples=40)
    assert r.status == "failed", str(r)
    assert r.worst is not None and not r.worst <= r.bound
    cex = r.counterexample
    assert cex["seed"] == 0 and {"x1", "x2", "lam", "mu", "nu", "t"} <= set(cex)
    assert r.check == law and r.subject == member and r.seed == 0
    # the shrunk counterexample reproduces on a fresh operator, without hypothesis
    again = OPERATOR_CHECKS[law](zoo.build(member), sample=cex)
    assert again.status == "failed", str(again)


def test_counterexamples_are_shrunk():
    """Hypothesis shrinks: a nonexpansiveness failure of the explicit step is reported on simple inputs."""
    r = OPERATOR_CHECKS["resolvent_nonexpansive"](zoo.build("explicit_step"), seed=1, examples=40)
    cex = r.counterexample
    assert r.status == "failed"
    assert np.count_nonzero(cex["x1"]) + np.count_nonzero(cex["x2"]) <= 2
    assert all(float(v).is_integer() for v in cex["x1"] + cex["x2"])


@pytest.mark.parametrize("op", catalog(2) + catalog(3)[:3], ids=lambda op: f"{op.name}/{op.dim}")
def test_no_law_fails_on_catalog_operator(op):
    """The whole battery at seed 1 (seed 0 was here too, 0.7 s CPU per operator): every (operator, law) pair of
    this catalog runs in the default tier as properties/laws_operators.py::test_catalog_battery, with the
    profile's seed (0 under ``ci``, a fresh one under ``dev``) and at least as many examples (5 or 10 per law)."""
    report = check_operator(op, seed=1, examples=6)
    assert isinstance(report, Report) and len(report) == len(LAWS)
    assert report.ok, "\n".join(str(r) for r in report.failures)
    skipped = {r.check for r in report if r.status == "skipped"}
    # the value laws run where the operator states g (∂(c|x|), ∂(Σ c_i|x_i|)); elsewhere they are skipped; no catalog
    # operator overrides yosida (Operator.yosida is (x - J_λx)/λ itself): yosida_member is skipped on each; on a
    # one-point domain every y is in F(p), so no pair breaks monotonicity: contains_rejects is all inconclusive there
    point = {"contains_rejects"} if "point" in op.name else set()
    assert skipped == (set() if op.provides("value") else VALUE_LAWS) | {"yosida_member"} | point, skipped


def test_unsupported_members_are_skipped_not_passed():
    op = operator_from_resolvent(lambda x, lam, t: np.asarray(x) / (1.0 + lam), 2, name="scaled")
    report = check_operator(op, seed=0, examples=5)
    skipped = {r.check for r in report if r.status == "skipped"}
    assert skipped == {"resolvent_in_domain", "yosida_in_graph", "yosida_bounded_by_min_norm", "yosida_limit",
                       "min_norm_in_graph", "min_norm_least", "yosida_member", "contains_rejects",
                       "project_domain_nearest"} | VALUE_LAWS
    assert all(r.message for r in report if r.status == "skipped")
    assert report.counts["passed"] == len(LAWS) - len(skipped)


def test_exceptions_and_nonfinite_values_are_failures():
    def raising(x, lam, t):
        if np.asarray(x)[0] > 1.0:
            raise ValueError("no convergence")
        return np.asarray(x) / (1.0 + lam)
    r = run_law("resolvent_nonexpansive", operator_from_resolvent(raising, 1, name="raising"), seed=0, examples=30)
    assert r.status == "failed" and "ValueError" in r.message
    nan = operator_from_resolvent(lambda x, lam, t: np.full_like(np.asarray(x, float), np.nan), 1, name="nan")
    r = run_law("resolvent_single_valued", nan, seed=0, examples=5)
    assert r.status == "failed" and "non-finite" in r.message


def test_registry_names_are_stable_and_seeded_runs_reproduce():
    names = [name for name, _ in operator_checks()]
    assert names == list(LAWS) == list(OPERATOR_CHECKS)
    assert all(OPERATOR_CHECKS[n].__name__ == f"check_{n}" for n in names)
    op = catalog(2)[0]
    a = check_operator(op, seed=123, examples=5)
    b = check_operator(op, seed=123, examples=5)
    assert [r.worst for r in a] == [r.worst for r in b]
    assert a.meta["seed"] == 123 and all(r.seed == 123 for r in a)
    c = check_operator(op, examples=3)           # no seed: a fresh one is drawn and recorded
    assert isinstance(c.meta["seed"], int) and all(r.seed == c.meta["seed"] for r in c)
    assert [r.check for r in c] == names


def test_nondeterministic_operator_does_not_escape_as_an_exception():
    r = run_law("resolvent_single_valued", zoo.build("nondeterministic"), seed=5, examples=20)
    assert r.status == "failed"


def test_yosida_limit_at_a_kink_reached_through_rounded_shifts():
    """x = J(0) - 0.2 - 0.1 = -0.30000000000000004 for |·| shifted by 0.1 then 0.2: x + Φ = -2.8e-17, not 0,
    so F^0(x) has norm c while Y_λx → 0 for every observable λ.  x is a zero of F up to its own rounding:
    the law must not fail there (a random dev-profile run found this) — the sample is inconclusive, so the
    one-sample record is skipped, never passed — and a wrong λ must still fail."""
    import numpy as np
    import verimono as vm
    from verimono.checks.operator_laws import check_yosida_limit
    from verimono.checks.engine.samples import Sample

    op = vm.Shifted(vm.Shifted(vm.NormSubdifferential(1.0), [0.1]), [0.2])
    sample = Sample(np.zeros(1), np.zeros(1), 1.0, 1.0, 1.0, 0.0)
    x = op.resolvent(np.zeros(1), 1.0)
    assert (x + 0.2) + 0.1 != 0.0 and np.linalg.norm(op.min_norm(x)) == 1.0   # the rounding is real
    assert check_yosida_limit(op, sample=sample).status == "skipped"
    from verimono.checks.operator_laws import check_min_norm_least
    assert check_min_norm_least(op, sample=sample).status == "skipped"
    wrong = vm.operator_from_resolvent(lambda z, lam, t: op.resolvent(z, 2 * lam, t), 1, min_norm=op.min_norm,
                                       project_domain=op.project_domain, name="wrong λ")
    assert check_yosida_limit(wrong, sample=Sample(np.array([3.0]), np.zeros(1), 1.0, 1.0, 1.0, 0.0)).status == "failed"


def test_yosida_limit_next_to_a_kink_closer_than_the_rounding_floor():
    """∂|·|₁ shifted by Φ(t) = (t, t) at t = 1, x + Φ = (1, 1e-8): |Y_λx| = √(1 + (1e-8/λ)²) for λ > 1e-8
    reaches |F^0| = √2 only below λ = 1e-8, under the sweep's rounding floor (4.8e-7).  The gap closes ever
    faster there, so the sample is inconclusive, not a failure (found by a thorough run).  Inconclusive for
    any operator: the decrements are those of |Y_λx| alone, so a wrong F^0 (1.5 times too long) looks the same
    there until λ passes the kink; it fails at a point away from kinks."""
    import numpy as np
    import verimono as vm
    from verimono.checks.operator_laws import check_yosida_limit
    from verimono.checks.engine.samples import Sample

    op = vm.Shifted(vm.L1Subdifferential(1.0, dim=2), lambda t: np.array([t, t]))
    s = Sample(np.array([1.0, 1e-8]), np.zeros(2), 1.0, 1.0, 1.0, 1.0)
    assert check_yosida_limit(op, sample=s).status == "skipped"                # inconclusive, not passed
    too_big = vm.operator_from_resolvent(op.resolvent, 2, min_norm=lambda z, t: 1.5 * op.min_norm(z, t),
                                         project_domain=op.project_domain, name="F^0 too long")
    assert check_yosida_limit(too_big, sample=s).status == "skipped"         # inconclusive at this sample
    away = Sample(np.array([3.0, 2.0]), np.zeros(2), 1.0, 1.0, 1.0, 1.0)
    assert check_yosida_limit(op, sample=away).status == "passed"
    assert check_yosida_limit(too_big, sample=away).status == "failed"


def test_yosida_limit_where_min_norm_and_resolvent_round_a_kink_differently():
    """∂(2|x₁| + ½|x₂|) whose F^0 sees x₁ = 0 as a rounding-size positive number while its resolvent sees 0 (a
    thorough run drew a doubly shifted ∂‖·‖₁ doing this at 2^-23 from a kink): |Y_λx| = ½ at every λ against
    |F^0| = √4.25, a gap flat down to the floor.  F^0 jumps within the floor's resolution of x, so the sample
    is inconclusive; the same operator away from its kinks passes, and a wrong λ there fails."""
    import numpy as np
    import verimono as vm
    from verimono.checks.operator_laws import check_yosida_limit
    from verimono.checks.engine.samples import Sample

    c = np.array([2.0, 0.5])
    soft = lambda z, lam, t: np.sign(z) * np.maximum(np.abs(z) - lam * c, 0.0)          # noqa: E731
    rounded = lambda z, t: c * np.sign(np.asarray(z) + np.array([1e-15, 0.0]))          # noqa: E731
    op = vm.operator_from_resolvent(soft, 2, min_norm=rounded, project_domain=lambda z, t: z, name="rounded F0")
    at_kink = Sample(np.array([0.0, 3.0]), np.zeros(2), 1.0, 1.0, 1.0, 0.0)
    rec = check_yosida_limit(op, sample=at_kink)
    assert rec.status == "skipped" and "jumps within" in rec.message, str(rec)   # every sample inconclusive
    away = Sample(np.array([5.0, 3.0]), np.zeros(2), 1.0, 1.0, 1.0, 0.0)     # J = (3, 2.5); 2λ: (1, 2)
    assert check_yosida_limit(op, sample=away).status == "passed"
    wrong = vm.operator_from_resolvent(lambda z, lam, t: soft(z, 2 * lam, t), 2, min_norm=rounded,
                                       project_domain=lambda z, t: z, name="wrong λ")
    assert check_yosida_limit(wrong, sample=away).status == "failed"


def test_laws_on_points_closer_than_the_square_root_of_the_smallest_double():
    """x1 - x2 = 1.9e-250: its square underflows, and the slack of yosida_monotone must not (found by a
    random dev-profile run on LogBarrier, where J rounds to neighbouring doubles)."""
    import numpy as np
    import verimono as vm
    from verimono.checks.operator_laws import check_yosida_monotone
    from verimono.checks.engine.samples import Sample

    s = Sample(np.zeros(1), np.array([-1.882470261721448e-250]), 0.5, 1.0, 1.0, 0.0)
    assert check_yosida_monotone(vm.LogBarrier(1.0), sample=s).status == "passed"


def test_default_effort_follows_the_profile(monkeypatch):
    """examples=None: the run configuration's profile's ``law_examples`` (dev/ci/thorough) is the effort, and
    its sweep the sweep, recorded in the record's details and the report's meta; an explicit ``examples``
    still wins.  The API's ``profile=`` chooses it for one call; the environment does not overrule it."""
    from verimono.checks.engine.sweep import sweep_count
    from verimono.execution.config import using
    from verimono.execution.profiles import get_profile

    op = operator_from_resolvent(lambda x, lam, t: np.asarray(x) / (1.0 + lam), 1, name="scaled")
    monkeypatch.setenv("HYPOTHESIS_PROFILE", "ci")
    for name in ("dev", "thorough"):
        with using(profile=name):
            r = run_law("resolvent_nonexpansive", op, seed=0)
        assert r.details["examples"] == get_profile(name).law_examples, r.details
        assert r.details["sweep"] == sweep_count(name, "resolvent_nonexpansive")
        assert r.details["profile"] == name
    rep = check_operator(op, seed=0, profile="dev")
    assert rep.meta["examples"] == get_profile("dev").law_examples
    assert all(r.details["examples"] == get_profile("dev").law_examples for r in rep)
    assert run_law("resolvent_nonexpansive", op, seed=0, examples=7).details["examples"] == 7
    with pytest.raises(vm.UnknownProfile, match="thorough"):
        check_operator(op, seed=0, profile="fast")


def _rejecting(contains_result=False):
    """∂|·| on R² with a correct resolvent and minimal section whose ``contains`` always answers no."""
    from verimono import NormSubdifferential

    F = NormSubdifferential(1.0, 2)
    return operator_from_resolvent(F.resolvent, 2, min_norm=F.min_norm, project_domain=F.project_domain,
                                   contains=lambda x, y, t, tol=None: contains_result, name="rejecting")


def test_min_norm_least_with_an_always_rejecting_contains_is_never_passed():
    """Every y0 is uncertified: each sample is inconclusive, counted, and the record is skipped, not passed."""
    from verimono.checks.operator_laws import check_min_norm_least
    from verimono.checks.engine.samples import Sample

    r = check_min_norm_least(_rejecting(), seed=0, examples=15)
    assert r.status == "skipped", str(r)
    assert r.details["inconclusive"] == r.details["evaluations"] > 0
    assert "inconclusive" in r.message
    one = check_min_norm_least(_rejecting(), sample=Sample(np.ones(2), np.zeros(2), 1.0, 1.0, 1.0, 0.0))
    assert one.status == "skipped" and one.details["inconclusive"] == 1
    ok = check_min_norm_least(_rejecting(True), seed=0, examples=15)      # certified: conclusive, passed
    assert ok.status == "passed" and ok.details["inconclusive"] == 0


def test_inconclusive_samples_of_yosida_limit_are_counted():
    """The rounding-kink sample of yosida_limit is inconclusive: alone it gives a skip; counted in details."""
    import verimono as vm
    from verimono.checks.operator_laws import check_yosida_limit
    from verimono.checks.engine.samples import Sample

    op = vm.Shifted(vm.Shifted(vm.NormSubdifferential(1.0), [0.1]), [0.2])
    r = check_yosida_limit(op, sample=Sample(np.zeros(1), np.zeros(1), 1.0, 1.0, 1.0, 0.0))
    assert r.status == "skipped" and r.details["inconclusive"] == 1 and r.details["evaluations"] == 1
    r = check_yosida_limit(op, sample=Sample(np.array([3.0]), np.zeros(1), 1.0, 1.0, 1.0, 0.0))
    assert r.status == "passed" and r.details["inconclusive"] == 0


def _twice_the_step(op):
    """``op`` whose resolvent takes ``2λ`` for ``λ`` (the bug of zoo.wrong_lambda) — other members correct."""
    return operator_from_resolvent(lambda x, lam, t: op.resolvent(x, 2 * lam, t), op.dim, min_norm=op.min_norm,
                                   project_domain=op.project_domain, contains=op.contains, name=f"2λ·{op.name}")


def test_section7_family_property_fails_on_a_broken_lcs_operator():
    """The property of properties/laws_operators.py on passive complementarity systems (the "lcs" family)
    holds for H and is seen failing when H's resolvent uses the wrong step.  The lawful control draws 5 systems:
    the no-false-alarm search at the profile's effort is test_laws_on_generated_operators[lcs] of that file (20
    systems here cost 4 s CPU); the broken step fails on the first system drawn."""
    from verimono import strategies as vs
    from verimono.properties.laws_operators import FAMILIES, family_property

    family_property(FAMILIES["lcs"](), examples=5, derandomize=True)()
    broken = vs.lcs_operators(moving_v=None).map(lambda s: _twice_the_step(s.operator))
    with pytest.raises(AssertionError, match=r"FAILED .*2λ·H\[LCS"):
        family_property(broken, examples=40, derandomize=True, shrink=False)()


@pytest.mark.parametrize("moving_v", [False, True])
def test_generated_lcs_meet_the_section7_hypotheses(moving_v):
    """lcs_operators builds systems satisfying Theorem thm: linear case by design: passive with K = I,
    maximal monotone relation, im C ∩ ri(im(𝓟 + D) − v(t)) ≠ ∅, v bounded and AC (lcs.check_hypotheses)."""
    from hypothesis import HealthCheck, given, settings

    from verimono import strategies as vs
    from verimono.lcs import check_hypotheses

    @settings(max_examples=8, derandomize=True, database=None, deadline=None, suppress_health_check=list(HealthCheck))
    @given(vs.lcs_operators(moving_v=moving_v))
    def run(stated):
        rep = check_hypotheses(stated.system, 1.0, samples=8)
        status = {r.check: r.status for r in rep}
        for item in ("lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int", "lcs.v_bounded", "lcs.v_ac", "lcs.A1"):
            assert status[item] == "passed", (item, [str(r) for r in rep])
        assert stated.operator.in_domain(np.zeros(stated.dim), 0.7)
        assert (stated.theta is None) == moving_v and (stated.phi is None) == moving_v
    run()


def test_lcs_min_norm_on_the_boundary_of_dom_H():
    """H of ẋ = Bz, w = Cx + v, 0 ≤ z ⊥ w ≥ 0 with C = Bᵀ = (0, 0, 1.5625), D = 0, v = 1: J_1(-2, -2, -2) lies
    on ∂dom H = {x₃ = -0.64} up to rounding; H^0 and membership must be answered there (as at any point of
    dom H), as they are in exact arithmetic (H^0 = 0 at that point: z = 0 is a multiplier).  Found by the Section 7
    operator property: the multiplier LCP, with the zero row 0·z ≥ -5e-17, raised SolverFailure."""
    from verimono.lcs import Complementarity, LinearRelationSystem

    b = 1.5625
    H = LinearRelationSystem(np.zeros((3, 3)), [[0.0], [0.0], [b]], [[0.0, 0.0, b]], [[0.0]], Complementarity(),
                             v=[1.0]).operator()
    x = H.resolvent(np.full(3, -2.0), 1.0, 0.0)
    assert np.linalg.norm(H.min_norm(x, 0.0)) <= 1e-8
    assert H.contains(x, (np.full(3, -2.0) - x) / 1.0, 0.0)


#: the sample of the false alarm in the no-false-alarm sweep (issue 13): H of the paper's Example, v = (−t, 0)
_THIN_WEDGE = {"x1": [1.0], "x2": [0.0], "lam": 1.0, "mu": 1.0, "nu": 1.0, "t": 2.0 ** -23}


@pytest.mark.parametrize("law", ["yosida_in_graph", "yosida_bounded_by_min_norm", "yosida_limit",
                                 "min_norm_in_graph", "min_norm_least"])
def test_the_example_H_at_a_thin_wedge_passes(law):
    """At x = 1, t = 2^-23 the multipliers (1, t) of H(t, x) are unique, but their SOL is cut out by rows t apart
    in angle: the selection QP failed verimono's KKT check and five laws recorded the operator as failed.
    The certified-unique multipliers now skip the selection, and the laws hold there (H^0 = −t exactly)."""
    from verimono.reference import lcs_example as E

    H = E.example_system(lambda s: np.array([-s, 0.0])).operator()
    rec = run_law(law, H, sample=_THIN_WEDGE)
    assert rec.status == "passed", str(rec)
    assert H.min_norm(np.array([1.0]), 2.0 ** -23)[0] == -(2.0 ** -23)


def _resolvent_whose_qp_gives_up(region):
    """The resolvent of N_[0,∞)ⁿ (projection onto the orthant) that raises UnverifiedSolution — verimono's QP
    giving up — wherever ``region(x)`` holds, as verimono's own Polyhedron does on degenerate data."""
    def J(x, lam, t):
        if region(x):
            raise vm.UnverifiedSolution("no QP back-end produced a verified solution (simulated)")
        return np.maximum(x, 0.0)
    return J


def test_a_limit_of_verimonos_own_solvers_is_undecided_never_failed_nor_passed():
    """UnverifiedSolution raised inside an operator is a limit of the harness: a sample it stops is not
    evidence against the operator (no failure) and not evidence for it (counted; every sample stopped is
    undecided).  A plain SolverFailure of the operator's own making still fails it."""
    everywhere = vm.operator_from_resolvent(_resolvent_whose_qp_gives_up(lambda x: True), 2, name="gives up")
    rec = run_law("resolvent_nonexpansive", everywhere, seed=1, examples=10)
    assert rec.status == "undecided" and "decided none" in rec.message, str(rec)
    sometimes = vm.operator_from_resolvent(_resolvent_whose_qp_gives_up(lambda x: x[0] > 2.0), 2, name="sometimes")
    rec = run_law("resolvent_nonexpansive", sometimes, seed=1, examples=30)
    assert rec.status == "passed" and rec.details["harness_limited"] > 0, str(rec)
    assert "undecided by verimono's own solvers" in rec.message

    def raises(x, lam, t):
        raise vm.SolverFailure("the user's own solver failed")
    rec = run_law("resolvent_single_valued", vm.operator_from_resolvent(raises, 2, name="own"), seed=1, examples=5)
    assert rec.status == "failed" and "SolverFailure" in rec.message, str(rec)   # the root cause, as any raise


def test_a_law_sees_the_numpy_draws_then_the_edge_samples_then_the_sweep_then_the_coordinates():
    """examples NumPy draws, then edge_count(examples) edge samples (no hypothesis example: the draws found
    nothing), then the scale sweep, then the scale phase, then the coordinate search: every sample counted once in
    details["evaluations"], the edge samples stated in details["searched"]."""
    from verimono.checks.engine.sweep import edge_count
    from verimono.reference import get

    op = get("t|x| (n=3)").operator
    for examples in (4, 20, 40):
        r = run_law("resolvent_nonexpansive", op, seed=3, examples=examples)
        edges = edge_count(examples)
        assert r.status == "passed" and r.details["evaluations"] == \
            examples + edges + r.details["sweep"] + r.details["searched"]["scales"]["points"] + r.details["coordinate"], \
            r.details
        assert r.details["searched"]["edge_samples"] == edges and "hypothesis_examples" not in r.details["searched"]


def test_a_violation_only_the_draws_meet_is_shrunk_and_replays(monkeypatch):
    """With hypothesis confined to one harmless sample (x1 = x2 = 0), the explicit step's violation comes from
    the NumPy draws: recorded as theirs, shrunk greedily, and replayed by sample=.  Without the draws, and the
    edge samples only that harmless pair, nothing finds it."""
    from hypothesis import strategies as st

    from verimono.checks.engine import coordinates, samples, search as L

    harmless = st.just(samples.Sample(np.zeros(2), np.zeros(2), 1.0, 1.0, 1.0, 0.0))
    monkeypatch.setattr(L, "law_samples", lambda n, horizon=1.0: harmless)
    monkeypatch.setattr(L, "_sweep", lambda *a, **k: 0)          # nor the sweep: only the draws can find it
    r = run_law("resolvent_nonexpansive", zoo.build("explicit_step"), seed=0, examples=20)
    assert r.status == "failed" and r.counterexample["found_by"] == "NumPy draws (shrunk greedily)", str(r)
    again = run_law("resolvent_nonexpansive", zoo.build("explicit_step"), sample=r.counterexample)
    assert again.status == "failed", str(again)
    monkeypatch.setattr(L, "edge_draws", lambda *a, **k: [samples.Sample(np.zeros(2), np.zeros(2), 1.0, 1.0, 1.0, 0.0)] * 5)
    monkeypatch.setattr(L, "scale_samples", lambda *a, **k: ([], {"points": 0}))    # (its whole points find it too)
    monkeypatch.setattr(L, "law_draws", lambda *a, **k: [])     # without the draws nothing finds it (but the
    monkeypatch.setattr(coordinates, "COORDINATES",                # direction search, from the pair x1 = x2)
                        tuple(c for c in coordinates.COORDINATES if c != "direction"))
    assert run_law("resolvent_nonexpansive", zoo.build("explicit_step"), seed=0, examples=20).status == "passed"


def test_law_draws_are_seeded_in_range_and_favour_simple_values():
    """The NumPy draws follow law_samples: x1 in [-10, 10]^n, x2 within 1e-2 of x1 about half the time, step
    sizes in [1e-3, 10] (the strategy's simple ones about half the time), t in [0, T]; the same seed draws
    the same samples, another seed others."""
    from verimono.checks.engine.samples import Sample
    from verimono.checks.engine.sweep import law_draws

    a = law_draws(3, 5, 2.0, 400, Sample)
    assert [s.to_dict() for s in a] == [s.to_dict() for s in law_draws(3, 5, 2.0, 400, Sample)]
    assert [s.to_dict() for s in a] != [s.to_dict() for s in law_draws(3, 6, 2.0, 400, Sample)]
    x1 = np.array([s.x1 for s in a])
    assert np.all(np.abs(x1) <= 10.0) and 0.15 < np.mean(np.isin(x1, (0.0, 0.5, -0.5, 1.0, -1.0, 2.0, -2.0))) < 0.5
    near = np.mean([np.max(np.abs(s.x2 - s.x1)) <= 1e-2 for s in a])
    assert 0.35 < near < 0.65
    steps = np.array([[s.lam, s.mu, s.nu] for s in a])
    assert np.all((steps >= 1e-3) & (steps <= 10.0)) and 0.35 < np.mean(np.isin(steps, (1.0, 0.5, 2.0, 0.1, 10.0, 1e-3))) < 0.65
    assert all(0.0 <= s.t <= 2.0 for s in a) and 0.35 < np.mean([s.t in (0.0, 1.0, 2.0) for s in a]) < 0.65


def test_a_value_returned_is_kept_over_a_later_call():
    """prop:maxmon-resolvent-Yosida i–ii: J_λ is a function, and what it returned is the caller's — a resolvent
    projecting onto the box [-1, 1]^3 into one preallocated buffer and returning that buffer fails (blind set 9's
    box_returns_shared_buffer, missed on 0288656); the same code returning a copy passes."""
    from verimono.checks.operator_laws import check_resolvent_single_valued

    def make(copy):
        buf = np.empty(3)

        def J(x, lam, t):
            np.clip(x, -1.0, 1.0, out=buf)
            return buf.copy() if copy else buf
        return vm.operator_from_resolvent(J, 3, name="box, " + ("copied" if copy else "one buffer"))

    bad = check_resolvent_single_valued(make(False), seed=0, examples=20)
    assert bad.status == "failed" and "one output buffer handed out twice" in bad.message, str(bad)
    assert check_resolvent_single_valued(make(True), seed=0, examples=20).status == "passed"


@pytest.mark.parametrize("dtype", [np.float32, np.float16])
def test_a_converted_value_returned_is_kept_over_a_later_call(dtype):
    """The same law on a float32 (and float16) subject: its value is converted to float64 (a copy) where verimono
    first sees it (verimono.core.arrays.Boundary), which the next call could not change — a shared float32 buffer
    passed.  The boundary now watches the array it converted: overwritten by a later call, the copy it handed out
    changes as the subject's own array did, and the law fails exactly as on float64.  Correct float32 code — a fresh
    array per call, or a memo returning the same cached array for the same input — passes."""
    from verimono.checks.operator_laws import check_resolvent_single_valued

    def make(kind):
        buf = np.empty(3, dtype=dtype)
        memo = {}

        def J(x, lam, t):
            if kind == "memo":
                key = (np.asarray(x).tobytes(), float(lam), float(t))
                if key not in memo:
                    memo[key] = np.clip(np.asarray(x, dtype=dtype), dtype(-1), dtype(1))
                return memo[key]
            np.clip(np.asarray(x, dtype=dtype), dtype(-1), dtype(1), out=buf)
            return buf.copy() if kind == "copied" else buf
        return vm.operator_from_resolvent(J, 3, name=f"box {np.dtype(dtype).name}, {kind}")

    bad = check_resolvent_single_valued(make("one buffer"), seed=0, examples=20)
    assert bad.status == "failed" and "one output buffer handed out twice" in bad.message, str(bad)
    assert bad.details["dtype"] == np.dtype(dtype).name
    for kind in ("copied", "memo"):
        rec = check_resolvent_single_valued(make(kind), seed=0, examples=20)
        assert rec.status == "passed", str(rec)
