"""Reliability probe: bad inputs of the fail-closed kinds, each judged typed, bounded and explained.

    OPENBLAS_NUM_THREADS=1 python tests/probe_bad_inputs.py [--list]

``tests/run/test_fail_closed.py`` runs it and shares its sample gate document (:func:`sample_report`).

Every case is new (not one of the unit tests' reproductions verbatim): forged gate documents, run marks,
paths that are not documents, time budgets, targets, subjects of the wrong kind, bad seeds and budgets,
unwritable outputs, subjects that hang.  A case *holds* when

* **typed**: the CLI exits with the expected status (2 "could not decide", 1 for a regression) with no
  traceback, or the API raises a :class:`verimono.VerimonoError`;
* **explained**: the message is one non-empty line that contains the expected words;
* **bounded**: it ends within :data:`LIMIT` seconds (``SIGALRM``; a case that hits it does not hold).

Prints one line per case and the count; exits 1 when any case does not hold.
"""

from __future__ import annotations

import atexit
import contextlib
import io
import json
import os
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

import verimono as vm
import verimono.testing  # noqa: F401 - vm.testing
import verimono.execution.timeouts  # noqa: F401 - vm.timeouts
from verimono.cli import main
from verimono.core.errors import VerimonoError
from verimono.records.results import CheckResult, Report

LIMIT = 60.0
TMP = Path(tempfile.mkdtemp(prefix="probe25-"))
atexit.register(shutil.rmtree, TMP, ignore_errors=True)
CASES: list[tuple[str, Callable[[], Any], Any, str]] = []   # name, thunk, expected (exit code or "raises"), words


def case(name: str, expected: Any, words: str = "") -> Callable:
    def register(fn: Callable) -> Callable:
        CASES.append((name, fn, expected, words))
        return fn
    return register


# -- documents for the gate ------------------------------------------------------------------------------

def sample_report() -> Report:
    rep = Report([CheckResult("monotone", "Linear", "passed", worst=0.5, bound=1.0),
                  CheckResult("monotone", "Ball", "passed", worst=0.2, bound=1.0),
                  CheckResult("siconos_agreement", "DiodeBridge", "passed", worst=0.1, bound=1.0,
                              details={"error": 1e-9}),
                  CheckResult("performance_per_step", "solve", "passed", worst=0.7, bound=1.5,
                              details={"timing_ratio": 1.1})])
    rep.meta.update({"command": "run", "profile": "ci", "target": None})
    return rep


_counter = [0]


def _doc(edit: Callable[[dict], Any] | None = None) -> Path:
    d = sample_report().to_dict()
    if edit is not None:
        edit(d)
    _counter[0] += 1
    path = TMP / f"doc{_counter[0]}" / "results.json"
    path.parent.mkdir()
    path.write_text(json.dumps(d))
    return path


GOOD = None


def _gate(base: Path | str, results: Path | str) -> list[str]:
    return ["gate", "--baseline", str(base), "--results", str(results)]


def _set(key: str, field: str, value: Any) -> Callable[[dict], None]:
    def edit(d: dict) -> None:
        rec = next(r for r in d["results"] if f"{r['check']}[{r['subject']}]" == key)
        (rec["details"] if field in ("error", "timing_ratio", "xfail_declared") else rec)[field] = value
    return edit


def _dup(index: int, status: str = "failed") -> Callable[[dict], None]:
    def edit(d: dict) -> None:
        d["results"].insert(index, dict(d["results"][1], status=status, worst=3.0))
    return edit


for i, where in enumerate([0, 2, 4]):
    case(f"gate: results repeat monotone[Ball] (copy at {where})", 2, "more than once")(
        lambda where=where: _gate(GOOD, _doc(_dup(where))))
case("gate: baseline repeats a key (both passed)", 2, "more than once")(
    lambda: _gate(_doc(_dup(0, "passed")), GOOD))
for key, field, value in [("monotone[Ball]", "worst", "nan"), ("monotone[Ball]", "worst", "-inf"),
                          ("monotone[Linear]", "bound", "nan"), ("monotone[Linear]", "bound", "inf"),
                          ("siconos_agreement[DiodeBridge]", "error", "inf"),
                          ("siconos_agreement[DiodeBridge]", "error", "a lot"),
                          ("siconos_agreement[DiodeBridge]", "error", True),
                          ("performance_per_step[solve]", "timing_ratio", "inf"),
                          ("performance_per_step[solve]", "timing_ratio", None)]:
    case(f"gate: baseline {key} {field} = {value!r}", 2, "unusable")(
        lambda key=key, field=field, value=value: _gate(_doc(_set(key, field, value)), GOOD))


