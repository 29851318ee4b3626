"""verimono.testing.parametrize_with_checks, run inside pytest sessions (pytester): stable ids, ``-k``
selection, strict expected failures, counted skips, loud errors for a shrinking battery, and the
three-line user battery."""

from __future__ import annotations

import importlib
import re

import pytest

from verimono.checks.stepper_battery import LAWS
from verimono.reference import get
from verimono.testing import check_id, checks_for

pytest_plugins = ["pytester"]

STEPPER_FILE = '''
import sys
sys.path.insert(0, {tests!r})
from verimono.reference import get
from verimono.testing import parametrize_with_checks
from zoo_steppers import amplifier

PROBLEMS = [get("t|x| (n=1)"), get("static ball, x0 outside (jump)")]

@parametrize_with_checks([amplifier], problems=PROBLEMS, expected_failed_checks={xfail!r}{extra})
def test_battery(subject, check):
    check(subject)
'''


def _write(pytester, xfail, extra=""):
    import pathlib

    tests = str(pathlib.Path(__file__).parents[1])
    pytester.makepyfile(test_battery=STEPPER_FILE.format(tests=tests, xfail=xfail, extra=extra))


def _ids(result):
    return [line.split("::", 1)[1] for line in result.outlines if "::test_battery[" in line]


@pytest.mark.slow
def test_ids_are_stable_readable_and_selectable(pytester):
    _write(pytester, {})
    first = _ids(pytester.runpytest_inprocess("--collect-only", "-q", "-p", "verimono.testing"))
    second = _ids(pytester.runpytest_inprocess("--collect-only", "-q", "-p", "verimono.testing"))
    assert first == second and len(first) == 2 * (1 + len(LAWS))
    assert "test_battery[amplifier-contraction-t_x_n=1]" in first
    assert all(re.fullmatch(r"test_battery\[[\w.=+-]+\]", i) for i in first)
    res = pytester.runpytest_inprocess("-q", "-p", "verimono.testing", "-k", "in_domain and t_x")
    res.assert_outcomes(passed=1)


@pytest.mark.slow
def test_strict_xfail_skips_counted_and_summary(pytester):
    # amplifier on t|x|: contraction fails (expected), in_domain passes (wrongly expected -> XPASS strict)
    _write(pytester, {"contraction[t|x| (n=1)]": "amplifies differences",
                      "amplifier-in_domain-t_x_n=1": "wrongly expected to fail"})
    res = pytester.runpytest_inprocess("-q", "-rsxX", "-p", "verimono.testing")
    truth = {}
    for p in (get("t|x| (n=1)"), get("static ball, x0 outside (jump)")):
        from zoo_steppers import amplifier
        for name, fn in checks_for(amplifier, problems=[p]):
            truth[name] = fn(amplifier).status
    failed = sum(s == "failed" for s in truth.values()) - 1          # contraction[t|x|] is an xfail
    skipped = sum(s == "skipped" for s in truth.values())
    passed = sum(s == "passed" for s in truth.values()) - 1          # in_domain[t|x|] is an xpass(strict)
    assert skipped >= 3
    res.assert_outcomes(passed=passed, failed=failed + 1, skipped=skipped, xfailed=1)
    out = res.stdout.str()
    assert "[XPASS(strict)] wrongly expected to fail" in out
    assert "verimono checks" in out
    assert f"{len(truth)} collected, {len(truth)} ran: {passed} passed, {failed} failed, {skipped} skipped, " \
           f"1 xfailed (expected), 1 xpassed" in out
    assert "skipped x1: x0 is outside cl dom F(0,·) (catching-up jump)" in out
    assert "counterexample: problem='t|x| (n=1)'" in out          # failing records print their counterexample


@pytest.mark.slow
def test_unknown_expected_failure_is_an_error(pytester):
    _write(pytester, {"no_such_law": "typo"})
    res = pytester.runpytest_inprocess("-q")
    assert res.ret != 0 and "names checks that do not exist: ['no_such_law']" in res.stdout.str()


@pytest.mark.slow
def test_shrinking_battery_is_an_error(pytester):
    _write(pytester, {}, extra=", min_checks=100")
    res = pytester.runpytest_inprocess("-q")
    assert res.ret != 0 and "checks were lost" in res.stdout.str()


