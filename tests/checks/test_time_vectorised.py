"""Issue 43: the time design of the assumption laws evaluated in one vectorised pass per law (``values.many``).

A law's vectorised form must give, at every time the engine accepts it at, the law's own value to the bit
(:func:`_mismatches`, on catalog problems whose laws run every time search: A1, A2, A3 with φ, LG with and
without σ, YB with θ); a form whose arithmetic is wrong by rounding only is caught by that comparison; and the
engine accepts a vectorised value only below ``SUSPECT`` times the form's bound — a value near or above it, or
not a number, is evaluated again by the law's own ``values`` (a wrong form never fails nor hides a violation
there)."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest

from verimono.checks import assumption_a2, assumption_bounds, assumptions
from verimono.checks.assumptions import check_assumptions
from verimono.checks.engine import supremum, times
from verimono.checks.engine.supremum import SUSPECT, Space, budgets, maximise
from verimono.reference import catalog

from assumption_records import assumption_records

#: a small time budget: the searches' shapes, not their resolution, are under test (96 strata)
SMALL = 16


@contextlib.contextmanager
def _recorded():
    """Every ``(values, lo, hi)`` the assumption laws hand :func:`search_time` within the block."""
    got, real = [], times.search_time

    def spy(values, lo, hi, **kw):
        got.append((values, float(lo), float(hi)))
        return real(values, lo, hi, **kw)

    mods = (assumptions, assumption_a2, assumption_bounds)
    for m in mods:
        m.search_time = spy
    try:
        yield got
    finally:
        for m in mods:
            m.search_time = real


def _mismatches(values, lo: float, hi: float, accepted_rows: list | None = None) -> list:
    """The times and families where the law's vectorised form, accepted by the engine, differs from its own
    ``values`` (bitwise), at 40 design times and for one and two families (``accepted_rows`` gets how many
    rows the engine would have taken from the form)."""
    width = np.asarray(values(lo, None)).size
    ts = times.time_design(lo, hi, 38, seed=3)
    form, bound = values.many, float(getattr(values.many, "bound", 1.0))
    bad = []
    for which in ([0], [width - 1], [0, width - 1] if width > 1 else [0]):
        table = np.asarray(form(ts, which), dtype=float).reshape(len(ts), len(which))
        for k, t in enumerate(ts.tolist()):
            own = np.asarray(values(t, which), dtype=float)
            row = table[k]
            with np.errstate(invalid="ignore"):
                accepted = (not np.isnan(row).any() if getattr(form, "own", False) else
                            np.all((row == -np.inf) | (np.isfinite(row) & (row <= SUSPECT * bound))))
            if accepted and accepted_rows is not None:
                accepted_rows.append(t)
            if accepted and not np.array_equal(row, own):
                bad.append((t, which, row.tolist(), own.tolist()))
    return bad


def _problem(name):
    return next(p for p in catalog() if p.name == name)


def _forms(name):
    with budgets(time=SMALL), _recorded() as got:
        check_assumptions(_problem(name), composite=False)
    return [(v, lo, hi) for v, lo, hi in got if hasattr(v, "many")]


@pytest.mark.parametrize("name, searches", [("moving box", 4), ("t|x| (n=3)", 5)])
def test_every_time_search_of_the_laws_has_a_vectorised_form_equal_to_the_law_to_the_bit(name, searches):
    """moving box: A1, A2, A3 (stated φ), LG's rays (no σ: the growth); t|x|: A1, A2, LG (stated σ) and its rays,
    YB (stated θ)."""
    forms = _forms(name)
    assert len(forms) == searches
    for values, lo, hi in forms:
        taken: list = []
        assert _mismatches(values, lo, hi, taken) == []
        assert len(taken) >= 40, values.many.__qualname__     # the comparison is not vacuous (of 120 rows)


def test_a_form_wrong_by_rounding_only_is_caught_by_the_comparison(monkeypatch):
    """(A1)'s pair ratio with its dot products reduced in another order (``np.einsum``: the form's first draft)
    differs from the law's ``z1 − z2 @ y1 − y2`` in the last bits at some times: the comparison sees it."""
    monkeypatch.setattr(assumptions, "_dots", lambda a, b: np.einsum("ij,ij->i", a, b))
    forms = _forms("moving half-space")
    a1 = [f for f in forms if f[0].many.__qualname__.startswith("_a1_sup")]
    assert len(a1) == 1
    assert _mismatches(*a1[0]), "an einsum-reduced A1 form should differ from the law's own ratio somewhere"


def _sup(values, **kw):
    return maximise(values, Space("t", 0.0, 1.0), design=[0.0, 1.0], cover=np.linspace(0.01, 0.99, 50),
                    points=80, seed=1, **kw)


def _law(t, which):
    """A law with two families: a bump at t = 0.3 (family 1), below the bound elsewhere."""
    v = np.array([0.2 + 0.1 * t, 0.2 + 0.7 * np.exp(-((t - 0.3) / 0.01) ** 2)])
    return v if which is None else v[list(which)]


