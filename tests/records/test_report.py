"""Results as data (lossless JSON, versioned schema) and the self-contained HTML report."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from verimono.run.execute import execute
from verimono.records.report.html import SECTIONS, render, reproduction
from verimono.records.results import SCHEMA_NAME, SCHEMA_VERSION, SchemaError, environment, load, loads
from verimono.records.results import CheckResult, Report
from verimono.run.stages import RunContext

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


def test_json_values_convert_non_finite_floats_wherever_they_sit():
    """Plain JSON from NumPy values: non-finite floats become their repr (strict JSON has no NaN), also inside
    arrays and lists of floats, which otherwise pass as they are (the trajectories' fast path)."""
    from verimono.records.results import to_jsonable

    assert to_jsonable((1.0, 2.5)) == [1.0, 2.5] and to_jsonable([1.0, math.inf]) == [1.0, "inf"]
    assert to_jsonable([1.0, 2]) == [1.0, 2] and to_jsonable([]) == []
    assert to_jsonable(np.array([[0.5, 1.0]])) == [[0.5, 1.0]]
    assert to_jsonable(np.array([math.nan, 1.0])) == ["nan", 1.0]
    assert to_jsonable(np.array([1, 2])) == [1, 2] and to_jsonable(np.float32(0.25)) == 0.25
    json.dumps(to_jsonable({"x": np.array([-math.inf]), "y": [math.nan]}), allow_nan=False)


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
    from verimono.run.gate import compare

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
    assert f"get({rec.study.problem!r})" in script


def test_html_without_baseline_says_so():
    html = render(Report([CheckResult("a", "b", "passed")], meta={"profile": "dev"}))
    assert "No baseline was given" in html and "All checks hold" in html


def test_schema_docstring_lists_every_meta_key_a_run_writes(small_report):
    from verimono import schema  # the document's layout is stated once, in its docstring

    for key in small_report.to_dict()["meta"]:
        assert f'"{key}"' in schema.__doc__, key


def test_environment_records_optional_solvers_and_blas():
    env = environment()
    for dist in ("cvxpy", "clarabel"):
        assert env["versions"][dist], dist  # a version, or "not installed"
    blas = env["blas"]
    assert blas and all(b["internal_api"] and b["version"] is not None for b in blas)


def test_a_document_of_an_older_minor_version_is_read(small_report):
    doc = small_report.to_dict()
    doc["schema_version"] = SCHEMA_VERSION.split(".")[0] + ".0"
    assert Report.from_dict(doc).to_dict()["results"] == doc["results"]


def _python_of(snippet: str) -> str:
    """The Python source of a reproduction (the body of its ``python - <<'EOF'`` heredoc, if any)."""
    lines = snippet.splitlines()
    if lines and lines[0].startswith("python - <<"):
        lines = lines[1:lines.index("EOF")]
    return "\n".join(lines)


@pytest.mark.parametrize("target", ["mypkg.steppers:euler", "mypkg.steppers:Schemes.euler", "lagged.py:solve",
                                    "{tmp}/x/lagged.py:solve", "{tmp}/my steppers/lagged.py:solve"])
def test_reproduction_binds_the_target_stepper_for_every_target_kind(small_report, target, tmp_path, monkeypatch):
    """The reproduction's import lines, run from the directory `verimono check` ran in, bind exactly the
    target (``lagged.py:solve`` once became ``from lagged.py import solve``: it compiles, and imports a
    submodule ``py`` of a package ``lagged``)."""
    import textwrap

    target = target.format(tmp=tmp_path)
    module, _, obj = target.partition(":")
    if module.endswith(".py"):
        path = tmp_path / module if not module.startswith("/") else Path(module)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"def solve(problem, t):\n    return {target!r}\n")
        expect = target
    else:
        pkg = tmp_path / "mypkg"
        pkg.mkdir(exist_ok=True)
        (pkg / "__init__.py").write_text("")
        (pkg / "steppers.py").write_text(textwrap.dedent("""
            def euler(problem, t):
                return "euler"
            class Schemes:
                euler = staticmethod(lambda problem, t: "Schemes.euler")
        """))
        expect = "euler" if obj == "euler" else "Schemes.euler"
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    rec = next(r for r in small_report if r.check == "convergence_order")
    script = _python_of(reproduction(rec, {"target": target, "command": "check"}))
    binding = "\n".join(line for line in script.splitlines()
                        if ("stepper" in line or "load_target" in line) and "check_" not in line)
    scope: dict = {}
    exec(compile(binding, "<repro>", "exec"), scope)
    assert scope["stepper"](None, None) == expect


