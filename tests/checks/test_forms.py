"""The input's form (verimono.checks.engine.forms): the operator laws pass a sample's points as int64, as strided and
offset views into garbage, read-only and in the declared dtype; a member that writes into its input fails.
The zoo's form bugs (tests/zoo.py) are seen failing in tests/checks/test_operator_laws.py; here the forms
themselves, the record and the replay, and the lawful controls."""

from __future__ import annotations

import numpy as np
import pytest

import zoo
import verimono as vm
from verimono.checks import LAWS, check_operator, run_law
from verimono.checks.engine.forms import (FORMS, INTEGER, READONLY, SLICE, STRIDED, InputModified, form_search, forms_for,
                                   in_form)
from verimono.checks.engine.samples import Sample

BALL = vm.sets.Ball([0.0, 0.0], 1.0)


def _seen(kinds):
    """A NumPy resolvent of N_B recording what arrays it is given."""
    def resolvent(x, lam, t):
        kinds.append((x.dtype, x.flags.c_contiguous, x.flags.writeable, x.base is not None))
        return BALL.project(np.asarray(x, dtype=float), t)
    return resolvent


def test_each_form_reaches_the_users_function_as_stated():
    kinds = []
    op = vm.operator_from_resolvent(_seen(kinds), 2)
    x = np.array([3.0, -4.0])
    expected = BALL.project(x, 0.0)
    for form, seen in [(INTEGER, (np.int64, True, True, False)), (STRIDED, (np.float64, False, True, True)),
                       (SLICE, (np.float64, True, True, True)), (READONLY, (np.float64, True, False, False))]:
        kinds.clear()
        assert np.array_equal(in_form(op, form).resolvent(x.copy(), 1.0, 0.0), expected)
        assert kinds == [seen], (form, kinds)
    kinds.clear()
    op.resolvent(x.copy(), 1.0, 0.0)        # outside the forms the adapter hands a float64 array as before
    assert kinds == [(np.float64, True, True, False)]
    kinds.clear()
    op.resolvent(np.array([3, -4]), 1.0, 0.0)
    assert kinds[0][0] == np.float64


def test_a_point_that_is_not_integer_valued_goes_as_float_in_the_integer_form():
    kinds = []
    in_form(vm.operator_from_resolvent(_seen(kinds), 2), INTEGER).resolvent(np.array([0.5, 2.0]), 1.0, 0.0)
    assert kinds[0][0] == np.float64


def test_the_views_garbage_is_outside_the_point_and_a_write_into_it_fails():
    def peek(x, lam, t):
        assert np.isnan(x.base).any() and np.isfinite(x).all()
        x.base[0] = 7.0                      # the caller's buffer around the point: not the subject's to write
        return np.asarray(x, dtype=float)
    op = vm.operator_from_resolvent(peek, 2)
    for form in (STRIDED, SLICE):
        with pytest.raises(InputModified, match="the buffer its input is a view of"):
            in_form(op, form).resolvent(np.array([1.0, 2.0]), 1.0, 0.0)


def test_a_write_into_the_input_fails_in_every_member():
    def scale(x, t=0.0):
        x *= 2
        return x
    op = vm.operator_from_resolvent(lambda x, lam, t: scale(x), 2, min_norm=scale, project_domain=scale)
    for member in ("resolvent", "min_norm", "project_domain"):
        args = (1.0, 0.0) if member == "resolvent" else (0.0,)
        with pytest.raises(InputModified, match=f"{member} wrote into its input"):
            getattr(in_form(op, INTEGER), member)(np.array([1.0, 2.0]), *args)
        with pytest.raises(ValueError, match="read-only"):
            getattr(in_form(op, READONLY), member)(np.array([1.0, 2.0]), *args)


def test_the_integer_form_rounds_the_sample_and_replays():
    s = Sample(np.array([2.4, -0.6]), np.array([1e300, 3.5]), 0.5, 1.0, 2.0, 0.25).in_form(INTEGER)
    assert s.x1.tolist() == [2.0, -1.0] and s.x2.tolist() == [1e300, 4.0] and s.form == INTEGER
    d = s.to_dict()
    assert d["form"] == INTEGER and Sample.from_dict(d).to_dict() == d
    assert repr(s).endswith("form='integer')")
    assert "form" not in Sample(np.zeros(2), np.ones(2), 1.0, 1.0, 1.0, 0.0).to_dict()
    with pytest.raises(ValueError, match="no input form"):
        s.in_form("fortran")


