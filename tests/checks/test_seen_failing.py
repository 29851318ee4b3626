"""Issue 32 item 5, no check that cannot fail: every registered law is seen failing on a subject built to
break it, and this file keeps the list (docs/paper.md's "seen failing on" column names the same tests).

``SEEN_FAILING`` maps every law of the registry to the test that sees it fail; a new law without an entry,
or an entry naming a test that does not exist, fails here.  The derived Section 7 assumptions are
derivations, not checks: they pass only when the items they follow from passed, and are *not established*
(skipped, never failed: the items are sufficient conditions) otherwise — the test named beside them sees
one not established.  The laws the other files did not yet see failing are seen failing below."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import verimono.checks.example  # noqa: F401 - every law joins the registry on import
import verimono.checks.hoffman  # noqa: F401
import verimono.checks.operator_battery  # noqa: F401
import verimono.checks.pseudo_distance  # noqa: F401
import verimono.checks.siconos  # noqa: F401
import verimono.checks.stepper_battery  # noqa: F401
from verimono import operator_from_resolvent
from verimono.checks import assumptions, load_every_law, section7  # noqa: F401
from verimono.checks.core import REGISTRY
from verimono.lcs import Complementarity, LinearRelationSystem, check_hypotheses
from verimono.records.results import FAILED, SKIPPED

TESTS = Path(__file__).resolve().parents[1]
ZOO_OPERATORS = "checks/test_operator_laws.py::test_every_law_is_broken_by_some_zoo_member"
ZOO_STEPPERS = "checks/test_trajectory_laws.py::test_every_law_fails_on_a_zoo_member"

#: law → the test that sees it failing (path relative to tests/, function)
SEEN_FAILING = {
    **{law: ZOO_OPERATORS for law in REGISTRY["operator"]},
    **{law: ZOO_STEPPERS for law in ("contraction", "in_domain", "selections", "bounds_lg", "bounds_yb",
                                     "psi_interpolation", "unique_limit", "initial_value", "trajectory_immutable")},
    "picard_step": "checks/test_picard.py::test_wrong_lipschitz_constant_fails_with_the_counterexample",
    "convergence_order": "checks/test_orders_limit.py::test_a_scheme_converging_to_a_wrong_limit_fails_without_an_exact_solution",
    "assumption_A1": "checks/test_search_over_time.py::test_non_monotone_on_a_narrow_window_fails_A1",
    "assumption_A2": "checks/test_search_where_bugs_live.py::test_a_right_limit_that_never_settles_fails_A2",
    "assumption_A3": "checks/test_search_over_time.py::test_phi_broken_on_a_narrow_window_fails_A3_and_holds_with_a_margin",
    "assumption_LG": "checks/test_search_where_bugs_live.py::test_LG_broken_only_far_from_x0_fails_and_holds_with_the_true_sigma",
    "assumption_YB": "checks/test_search_over_time.py::test_theta_broken_on_a_narrow_window_fails_YB_and_holds_with_a_margin",
    "assumptions_thm_main": "checks/test_core.py::test_thm_main_is_a_composite_law_over_the_assumption_records",
    "lcs.passivity": "lcs/test_lcs_system.py::test_non_passive_system_fails_the_check",
    "lcs.pass_D_psd": "checks/test_seen_failing.py::test_pass_D_psd_and_pass_kernel_fail_on_their_counterexamples",
    "lcs.pass_kernel": "checks/test_seen_failing.py::test_pass_D_psd_and_pass_kernel_fail_on_their_counterexamples",
    "lcs.relation_maxmon": "checks/test_seen_failing.py::test_relation_maxmon_fails_on_a_relation_that_is_not_monotone",
    "lcs.rel_int": "checks/test_search_where_bugs_live.py::test_rel_int_lost_at_one_isolated_time_fails",
    "lcs.v_bounded": "checks/test_search_where_bugs_live.py::test_v_growing_toward_a_singularity_fails_v_bounded",
    "lcs.v_ac": "lcs/test_lcs_example.py::test_a_jump_in_v_fails_v_ac_and_the_derived_A2_A3_are_not_established",
    "lcs.least_norm_growth": "lcs/test_lcs_example.py::test_least_norm_growth_fails_on_a_wrong_selection",
    "example_resolvent_closed_form": "lcs/test_lcs_example.py::test_example_records_for_the_run_stage",
    "example_batched_scheme": "lcs/test_lcs_example.py::test_batched_scheme_record_passes_and_fails_on_an_unchecked_kernel",
    "example_pseudo_distance_unbounded": "checks/test_seen_failing.py::test_the_unbounded_pseudo_distance_record_fails_on_a_bounded_estimate",
    "siconos_agreement": "lcs/test_lcs_siconos.py::test_check_siconos_fails_on_a_wrong_scheme",
    "siconos_lcp": "checks/test_seen_failing.py::test_siconos_lcp_fails_on_a_wrong_solution",
    "hoffman_bound": "checks/test_search_where_bugs_live.py::test_hoffman_understated_on_a_thin_cone_fails",
    "pseudo_distance_hausdorff": "checks/test_pseudo_distance_check.py::test_broken_estimators_fail",
    "tolerance_rate": "integrators/test_own_steps.py::test_planted_wrapper_bugs_fail_beside_their_lawful_controls",
    "switching_times": "integrators/test_own_steps.py::test_event_driven_locates_the_switching_times",
}
#: derivations: passed only when their items passed, else not established (skipped), never failed
DERIVED = {law: "checks/test_seen_failing.py::test_a_derived_assumption_is_not_established_when_an_item_fails"
           for law in ("lcs.A1", "lcs.A2", "lcs.A3", "lcs.LG")}


def _functions(path: Path) -> set[str]:
    return {n.name for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.FunctionDef)}


def test_every_registered_check_is_seen_failing_by_a_named_test():
    registered = {name for laws in load_every_law().values() for name in laws}
    assert registered == set(SEEN_FAILING) | set(DERIVED), sorted(registered ^ (set(SEEN_FAILING) | set(DERIVED)))
    for law, where in {**SEEN_FAILING, **DERIVED}.items():
        path, _, func = where.partition("::")
        assert func in _functions(TESTS / path), f"{law}: no test {where}"
    assert set(section7.DERIVED) == set(DERIVED)


def test_pass_D_psd_and_pass_kernel_fail_on_their_counterexamples():
    # Proposition p:pass i: D + Dᵀ ⪰ 0 — D = −1; ii: (B − Cᵀ) ker(D + Dᵀ) = {0} — B = 2, C = 1, D = 0
    neg = LinearRelationSystem([[0.0]], [[1.0]], [[1.0]], [[-1.0]], Complementarity())
    assert check_hypotheses(neg, 1.0).by_check("lcs.pass_D_psd")[0].status == FAILED
    ker = LinearRelationSystem([[0.0]], [[2.0]], [[1.0]], [[0.0]], Complementarity())
    rep = check_hypotheses(ker, 1.0)
    assert rep.by_check("lcs.pass_kernel")[0].status == FAILED and rep.by_check("lcs.pass_D_psd")[0].status != FAILED
    ok = LinearRelationSystem([[0.0]], [[1.0]], [[1.0]], [[0.0]], Complementarity())
    assert {r.status for r in check_hypotheses(ok, 1.0).by_check("lcs.pass_kernel")} == {"passed"}


def test_relation_maxmon_fails_on_a_relation_that_is_not_monotone():
    from verimono.lcs.relations import OperatorRelation

    good = operator_from_resolvent(lambda x, lam, t: np.sign(x) * np.maximum(np.abs(x) - lam, 0.0), 1, name="soft")
    rel = OperatorRelation(good)
    system = LinearRelationSystem([[0.0]], [[1.0]], [[1.0]], [[1.0]], rel)
    assert check_hypotheses(system, 1.0).by_check("lcs.relation_maxmon")[0].status == "passed"
    # the relation's operator swapped for an expansive "resolvent" after construction's own test
    rel.op = operator_from_resolvent(lambda x, lam, t: 2.0 * np.asarray(x), 1, name="expansive")
    assert check_hypotheses(system, 1.0).by_check("lcs.relation_maxmon")[0].status == FAILED


def test_the_unbounded_pseudo_distance_record_fails_on_a_bounded_estimate(monkeypatch):
    from verimono.checks import example

    assert example.check_pseudo_distance_unbounded().status == "passed"
    monkeypatch.setattr(example, "pseudo_distance_demo", lambda rhos: [(r, min((r + 1) / 2, 3.0)) for r in rhos])
    rec = example.check_pseudo_distance_unbounded()
    assert rec.status == FAILED and rec.worst > 1.0


def test_siconos_lcp_fails_on_a_wrong_solution(monkeypatch):
    from verimono.checks import siconos
    from verimono.lcs.siconos import PACKAGED_DATA, siconos_root

    path = sorted((siconos_root(PACKAGED_DATA) / "lcp").glob("lcp_trivial.dat"))[0]
    assert siconos.check_lcp_file(path).status == "passed"
    monkeypatch.setattr(siconos, "solve_lcp", lambda M, q: np.ones(len(q)) * 7.0)
    assert siconos.check_lcp_file(path).status == FAILED


def _not_passive():
    return LinearRelationSystem([[1.0]], [[1.0]], [[1.0]], [[0.0]], Complementarity())


def _no_relative_interior():
    return LinearRelationSystem([[0.0]], [[1.0]], [[0.0]], [[0.0]], Complementarity(), v=[-1.0])


def _unbounded_v():
    return LinearRelationSystem([[0.0]], [[1.0]], [[1.0]], [[1.0]], Complementarity(),
                                v=lambda t: np.array([-1.0 / abs(t - 0.3) if t != 0.3 else -np.inf]))


@pytest.mark.parametrize("law,system,item", [("lcs.A1", _not_passive, "lcs.passivity"),
                                             ("lcs.A2", _not_passive, "lcs.passivity"),
                                             ("lcs.A3", _no_relative_interior, "lcs.rel_int"),
                                             ("lcs.LG", _unbounded_v, "lcs.v_bounded")])
def test_a_derived_assumption_is_not_established_when_an_item_fails(law, system, item):
    rec = check_hypotheses(system(), 1.0).by_check(law)[0]
    assert rec.status == SKIPPED and f"{item} (failed)" in rec.message, rec.message
