"""Operator laws of :mod:`verimono.checks.operator_laws` (Proposition ``prop:maxmon-resolvent-Yosida``,
items i–vi, monotonicity (A1), the minimal section) on every generator family and the whole catalog.

* the catalog battery through :func:`verimono.testing.parametrize_with_checks` — one case per
  (operator, law), the same generator as :func:`verimono.check_operator`, each law searched by
  hypothesis inside the check;
* each generator family of :mod:`verimono.strategies` under ``@given``: hypothesis draws an operator *and*
  a law sample ``(x1, x2, λ, μ, ν, t)`` and every law is evaluated on that sample (``sample=`` mode, no
  nested search), so a failure shrinks to a small operator and simple inputs; the assertion message is the
  record with its counterexample.
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, event, given, settings, target
from hypothesis import strategies as st

from verimono import NormalCone, Shifted
from verimono import strategies as vs
from verimono.checks.operator_laws import LAWS, law_samples, operator_checks
from verimono.profiles import active_profile, get_profile
from verimono.results import FAILED
from verimono.testing import describe, parametrize_with_checks

T = 1.0
#: the catalog: every operator class, static and time-dependent, shifted, normal cones of every set type
CATALOG = vs.catalog(2) + vs.catalog(3)[:3]
#: hypothesis examples per law inside each catalog case (the profile's per-law effort)
LAW_EXAMPLES = max(5, get_profile(active_profile()).law_examples // 2)


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


@pytest.mark.parametrize("family", list(FAMILIES))
def test_laws_on_generated_operators(family):
    @settings(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(data=st.data())
    def run(data):
        op = data.draw(FAMILIES[family](), label="operator")
        sample = data.draw(law_samples(op.dim, T), label="sample")
        rec = _all_laws_hold(op, sample)
        assert rec is None, describe(rec)
    run()


def test_every_law_is_exercised():
    """Every law has a check in the battery (the registry and the law table agree)."""
    assert [name for name, _ in operator_checks()] == list(LAWS)