def _section(html: str, name: str) -> str:
    return re.search(rf'<section id="{name}">(.*?)</section>', html, re.S).group(1)


def _law_row(html: str, check: str) -> str:
    return re.search(rf'<tr[^>]*><td><a href="#law-{check}">.*?</tr>', _section(html, "laws"), re.S).group(0)


def test_laws_table_ranks_worst_among_passed_and_failed_and_shows_xfail_apart():
    rep = Report([CheckResult("assumption_LG", "a", "passed", worst=2.0, bound=10.0),
                  CheckResult("assumption_LG", "b", "xfail", worst=1183.0, bound=10.0, message="declared")])
    row = _law_row(render(rep), "assumption_LG")
    cells = re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)
    assert cells[6:8] == ["2", "10"] and "1183" not in "".join(cells[6:10])   # worst, bound, bar, subject
    assert "#c62828" not in row                                                # no red bar: nothing failed
    assert "1183" in row and "xfail" in row                                   # shown apart, labelled


def test_negative_zero_is_shown_as_zero():
    html = render(Report([CheckResult("monotone", "op", "passed", worst=-0.0, bound=1.0)]))
    assert ">-0<" not in html and ">0<" in _law_row(html, "monotone")


def test_counterexamples_are_compact_and_as_precise_in_memory_as_from_json():
    rec = CheckResult("firmly_nonexpansive", "op", "failed", worst=3.0, bound=1.0, message="m",
                      counterexample={"x": np.array([1 / 3, -2.0, 1e-20]), "lam": np.float64(0.25),
                                      "A": np.eye(2), "t": 0.0})
    rep = Report([rec])
    live = _section(render(rep), "failures")
    again = _section(render(Report.from_dict(rep.to_dict())), "failures")
    assert live == again
    ce = re.search(r"<b>Counterexample</b>.*?<pre>(.*?)</pre>", live, re.S).group(1)
    assert "&quot;x&quot;: [0.333333, -2, 1e-20]" in ce                     # a vector on one line
    assert "&quot;A&quot;: [[1, 0], [0, 1]]" in ce
    assert len(ce.splitlines()) == 6                                         # braces + one line a key


def test_siconos_error_the_gate_checks_is_in_the_laws_table():
    rep = Report([CheckResult("siconos_agreement", "DiodeBridge.ref", "passed", worst=4.27e-4, bound=1.0,
                              message="max relative state error 4.27e-14", details={"error": 4.274e-14})])
    html = render(rep)
    assert "4.274e-14" in _law_row(html, "siconos_agreement")
    block = re.search(r'<details id="law-siconos_agreement">.*?</details>', html, re.S).group(0)
    assert re.search(r'<td class="num">4.274e-14</td>', block)


