"""Results as data (lossless JSON, versioned schema) and the self-contained HTML report."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from verimono.cli import execute
from verimono.report.html import SECTIONS, render, reproduction
from verimono.report.schema import SCHEMA_NAME, SCHEMA_VERSION, SchemaError, environment, load, loads
from verimono.results import CheckResult, Report
from verimono.stages import RunContext

REFS = ["t|x| (n=1)", "moving box", "static ball, x0 inside"]


@pytest.fixture(scope="module")
def small_report() -> Report:
    """A real run of two stages on three references, plus hand-made records of every status."""
    from verimono.reference import get

    ctx = RunContext(problems=[get(n) for n in REFS])
    rep = execute(command="run", profile_name="ci", stages=["convergence", "trajectory_laws"], context=ctx)
    rep.add(CheckResult("firmly_nonexpansive", "broken resolvent", "failed", worst=math.inf, bound=1.0,
                        counterexample={"x": np.array([1.0, -2.0]), "y": [0.5, 0.5], "lam": 0.25, "t": 0.0},
                        message="ratio 3.2 > 1", seed=1234, details={"nested": {"a": [1, 2, math.nan]}},
                        duration=0.01))
    rep.add(CheckResult("min_norm_least", "an operator without F0", "skipped", message="min_norm missing"))
    rep.add(CheckResult("resolvent_identity", "known bad", "xfail", worst=2.0, bound=1.0, message="declared"))
    return rep


def test_json_round_trip_is_lossless(small_report, tmp_path):
    doc = small_report.to_dict()
    again = Report.from_dict(json.loads(json.dumps(doc)))
    assert again.to_dict() == doc
    path = small_report.save(tmp_path / "r.json")
    assert load(path).to_dict() == doc
    assert Report.from_json(small_report.to_json()).to_dict() == doc
    # the records themselves survive, including non-finite values and counterexamples
    by_key = {r.key: r for r in again}
    bad = by_key["firmly_nonexpansive[broken resolvent]"]
    assert bad.worst == math.inf and bad.seed == 1234 and bad.counterexample["x"] == [1.0, -2.0]
    assert [r.status for r in again] == [r.status for r in small_report]
    # studies come back as ConvergenceStudy objects with every error and interval
    s0, s1 = small_report.studies[0], again.studies[0]
    assert s1.errors == s0.errors and s1.mesh == s0.mesh and s1.steps == s0.steps
    assert s1.fits["sup"].low == s0.fits["sup"].low and s1.fits["sup"].high == s0.fits["sup"].high
    assert s1.expected == s0.expected and s1.verdict() == s0.verdict()
    assert again.trajectories == json.loads(json.dumps(small_report.trajectories))


def test_document_records_versions_machine_seeds_and_timings(small_report):
    doc = small_report.to_dict()
    assert doc["schema"] == SCHEMA_NAME and doc["schema_version"] == SCHEMA_VERSION
    versions = doc["meta"]["environment"]["versions"]
    for dist in ("verimono", "python", "numpy", "scipy", "hypothesis", "qpsolvers", "proxsuite", "daqp"):
        assert versions[dist], dist
    machine = doc["meta"]["environment"]["machine"]
    assert machine["cpu_count"] and machine["platform"] and machine["cpu"]
    assert doc["meta"]["profile"] == "ci" and doc["meta"]["calibration"] > 0
    assert [s["name"] for s in doc["meta"]["stages"]] == ["convergence", "trajectory_laws"]
    assert all(s["duration"] >= 0 for s in doc["meta"]["stages"])
    assert doc["summary"] == small_report.counts
    assert all("duration" in r for r in doc["results"])
    assert set(environment()["versions"]) >= {"python", "numpy"}


@pytest.mark.parametrize("text, reason", [
    ("not json", "not valid JSON"),
    ("[1, 2]", "expected a JSON object"),
    ('{"schema": "something.else", "schema_version": "1.0"}', "not a verimono results document"),
    (json.dumps({"schema": SCHEMA_NAME, "schema_version": "99.0", "results": [], "studies": [], "meta": {}}),
     "incompatible schema version"),
    (json.dumps({"schema": SCHEMA_NAME, "schema_version": "1.0", "studies": [], "meta": {}}), "results"),
    (json.dumps({"schema": SCHEMA_NAME, "schema_version": "1.0", "results": [{"check": "x"}], "studies": [],
                 "meta": {}}), "malformed result record"),
])
def test_bad_documents_raise_schema_error(text, reason):
    with pytest.raises(SchemaError, match=reason):
        loads(text)


def test_missing_file_raises_schema_error(tmp_path):
    with pytest.raises(SchemaError, match="does not exist"):
        load(tmp_path / "nope.json")


#: anything that would make a browser fetch something: remote src/href, external scripts, CSS imports
EXTERNAL = [
    re.compile(r"""(?:src|href)\s*=\s*["']?\s*(?:https?:)?//""", re.I),
    re.compile(r"<script\b", re.I),
    re.compile(r"@import", re.I),
    re.compile(r"""url\(\s*["']?(?!#)""", re.I),  # url(#clip) inside an SVG is internal
    re.compile(r"<link\b", re.I),
    re.compile(r"<iframe\b|<object\b|<embed\b|<img\b", re.I),
]


def test_html_report_structure_is_complete_and_self_contained(small_report):
    from verimono.gate import compare

    baseline = Report.from_dict(small_report.to_dict())
    baseline.results[0].status = "passed"
    changes = compare(baseline, small_report)
    html = render(small_report, changes=changes)
    assert html.startswith("<!DOCTYPE html>")
    for section in SECTIONS:
        assert re.search(rf'<section id="{section}">\s*<h2>', html), section
    # every plot is an inline SVG: one convergence plot per study, one per trajectory sample
    figures = re.findall(r"<figure>(.*?)</figure>", html, re.S)
    assert len(figures) == len(small_report.studies) + len(small_report.trajectories) > 0
    assert all(f.lstrip().startswith("<svg") for f in figures)
    assert html.count("<svg") == len(figures)
    for pattern in EXTERNAL:
        assert not pattern.search(html), pattern.pattern
    # internal references only: every xlink:href / href points inside the document
    assert all(h.startswith("#") for h in re.findall(r'href="([^"]*)"', html))
    # summary counts, a failure with its counterexample and reproduction, the law table, timings
    c = small_report.counts
    assert f'<div class="n">{c["failed"]}</div><div class="l">failed</div>' in html
    assert "broken resolvent" in html and "&quot;lam&quot;: 0.25" in html and "--seed 1234" in html
    for law in {r.check for r in small_report}:
        assert f'id="law-{law}"' in html
    assert "Calibration workload" in html and "numpy" in html


def test_reproduction_of_a_convergence_record_is_a_runnable_script(small_report):
    rec = next(r for r in small_report if r.check == "convergence_order")
    script = reproduction(rec, {"target": "mypkg.steppers:euler"})
    assert "from mypkg.steppers import euler as stepper" in script
    assert f"get({rec.details['study']['problem']!r})" in script


def test_html_without_baseline_says_so():
    html = render(Report([CheckResult("a", "b", "passed")], meta={"profile": "dev"}))
    assert "No baseline was given" in html and "All checks hold" in html
