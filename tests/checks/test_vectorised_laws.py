"""The operator laws' vectorised forms (verimono.checks.engine.batches): the same inequalities over many samples at
once.  A vectorised ratio must equal the law's own ratio sample by sample (same tolerances, same slack), on lawful
operators and on broken ones alike, whether the operator maps batches (one call per distinct (λ, t)) or is called
row by row; the search accepts a vectorised ratio only clearly inside the bound and re-evaluates every other row by
the law's own evaluator, so a failure is still found, recorded with the law's own numbers and replayed."""

from __future__ import annotations

import numpy as np
import pytest

import zoo
import verimono as vm
from verimono.checks import operator_laws, prox_laws  # noqa: F401 - the laws and their vectorised forms register
from verimono.checks.core import REGISTRY, Member, provides
from verimono.checks.engine.batches import SUSPECT, VECTORISED, Rows, rows_accepted
from verimono.checks.engine.samples import Sample
from verimono.checks.engine.search import evaluate_sample, run_law
from verimono.checks.engine.supremum import budgets
from verimono.checks.engine.sweep import law_draws, sweep_samples
from verimono.core.sets import Ball

#: the laws' sums are BLAS dots (scalar) and einsum (rows): their ratios agree to a few units of rounding of the
#: larger side, i.e. relatively, and absolutely in units of the bound (1) where a ratio is a cancellation ~1e-9
AGREE = 1e-9


#: the lawful operators of the parametrisation: most of their rows are decided by the vectorised form
LAWFUL = ("ball", "norm")


def _samples(op, count=12):
    return (law_draws(op.dim, 5, 1.0, count, Sample) + sweep_samples(op, 5, 1.0, count, Sample))


@pytest.mark.parametrize("law", sorted(VECTORISED))
@pytest.mark.parametrize("make", [lambda: vm.NormalCone(Ball(np.zeros(3), 1.0)),
                                  lambda: vm.NormSubdifferential(lambda t: 1.0 + t, dim=3),
                                  lambda: zoo.build("explicit_step"), lambda: zoo.build("non_monotone_linear")],
                         ids=["ball", "norm", "explicit_step", "non_monotone_linear"])
def test_a_vectorised_ratio_is_the_laws_own_ratio(law, make, request):
    op = make()
    decl = REGISTRY["operator"][law]
    lacking = [m.name for m in decl.requires if isinstance(m, Member) and not provides(op, m.name)]
    if lacking:       # the law is skipped on this operator before it runs: its form is never called there
        assert run_law(law, op, seed=1, examples=3).status == "skipped"
        return
    ss = _samples(op)
    rows = Rows(ss)
    with np.errstate(all="ignore"):
        q = VECTORISED[law](op, rows)
    own = np.array([evaluate_sample(decl, op, s).ratio for s in ss])
    fine = rows.ok & np.isfinite(own)
    if request.node.callspec.id.split("-")[0] in LAWFUL:      # a broken operator's rows may all go to the law
        assert fine.sum() >= len(ss) // 2
    # to AGREE, or within the form's stated rounding bound where its law's ratio is a cancellation of two norms
    # (yosida_limit's gap ||F^0| - |Y_λx||: up to ~eps/rtol in units of the slack)
    agree = np.maximum(AGREE * (1.0 + np.abs(own)), 0.0 if rows.err is None else rows.err)
    assert (np.abs(q - own)[fine] <= agree[fine]).all(), (law, q[fine], own[fine])
    assert not (q[fine] <= SUSPECT)[own[fine] > 1.0].any()       # a violated row is never accepted
    if rows.err is not None:      # the form's stated rounding bound covers its difference from the law's own ratio
        finite = fine & np.isfinite(q)
        assert (np.abs(q - own)[finite] <= rows.err[finite]).all(), (law, np.abs(q - own)[finite], rows.err[finite])
        assert not rows.accepted(q)[fine & (own > 1.0)].any()