def test_changes_are_grouped_per_subject():
    from verimono.run.gate import Change, Comparison

    broken = "solve on moving box"
    changes = [Change("status", f"convergence_order[{broken}]", "passed → failed", True),
               Change("status", f"contraction[{broken}]", "passed → failed", True),
               Change("order", broken, "sup-norm order fell", True)]
    changes += [Change("error", broken, f"sup error at h={h} grew", True) for h in (0.1, 0.05, 0.025)]
    changes += [Change("status", "monotone[Ball]", "passed → failed", True)]
    html = _section(render(Report([CheckResult("a", "b", "passed")]),
                           changes=Comparison(changes, 10, {})), "changes")
    table = re.search(r"<table>.*?</table>", html, re.S).group(0)
    rows = re.findall(r"<tr[ >].*?</tr>", table.split("<tbody>")[1], re.S)
    assert len(rows) == 2                                   # the broken study, and monotone[Ball]
    assert broken in rows[0] and "6 regressions" in rows[0]
    assert all(_e in html for _e in ("sup error at h=0.025 grew", "sup-norm order fell"))


def test_a_failing_law_reproduces_with_the_reference_the_run_names():
    """The run (not the renderer) says which catalog reference a counterexample needs: `--reference NAME`."""
    from zoo_steppers import leaves_domain

    from verimono.reference import get

    ctx = RunContext(stepper=leaves_domain, problems=[get("moving box")])
    rep = execute(command="run", profile_name="ci", stages=["trajectory_laws"], context=ctx)
    failed = [r for r in rep if r.check == "in_domain" and r.status == "failed"]
    assert failed and failed[0].details["reference"] == "moving box"
    assert "--reference 'moving box'" in reproduction(failed[0], {"command": "run", "profile": "ci"})
    own = CheckResult("in_domain", "mine", "failed", counterexample={"problem": "moving box"})
    assert "--reference" not in reproduction(own, {"command": "run"})  # nothing said, nothing guessed


def test_plots_drawn_ahead_are_the_reports_plots_drawn_once(small_report, monkeypatch):
    """A run on worker processes draws its plots while it waits (``plots.draw_ahead``): the report then uses
    them, draws none twice, and is the document it would be without them (apart from the figures' ids)."""
    from verimono.records.report import plots

    drawn = []
    figure = plots.convergence_figure
    monkeypatch.setattr(plots, "convergence_figure",
                        lambda s, ax=None, **kw: drawn.append(s) or figure(s, ax, **kw))
    plots.forget()
    plain = render(small_report)
    assert len(drawn) == len(small_report.studies) > 0
    plots.forget()
    drawn.clear()
    plots.draw_ahead(small_report.studies, small_report.trajectories).join()
    assert len(drawn) == len(small_report.studies)
    ahead = render(small_report)
    assert len(drawn) == len(small_report.studies)      # nothing drawn again
    svg = re.compile(r'<svg role="img" class="plot".*?</svg>', re.S)
    assert len(svg.findall(ahead)) == len(svg.findall(plain)) == len(small_report.studies) + len(
        small_report.trajectories)
    assert svg.sub("", ahead) == svg.sub("", plain)
    plots.forget()


def test_the_reports_reused_axes_draw_what_a_fresh_figure_draws(small_report):
    """The report draws every plot of a kind on one reused axes (``plots._reused_axes``): each plot, drawn
    after the others, is the SVG a new figure gives (apart from the figures' salted ids)."""
    from verimono.records.report import plots

    def same(svg: str) -> str:
        return re.sub(r"\b[mp][0-9a-f]{10}\b", "ID", re.sub(r"vm\d+x\d+", "vm", svg))

    kinds = [(plots.convergence_figure, "convergence", small_report.studies),
             (plots.trajectory_figure, "trajectory", small_report.trajectories)]
    for figure, kind, subjects in kinds:
        assert len(subjects) >= 2
        fresh = [same(plots._svg(figure(s, legend=False))) for s in subjects]
        for _ in range(2):                      # each plot drawn over every other one
            reused = [same(plots._svg(figure(s, plots._reused_axes(kind), legend=False))) for s in subjects]
            assert reused == fresh
            subjects, fresh = subjects[::-1], fresh[::-1]


