"""The check core: laws declared once, requirements judged before anything runs, one driver, one outcome."""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import verimono as vm
from verimono.checks import core
from verimono.checks.assumptions import ASSUMPTION_LAWS, check_assumptions
from verimono.checks.operator_battery import LAWS as OPERATOR_LAWS
from verimono.checks.engine.search import ROOT_LAW
from verimono.checks.stepper_battery import CHECKS, LAWS as STEPPER_LAWS
from verimono.reference import get
from verimono.records.results import CheckResult


def _declarations() -> dict[int, core.Law]:
    """Every law declaration attached to a function of a ``verimono.checks`` module (``fn.law``), by identity."""
    import importlib
    import pkgutil

    import verimono.checks

    found = {}
    for info in pkgutil.iter_modules(verimono.checks.__path__):
        for obj in vars(importlib.import_module(f"verimono.checks.{info.name}")).values():
            decl = getattr(obj, "law", None)
            if isinstance(decl, core.Law):
                found[id(decl)] = decl
    return found


def test_every_law_is_declared_once_with_its_label_and_subject_kind():
    reg = core.REGISTRY
    assert set(OPERATOR_LAWS) == set(reg["operator"])
    assert ROOT_LAW in OPERATOR_LAWS
    # declared once: a second declaration of a name replaces the first in the registry, leaving the first
    # function's declaration out of it
    declared = list(_declarations().values())
    assert declared and all(reg[d.subject].get(d.name) is d for d in declared), [d.name for d in declared]
    assert set(STEPPER_LAWS) | {"convergence_order"} == set(core.laws_of("stepper", battery=True))
    assert set(ASSUMPTION_LAWS) | {"assumptions_thm_main"} == set(reg["problem"])
    for kind, laws in reg.items():
        for name, decl in laws.items():
            assert decl.name == name and decl.subject == kind and decl.label, decl
            # the decorator made the public check: the driver applied to the law, documented by the evaluator
            assert decl.public.__name__ == f"check_{name}" and decl.public.law is decl and decl.doc
    assert list(CHECKS) == list(STEPPER_LAWS)


def test_a_law_that_does_not_apply_is_skipped_before_the_stepper_runs():
    calls = []

    def recording(problem, t_grid):
        calls.append(len(t_grid))
        return vm.solve(problem, t_grid).x

    any_scheme = vm.Stepper(recording, scheme="any")
    rec = CHECKS["selections"](any_scheme, get("t|x| (n=1)"))
    assert rec.status == "skipped" and "needs scheme='proximal'" in rec.message and calls == []
    assert rec.details["label"] == "eq:iteration"
    # a problem that states no θ: bounds_yb is skipped from its declaration, nothing runs
    rec = CHECKS["bounds_yb"](recording, get("moving box"))
    assert rec.status == "skipped" and "θ" in rec.message and calls == []
    # f without its Lipschitz constant: contraction cannot state its bound
    p = get("Lipschitz field and input")
    rec = CHECKS["contraction"](recording, p.replace(lipschitz=None))
    assert rec.status == "skipped" and "Lipschitz constant" in rec.message and calls == []


def test_operator_members_are_requirements_judged_from_the_declaration():
    op = vm.operator_from_resolvent(lambda x, lam, t: np.asarray(x) / (1.0 + lam), 2, name="scaled")
    rep = vm.check_operator(op, seed=0, examples=5)
    skipped = {r.check: r.message for r in rep if r.status == "skipped"}
    assert set(skipped) == {"resolvent_in_domain", "yosida_in_graph", "yosida_bounded_by_min_norm", "yosida_limit",
                            "min_norm_in_graph", "min_norm_least", "prox_inequality", "prox_optimal",
                            "prox_minimiser", "moreau_envelope", "yosida_member", "contains_rejects",
                            "project_domain_nearest"}
    assert all("does not provide" in m for m in skipped.values())
    assert all(r.details["evaluations"] == 0 for r in rep if r.status == "skipped")


def test_an_operator_whose_resolvent_raises_gives_one_root_cause_record():
    def broken(x, lam, t):
        raise RuntimeError("factorization not initialised")

    rep = vm.check_operator(vm.operator_from_resolvent(broken, 3, name="broken"), seed=0)
    assert [r.check for r in rep.failures] == [ROOT_LAW]
    root = rep.failures[0]
    assert "RuntimeError: factorization not initialised" in root.message and "root cause" in root.message
    others = [r for r in rep if r.check != ROOT_LAW]
    assert sorted(r.check for r in others) == sorted(set(OPERATOR_LAWS) - {ROOT_LAW})   # one record per law
    assert all(r.status == "skipped" for r in others)
    assert all("root cause is recorded once" in r.message or "does not provide" in r.message for r in others)