def test_the_catalog_maps_batches_and_a_patched_resolvent_is_called_row_by_row():
    op = vm.NormalCone(Ball(np.zeros(3), 1.0))
    assert rows_accepted(op)
    op.resolvent = lambda x, lam, t=0.0: np.zeros(3)           # instrumented on the object: one call per row
    assert not rows_accepted(op)


@pytest.mark.slow       # three searches through hypothesis: ~3 s
def test_a_row_the_vectorised_form_cannot_decide_is_failed_by_the_law_itself():
    """A ball's projection that triples points of |x| < 10^-3 (expansive there, by 3): the vectorised form passes
    the rows it sees inside the bound, the tiny rows of the sweep it does not are evaluated by the law, which fails
    one with its own numbers (ratio 3 up to the slack); the control (correct everywhere, same seed) passes."""
    def proj(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        r = np.linalg.norm(x)
        return x * (3.0 if r < 1e-3 else 1.0) / max(1.0, r)
    bad = vm.operator_from_resolvent(proj, 3, name="triples tiny points")
    good = vm.operator_from_resolvent(lambda x, lam, t=0.0: np.asarray(x, float) / max(1.0, np.linalg.norm(x)), 3,
                                      name="ball projection")
    with budgets(coordinate=3):         # the draws and the sweep decide here: a short coordinate phase
        rec = run_law("resolvent_nonexpansive", bad, seed=1, examples=20)
        ctl = run_law("resolvent_nonexpansive", good, seed=1, examples=20)
    cex = rec.counterexample
    assert rec.status == "failed" and abs(cex["lhs"] / cex["rhs"] - 3.0) < 1e-9, str(rec)     # |ΔJ| = 3|Δx|
    again = run_law("resolvent_nonexpansive", bad, sample=rec.counterexample)
    assert again.status == "failed"
    assert ctl.status == "passed", str(ctl)


def test_the_points_searched_are_fixed_by_seed_and_profile():
    op = vm.NormalCone(Ball(np.zeros(3), 1.0))
    with budgets(coordinate=9):
        a, b = (run_law("monotone", op, seed=7, examples=10) for _ in range(2))
    assert a.details["evaluations"] == b.details["evaluations"] and a.worst == b.worst
    assert a.details["searched"]["coordinates"] == b.details["searched"]["coordinates"]


def test_yosida_limits_form_halves_lambda_as_the_law_does():
    """``yosida_limit``'s form halves λ over all rows at once, as the law halves it: on a linear operator
    (``|Y_λx| → |Ax|`` only as ``λ → 0``, so the gap closes after many halvings) it decides most rows at a later λ,
    each at the law's own ratio within its stated rounding bound — ratios up to ~1, the gap closing just inside the
    slack; a row whose λ is below the law's rounding floor starts, as the law does, at that floor (the λ decades of
    the coordinate search reach 10^-150); on ``wrong_lambda`` (zoo) no row the law fails is accepted."""
    law, decl = "yosida_limit", REGISTRY["operator"]["yosida_limit"]
    lin = vm.Linear(np.array([[2.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.5]]))
    for op, lawful in ((lin, True), (zoo.build("wrong_lambda"), False)):
        ss = _samples(op, 20)
        tiny = [Sample(s.x1, s.x2, lam, s.mu, s.nu, s.t) for s in ss[:4] for lam in (1e-150, 1e-40, 1e-16)]
        ss += tiny
        rows = Rows(ss)
        with np.errstate(all="ignore"):
            q = VECTORISED[law](op, rows)
        own = np.array([evaluate_sample(decl, op, s).ratio for s in ss])
        took = rows.accepted(q)
        assert (np.abs(q - own)[took] <= rows.err[took]).all(), (q[took], own[took])
        assert not (took & (own > 1.0)).any()
        if lawful:      # decided after halvings (a ratio well above the first λ's): most rows, not only the easy ones
            assert took.sum() >= 0.5 * len(ss) and (took & (q > 0.5)).sum() >= 0.2 * len(ss), (took.sum(), q[took])
            assert took[-len(tiny):].all(), q[-len(tiny):]       # from the floor, where the gap closes at once
        else:
            assert (own > 1.0).any()
