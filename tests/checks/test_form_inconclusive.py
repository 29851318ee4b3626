"""A vectorised form may state rows inconclusive by its law's own test (``Rows.inconclusive``): the search then counts
them as the evaluator's inconclusive samples, in their turn, without evaluating them again.  Such a row must be one the
law's evaluator finds inconclusive too (never a row it would judge), and the records must be the ones the evaluator
alone gives."""

from __future__ import annotations

import numpy as np
import pytest

import zoo
import verimono as vm
from verimono.checks import operator_laws  # noqa: F401 - the laws and their vectorised forms register
from verimono.checks.core import REGISTRY
from verimono.checks.engine.batches import VECTORISED, Rows
from verimono.checks.engine.samples import Sample
from verimono.checks.engine.search import evaluate_sample, run_law
from verimono.checks.engine.supremum import budgets
from verimono.checks.engine.sweep import law_draws, sweep_samples
from verimono.core.sets import Ball, Box

LAW = "contains_rejects"


def _samples(op):
    """Draws and the sweep, each again at tiny and huge λ (every point mapped to one J_λx, or J_λx1 within rounding of
    J_λx2: the evaluator's inconclusive samples) and at λ = 1."""
    base = law_draws(op.dim, 5, 1.0, 10, Sample) + sweep_samples(op, 5, 1.0, 10, Sample)
    return [Sample(s.x1, s.x2, lam, s.mu, s.nu, s.t) for s in base for lam in (1e-14, 1.0, 1e9)]


_OPERATORS = {
    "ball": lambda: vm.NormalCone(Ball(np.zeros(3), 1.0)),
    "box": lambda: vm.NormalCone(Box([-1.0, 0.0], [1.0, 2.0])),
    "norm": lambda: vm.NormSubdifferential(lambda t: 1.0 + t, dim=3),
    "l1": lambda: vm.L1Subdifferential(2.0, 2),
    "accepts_everything": lambda: zoo.build("contains_accepts_everything"),
}


@pytest.mark.parametrize("name", sorted(_OPERATORS))
def test_a_row_stated_inconclusive_is_inconclusive_to_the_law(name):
    op = _OPERATORS[name]()
    ss = _samples(op)
    rows = Rows(ss)
    with np.errstate(all="ignore"):
        VECTORISED[LAW](op, rows)
    decl = REGISTRY["operator"][LAW]
    outs = [evaluate_sample(decl, op, s) for s in ss]
    own = np.array([o.inconclusive for o in outs])
    assert rows.inconclusive is not None
    stated = rows.inconclusive & ~rows.ok       # what the search counts (a row still ok is the form's to decide)
    assert stated.any() and own[stated].all(), [ss[i] for i in np.flatnonzero(stated & ~own)]
    assert not (rows.inconclusive & rows.ok).any()
    # it finds most of them: the rows it leaves to the evaluator are near the threshold or lacked a call
    assert stated.sum() >= 0.9 * own.sum(), (int(stated.sum()), int(own.sum()))
    assert rows.inconclusive_what == next(o.what for o in outs if o.inconclusive)


@pytest.mark.parametrize("name", ["l1", "accepts_everything"])
def test_the_records_are_the_evaluators_own(name, monkeypatch):
    """The law's record (status, worst, counterexample, evaluations, inconclusive count and message) with the form's
    inconclusive rows is the record without them (the form stating none: every such row evaluated by the law)."""
    op = _OPERATORS[name]()
    with budgets(coordinate=3):
        got = run_law(LAW, op, seed=3, examples=4)
        form = VECTORISED[LAW]

        def stating_none(op_, r):
            q = form(op_, r)
            r.inconclusive = None
            return q
        monkeypatch.setitem(VECTORISED, LAW, stating_none)
        ref = run_law(LAW, op, seed=3, examples=4)
    for k in ("status", "worst", "counterexample", "message"):
        assert getattr(got, k) == getattr(ref, k), k
    for k in ("evaluations", "inconclusive", "harness_limited", "searched"):
        assert got.details[k] == ref.details[k], k
    assert got.details["inconclusive"] > 0
    assert got.status == ("failed" if name == "accepts_everything" else "passed"), str(got)
