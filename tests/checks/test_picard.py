"""picard_step: the Picard estimate e: bound x l plus one to x l (Step 1 of the proof of the Lipschitz
theorem of Section 6) on iterates built with the stepper; it must fail on a wrong Lipschitz constant."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.checks.picard import check_picard
from verimono.reference import get
from verimono.records.results import FAILED, PASSED, SKIPPED
from zoo_estimators import understated_lipschitz


def test_picard_bound_holds_and_iterates_converge_to_the_scheme():
    p = get("Lipschitz field and input")
    rec = check_picard(vm.solve, p)
    assert rec.status == PASSED and rec.worst <= 1.0, str(rec)
    d = rec.details["sup_differences"]
    assert all(b < a for a, b in zip(d, d[1:]))                    # a Cauchy sequence
    # its limit is the scheme with the explicit f: the last iterate is within the tail of the bound
    L, T, n = p.lipschitz, p.T, rec.details["iterations"]
    tail = sum((L * T) ** m / math.factorial(m) for m in range(n, n + 40)) * d[0]
    assert rec.details["limit_gap"] <= tail


def test_picard_bound_is_tight_for_a_pure_rotation():
    """F = 0 on the iterates (inside a ball of radius 100) and f(x) = Ax, A a rotation by π/2 (L = 1): the
    bound is attained up to the oscillation of the iterates; half the constant is contradicted."""
    A = np.array([[0.0, -1.0], [1.0, 0.0]])
    q = vm.Problem(vm.NormalCone(vm.sets.Ball([0.0, 0.0], 100.0)), [1.0, 0.0], 2.0, f=lambda x: A @ x,
                   lipschitz=1.0, name="rotation in a ball")
    assert check_picard(vm.solve, q).status == PASSED
    bad = check_picard(vm.solve, q, L=understated_lipschitz(q))
    assert bad.status == FAILED and bad.counterexample["diff"] > bad.counterexample["bound"], str(bad)


def test_wrong_lipschitz_constant_fails_with_the_counterexample():
    p = get("Lipschitz field and input")                           # f(x) = -0.5 x + 0.2: L = 0.5
    rec = check_picard(vm.solve, p, L=understated_lipschitz(p))
    assert rec.status == FAILED, str(rec)
    c = rec.counterexample
    assert c["L"] == 0.25 and c["diff"] > c["bound"] and c["form"] in ("recursion", "estimate")
    if c["form"] == "estimate":
        assert c["bound"] == (0.25 * c["tau"]) ** c["ell"] / math.factorial(c["ell"]) * c["sup_x1_minus_x0"]
    assert 0.25 < rec.details["L_hat"] <= 0.5 * (1 + 1e-9)        # the data need more than 0.25, never more than L
    assert "e: bound x l plus one to x l" in rec.message


def test_no_f_skips():
    assert check_picard(vm.solve, get("t|x| (n=1)")).status == SKIPPED


@pytest.mark.parametrize("stated", [0.8, 0.95, 0.99])
def test_picard_has_power_on_a_rotation_with_a_slightly_understated_L(stated):
    """Issue 24: the estimate alone has ratio 1/((ℓ+1)L^ℓ) to the truth on a rotation (L = 1), so with 8
    iterates only L < 0.743 was caught and L = 0.8 passed.  The step Δ^ℓ_k ≤ L Σ h_j Δ^{ℓ−1}_j is attained
    there: the data need L ≥ 1, and every understated L fails."""
    A = np.array([[0.0, -1.0], [1.0, 0.0]])
    q = vm.Problem(vm.NormalCone(vm.sets.Ball([0.0, 0.0], 100.0)), [1.0, 0.0], 2.0, f=lambda x: A @ x,
                   lipschitz=1.0, name="rotation in a ball")
    ok = check_picard(vm.solve, q)
    assert ok.status == PASSED and ok.details["L_hat"] == pytest.approx(1.0, rel=1e-9), str(ok)
    bad = check_picard(vm.solve, q, L=stated)
    assert bad.status == FAILED and bad.counterexample["form"] == "recursion", str(bad)
    assert "the data need L ≥ 1" in bad.message
