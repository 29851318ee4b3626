"""Records are built in one place: every ``CheckResult`` of verimono is made by the record builder
(:func:`verimono.records.verdicts.new_record`, re-exported by the check core) or read back by the schema
reader (:func:`verimono.records.results.load`, :meth:`CheckResult.from_dict`).  A call ``CheckResult(...)``
anywhere else in the package is a record that bypasses the builder's rules."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from verimono.core.errors import UnitTimeout, UnverifiedSolution
from verimono.records.results import FAILED, SKIPPED, UNDECIDED
from verimono.records.verdicts import classify, new_record, record_of_exception

REPO = Path(__file__).resolve().parents[2]
#: the builder, and the schema reader that turns a results document back into records
ALLOWED = {"verimono/records/verdicts.py", "verimono/records/results.py"}


def constructions(source: str) -> list[int]:
    """Lines of the calls ``CheckResult(...)`` / ``x.CheckResult(...)`` in ``source``."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            f = node.func
            name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None
            if name == "CheckResult":
                lines.append(node.lineno)
    return lines


def test_the_finder_sees_a_construction():
    assert constructions("from x import CheckResult\nr = CheckResult('a', 'b', 'passed')\n") == [2]
    assert constructions("import verimono as vm\nr = vm.CheckResult('a', 'b', 'passed')\n") == [2]
    assert constructions('"""CheckResult(a, b)"""\nx = 1  # CheckResult(\n') == []


def test_no_record_is_built_outside_the_builder_and_the_schema_reader():
    found = []
    for folder in ("verimono", "reference", "properties"):
        for path in sorted((REPO / folder).rglob("*.py")):
            rel = path.relative_to(REPO).as_posix()
            if rel in ALLOWED:
                continue
            found += [f"{rel}:{line}" for line in constructions(path.read_text(encoding="utf-8"))]
    assert not found, "records built by hand, not by verimono.records.verdicts.new_record:\n" + "\n".join(found)


def test_the_builder_refuses_a_record_without_a_key_or_a_reason():
    rec = new_record("law", "subject", "passed", worst=0.5, bound=1.0)
    assert rec.key == "law[subject]" and rec.details == {}
    details = {"a": 1}
    assert new_record("law", "s", FAILED, message="m", details=details).details is not details
    for check, subject in (("", "s"), ("law", ""), ("law", None), (None, "s")):
        with pytest.raises(TypeError):
            new_record(check, subject, "passed")
    with pytest.raises(ValueError, match="status"):
        new_record("law", "s", "ok")
    for status in (UNDECIDED, SKIPPED):
        with pytest.raises(ValueError, match="say why"):
            new_record("law", "s", status)
    # a pass the ratio does not earn is not a pass, whoever builds it
    assert new_record("law", "s", "passed", worst=float("nan"), bound=1.0).status == FAILED


def test_the_policy_judges_an_exception_the_same_for_every_producer():
    assert classify(UnverifiedSolution("no verified answer"))[0] == UNDECIDED
    assert classify(NotImplementedError("no .contains"))[0] == SKIPPED
    assert classify(ZeroDivisionError("x"))[0] == FAILED
    assert classify(UnitTimeout("unit exceeded its budget"))[0] == FAILED
    rec = record_of_exception("law", "s", UnverifiedSolution("no verified answer"), seed=3)
    assert (rec.status, rec.seed, rec.details["exception"]) == (UNDECIDED, 3, "UnverifiedSolution")