@pytest.mark.slow
def test_user_operator_in_three_lines(pytester):
    pytester.makepyfile(test_mine='''
import numpy as np
from verimono import operator_from_resolvent
my_operator = operator_from_resolvent(lambda x, lam, t: np.asarray(x) / (1.0 + lam), 2, name="identity_map")

from verimono.testing import parametrize_with_checks
@parametrize_with_checks([my_operator], examples=10)
def test_my_operator(subject, check): check(subject)
''')
    res = pytester.runpytest_inprocess("-q", "-p", "verimono.testing")
    n = len(checks_for(__import__("verimono").operator_from_resolvent(lambda x, l, t: x, 2)))
    outcomes = res.parseoutcomes()
    assert outcomes.get("failed", 0) == 0 and outcomes.get("passed", 0) + outcomes.get("skipped", 0) == n
    assert outcomes.get("skipped", 0) >= 1            # no min_norm / contains: those laws are skipped, counted
    assert f"{n} collected, {n} ran" in res.stdout.str()


def test_unknown_expected_failure_is_an_error_when_the_battery_is_built():
    """The session-free counterpart of the pytester test above (tier ``slow``): the decorator itself refuses."""
    from verimono.testing import parametrize_with_checks
    from zoo_steppers import amplifier

    problems = [get("t|x| (n=1)")]
    parametrize_with_checks([amplifier], problems=problems, expected_failed_checks={"contraction[t|x| (n=1)]": "x"})
    with pytest.raises(ValueError, match=re.escape("names checks that do not exist: ['no_such_law']")):
        parametrize_with_checks([amplifier], problems=problems, expected_failed_checks={"no_such_law": "typo"})


def test_check_id():
    assert check_id("selections[t|x| (n=1)]") == "selections-t_x_n=1"
    assert check_id("monotone") == "monotone"


def test_dropping_a_law_from_the_registry_is_a_shrunk_battery(monkeypatch):
    """Without min_checks the battery must still be the full registry: len(subjects) × the law table for
    operators, the references × (order + laws) plus the generated problems × laws for steppers."""
    import pytest

    from verimono import Linear
    from verimono.testing import parametrize_with_checks

    # the modules parametrize_with_checks imports (sys.modules): pytester's in-process runs restore
    # sys.modules afterwards, which can leave a stale submodule attribute on the verimono.checks package
    operator_battery = importlib.import_module("verimono.checks.operator_battery")
    stepper_battery = importlib.import_module("verimono.checks.stepper_battery")
    from zoo_steppers import amplifier

    ops = [Linear([[1.0]], name="a"), Linear([[2.0]], name="b")]
    parametrize_with_checks(ops)                                        # the full battery: fine
    reduced = {k: v for k, v in operator_battery.LAWS.items() if k != "monotone"}
    monkeypatch.setattr(operator_battery, "LAWS", reduced)
    with pytest.raises(ValueError, match="checks were lost"):
        parametrize_with_checks(ops)
    monkeypatch.undo()

    problems = [get("t|x| (n=1)")]
    parametrize_with_checks([amplifier], problems=problems)
    full = stepper_battery.stepper_checks

    def one_less(*args, **kw):
        return list(full(*args, **kw))[:-1]
    monkeypatch.setattr(stepper_battery, "stepper_checks", one_less)
    with pytest.raises(ValueError, match="checks were lost"):
        parametrize_with_checks([amplifier], problems=problems)


CLAIMS_FILE = '''
import sys
sys.path.insert(0, {tests!r})
import verimono as vm
from verimono.reference import get
from verimono.testing import parametrize_with_checks
from zoo_steppers import midpoint_time

PROBLEMS = [get("moving half-space")]

@parametrize_with_checks([vm.Stepper(midpoint_time, scheme="any", order=1), get("x' = c/x from 0 (order 1/2)")],
                         problems=PROBLEMS)
def test_battery(subject, check):
    check(subject)
'''


@pytest.mark.slow
def test_claims_and_problems_are_subjects_of_the_pytest_battery(pytester):
    """A declared scheme='any' stepper passes its battery with the proximal-only laws skipped (counted, with
    the declaration's reason); a Problem gets the assumption evidence, thm_main included."""
    import pathlib

    pytester.makepyfile(test_battery=CLAIMS_FILE.format(tests=str(pathlib.Path(__file__).parents[1])))
    res = pytester.runpytest_inprocess("-q", "-rs", "-p", "verimono.testing")
    # stepper: orders, unique_limit, in_domain, initial_value, trajectory_immutable pass; contraction and the 4
    # proximal-only laws skip.  problem: A1, A2, A3, YB, thm_main pass; LG is an expected failure (YB holds), a
    # skip-free pass here
    res.assert_outcomes(passed=5 + 6, skipped=5)
    out = "\n".join(res.outlines)
    assert "needs scheme='proximal'" in out and "contracts=True" in out
    assert "selections[moving half-space]: needs scheme='proximal'" in out
    assert "11 passed, 0 failed, 5 skipped" in out                 # the battery summary counts them