def test_a_resolvent_of_the_wrong_shape_is_the_root_cause_too():
    op = vm.operator_from_resolvent(lambda x, lam, t: np.zeros(len(x) + 1), 2, name="long")
    rep = vm.check_operator(op, seed=0, examples=5)
    assert [r.check for r in rep.failures] == [ROOT_LAW] and "shape" in rep.failures[0].message


def test_an_exception_of_any_type_is_a_failure_of_the_subject_not_a_crash():
    def typo(problem, t_grid):
        return problem.x00        # AttributeError

    rec = CHECKS["in_domain"](typo, get("moving box"))
    assert rec.status == "failed" and "AttributeError" in rec.message


def test_the_one_outcome_type_fails_on_nan_and_infinite_sides():
    assert core.Outcome.compare(1.0, 2.0, 0.0, "x").worst == 0.5
    assert core.Outcome.compare(math.nan, 1.0, 0.0, "x").failed
    assert core.Outcome.compare(1.0, math.inf, 0.0, "x").failed
    assert core.Outcome(math.nan).failed and not core.Outcome(1.0).failed


def test_thm_main_is_a_composite_law_over_the_assumption_records():
    rep = check_assumptions(get("x' = c/x from 0 (order 1/2)"), seed=0)
    by = {r.check: r for r in rep}
    assert list(by) == list(ASSUMPTION_LAWS) + ["assumptions_thm_main"]
    # (LG) fails (|F^0| = c/x is unbounded) while (YB) holds: an expected failure, and the theorem applies
    assert by["assumption_LG"].status == "xfail" and "(YB) has evidence for it" in by["assumption_LG"].message
    assert by["assumptions_thm_main"].status == "passed"
    # both alternatives failing is evidence against the theorem's hypotheses
    recs = {n: CheckResult(n, "p", "failed" if n in ("assumption_LG", "assumption_YB") else "passed")
            for n in ASSUMPTION_LAWS}
    from verimono.checks.assumptions import thm_main
    out = thm_main(get("t|x| (n=1)"), recs)
    assert out.status == "failed" and "assumption_LG" in out.message and "assumption_YB" in out.message


def test_check_on_a_bare_resolvent_says_to_wrap_it_in_process(tmp_path, capsys):
    """The in-process counterpart of the next test (a subprocess, tier ``slow``)."""
    from verimono.cli import main

    mod = tmp_path / "myprox_inproc.py"
    mod.write_text("import numpy as np\ndef soft_threshold(x, lam, t=0.0):\n"
                   "    return np.sign(x) * np.maximum(np.abs(x) - lam, 0.0)\n")
    assert main(["check", f"{mod}:soft_threshold", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "operator_from_resolvent(soft_threshold" in err and "step size" in err


@pytest.mark.slow
def test_verimono_check_on_a_bare_resolvent_says_to_wrap_it(tmp_path):
    mod = tmp_path / "myprox.py"
    mod.write_text(textwrap.dedent("""
        import numpy as np
        def soft_threshold(x, lam, t=0.0):
            return np.sign(x) * np.maximum(np.abs(x) - lam, 0.0)
    """))
    out = subprocess.run([sys.executable, "-m", "verimono.cli", "check", f"{mod}:soft_threshold", "--out",
                          str(tmp_path / "out")], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 2, out
    assert "operator_from_resolvent(soft_threshold" in out.stderr and "step size" in out.stderr
    assert "Traceback" not in out.stderr


def test_a_nan_outcome_is_a_failed_record_never_a_pass():
    """Every law's record is built from the core's Outcome: a NaN ratio is a failure, not a pass
    (``nan > 1`` is False, which an old comparison took for a pass)."""
    rec = core.record("assumption_A1", "p", core.Outcome(math.nan, message="held"))
    assert rec.status == "failed"
    assert core.record("assumption_A1", "p", core.Outcome(0.5, message="held")).status == "passed"

def test_a_subject_has_one_name_whatever_the_status():
    """A stepper whose ``__name__`` and ``name`` differ is named once (its ``name``), whether the law runs or
    is skipped: the gate's key does not change with the status."""
    def my_stepper(problem, t_grid):
        return vm.solve(problem, t_grid).x
    my_stepper.name = "My stepper"
    p = get("moving box")
    ran = CHECKS["in_domain"](my_stepper, p)                 # runs: the problem's operator projects
    skipped = CHECKS["bounds_yb"](my_stepper, p)             # skipped: the problem states no θ
    assert ran.status == "passed" and skipped.status == "skipped"
    assert ran.subject == skipped.subject == "My stepper on moving box"
    assert core.subject_name(vm.Stepper(my_stepper, name="S")) == "S"
    assert core.subject_name(my_stepper) == "My stepper" and core.subject_name(lambda: 0) == "<lambda>"
