"""Operator laws of :mod:`verimono.checks.operator_laws` (Proposition ``prop:maxmon-resolvent-Yosida``,
items i–vi, monotonicity (A1), the minimal section) on every generator family and the whole catalog.

* the catalog battery through :func:`verimono.testing.parametrize_with_checks` — one case per
  (operator, law), the same generator as :func:`verimono.check_operator`, each law searched by
  hypothesis inside the check;
* each generator family of :mod:`verimono.strategies` (with Section 7's passive complementarity systems)
  under ``@given``: hypothesis draws an operator *and*
  a law sample ``(x1, x2, λ, μ, ν, t)`` and every law is evaluated on that sample (``sample=`` mode, no
  nested search), so a failure shrinks to a small operator and simple inputs; the assertion message is the
  record with its counterexample.
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, Phase, event, given, settings, target
from hypothesis import strategies as st

from verimono import NormalCone, Shifted
from verimono import strategies as vs
from verimono.checks.operator_battery import LAWS, operator_checks
from verimono.checks.engine.samples import law_samples
from verimono.execution.config import current as current_config
from verimono.execution.profiles import get_profile
from verimono.records.results import FAILED
from verimono.testing import describe, parametrize_with_checks

T = 1.0
#: the catalog: every operator class, static and time-dependent, shifted, normal cones of every set type
CATALOG = vs.catalog(2) + vs.catalog(3)[:3]
#: hypothesis examples per law inside each catalog case (the profile's per-law effort)
LAW_EXAMPLES = max(5, (current_config().effort or get_profile("dev")).law_examples // 2)


@parametrize_with_checks(CATALOG, min_checks=len(CATALOG) * len(LAWS), examples=LAW_EXAMPLES)
def test_catalog_battery(subject, check):
    check(subject)


# -- generator families -----------------------------------------------------------------------------

def _moving_set_normal_cones(n=None):
    return vs.moving_sets(n, T).map(lambda m: NormalCone(m.set, name=f"NormalCone[{m.set.name}]"))


def _shifted(n=None):
    @st.composite
    def draw(draw_):
        F = draw_(vs.maximal_monotone_operators(n, T), label="F")
        u = draw_(vs.ac_inputs(F.dim, T), label="u")
        return Shifted(F, u.integral, name=f"Shifted[{F.name}, Φ=∫{u!r}]")
    return draw()


FAMILIES = {
    "monotone_linear": vs.monotone_linear_operators,
    "subdifferential": vs.subdifferential_operators,
    "moving_set_normal_cone": _moving_set_normal_cones,
    "shifted": _shifted,
    "maximal_monotone": lambda n=None: vs.maximal_monotone_operators(n, T),
    "catalog": lambda n=None: st.one_of(vs.catalog_operators(2), vs.catalog_operators(3)),
    # Section 7: H of a passive complementarity system (K = I, v > 0 so the relative-interior condition holds
    # by design; constant or moving v), n ≤ 3, m ≤ 2
    "lcs": lambda n=None: vs.lcs_operators(n, None, moving_v=None).map(lambda s: s.operator),
}


def _all_laws_hold(op, sample):
    """Evaluate every law on one sample; return the first failed record (or ``None``)."""
    worst = {}
    for name, check in operator_checks(op):
        rec = check(op, sample=sample)
        event(f"{name}: {rec.status}")
        if rec.worst is not None and rec.worst == rec.worst and rec.worst < float("inf"):
            worst[name] = rec.worst
        if rec.status == FAILED:
            return rec
    for name, w in worst.items():
        target(w, label=name)
    return None


def family_property(operators: st.SearchStrategy, examples: int | None = None, derandomize: bool | None = None,
                    shrink: bool = True):
    """The hypothesis test "every law holds on every operator of ``operators``": draws an operator and a law
    sample, the failed record (with its counterexample) is the assertion message.  ``examples``/``derandomize``
    override the profile and ``shrink=False`` reports the first failure unshrunk (tests that must see it fail
    on a broken family)."""
    extra = {} if examples is None else {"max_examples": examples}
    if derandomize is not None:
        extra.update(derandomize=derandomize, database=None)
    if not shrink:
        extra["phases"] = [Phase.explicit, Phase.reuse, Phase.generate]

    @settings(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large], **extra)
    @given(data=st.data())
    def run(data):
        op = data.draw(operators, label="operator")
        sample = data.draw(law_samples(op.dim, T), label="sample")
        rec = _all_laws_hold(op, sample)
        assert rec is None, describe(rec)
    return run


@pytest.mark.parametrize("family", list(FAMILIES))
def test_laws_on_generated_operators(family):
    family_property(FAMILIES[family]())()


def test_every_law_has_a_check_naming_its_paper_item():
    """Each law of the table has its own ``check_<law>`` in the registry, and that check's docstring names
    the paper item the law states (``Law.label``) — a law renamed, re-pointed or left undocumented fails."""
    import importlib

    from verimono.checks.operator_battery import OPERATOR_CHECKS

    for name, law in LAWS.items():
        fn = getattr(importlib.import_module(law.evaluate.__module__), f"check_{name}", None)
        assert fn is not None and OPERATOR_CHECKS.get(name) is fn, name
        doc = " ".join((fn.__doc__ or "").split())
        assert law.label in doc, f"check_{name} does not name its paper item {law.label!r}"