def _xfail(declared: Any) -> Callable[[dict], None]:
    def edit(d: dict) -> None:
        d["results"][0]["status"] = "xfail"
        if declared is not ...:
            d["results"][0]["details"]["xfail_declared"] = declared
    return edit


for declared in (..., "", "   ", 42, None):
    case(f"gate: passed → xfail, declaration {declared!r}", 1, "without a declaration")(
        lambda declared=declared: _gate(GOOD, _doc(_xfail(declared))))


def _fifo() -> Path:
    p = TMP / f"fifo{time.monotonic_ns()}.json"
    os.mkfifo(p)
    return p


def _symlink(target: str) -> Path:
    p = TMP / f"link{time.monotonic_ns()}.json"
    p.symlink_to(target)
    return p


def _bytes(data: bytes) -> Path:
    p = TMP / f"raw{time.monotonic_ns()}.json"
    p.write_bytes(data)
    return p


case("gate: results are /dev/zero", 2, "not a regular file")(lambda: _gate(GOOD, "/dev/zero"))
case("gate: baseline is /dev/urandom", 2, "not a regular file")(lambda: _gate("/dev/urandom", GOOD))
case("gate: results are /dev/null", 2, "not a regular file")(lambda: _gate(GOOD, "/dev/null"))
case("gate: baseline is a FIFO nobody writes", 2, "not a regular file")(lambda: _gate(_fifo(), GOOD))
case("gate: baseline is a symlink to /dev/zero", 2, "not a regular file")(lambda: _gate(_symlink("/dev/zero"), GOOD))
case("gate: results are a dangling symlink", 2, "does not exist")(lambda: _gate(GOOD, _symlink(str(TMP / "nowhere"))))
case("gate: results are a folder", 2, "a folder")(lambda: _gate(GOOD, TMP))
case("gate: baseline is /proc/self/mem", 2, "")(lambda: _gate("/proc/self/mem", GOOD))
case("gate: results are invalid UTF-8", 2, "cannot be")(lambda: _gate(GOOD, _bytes(b"\xff\xfe{}")))
case("gate: results are a JSON array", 2, "")(lambda: _gate(GOOD, _bytes(b"[1, 2, 3]")))
case("gate: results are 3 MiB of spaces", 2, "larger than the limit")(
    lambda: (os.environ.__setitem__("VERIMONO_MAX_DOCUMENT_MIB", "1"), _gate(GOOD, _bytes(b" " * (3 << 20))))[1])
for value in ("-1", "nan", "inf", "0", "1e999", "lots"):
    case(f"gate: $VERIMONO_MAX_DOCUMENT_MIB={value}", 2, "positive number of MiB")(
        lambda value=value: (os.environ.__setitem__("VERIMONO_MAX_DOCUMENT_MIB", value), _gate(GOOD, GOOD))[1])


def _marked(content: str | None, kind: str = "file") -> Path:
    path = _doc()
    mark = path.with_name("results.json.in-progress")
    if kind == "dir":
        mark.mkdir()
    else:
        mark.write_text(content or "")
    return path


case("gate: results beside a run's in-progress mark", 2, "never completed")(
    lambda: _gate(GOOD, _marked(json.dumps({"run_id": "abc123", "command": "run"}))))
case("gate: baseline beside an in-progress mark", 2, "never completed")(
    lambda: _gate(_marked(json.dumps({"run_id": "abc123"})), GOOD))
case("gate: in-progress mark is garbage", 2, "never completed")(lambda: _gate(GOOD, _marked("\x00garbage")))
case("gate: in-progress mark is a JSON list", 2, "never completed")(lambda: _gate(GOOD, _marked("[1]")))
case("gate: in-progress mark is a folder", 2, "never completed")(lambda: _gate(GOOD, _marked(None, "dir")))
case("baseline --from beside an in-progress mark", 2, "never completed")(
    lambda: ["baseline", "--from", str(_marked('{"run_id": "x"}')), "--out", str(TMP / "b.json")])
case("run --resume beside a killed run's mark", 2, "never completed")(
    lambda: ["run", "--resume", "--out", str(_marked('{"run_id": "dead1"}').parent), "--profile", "ci"])


# -- time budgets and seeds on the command line ------------------------------------------------------------

