"""Stepper claims: correct schemes that are not the paper's one-step scheme pass under ``scheme="any"``,
the laws that bind only the proximal scheme are skipped for them with the declaration's reason, and
broken steppers are still caught under the claim they make."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.core.claims import ANY, PROXIMAL, Claim, InvalidClaim, Stepper, claim_of, with_claim
from verimono.checks.trajectory_laws import check_in_domain, check_selections
from verimono.reference import catalog, get

import zoo_steppers as zoo

PROXIMAL_ONLY = {"selections", "bounds_lg", "bounds_yb", "psi_interpolation"}


def test_a_bare_callable_claims_the_proximal_scheme_and_solve_is_declared_proximal():
    assert claim_of(zoo.wrong_time) == Claim(PROXIMAL, None, True)
    assert claim_of(vm.solve).proximal
    s = Stepper(zoo.midpoint_time, scheme="any")
    assert (s.claim.scheme, s.claim.order, s.claim.contracts) == (ANY, 1.0, False)
    assert s.__name__ == "midpoint_time" and "scheme='any', order=1" in repr(s)
    assert with_claim(vm.solve) is vm.solve
    assert with_claim(zoo.midpoint_time, order=2).claim == Claim(ANY, 2.0, False)


@pytest.mark.parametrize("kw", [dict(scheme="implicit"), dict(scheme="any", order=0), dict(scheme="any", order=-1),
                                dict(scheme="any", order=math.nan), dict(scheme="any", order="fast"),
                                dict(scheme="proximal", order=2), dict(scheme="proximal", contracts=False)])
def test_claims_that_cannot_be_stated_are_typed_errors(kw):
    with pytest.raises(InvalidClaim):
        Stepper(zoo.midpoint_time, **kw)
    assert issubclass(InvalidClaim, vm.VerimonoError)


def test_a_stepper_must_be_callable():
    with pytest.raises(InvalidClaim, match="callable"):
        Stepper(42)


@pytest.mark.parametrize("scheme", zoo.VALID_ALTERNATIVES, ids=lambda f: f.__name__)
def test_valid_alternative_schemes_pass_the_whole_catalog_under_scheme_any(scheme):
    report = vm.check_stepper(Stepper(scheme, scheme="any", order=1), problems=catalog())
    assert report.ok, "\n".join(str(r) for r in report.failures)
    assert report.counts["passed"] >= 3 * len(catalog())       # orders, unique limits and domains ran
    for r in report:
        if r.check in PROXIMAL_ONLY:
            assert r.status == "skipped" and "needs scheme='proximal'" in r.message, r
        if r.check == "contraction":
            assert r.status == "skipped" and "contracts=True" in r.message, r


def test_the_same_schemes_claimed_proximal_are_told_apart_from_the_paper_scheme():
    """Claimed as the paper's scheme they are not it: the proximal-only laws see the difference."""
    p = get("t|x| (n=1)")
    assert check_selections(zoo.midpoint_time, p).status == "failed"
    assert check_selections(zoo.exact_sampled, p).status == "failed"
    assert check_selections(Stepper(zoo.midpoint_time, scheme="any"), p).status == "skipped"


def test_the_regularity_cap_binds_a_claimed_order_above_it():
    """Claiming order 2 on t|x| (Lipschitz solution with a kink) is held to order 1 only; on the smooth
    linear reference the claim itself binds, and the first-order midpoint scheme fails it."""
    two = Stepper(zoo.midpoint_time, scheme="any", order=2)
    rec = vm.checks.check_convergence_order(two, get("t|x| (n=1)"))
    assert rec.status == "passed" and rec.details["expected"]["order"] == 1.0, rec
    rec = vm.checks.check_convergence_order(two, get("linear x' = -Mx"))
    assert rec.status == "failed" and rec.details["expected"]["order"] == 2.0, rec


def test_every_reference_states_the_order_its_regularity_allows_with_a_source():
    for p in catalog():
        assert p.order.regularity is not None and p.order.regularity > 0, p.name
        assert p.order.regularity_source, p.name


@pytest.mark.parametrize("broken, law, problem", [
    (zoo.double_step, "convergence_order", "linear x' = -Mx"),       # converges to the wrong limit
    (zoo.leaves_domain, "in_domain", "moving box"),                 # a distance that does not vanish
    (zoo.mean_step, "unique_limit", "t|x| (n=1)"),
    (zoo.drops_input, "convergence_order", "Lipschitz field and input"),
])
def test_broken_steppers_are_caught_under_scheme_any_too(broken, law, problem):
    orders = law == "convergence_order"
    report = vm.check_stepper(Stepper(broken, scheme="any"), problems=[get(problem)],
                              laws=False if orders else [law], orders=orders)
    assert [r.status for r in report.by_check(law)] == ["failed"], report.results


def test_domain_vanishing_fails_a_constant_offset_and_passes_the_exact_solution():
    p = get("moving box")
    assert check_in_domain(Stepper(zoo.exact_sampled, scheme="any"), p).status == "passed"
    rec = check_in_domain(Stepper(zoo.leaves_domain, scheme="any"), p)
    assert rec.status == "failed" and rec.worst > 1
    assert "does not vanish at order 1" in rec.message
    d = rec.counterexample["distances"]
    assert min(d) > 1e-4                                          # the push is 1e-3 (1 + |x|) at every level


def test_claims_survive_pickling_for_process_pools():
    import pickle

    s = pickle.loads(pickle.dumps(Stepper(zoo.midpoint_time, scheme="any", order=1, name="mid")))
    assert s.claim == Claim(ANY, 1.0, False) and s.__name__ == "mid"
    p = get("t|x| (n=1)")
    t = np.linspace(0.0, p.T, 5)
    assert np.array_equal(s(p, t), zoo.midpoint_time(p, t))
