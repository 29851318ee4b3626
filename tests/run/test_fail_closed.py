"""Issue 25, the gate and file parts: the gate never hides, a run never hangs on files, misuse is never the
subject's fault.

Each test reproduces a hole found by the reliability probe and shows it closed: a repeated record key
hiding a failure, a baseline whose NaN figures let anything pass, a pass turned into an undeclared xfail, a
killed run's stale pair gated green, a full disk ending in a traceback with the results lost, a target that
is not ``module:object`` crashing importlib, the advice of a command that does not exist, output files
mode 0600, reading ``/dev/zero`` or a FIFO, and time budgets of ``inf``, ``-1`` or ``nan``.
"""

from __future__ import annotations

import copy
import errno
import json
import os
import signal
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

import verimono as vm
from verimono.cli import main
from verimono.run.gate import compare
from verimono.records.results import CheckResult, Report, SchemaError, load

from probe_bad_inputs import CASES, run_probe, sample_report
from zoo_runs import stage_killer

ONE_REF = ["--stage", "convergence", "--reference", "moving box", "--profile", "ci", "--executor", "serial"]


def _save(path: Path, doc: dict) -> Path:
    path.write_text(json.dumps(doc))
    return path


def _gate(capsys, base: Path, results: Path) -> tuple[int, str]:
    capsys.readouterr()
    code = main(["gate", "--baseline", str(base), "--results", str(results)])
    out = capsys.readouterr()
    return code, out.err + out.out


# -- 1. the gate cannot be fooled by its inputs ------------------------------------------------------------

@pytest.mark.parametrize("role", ["baseline", "results"])
@pytest.mark.parametrize("where", ["before", "after"])
def test_a_repeated_record_key_exits_2_naming_it(tmp_path, capsys, role, where):
    """A failed copy inserted *before* the passed original was gated green (the later copy won)."""
    good = sample_report().to_dict()
    bad = copy.deepcopy(good)
    failed = dict(bad["results"][0], status="failed", message="ratio 1.3 > 1", worst=1.3)
    bad["results"].insert(0 if where == "before" else len(bad["results"]), failed)
    files = {"baseline": _save(tmp_path / "good.json", good), "results": _save(tmp_path / "good.json", good)}
    files[role] = _save(tmp_path / "twice.json", bad)
    code, text = _gate(capsys, files["baseline"], files["results"])
    assert code == 2
    assert "monotone[Linear]" in text and "more than once" in text and "twice.json" in text


def test_compare_refuses_repeated_keys_of_reports_in_memory():
    cur = sample_report()
    cur.results.insert(0, CheckResult("monotone", "Linear", "failed", worst=1.3, bound=1.0))
    with pytest.raises(SchemaError, match=r"monotone\[Linear\].*more than once"):
        compare(sample_report(), cur)


@pytest.fixture(scope="module")
def studied() -> Report:
    from verimono.reference import get

    rep = vm.check_stepper(vm.solve, [get("moving box")], laws=False)
    rep.meta.update({"command": "run", "profile": "ci", "target": None})
    return Report.from_dict(rep.to_dict())


def test_a_baseline_with_nan_study_errors_is_unusable_not_a_free_pass(studied, tmp_path, capsys):
    """NaN errors in the baseline's study masked results whose errors were all 10x larger."""
    base, cur = copy.deepcopy(studied.to_dict()), copy.deepcopy(studied.to_dict())
    for norm in ("sup", "l2", "final"):
        base["studies"][0]["errors"][norm] = ["nan"] * len(base["studies"][0]["errors"][norm])
        cur["studies"][0]["errors"][norm] = [10 * e for e in cur["studies"][0]["errors"][norm]]
    results = _save(tmp_path / "results.json", cur)
    code, text = _gate(capsys, _save(tmp_path / "ok.json", studied.to_dict()), results)
    assert code == 1 and "grew from" in text                       # a finite baseline catches the growth
    code, text = _gate(capsys, _save(tmp_path / "nan.json", base), results)
    assert code == 2 and "nan.json is unusable" in text and "sup error at h=" in text


def _set(doc: dict, key: str, field: str, value) -> None:
    rec = next(r for r in doc["results"] if f"{r['check']}[{r['subject']}]" == key)
    if field in ("error", "timing_ratio"):
        rec["details"][field] = value
    else:
        rec[field] = value