for flag in ("--timeout", "--unit-timeout"):
    for value in ("-inf", "1e999", "-0", "0x10", "", " nan "):
        case(f"run {flag} {value!r}", 2, flag)(
            lambda flag=flag, value=value: ["run", "--stage", "convergence", "--out", str(TMP / "never"), flag, value])


# -- targets ---------------------------------------------------------------------------------------------

def _file(name: str, text: str) -> str:
    p = TMP / name
    p.write_text(text)
    return str(p)


for target, words in [("verimono", "MODULE:OBJECT"), (":solve", "MODULE:OBJECT"), ("verimono:", "MODULE:OBJECT"),
                      ("verimono.stepping:solve()", "OBJECT must be a dotted"),
                      ("verimono..stepping:solve", "MODULE must be a dotted"),
                      ("~/x.py:f", "does not exist"), ("/dev/null:f", "MODULE must be a dotted"),
                      ("C:\\mod.py:f", "does not exist"), ("no_such_module_xyz:f", "cannot import"),
                      ("verimono:__version__", "expected"), ("verimono:Problem", "expected"),
                      ("os:sep", "expected")]:
    case(f"check target {target!r}", 2, words)(lambda target=target: ["check", target, "--out", str(TMP / "never")])
case("check target: a file calling os._exit? (sys.exit(3) at import)", 2, "SystemExit")(
    lambda: ["check", _file("exit3.py", "import sys\nsys.exit(3)\n") + ":f", "--out", str(TMP / "never")])
case("check target: a file raising KeyboardInterrupt at import", 2, "")(
    lambda: ["check", _file("kbd.py", "raise KeyError('x')\n") + ":f", "--out", str(TMP / "never")])
case("check target: a prox (x, gamma) where a stepper is expected", 2, "operator_from_prox")(
    lambda: ["check", _file("proxmod.py", "def prox(x, gamma):\n    return x\n") + ":prox", "--out",
             str(TMP / "never")])
case("check target: a stepper without its t_grid", 2, "stepper(problem, t_grid)")(
    lambda: ["check", _file("one.py", "def step(problem):\n    return None\n") + ":step", "--out",
             str(TMP / "never")])
case("check --seed -5", 2, "seed")(lambda: ["check", "verimono.stepping:solve", "--seed", "-5", "--out",
                                              str(TMP / "never")])


# -- the Python API: subjects of the wrong kind, bad seeds and budgets --------------------------------------

OP = vm.operator_from_resolvent(lambda x, lam, t: np.asarray(x) / (1 + lam), 2, name="contraction")
for name, thunk, words in [
    ("check_operator(None)", lambda: vm.check_operator(None), "expected an operator"),
    ("check_operator('NormalCone')", lambda: vm.check_operator("NormalCone"), "expected an operator"),
    ("check_operator(a class)", lambda: vm.check_operator(vm.Problem), "expected an operator"),
    ("check_operator(a stepper)", lambda: vm.check_operator(vm.solve), "expected an operator"),
    ("check_stepper(an operator)", lambda: vm.check_stepper(OP), "check_operator"),
    ("check_stepper(a Problem)", lambda: vm.check_stepper(vm.Problem(OP, x0=np.zeros(2), T=1.0)), "expected a stepper"),
    ("check_stepper(lambda x, tau)", lambda: vm.check_stepper(lambda x, tau: x), "operator_from"),
    ("check_stepper(seed=-2**70)", lambda: vm.check_stepper(vm.solve, seed=-2 ** 70), "seed"),
    ("check_stepper(seed=1.5)", lambda: vm.check_stepper(vm.solve, seed=1.5), "seed"),
    ("check_stepper(seed=True)", lambda: vm.check_stepper(vm.solve, seed=True), "seed"),
    ("check_operator(seed=-3)", lambda: vm.check_operator(OP, seed=-3), "seed"),
    ("check_operator(examples=0)", lambda: vm.check_operator(OP, examples=0), "examples"),
    ("check_operator(examples=-1)", lambda: vm.check_operator(OP, examples=-1), "examples"),
    ("check_operator(horizon=nan)", lambda: vm.check_operator(OP, horizon=float("nan")), "horizon"),
    ("check_operator(horizon=-1)", lambda: vm.check_operator(OP, horizon=-1.0), "horizon"),
    ("budget(-1)", lambda: vm.timeouts.budget(-1).__enter__(), "> 0"),
    ("budget(nan)", lambda: vm.timeouts.budget(float("nan")).__enter__(), "> 0"),
    ("budget('soon')", lambda: vm.timeouts.budget("soon").__enter__(), "> 0"),
    ("parametrize_with_checks([3])", lambda: vm.testing.parametrize_with_checks([3]), "expected"),
    ("parametrize_with_checks([a prox fn])", lambda: vm.testing.parametrize_with_checks([lambda x, gamma: x]),
     "operator_from"),
]:
    case(f"api: {name}", "raises", words)(thunk)


