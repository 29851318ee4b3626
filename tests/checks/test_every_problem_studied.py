"""Every problem gets a convergence verdict (issue 40): a user's problem without an exact solution, stated order
or step sizes is studied against a fine-grid reference — at the order the stepper claims, or for the proximal
scheme the general O(h^(1/2)) — never skipped; a stepper converging to the solution from the wrong x0 fails."""

from __future__ import annotations

import numpy as np

import verimono as vm
from verimono.core.convergence import GENERAL_ORDER, expected_order
from verimono.records.results import FAILED, PASSED


def disc(x, lam, t):
    c = np.array([t, 0.0])
    d = np.asarray(x, dtype=float) - c
    return c + d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1.0)


OP = vm.operator_from_resolvent(disc, 2, name="moving disc", project_domain=lambda x, t: disc(x, 1.0, t))
PROBLEM = vm.Problem(OP, x0=[0.0, 0.5], T=2.0, name="my moving disc")     # no exact solution, order or steps


def order_record(stepper):
    return next(r for r in vm.check_stepper(stepper, [PROBLEM], laws=False)
                if r.check == "convergence_order")


def test_the_proximal_scheme_is_held_to_the_general_order_on_a_problem_that_states_none():
    assert expected_order(vm.solve, PROBLEM) is GENERAL_ORDER and GENERAL_ORDER.value == 0.5
    rec = order_record(vm.solve)
    assert rec.status == PASSED and "expected 0.5" in rec.message, str(rec)


def test_a_stepper_started_from_a_wrong_x0_fails_the_order_on_a_users_problem():
    # self-convergent (the same scheme from 1.2 x0 converges), but to another limit: before, the order record
    # was skipped ("the problem states no expected order or no step sizes") and the battery was ok
    def scaled_x0(p, t_grid):
        return vm.solve(p.replace(x0=1.2 * np.asarray(p.x0)), t_grid)

    rec = order_record(scaled_x0)
    assert rec.status == FAILED and "not to the solution" in rec.message, str(rec)
    rep = vm.check_stepper(scaled_x0, [PROBLEM])
    assert {"convergence_order", "initial_value"} <= {r.check for r in rep.failures}


def test_a_claimed_order_on_a_users_problem_is_the_one_judged():
    stepper = vm.Stepper(vm.solve, scheme="any", order=1, name="solve claiming 1")
    assert expected_order(stepper, PROBLEM).value == 1.0
    assert order_record(stepper).status == PASSED