@pytest.mark.parametrize("key, field, value", [
    ("monotone[Linear]", "worst", "nan"),
    ("monotone[Linear]", "worst", "inf"),
    ("monotone[Ball]", "bound", "inf"),
    ("siconos_agreement[DiodeBridge]", "error", "nan"),
    ("siconos_agreement[DiodeBridge]", "error", None),
    ("performance_per_step[solve]", "timing_ratio", "nan"),
], ids=["worst nan", "worst inf", "bound inf", "error nan", "error null", "timing ratio nan"])
def test_a_baseline_with_a_non_finite_figure_is_unusable(tmp_path, capsys, key, field, value):
    """A baseline with NaN worst ratios was accepted (the record read back as failed, so anything 'fixed'
    it); a NaN error or timing ratio compared false against every threshold."""
    base = sample_report().to_dict()
    _set(base, key, field, value)
    code, text = _gate(capsys, _save(tmp_path / "base.json", base), _save(tmp_path / "cur.json", sample_report().to_dict()))
    assert code == 2 and "unusable" in text and key in text


def test_a_baseline_recording_a_genuine_failure_stays_usable(tmp_path, capsys):
    """Not over-strict: a failed record may carry a NaN ratio, and a baseline may record known failures."""
    rep = sample_report()
    rep.add(CheckResult("known_bad", "op", "failed", worst=float("nan"), bound=1.0, message="diverged"))
    code, _ = _gate(capsys, _save(tmp_path / "base.json", rep.to_dict()), _save(tmp_path / "cur.json", rep.to_dict()))
    assert code == 0


def test_a_pass_that_becomes_an_undeclared_xfail_regresses_a_declared_one_does_not():
    cur = sample_report()
    cur.results[0].status, cur.results[0].message = "xfail", "ratio 1.3 > 1"
    regs = compare(sample_report(), cur).regressions
    assert [(c.kind, c.key) for c in regs] == [("status", "monotone[Linear]")]
    assert "without a declaration" in regs[0].message
    cur.results[0].details["xfail_declared"] = "known: the test operator is not monotone"
    comp = compare(sample_report(), cur)
    assert comp.ok and any("declared: known" in c.message for c in comp.others)


def test_thm_main_declares_the_xfails_it_makes():
    """The run's own xfails (Theorem thm:main needs (LG) *or* (YB)) carry their declaration."""
    from verimono.reference import get

    rep = vm.check_assumptions(get("moving box"), seed=0)
    (xf,) = [r for r in rep if r.status == "xfail"]
    assert xf.check == "assumption_YB" and "(LG) has evidence for it" in xf.details["xfail_declared"]


def test_the_plugin_declares_the_xfails_of_expected_failed_checks():
    from types import SimpleNamespace

    from verimono.plugin import _Collector

    col = _Collector(None, None, "dev")
    rec = CheckResult("selections", "my_stepper on t|x| (n=1)", "failed", worst=2.0, bound=1.0)
    col.by_node["t::case"] = [rec]
    col.pytest_runtest_logreport(SimpleNamespace(when="call", skipped=True, wasxfail="known: no input term",
                                                 nodeid="t::case"))
    assert rec.status == "xfail" and rec.details["xfail_declared"] == "known: no input term"


def test_the_committed_baselines_xfails_pass_against_fresh_records():
    """The six xfail records of reports/baseline.json (written before declarations existed) against the
    assumptions stage run now on the same references: no regression."""
    from verimono.reference import get
    from verimono.run.execute import execute
    from verimono.run.stages import RunContext

    committed = load(Path(__file__).resolve().parents[2] / "reports" / "baseline.json")
    xfails = [r for r in committed if r.status == "xfail"]
    assert len(xfails) == 6
    subjects = sorted({r.subject for r in xfails})
    fresh = execute(command="run", profile_name="ci", stages=["assumptions"],
                    context=RunContext(problems=[get(s) for s in subjects]))
    mine = Report([r for r in committed if r.details.get("stage") == "assumptions" and r.subject in subjects])
    assert len(mine) == len(fresh) and len(mine) >= 6 * 6
    comp = compare(mine, fresh)
    assert comp.ok, [str(c) for c in comp.regressions]
    now = {r.key: r for r in fresh}
    assert all(now[r.key].status == "xfail" and now[r.key].details.get("xfail_declared") for r in xfails)


# -- 2. a run in progress is visible ---------------------------------------------------------------------

KILLER = stage_killer('convergence')


