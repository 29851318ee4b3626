"""Precision-aware judgement (issue 23, item 1): a subject computing in float32 is judged at float32
precision — every correct one passes, every broken one is still caught — and the record states the
precision it was judged at.  The multi-seed sweeps of the issue's "done when" are marked ``slow``; each has a
one-seed counterpart here."""

from __future__ import annotations

import math

import numpy as np
import pytest

import zoo
import zoo_steppers
from zoo_precision import float32, float32_problem, float32_stepper
from verimono import L1Subdifferential, operator_from_resolvent, solve
from verimono.checks import OPERATOR_CHECKS, check_operator, check_stepper, run_law
from verimono.checks.stepper_battery import CHECKS, LAWS as STEPPER_LAWS
from verimono.execution.profiles import get_profile
from verimono.reference import catalog as reference_catalog
from verimono.reference import get
from verimono.strategies import catalog
from verimono import tolerances as tol

CI = get_profile("ci").law_examples
OPERATORS = catalog(2) + catalog(3)[:3]
# the input-form bugs are out of reach behind float32(), which hands the member a fresh float64 copy
# (their float32 counterpart: tests/checks/test_forms.py)
ZOO_CASES = [(member, law) for member, laws in zoo.BREAKS.items() for law in laws if member not in zoo.FORM_BUGS]


# -- the derivation (tolerances.py) -------------------------------------------------------------------

def test_each_precision_sits_where_float64_sits_between_rounding_and_real_violations():
    assert tol.RTOL_BY_PRECISION["float64"] == tol.RTOL
    for p, eps in tol.EPS_BY_PRECISION.items():
        headroom = math.log10(tol.RTOL_BY_PRECISION[p] / eps)     # decades above the precision's rounding
        distance = -math.log10(tol.RTOL_BY_PRECISION[p])          # decades below violations of unit size
        # the geometric middle, as float64's RTOL ≈ 0.67 sqrt(EPS): both sides within 0.4 decades
        assert headroom > 0.8 and abs(distance - headroom) < 0.4 + 0.1 * (p != "float64"), (p, headroom, distance)
    assert tol.RTOL_BY_PRECISION["float32"] == pytest.approx(2.3e-4, rel=0.02)
    # a violation of 1e-2 (a real bug in float32) is still ~40 times the float32 slack
    assert 1e-2 / tol.RTOL_BY_PRECISION["float32"] > 40


def test_precision_names_and_the_coarser_deciding():
    assert tol.precision_name(np.float32) == "float32" and tol.precision_name("torch.float16") == "float16"
    assert tol.precision_name(np.complex64) == "float32" and tol.precision_name(np.int64) is None
    assert tol.coarser("float64", None, "float32") == "float32" and tol.coarser() == "float64"
    assert tol.coarser("float32", "bfloat16", "float16") == "bfloat16"
    with tol.judged_precision() as p:
        assert tol.tolerance(1.0) == pytest.approx(2 * tol.RTOL)
        tol.observe(np.float32)
        assert p.name == "float32" and tol.current_rtol() == tol.RTOL_BY_PRECISION["float32"]
        tol.observe(np.float64)                     # finer: changes nothing
        assert p.name == "float32"
    assert tol.current_rtol() == tol.RTOL          # outside any judgement: float64


def test_the_record_states_the_precision_and_the_coarser_of_input_and_output_decides():
    op = catalog(2)[3]
    r64 = run_law("resolvent_identity", op, seed=0, examples=5)
    assert r64.details["dtype"] == "float64" and r64.details["rtol"] == tol.RTOL
    r32 = run_law("resolvent_identity", float32(op), seed=0, examples=5)
    assert r32.status == "passed" and r32.details["dtype"] == "float32"
    # float64 outputs of a resolvent given float32 inputs (declared): float32 decides
    given32 = operator_from_resolvent(lambda x, lam, t: op.resolvent(np.asarray(x, np.float64), lam, t), 2,
                                      dtype="float32", name="given float32")
    assert run_law("resolvent_nonexpansive", given32, seed=0, examples=5).details["dtype"] == "float32"
    # half precision outputs: judged at float16
    half = operator_from_resolvent(lambda x, lam, t: np.asarray(op.resolvent(x, lam, t), np.float16), 2, name="half")
    rh = run_law("resolvent_nonexpansive", half, seed=0, examples=5)
    assert rh.details["dtype"] == "float16" and rh.status == "passed", str(rh)


def test_a_failure_at_float32_says_so():
    r = OPERATOR_CHECKS["resolvent_identity"](float32(zoo.build("stale_cache")), seed=0, examples=40)
    assert r.status == "failed" and "float32 precision" in r.message and r.details["dtype"] == "float32"


