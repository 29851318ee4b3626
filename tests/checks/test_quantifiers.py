"""A law declares its statement's quantifiers as data (``Law.over``, :data:`verimono.checks.core.QUANTIFIERS`), and
the engine searches what it declares: every declared coordinate appears in the record's ``details["searched"]``, and
a violation living in one coordinate only (a band of step decades no draw reaches) is found when the law declares
that coordinate and is outside the search when it does not."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks import laws_of
from verimono.checks.core import QUANTIFIERS, REGISTRY, Outcome
from verimono.checks.engine.coordinates import COORDINATES, MORE_FROM
from verimono.checks.engine.search import OPERATOR_DOMAIN, operator_law
from verimono.checks.engine.supremum import budget
from verimono.records.results import FAILED, PASSED

BALL = vm.NormalCone(vm.sets.Ball(np.zeros(3), 1.0))


def test_every_operator_and_assumption_law_declares_its_quantifiers():
    for kind in ("operator", "problem"):
        for name, decl in laws_of(kind).items():
            if name == "assumptions_thm_main":          # a composite of the others: their quantifiers
                continue
            assert decl.over and set(decl.over) <= set(QUANTIFIERS), (name, decl.over)
    assert "t" in laws_of("problem")["assumption_A1"].over
    with pytest.raises(ValueError, match="unknown quantifiers"):
        operator_law("_bad_quantifier", "none", over=("points", "angle"))(lambda op, s: None)


@pytest.mark.parametrize("law", ["monotone", "min_norm_least"])     # a vectorised law and one of its own
def test_each_declared_coordinate_is_in_the_record(law):
    rec = laws_of("operator")[law].check(BALL, seed=0)
    assert rec.status == PASSED, rec
    seen = {c["coordinate"] for c in rec.details["searched"]["coordinates"]}
    for q in laws_of("operator")[law].over:
        if q in COORDINATES and not (q in ("mu", "nu", "scale") and budget("coordinate") < MORE_FROM):
            assert q in seen, (q, seen)
    assert "form" in seen


def _band_law(name: str, over: tuple, band: tuple):
    """A toy operator law broken only for λ in ``band`` (far below the steps any draw, hypothesis example or
    sweep point has); the step decades reach it."""
    def check(op, s):
        bad = band[0] < s.lam < band[1]
        return Outcome.compare(2.0 if bad else 0.5, 1.0, 0.0, "a toy bound in λ")
    return operator_law(name, "toy", over=over)(check)


@pytest.mark.parametrize("band", [(1e-100, 1e-90), (1e-20, 1e-12)])
def test_the_engine_searches_what_the_law_declares(band):
    declared, undeclared = "_toy_band_declared", "_toy_band_undeclared"
    try:
        with_lam = _band_law(declared, OPERATOR_DOMAIN, band)(BALL, seed=0)
        without = _band_law(undeclared, ("points", "form", "t"), band)(BALL, seed=0)
    finally:
        REGISTRY["operator"].pop(declared, None)
        REGISTRY["operator"].pop(undeclared, None)
    assert with_lam.status == FAILED and band[0] < with_lam.counterexample["lam"] < band[1], with_lam
    assert without.status == PASSED, without
    seen = {c["coordinate"] for c in without.details["searched"]["coordinates"]}
    assert "lam decades" not in seen and "lam" not in seen and "direction" not in seen, seen