def test_the_engine_with_a_form_finds_the_same_sup_as_time_by_time():
    def values(t, which):
        return _law(t, which)
    plain = _sup(values)
    values.many = lambda ts, which: np.array([_law(t, which) for t in ts])
    fast = _sup(values)
    assert (fast.value, fast.at, fast.family) == (plain.value, plain.at, plain.family)
    assert fast.searched.as_dict() == plain.searched.as_dict() and fast.local == plain.local


@pytest.mark.parametrize("wrong", [np.nan, np.inf, 0.9995, 5.0])
def test_a_vectorised_value_near_or_above_the_bound_or_not_a_number_goes_to_the_laws_own_values(wrong):
    """A form that answers ``wrong`` at every time: near or above the bound, or not a number, is never taken —
    the law's own values are, and the sup is the law's."""
    calls = []

    def values(t, which):
        calls.append(t)
        return _law(t, which)
    values.many = lambda ts, which: np.full((len(ts), len(which)), wrong)
    plain = _sup(lambda t, which: _law(t, which))
    got = _sup(values)
    assert (got.value, got.at, got.family) == (plain.value, plain.at, plain.family)
    assert len(calls) >= 50        # every coverage time evaluated again by the law


def test_an_accepted_form_that_hides_a_violation_is_what_the_bitwise_comparison_is_for():
    """The engine's acceptance alone cannot see a form that answers 0.5 where the law says 3 (it takes it):
    the sup then misses the violation — which is why every law's form is compared with its evaluator above."""
    def law(t, which):
        v = np.array([3.0 if abs(t - 0.5) < 0.05 else 0.1])
        return v if which is None else v[list(which)]

    def values(t, which):
        return law(t, which)
    values.many = lambda ts, which: np.full((len(ts), len(which)), 0.5)
    hidden = maximise(values, Space("t", 0.0, 1.0), design=[0.0, 1.0], cover=np.linspace(0.01, 0.99, 50),
                      points=60, seed=1, direct_points=0)
    assert hidden.value < 1.0 < _sup(law).value
    assert supremum.SUSPECT == SUSPECT


def test_a_form_that_is_the_laws_own_values_is_taken_as_it_is_but_for_a_row_it_could_not_evaluate():
    """``own = True``: the law's own values in a loop — a value above the bound is the law's (no second call),
    a NaN row (a block that met an unverified solve) is evaluated again."""
    calls = []

    def law(t, which):
        v = np.array([3.0 if abs(t - 0.5) < 0.05 else 0.1])
        return v if which is None else v[list(which)]

    def values(t, which):
        calls.append(t)
        return law(t, which)
    cover = np.linspace(0.01, 0.99, 50)
    values.many = lambda ts, which: np.array([np.nan if abs(t - 0.01) < 1e-12 else law(t, which)[0]
                                              for t in ts])[:, None]
    values.many.own = True
    got = maximise(values, Space("t", 0.0, 1.0), design=[0.0, 1.0], cover=cover, points=60, seed=1,
                   direct_points=0)
    assert got.value == 3.0
    assert sum(abs(t - 0.01) < 1e-12 for t in calls) >= 1          # the NaN row: the law itself
    assert not any(abs(t - 0.5) < 0.05 and t in cover.tolist() for t in calls)     # 3.0 taken from the form


# -- a time per row (issue 43): the catalog's operators called once per block of times ----------------------

#: a tinier time budget for the records' comparison (24 strata): every path is taken, at a fraction of the cost
TINY = 4


def _records(name, monkeypatch, **patches):
    """The five assumption records of reference ``name`` (tiny time budget) as dicts without ``duration``,
    with ``patches`` set on every module that asks ``accepts_times`` (tests/assumption_records.py)."""
    return assumption_records(name, monkeypatch, TINY, **patches)


@pytest.mark.parametrize("name", ["moving-box", "tnorm-3", pytest.param("translating-ball", marks=pytest.mark.slow),
                                  pytest.param("play-piecewise-linear", marks=pytest.mark.slow),
                                  pytest.param("c-over-x", marks=pytest.mark.slow)])
def test_the_laws_give_the_same_records_with_a_time_per_row_as_time_by_time(name, monkeypatch):
    """Every path that calls the operator once per block of times — the forms of the coverage, the sample-time
    loops, (A2)'s levels and zoom — against the per-time path a user's operator takes (``accepts_times`` False):
    the records are equal field by field (status, worst, counterexample, what was searched)."""
    per_time = _records(name, monkeypatch, accepts_times=lambda op: False)
    assert _records(name, monkeypatch) == per_time


def test_a_time_per_row_taken_in_the_wrong_order_changes_the_records(monkeypatch):
    """The comparison above is not vacuous: ``on_times`` with each block's times reversed (row ``i`` at
    ``t[B−1−i]``) gives other records."""
    from verimono.checks.assumption_samples import on_times

    def reversed_times(op, P, lam, ts):
        return on_times(op, P, lam, np.asarray(ts)[::-1])
    assert _records("moving-box", monkeypatch, on_times=reversed_times) != _records("moving-box", monkeypatch)