def _subprocess_env() -> dict[str, str]:
    """The environment of a child that imports the very verimono under test."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(vm.__file__).resolve().parent.parent),
                                         env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def test_a_killed_run_is_visible_and_its_stale_pair_is_refused(tmp_path, capsys):
    """``kill -9`` during ``verimono run`` over a complete pair left that pair, which the gate then passed
    as this run's, and ``--resume`` called "a complete run"."""
    out, base = tmp_path / "out", tmp_path / "baseline.json"
    assert main(["run", *ONE_REF, "--out", str(out)]) == 0
    old_id = load(out / "results.json").meta["run_id"]
    assert main(["baseline", "--from", str(out / "results.json"), "--out", str(base)]) == 0
    assert _gate(capsys, base, out / "results.json")[0] == 0

    proc = subprocess.run([sys.executable, "-c", KILLER, "run", *ONE_REF, "--out", str(out)],
                          env=_subprocess_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == -signal.SIGKILL, proc.stderr[-2000:]
    assert load(out / "results.json").meta["run_id"] == old_id          # the stale pair is still there ...
    mark = json.loads((out / "results.json.in-progress").read_text())    # ... beside the killed run's mark
    assert mark["run_id"] != old_id and mark["command"] == "run"

    code, text = _gate(capsys, base, out / "results.json")
    assert code == 2 and "never completed" in text and mark["run_id"] in text
    capsys.readouterr()
    assert main(["run", *ONE_REF, "--out", str(out), "--resume"]) == 2
    err = capsys.readouterr().err
    assert mark["run_id"] in err and "never completed" in err and old_id in err
    assert main(["baseline", "--from", str(out / "results.json"), "--out", str(tmp_path / "b2.json")]) == 2

    assert main(["run", *ONE_REF, "--out", str(out)]) == 0               # a run that completes clears it
    assert not (out / "results.json.in-progress").exists()
    assert _gate(capsys, base, out / "results.json")[0] == 0


def test_the_mark_is_written_before_the_work_with_the_run_id_of_the_results(tmp_path, monkeypatch):
    import verimono.run.stages as stages
    from verimono.records.atomic import in_progress

    out, seen = tmp_path / "out", []
    real = stages.STAGES["convergence"]

    def spy(profile, context):
        seen.append(in_progress(out / "results.json"))
        return real.fn(profile, context)

    monkeypatch.setitem(stages.STAGES, "convergence", stages.Stage("convergence", spy, real.description))
    assert main(["run", *ONE_REF, "--out", str(out)]) == 0
    assert seen[0] is not None and seen[0]["run_id"] == load(out / "results.json").meta["run_id"]
    assert seen[0]["pid"] == os.getpid() and in_progress(out / "results.json") is None


def test_resume_names_the_run_it_continues(tmp_path, monkeypatch, capsys):
    import verimono.run.stages as stages

    out = tmp_path / "out"
    real = stages.STAGES["section7"]

    def interrupt(profile, context):
        raise KeyboardInterrupt

    monkeypatch.setitem(stages.STAGES, "section7", stages.Stage("section7", interrupt, real.description))
    args = ["run", "--stage", "convergence", "--stage", "section7", "--reference", "moving box", "--profile", "ci",
            "--executor", "serial", "--out", str(out)]
    assert main(args) == 130
    partial = load(out / "results.json")
    assert not (out / "results.json.in-progress").exists()          # its own pair, marked incomplete, is there
    monkeypatch.setitem(stages.STAGES, "section7", real)
    capsys.readouterr()
    assert main([*args, "--resume"]) == 0
    assert f"resuming run {partial.meta['run_id']}" in capsys.readouterr().err
    full = load(out / "results.json")
    assert full.meta["resumed_from"] == partial.meta["run_id"] != full.meta["run_id"]


def test_the_advice_after_an_interrupted_check_names_a_command_that_exists(tmp_path, monkeypatch, capsys):
    import verimono.run.stages as stages

    (tmp_path / "good.py").write_text("from verimono.core.stepping import solve\n")
    real = stages.STAGES["convergence"]

    def interrupt(profile, context):
        raise KeyboardInterrupt

    monkeypatch.setitem(stages.STAGES, "convergence", stages.Stage("convergence", interrupt, real.description))
    target = f"{tmp_path / 'good.py'}:solve"
    assert main(["check", target, "--profile", "ci", "--out", str(tmp_path / "o")]) == 130
    err = capsys.readouterr().err
    assert "check --resume" not in err
    assert "run the same command again" in err and f"verimono check {target} --profile ci --out" in err


# -- 3. faults end cleanly -------------------------------------------------------------------------------

def _failing_pair_writes(monkeypatch, code: int = errno.ENOSPC) -> None:
    """The pair's temporaries fail as on a full disk (the small in-progress mark still fits)."""
    import verimono.records.atomic as atomic

    real = atomic._temp_for

    def temp_for(path, text):
        if path.name in ("results.json", "report.html", "baseline.json", "r.html"):
            raise OSError(code, os.strerror(code))
        return real(path, text)

    monkeypatch.setattr(atomic, "_temp_for", temp_for)


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EACCES, errno.EROFS])
def test_a_full_disk_at_the_end_of_a_run_exits_2_in_one_line_and_keeps_the_results(tmp_path, monkeypatch, capsys,
                                                                                     code):
    out, spill = tmp_path / "out", tmp_path / "spill"
    spill.mkdir()
    assert main(["run", *ONE_REF, "--out", str(out)]) == 0
    before = (out / "results.json").read_text(), (out / "report.html").read_text()
    monkeypatch.setattr(tempfile, "tempdir", str(spill))
    _failing_pair_writes(monkeypatch, code)
    capsys.readouterr()
    assert main(["run", *ONE_REF, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    last = err.strip().splitlines()[-1]
    assert "Traceback" not in err and last.startswith("verimono run: cannot write ")
    assert str(out / "results.json") in last and os.strerror(code) in last and "unchanged" in last
    (kept,) = spill.glob("verimono-results-*.json")
    run = load(kept)
    assert str(kept) in last and [r.key for r in run] == [r.key for r in load(out / "results.json")]
    assert ((out / "results.json").read_text(), (out / "report.html").read_text()) == before
    mark = json.loads((out / "results.json.in-progress").read_text())   # this run never wrote its pair ...
    assert mark["run_id"] == run.meta["run_id"]
    assert main(["gate", "--baseline", str(kept), "--results", str(out / "results.json")]) == 2   # ... the gate says so


def test_a_full_disk_for_report_and_baseline_exits_2_in_one_line(tmp_path, monkeypatch, capsys):
    sample_report().save(tmp_path / "results.json")
    (tmp_path / "r.html").write_text("old")
    sample_report().save(tmp_path / "baseline.json")
    before = (tmp_path / "baseline.json").read_text()
    _failing_pair_writes(monkeypatch)
    capsys.readouterr()
    assert main(["report", "--results", str(tmp_path / "results.json"), "--out", str(tmp_path / "r.html")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"cannot write {tmp_path / 'r.html'}: No space left on device" in err
    assert main(["baseline", "--from", str(tmp_path / "results.json"), "--out", str(tmp_path / "baseline.json")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"cannot write {tmp_path / 'baseline.json'}" in err
    assert (tmp_path / "r.html").read_text() == "old" and (tmp_path / "baseline.json").read_text() == before


@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o027, 0o640), (0o077, 0o600)])
def test_output_files_honour_the_umask(tmp_path, umask, mode):
    from verimono.records.report import write

    old = os.umask(umask)
    try:
        paths = write(sample_report(), tmp_path / "out")
        saved = sample_report().save(tmp_path / "baseline.json")
    finally:
        os.umask(old)
    for p in (paths["json"], paths["html"], saved):
        assert stat.S_IMODE(p.stat().st_mode) == mode, p


def test_a_replaced_file_keeps_its_own_mode_as_with_open(tmp_path):
    path = tmp_path / "baseline.json"
    sample_report().save(path)
    path.chmod(0o664)
    sample_report().save(path)
    assert stat.S_IMODE(path.stat().st_mode) == 0o664


@pytest.fixture
def odd_targets(tmp_path, monkeypatch):
    (tmp_path / "exits.py").write_text("import sys\nsys.exit(0)\n")
    (tmp_path / "boom_issue25.py").write_text("raise TypeError('not at import time, please')\n")
    (tmp_path / "folder.py").mkdir()
    os.mkfifo(tmp_path / "fifo.py")
    monkeypatch.syspath_prepend(str(tmp_path))
    return tmp_path


@pytest.mark.parametrize("target, reason", [
    ("../../../../etc/passwd:x", "MODULE must be a dotted module name"),
    ("/etc/passwd:x", "MODULE must be a dotted module name"),
    ("mod with spaces:x", "MODULE must be a dotted module name"),
    ("verimono:no such", "OBJECT must be a dotted Python name"),
    ("{d}/exits.py:x", "SystemExit"),
    ("boom_issue25:x", "TypeError: not at import time"),
    ("{d}/folder.py:x", "not a regular file"),
    ("{d}/fifo.py:x", "not a regular file"),
    ("{d}/../{name}/missing.py:x", "does not exist"),
], ids=["relative path", "absolute path", "spaces", "bad object", "sys.exit at import", "error at import",
        "folder", "fifo", "missing file"])
def test_a_target_that_is_not_module_object_is_bad_usage(odd_targets, tmp_path, capsys, target, reason):
    target = target.format(d=odd_targets, name=odd_targets.name)
    code = main(["check", target, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("verimono check: ") and reason in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()                     # refused before any output


def _limited(seconds: int = 60):
    """A child with at most 2 GiB of address space: a read that never ends fails instead of swapping."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    return {"preexec_fn": limit, "timeout": seconds, "capture_output": True, "text": True, "env": _subprocess_env()}


@pytest.mark.parametrize("kind", ["/dev/zero", "fifo", "folder"])
@pytest.mark.parametrize("role", ["--baseline", "--results"])
def test_reading_a_device_fifo_or_folder_exits_2_without_hanging(tmp_path, kind, role):
    good = sample_report().save(tmp_path / "good.json")
    if kind == "fifo":
        bad = tmp_path / "fifo.json"
        os.mkfifo(bad)
    else:
        bad = tmp_path if kind == "folder" else Path(kind)
    files = {"--baseline": good, "--results": good, role: bad}
    proc = subprocess.run([sys.executable, "-m", "verimono.cli", "gate", "--baseline", str(files["--baseline"]),
                           "--results", str(files["--results"])], **_limited())
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert f"{bad} is " in proc.stderr and ("not a regular file" in proc.stderr or "a folder" in proc.stderr)


def test_a_document_over_the_size_limit_exits_2(tmp_path, capsys, monkeypatch):
    good = sample_report().save(tmp_path / "good.json")
    monkeypatch.setenv("VERIMONO_MAX_DOCUMENT_MIB", str(512 / (1 << 20)))   # 512 bytes
    code, text = _gate(capsys, good, good)
    assert code == 2 and "larger than the limit" in text and "VERIMONO_MAX_DOCUMENT_MIB" in text
    monkeypatch.setenv("VERIMONO_MAX_DOCUMENT_MIB", "lots")
    code, text = _gate(capsys, good, good)
    assert code == 2 and "must be a positive number of MiB" in text
    monkeypatch.delenv("VERIMONO_MAX_DOCUMENT_MIB")
    assert _gate(capsys, good, good)[0] == 0


@pytest.mark.parametrize("flag, value, reason", [
    ("--timeout", "nan", "number of seconds > 0"),
    ("--timeout", "-1", "number of seconds > 0"),
    ("--timeout", "0", "number of seconds > 0"),
    ("--timeout", "1e999", "overflows to infinity"),
    ("--unit-timeout", "-1", "number of seconds > 0"),
    ("--unit-timeout", "nan", "number of seconds > 0"),
])
def test_time_budgets_are_validated_before_any_work(tmp_path, capsys, flag, value, reason):
    """``--unit-timeout -1`` failed a correct stepper, ``--unit-timeout nan`` ran with no bound: each is
    now refused up front, exit 2 (``inf`` is no limit: tests/execution/test_native_hang.py)."""
    with pytest.raises(SystemExit) as info:
        main(["run", *ONE_REF, "--out", str(tmp_path / "o"), flag, value])
    err = capsys.readouterr().err
    assert info.value.code == 2 and flag in err and reason in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("seed", ["-1", "abc", "1.5"])
def test_a_bad_seed_on_the_command_line_is_refused_before_any_work(tmp_path, capsys, seed):
    """``verimono check … --seed -1`` failed 7 trajectory laws of a correct stepper ("expected
    non-negative integer"), exit 1."""
    with pytest.raises(SystemExit) as info:
        main(["check", "verimono.stepping:solve", "--seed", seed, "--out", str(tmp_path / "o")])
    assert info.value.code == 2 and "--seed: must be a non-negative integer" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_the_bad_input_probe_holds(capsys):
    """tests/probe_bad_inputs.py: at least 60 new bad inputs, every one typed, bounded and explained."""
    assert len(CASES) >= 60
    assert run_probe(show=False) == 0, capsys.readouterr().out