def test_a_drawer_process_draws_the_reports_plots_and_a_dead_one_leaves_them_here(small_report, tmp_path):
    """The command line's drawer (``report.drawer``, forked with the first calibration): the plots asked
    of it are the ones this process would draw (apart from the figures' ids), each drawn once there; when
    it dies, the report draws what it owed here."""
    import pickle
    import subprocess
    import sys

    if not sys.platform.startswith("linux"):
        pytest.skip("the drawer is forked on Linux only")
    path = tmp_path / "subjects.pickle"
    path.write_bytes(pickle.dumps((small_report.studies, small_report.trajectories)))
    code = f"""
import os, pickle, re, signal
from verimono.execution.calibration import PendingCalibration
from verimono.records.report import drawer, plots
studies, samples = pickle.loads(open({str(path)!r}, "rb").read())
same = lambda h: re.sub(r"\\b[mp][0-9a-f]{{10}}\\b", "ID", re.sub(r"vm\\d+x\\d+", "vm", h))
serve_it, connect = drawer.drawer_pipe()
pending = PendingCalibration(then=serve_it)
assert pending.forked and pending.result() > 0
connect(True)
assert plots.drawing_elsewhere()
plots.draw_ahead(studies, samples)
there = [plots.convergence_plot(s) for s in studies] + [plots.trajectory_plot(s) for s in samples]
assert plots.convergence_plot(studies[0]) == there[0]          # shown twice: fetched once, the same plot
assert "matplotlib" not in __import__("sys").modules          # this process drew none of them
plots.forget()
drawer.disconnect(); pending.close()                            # the drawer ends and is reaped
here = [plots.convergence_plot(s) for s in studies] + [plots.trajectory_plot(s) for s in samples]
print(len(there), [same(a) for a in there] == [same(b) for b in here], len({{a for a in there}}) == len(there))
plots.forget()
serve_it, connect = drawer.drawer_pipe()
pending = PendingCalibration(then=serve_it)
pending.result(); connect(True)
plots.draw_ahead(studies, samples)
os.kill(pending._pid, signal.SIGKILL)                          # dies with plots owed
print(all(same(plots.convergence_plot(s)) == same(h) for s, h in zip(studies, here)))
drawer.disconnect(); pending.close()
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    n = len(small_report.studies) + len(small_report.trajectories)
    assert out.stdout.split() == [str(n), "True", "True", "True"]


# -- the report's plots: thinned for drawing, each segment's extrema kept ------------------------------------------

def _segments_missing_extrema(y, kept, count):
    """The segments ``[a, b]`` between evenly spaced neighbours (every ``ceil((n-1)/count)``-th point, and the
    last) whose lowest or highest value is not among ``kept``: what a decimation for a plot must never do."""
    y, kept = np.asarray(y, float), np.asarray(kept)
    n = len(y)
    every = max(1, -(-(n - 1) // count))
    base = sorted({*range(0, n, every), n - 1})
    bad = []
    for a, b in zip(base, base[1:]):
        seg, mine = y[a:b + 1], y[kept[(kept >= a) & (kept <= b)]]
        if np.all(np.isnan(seg)):
            continue
        if not (mine.size and np.nanmax(mine) == np.nanmax(seg) and np.nanmin(mine) == np.nanmin(seg)):
            bad.append((a, b))
    return bad


@pytest.mark.parametrize("n, count", [(2, 60), (61, 60), (62, 60), (201, 60), (1000, 60), (10_007, 342), (400, 342)])
def test_keep_extrema_keeps_each_segments_min_and_max(n, count):
    """``plots.keep_extrema``: about ``count`` evenly spaced points, and between two of them the segment's lowest
    and highest point: every segment's extremes are drawn (a random walk with one-point spikes and NaN gaps)."""
    from verimono.records.report.plots import keep_extrema

    rng = np.random.default_rng(n)
    y = np.cumsum(rng.normal(size=n))
    for i in rng.integers(0, n, size=3):
        y[i] += rng.choice([-1, 1]) * 40.0                      # spikes, most of them between even points
    if n > 100:
        y[n // 3: n // 3 + 5] = np.nan                          # a gap in the line
    kept = keep_extrema(y, count)
    assert list(kept) == sorted(set(kept.tolist())) and kept[0] == 0 and kept[-1] == n - 1
    assert len(kept) <= 3 * count + 2
    assert _segments_missing_extrema(y, kept, count) == []
    if n > 2 * count:                                           # it thins: fewer points than given
        assert len(kept) < n


def test_a_stride_decimation_drops_a_spike_the_extrema_check_sees():
    """The check above, seen failing: every k-th point (the trajectory plot's markers before) steps over a spike."""
    from verimono.records.report.plots import keep_extrema

    y = np.sin(np.linspace(0, 3, 1000))
    y[501] = 9.0                                                # between two of every 17th point
    stride = np.arange(0, 1000, 17)
    assert _segments_missing_extrema(y, stride, 60) != []
    assert _segments_missing_extrema(y, keep_extrema(y, 60), 60) == []


def test_a_trajectory_plot_of_a_long_sample_draws_its_spike_at_the_axes_resolution():
    """A sample of 10^4 points: the exact line is drawn at about one point per pixel column (the figure needs
    no more) and the markers at about 60, both through the one-point spike between evenly spaced points."""
    from verimono.records.report import plots

    t = np.linspace(0.0, 1.0, 10_001)
    x = np.column_stack([np.cos(3 * t), np.sin(3 * t)])
    x[5_003, 1] = 4.0
    sample = {"problem": "spike", "h": 1e-4, "t": t.tolist(), "x": x.tolist(), "t_exact": t.tolist(),
              "exact": x.tolist()}
    ax = plots.trajectory_figure(sample, legend=False).axes[0]
    exact, marks = [ln for ln in ax.lines if ln.get_marker() in ("None", "", None)], \
        [ln for ln in ax.lines if ln.get_marker() == "o"]
    assert len(exact) == len(marks) == 2
    for ln, most in ((exact[1], 3 * plots.LINE_POINTS + 2), (marks[1], 3 * plots.MARKERS + 2)):
        assert ln.get_ydata().max() == 4.0 and len(ln.get_ydata()) <= most
    assert exact[0].get_ydata().min() == x[:, 0].min() and exact[0].get_ydata().max() == x[:, 0].max()


def test_a_report_with_many_plots_has_unique_element_ids(small_report):
    """Every id in the document once (the grid's line collections too: ``_svg`` salts them per figure)."""
    from verimono.records.report import plots

    plots.forget()
    ids = re.findall(r'\bid="([^"]+)"', render(small_report))
    assert len(ids) == len(set(ids)) > 0
    plots.forget()


def test_a_runs_trajectory_sample_keeps_a_spike_of_a_long_trajectory():
    """``sample_trajectory`` thins a long trajectory for the report (400 evenly spaced points before): a one-step
    spike of the stepper's is kept among them, as each segment's extremes are; a short one is kept whole."""
    import verimono as vm
    from verimono.reference import get
    from verimono.run.stages.builtin import TRAJECTORY_SAMPLES, sample_trajectory

    problem = get("t|x| (n=1)")

    def spiky(problem, t):
        x = np.array(vm.solve(problem, t), dtype=float)
        x[1001] += 5.0                                      # between two of 400 evenly spaced nodes of 2001
        return x

    sample = sample_trajectory(spiky, problem, h=problem.T / 2000)
    x, full = np.asarray(sample["x"], float), spiky(problem, np.linspace(0.0, problem.T, 2001))
    assert np.max(x) == np.max(full) and np.min(x) == np.min(full)
    assert TRAJECTORY_SAMPLES // 2 <= len(x) <= 3 * TRAJECTORY_SAMPLES
    short = sample_trajectory(vm.solve, problem, h=problem.T / 50)
    assert len(short["t"]) == 51