# -- outputs that cannot be written -------------------------------------------------------------------------

case("report --out under /proc", 2, "cannot")(
    lambda: ["report", "--results", str(GOOD), "--out", "/proc/verimono/report.html"])
case("baseline --from --out under /proc", 2, "")(
    lambda: ["baseline", "--from", str(GOOD), "--out", "/proc/verimono/baseline.json"])
case("run --out is a regular file", 2, "")(
    lambda: ["run", "--stage", "convergence", "--out", str(GOOD), "--profile", "ci"])
case("check --out under /sys", 2, "")(lambda: ["check", "verimono.stepping:solve", "--out", "/sys/verimono"])


# -- subjects that hang ---------------------------------------------------------------------------------------

def _hanging_operator() -> Report:
    def resolvent(x, lam, t):
        time.sleep(30)
        return np.asarray(x)

    with vm.timeouts.budget(0.5):
        return vm.check_operator(vm.operator_from_resolvent(resolvent, 2, name="hangs"), seed=0, examples=5)


def _hanging_stepper() -> Report:
    from verimono.reference import get
    from verimono.run.stages.builtin import _convergence_unit

    def stepper(problem, t_grid):
        time.sleep(30)

    with vm.timeouts.budget(0.5):
        return _convergence_unit(stepper, get("moving box"))


case("api: a resolvent sleeping 30 s under a 0.5 s budget", "report", "does not return within")(_hanging_operator)
case("run unit: a stepper sleeping 30 s under a 0.5 s budget", "report", "timed out")(_hanging_stepper)


# -- the judge ----------------------------------------------------------------------------------------------

class _Alarm(BaseException):
    pass


def judge(name: str, thunk: Callable[[], Any], expected: Any, words: str) -> tuple[bool, str, float]:
    def alarm(signum, frame):
        raise _Alarm

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, LIMIT)
    start = time.perf_counter()
    err, out = io.StringIO(), io.StringIO()
    try:
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
                got = thunk()
                if isinstance(got, list):                       # a command line
                    try:
                        got = main(got)
                    except SystemExit as exc:                   # argparse
                        got = exc.code
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)
            os.environ.pop("VERIMONO_MAX_DOCUMENT_MIB", None)
    except _Alarm:
        return False, f"not bounded: still running after {LIMIT:g} s", LIMIT
    except VerimonoError as exc:
        took = time.perf_counter() - start
        text = str(exc)
        ok = expected == "raises" and bool(text) and "\n" not in text and words in text
        return ok, f"{type(exc).__name__}: {text}", took
    except BaseException as exc:                                 # noqa: BLE001 - the probe judges everything
        return False, f"untyped {type(exc).__name__}: {exc}", time.perf_counter() - start
    took = time.perf_counter() - start
    if expected == "report":
        msgs = " ".join(r.message for r in got)
        return words in msgs and took < 10 * 0.5 + 5, f"{len(got)} records in {took:.1f} s: {msgs[:120]}", took
    if expected == "raises":
        return False, f"no error: returned {type(got).__name__}", took
    text = err.getvalue().strip()
    last = text.splitlines()[-1] if text else ""
    text = (err.getvalue() + out.getvalue()).strip() if got == 1 else text    # regressions go to stdout
    last = text.splitlines()[-1] if text else ""
    ok = got == expected and "Traceback" not in text and bool(last) and words in text
    return ok, f"exit {got}: {last}", took


def run_probe(show: bool = True) -> int:
    global GOOD
    GOOD = _doc()
    held = 0
    for i, (name, thunk, expected, words) in enumerate(CASES, 1):
        ok, what, took = judge(name, thunk, expected, words)
        held += ok
        if show:
            print(f"{'ok ' if ok else 'NO '} {i:3d} {took:6.2f}s  {name}  →  {what[:160]}")
    print(f"probe: {held} of {len(CASES)} bad inputs typed, bounded and explained")
    return 0 if held == len(CASES) else 1


if __name__ == "__main__":
    if "--list" in sys.argv:
        print("\n".join(name for name, *_ in CASES), f"\n{len(CASES)} cases")
        sys.exit(0)
    sys.exit(run_probe())