def test_a_form_failure_is_recorded_with_its_form_and_replays():
    r = run_law("yosida_in_graph", zoo.build("truncates_integers"), seed=0, examples=40)
    assert r.status == "failed" and r.counterexample["form"] == INTEGER
    assert all(float(v).is_integer() for v in r.counterexample["x1"] + r.counterexample["x2"])
    again = run_law("yosida_in_graph", zoo.build("truncates_integers"), sample=r.counterexample)
    assert again.status == "failed"
    plain = {k: v for k, v in r.counterexample.items() if k != "form"}     # the same points, contiguous: holds
    assert run_law("yosida_in_graph", zoo.build("truncates_integers"), sample=plain).status == "passed"


def test_what_was_searched_names_the_forms():
    r = run_law("resolvent_nonexpansive", vm.NormalCone(vm.sets.Ball([0.0, 0.0, 0.0], 1.0)), seed=0, examples=20)
    assert r.status == "passed"
    forms = r.details["searched"]["forms"]
    assert set(forms) == {"contiguous", INTEGER, STRIDED, SLICE, READONLY}
    assert all(forms[f] >= 2 for f in (INTEGER, STRIDED, SLICE, READONLY))       # cycled draws + the worst sample
    assert sum(forms.values()) == r.details["evaluations"]
    assert {"coordinate": "form", "forms": [INTEGER, STRIDED, SLICE, READONLY], "points": 4} in \
        r.details["searched"]["coordinates"]


def test_forms_apply_to_numpy_subjects_and_the_declared_dtype():
    op = vm.NormalCone(BALL)
    assert forms_for(op) == (INTEGER, STRIDED, SLICE, READONLY)

    class Torchy:
        array, dim = "torch", 2
    assert forms_for(Torchy()) == ()
    kinds = []
    f32 = vm.operator_from_resolvent(_seen(kinds), 2, array="numpy", dtype="float32")
    assert forms_for(f32) == (INTEGER, STRIDED, SLICE, READONLY, "declared_dtype") and set(FORMS) > set(forms_for(f32))
    for form in (STRIDED, SLICE, READONLY, "declared_dtype"):
        kinds.clear()
        in_form(f32, form).resolvent(np.array([3.0, -4.0]), 1.0, 0.0)
        assert kinds[0][0] == np.float32, (form, kinds)       # built in float32: the adapter passes it on as it is
    assert kinds[0][2] is True
    kinds.clear()
    in_form(f32, STRIDED).resolvent(np.array([3.0, -4.0]), 1.0, 0.0)
    assert kinds[0][1] is False


def test_form_search_evaluates_the_worst_sample_once_per_form():
    seen = []
    start = Sample(np.array([2.5, 0.0]), np.zeros(2), 1.0, 1.0, 1.0, 0.0)
    out = form_search(lambda s: seen.append(s) or 0.0, start, (INTEGER, READONLY))
    assert [s.form for s in seen] == [INTEGER, READONLY] and seen[0].x1.tolist() == [2.0, 0.0]
    assert out == {"coordinate": "form", "forms": [INTEGER, READONLY], "points": 2}
    assert form_search(lambda s: 1 / 0, start, ()) is None


@pytest.mark.parametrize("member", sorted(zoo.FORM_CONTROLS))
def test_the_form_bugs_written_correctly_pass_every_law(member):
    report = check_operator(zoo.FORM_CONTROLS[member](), seed=0, examples=8)
    assert len(report) == len(LAWS) and report.ok, "\n".join(str(r) for r in report.failures)
    assert all(r.details["searched"]["forms"].get(READONLY, 0) >= 1 for r in report if r.status == "passed")


def test_a_float32_subject_meets_the_view_forms_in_float32():
    """Declared float32 (operator_from_resolvent(..., dtype="float32")): the views are built in float32, so its
    adapter's conversion passes them on and a read of the parent buffer is caught at float32 precision."""
    def reads_base(x, lam, t):
        assert x.dtype == np.float32
        data = x if x.base is None else x.base
        return BALL.project(np.asarray(data, dtype=float)[:2], t).astype(np.float32)
    op = vm.operator_from_resolvent(reads_base, 2, array="numpy", dtype="float32")
    r = run_law("resolvent_nonexpansive", op, seed=0, examples=20)
    assert r.status == "failed" and r.details["dtype"] == "float32", str(r)
    assert r.counterexample["form"] in (STRIDED, SLICE)
    good = vm.operator_from_resolvent(lambda x, lam, t: BALL.project(np.asarray(x, dtype=float), t).astype(np.float32),
                                      2, array="numpy", dtype="float32")
    assert run_law("resolvent_nonexpansive", good, seed=0, examples=20).status == "passed"