def test_a_float32_trajectory_states_its_precision():
    p = float32_problem(get("moving box"))
    traj = solve(p, np.linspace(0.0, p.T, 11))
    assert traj.precision == "float32" and traj.x.dtype == np.float64
    assert solve(get("moving box"), np.linspace(0.0, p.T, 11)).precision == "float64"


# -- float32 versions of the catalog and of solve pass at ci ------------------------------------------

def _passes(op, seed):
    report = check_operator(float32(op), seed=seed, examples=CI)
    assert report.ok, "\n".join(str(r) for r in report.failures)
    assert {r.details["dtype"] for r in report if r.status == "passed"} == {"float32"}


@pytest.mark.parametrize("op", OPERATORS, ids=lambda op: f"{op.name}/{op.dim}")
def test_float32_catalog_operator_passes_at_ci(op):
    _passes(op, 0)


@pytest.mark.sweep      # seed 0 is test_float32_catalog_operator_passes_at_ci, in the fast tier
@pytest.mark.parametrize("op", OPERATORS, ids=lambda op: f"{op.name}/{op.dim}")
def test_float32_catalog_operator_passes_at_ci_over_seeds_0_to_9(op):
    for seed in range(1, 10):
        _passes(op, seed)


def _solve_passes(seed, problems=None):
    report = check_stepper(float32_stepper(solve), problems, seed=seed)
    assert report.ok, "\n".join(str(r) for r in report.failures)
    assert {r.details.get("dtype") for r in report if r.status == "passed"} == {"float32"}


def test_float32_solve_passes_on_the_catalog():
    _solve_passes(0, reference_catalog()[:6])


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0] + [pytest.param(s, marks=pytest.mark.sweep) for s in range(1, 10)])
def test_float32_solve_passes_over_seeds_0_to_9(seed):
    _solve_passes(seed)


# -- float32 versions of the zoo are still caught -----------------------------------------------------

@pytest.mark.parametrize("member,law", ZOO_CASES, ids=[f"{m}-{lw}" for m, lw in ZOO_CASES])
def test_float32_zoo_operator_is_still_caught(member, law):
    r = OPERATOR_CHECKS[law](float32(zoo.build(member)), seed=0, examples=40)
    assert r.status == "failed" and r.details["dtype"] == "float32", str(r)


@pytest.mark.sweep      # seed 0 is test_float32_zoo_operator_is_still_caught, in the fast tier
@pytest.mark.parametrize("member,law", ZOO_CASES, ids=[f"{m}-{lw}" for m, lw in ZOO_CASES])
def test_float32_zoo_operator_is_still_caught_over_seeds_0_to_9(member, law):
    for seed in range(1, 10):
        r = OPERATOR_CHECKS[law](float32(zoo.build(member)), seed=seed, examples=40)
        assert r.status == "failed", f"seed {seed}: {r}"


@pytest.mark.parametrize("law", STEPPER_LAWS)
def test_float32_zoo_stepper_is_still_caught(law):
    member, ref, _ = zoo_steppers.BREAKS[law]
    rec = CHECKS[law](float32_stepper(member), get(ref))
    assert rec.status == "failed" and rec.details["dtype"] == "float32", str(rec)


@pytest.mark.slow
@pytest.mark.parametrize("member", zoo_steppers.ZOO, ids=lambda m: m.__name__)
def test_every_float32_zoo_stepper_is_caught_somewhere(member):
    m32 = float32_stepper(member)
    assert any(CHECKS[law](m32, q).status == "failed" for q in reference_catalog()[:12] for law in STEPPER_LAWS)


@pytest.mark.parametrize("rel,status", [(1e-3, "failed"), (0.0, "passed")])
def test_a_float32_resolvent_off_by_a_thousandth_in_ten_thousand_dimensions_fails(rel, status):
    """Power at float32 and large n (branch f32power): ``∂|·|₁`` in R^10^4 computing in float32, its resolvent times
    ``1 + rel``.  The tolerance ``rtol·(1 + |x|∞)`` does not grow with n (a correct float32 resolvent's Euclidean error,
    ``eps·|J|₂ ≤ sqrt(n)·eps·|J|∞``, stays below it while ``sqrt(n) ≤ rtol/eps ≈ 1950``), so a thousandth is caught by
    the resolvent identity ~36 times over its slack; the exact one stays ~0.006 of it."""
    n = 10_000
    F = float32(L1Subdifferential(1.0, n))
    op = operator_from_resolvent(lambda x, lam, t=0.0: np.asarray(F.resolvent(x, lam, t) * np.float32(1 + rel),
                                                                   np.float32), n, name=f"L1 times 1 + {rel}")
    r = run_law("resolvent_identity", op, seed=0, examples=5)
    assert r.status == status and r.details["dtype"] == "float32", str(r)
    assert (r.worst > 10) if status == "failed" else (r.worst < 0.1), str(r)
