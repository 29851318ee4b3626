"""Command line of verimono.

    verimono run [--profile dev|ci|thorough] [--out DIR] [--stage NAME ...] [--seed N] [--data DIR]
                 [--baseline FILE] [--timeout S] [--resume] [--executor serial|process:N|tcp://host:port]
                 [--unit-timeout S]
        The whole verification (every registered stage, see ``verimono.stages``); writes DIR/results.json
        and DIR/report.html (DIR defaults to reports/).  Exit 0 when every check holds, 1 when one fails,
        2 when nothing failed but a check was undecided (a limitation of the harness) — except a speed the machine
        was too noisy to judge (a timing record undecided for "timing noise"), which exits 0 and says so.
        The output folder is checked writable before any work; both files are written atomically with one
        run id.  An interrupt (Ctrl-C, SIGTERM) writes the finished stages to a results file marked
        incomplete (the gate refuses it, exit 2) and exits 130; ``--resume`` runs the stages that file lacks
        and completes it.  ``--timeout S``: seconds per unit of work (one law on one operator, one check of
        one stepper; default: the profile's), beyond which the unit is stopped and recorded as failed.
    verimono check MODULE:OBJECT [--profile P] [--out DIR] [--seed N]
        The operator battery on an operator, or the stepper battery on a stepper ``f(problem, t_grid)``.
    verimono baseline [--out reports/baseline.json] [--from RESULTS] [run options]
        Record the current results (runs the verification, or copies RESULTS) as the gate's baseline.
    verimono gate --baseline FILE [--results reports/results.json]
        Exit 1 and print why on a regression; exit 2 when either file is missing, garbled or incompatible.
    verimono report [--results reports/results.json] [--out reports/report.html] [--baseline FILE]
        Re-render the HTML report from a results file.

Exit status 2 always means "could not decide" (bad usage, unreadable input); it is never a pass.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import shutil
import sys
import time
from pathlib import Path
from typing import Any, Callable, TextIO

from .claims import SCHEMES, claim_of, with_claim
from .errors import BadTarget, NothingToResume, VerimonoError
from .profiles import PROFILES, active_profile, get_profile, load_hypothesis_profile
from .results import SKIPPED, Report

EXIT_OK, EXIT_FAILED, EXIT_UNDECIDED = 0, 1, 2


# -- progress ----------------------------------------------------------------------------------------


class Progress:
    """Progress of a run: on a terminal, one redrawn line (stage, units done / total within it, the
    current subject); otherwise — output not a terminal, or ``$CI`` set — quiet and line-oriented: one
    plain line per finished stage, and within a long stage at most one line every ``interval`` seconds."""

    def __init__(self, stream: TextIO | None = None, enabled: bool | None = None, interval: float = 60.0) -> None:
        self.stream = stream or sys.stderr
        if enabled is None:
            enabled = self.stream.isatty() and not _ci()
        self.tty = enabled
        self.stage, self.index, self.total = "", 0, 1
        self.width = min(shutil.get_terminal_size((100, 20)).columns, 120)
        self.interval = interval
        self._last_line = time.monotonic()

    def start(self, stage: Any, index: int, total: int) -> None:
        self.stage, self.index, self.total = stage.name, index, total
        self._last_line = time.monotonic()
        self.within(0, 1, "")

    def within(self, done: int, total: int, label: str) -> None:
        if not self.tty:
            now = time.monotonic()
            if total and 0 < done < total and now - self._last_line >= self.interval:
                self._last_line = now
                self.stream.write(f"[{self.index + 1}/{self.total}] {self.stage}: {done}/{total} units done"
                                  + (f", at {label}" if label else "") + "\n")
                self.stream.flush()
            return
        frac = (self.index + (done / total if total else 1.0)) / self.total
        bar_w = 24
        fill = int(round(frac * bar_w))
        text = (f"\r[{'#' * fill}{'-' * (bar_w - fill)}] {frac * 100:3.0f}%  stage {self.index + 1}/{self.total} "
                f"{self.stage}  {done}/{total} units  {label}")
        self.stream.write(text[: self.width - 1].ljust(self.width - 1))
        self.stream.flush()

    def done(self, stage: Any, report: Report, info: dict) -> None:
        line = (f"[{self.index + 1}/{self.total}] {stage.name}: {info['status']} — "
                f"{info['records']} records, {info['duration']:.1f} s"
                + (f" ({info['message']})" if info["status"] in ("skipped", "error") else f" ({report.summary()})"))
        if self.tty:
            self.stream.write("\r" + " " * (self.width - 1) + "\r")
        self.stream.write(line + "\n")
        self.stream.flush()


def _ci() -> bool:
    """``$CI`` set (non-empty, not ``0``/``false``/``no``), as CI services do."""
    ci = os.environ.get("CI", "").strip().lower()
    return bool(ci) and ci not in ("0", "false", "no")


# -- running -----------------------------------------------------------------------------------------


def execute(*, command: str, profile_name: str, stages: list[str] | None, context: Any, target: str | None = None,
            progress: Progress | None = None, executor: Any = None, unit_timeout: float | None = None,
            on_done: Callable | None = None) -> Report:
    """Run ``stages`` with ``context`` under a profile and return the merged, fully annotated report.

    ``executor`` (``"process:N"``, a dask scheduler address or ``Client``; ``None``: serial) is where the
    stages' independent units run (:mod:`verimono.executors`); ``unit_timeout`` bounds each unit there.
    ``on_done(stage, report, info)`` is called after each stage (the interrupt handler keeps them)."""
    from .executors import make_runner
    from .report.schema import environment
    from .stages import calibrate, run_stages

    profile = get_profile(profile_name)
    load_hypothesis_profile(profile_name)
    progress = progress or Progress(enabled=False)
    context.progress = progress.within
    runner = make_runner(executor, timeout=unit_timeout)
    if executor is not None and context.executor is None:
        print(f"verimono: units run on {runner.spec}", file=sys.stderr)
    context.executor = context.executor if context.executor is not None else runner
    cal = calibrate()                 # on a quiet machine, before any worker starts
    from .timing import MachineProbe, set_calibration

    set_calibration(cal)              # the unit of this process's time budgets (verimono.timeouts)
    if hasattr(runner, "prestart"):   # the workers import while this process builds the catalog
        runner.prestart()
    if getattr(runner, "workers", 1) >= 2:   # this process waits on the workers: draw the report's first
        import threading                     # figure meanwhile (matplotlib's import and font cache)

        from .report.plots import warm_up
        threading.Thread(target=warm_up, name="verimono-report-warm-up", daemon=True).start()
    start = time.perf_counter()
    probe = MachineProbe()

    def done(stage, rep, info):
        info.update(probe.lap())      # how busy the machine was during the stage: the gate's evidence
        progress.done(stage, rep, info)
        if on_done is not None:
            on_done(stage, rep, info)

    try:
        report = run_stages(stages, profile, context, on_start=progress.start, on_done=done)
    finally:
        runner.close()
    duration = time.perf_counter() - start
    # once more at the end: one calibration (best of 3 x 0.1 s) samples one moment of a shared machine and
    # read 0.08-0.16 s here within an hour; noise only slows a workload down, so the faster of the two ends
    # (best of 6) is the steadier unit, in the baseline and in the run gated against it alike
    cals = [cal, calibrate()]
    selection = {"stages": stages, "references": None if context.problems is None else
                 [p.name for p in context.problems]}
    report.meta.update({"command": command, "target": target, "profile": profile_name, "seed": context.seed,
                        "selection": selection, "executor": getattr(runner, "spec", type(runner).__name__),
                        "calibrations": cals,
                        "calibration": min(cals), "duration": duration,
                        "data_dir": None if context.data_dir is None else str(context.data_dir),
                        "environment": environment()})
    return report


def _context(args: argparse.Namespace, **kw: Any) -> Any:
    from .stages import RunContext, StageUnavailable, locate_data

    try:
        data = locate_data(getattr(args, "data", None))
    except StageUnavailable as exc:
        raise BadTarget(str(exc)) from None
    problems = None
    if getattr(args, "reference", None):
        from verimono.reference import get

        try:
            problems = [get(name) for name in args.reference]
        except KeyError as exc:
            raise BadTarget(str(exc.args[0])) from None
    return RunContext(seed=getattr(args, "seed", None), data_dir=data, problems=problems, **kw)


def _executor_options(args: argparse.Namespace) -> dict[str, Any]:
    spec = getattr(args, "executor", None)
    return {"executor": None if spec in (None, "serial") else spec, "unit_timeout": getattr(args, "unit_timeout", None)}


def _baseline_for(args: argparse.Namespace) -> Report | None:
    """The baseline to show changes against: ``--baseline`` (must load) or reports/baseline.json if present."""
    from .report.schema import load

    path = getattr(args, "baseline", None)
    if path:
        return load(path)
    default = Path("reports/baseline.json")
    if default.is_file():
        try:
            return load(default)
        except VerimonoError as exc:
            print(f"verimono: ignoring {default}: {exc}", file=sys.stderr)
    return None


def _changes(baseline: Report | None, report: Report) -> Any:
    if baseline is None:
        return None
    from .gate import IncompatibleBaseline, check_runs_compatible, compare

    try:
        check_runs_compatible(baseline, report)
    except IncompatibleBaseline as exc:
        print(f"verimono: not comparing with the baseline: {exc}", file=sys.stderr)
        return None
    return compare(baseline, report)


def order_table(report: Report) -> list[str]:
    """One line per convergence study: reference, expected order, measured sup-norm order with its 95%
    interval, verdict (``missed`` when the stepper does not reach the expected order)."""
    rows = []
    for s in report.studies:
        exp = "-" if s.expected is None else ("exact" if s.expected.exact else f"{s.expected.value:g}")
        rows.append((s.problem, exp, str(s.order), "ok" if s.verdict()[0] else "MISSED"))
    if not rows:
        return []
    head = ("reference", "expected", "measured sup-norm order [95%]", "verdict")
    w = [max(len(r[i]) for r in rows + [head]) for i in range(4)]
    fmt = "  {:<%d}  {:<%d}  {:<%d}  {}" % (w[0], w[1], w[2])
    return [fmt.format(*head)] + [fmt.format(*r) for r in rows]


def _exit_status(report: Report) -> int:
    """1 when a check failed; else 2 when one was undecided (nothing failed, but not everything was
    verified: a limitation of the harness is never a pass); else 0.  A timing record undecided because the
    machine was too noisy to judge a speed (``verimono.timing.is_noise_undecided``) does not count: the
    machine's load is not the code's defect, and the summary line says that speed was not judged."""
    from .timing import is_noise_undecided

    if report.failures:
        return EXIT_FAILED
    if any(not is_noise_undecided(r) for r in report.undecided) or report.meta.get("incomplete"):
        return EXIT_UNDECIDED
    return EXIT_OK


def _finish(report: Report, out: Path, baseline: Report | None) -> int:
    from .report import write

    changes = _changes(baseline, report)
    paths = write(report, out, changes=changes)
    for line in order_table(report):
        print(line)
    for r in report.failures:
        print(f"  {r}")
    line = f"verimono: {report.summary()}"
    from .timing import is_noise_undecided

    noisy = [r for r in report.undecided if is_noise_undecided(r)]
    if noisy:
        line += (f"; speed could not be judged here: {len(noisy)} timing record{'s' if len(noisy) != 1 else ''} "
                 "undecided, the machine too noisy (not a failure)")
    if changes is not None:
        line += f"; against the baseline: {changes.summary()}"
    print(line)
    print(f"verimono: wrote {paths['html']} and {paths['json']}")
    for r in report.undecided:
        print(f"  {r}")
    return _exit_status(report)


#: exit status of an interrupted run (the shell's convention for SIGINT)
EXIT_INTERRUPTED = 130


def _interruptible(run: Callable[[Callable], Report], out: Path, *, command: str, profile: str,
                   stages: list[str] | None, previous: Report | None = None) -> Report | int:
    """``run(on_done)`` with SIGTERM treated as an interrupt; on an interrupt write the stages finished so
    far (with ``previous``'s, when resuming) to ``out`` marked ``incomplete`` and return the exit status."""
    import signal

    finished: list[tuple[Report, dict]] = []

    def on_done(stage, rep, info):
        finished.append((rep, info))

    def term(signum, frame):
        raise KeyboardInterrupt(f"signal {signum}")

    old = signal.signal(signal.SIGTERM, term) if _main_thread() else None
    try:
        return run(on_done)
    except KeyboardInterrupt:
        partial = previous if previous is not None else Report(meta={"stages": []})
        for rep, info in finished:
            partial.extend(rep)
            partial.meta.setdefault("stages", []).append(info)
        done = [s["name"] for s in partial.meta.get("stages") or []]
        partial.meta.update({"command": command, "profile": profile, "incomplete": True,
                             "finished_stages": done,
                             "selection": partial.meta.get("selection") or {"stages": stages, "references": None}})
        from .report import write

        paths = write(partial, out)
        print(f"\nverimono: interrupted; the {len(done)} finished stage(s) ({', '.join(done) or 'none'}) are in "
              f"{paths['json']}, marked incomplete; continue with `verimono {command} --resume`",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        if old is not None:
            signal.signal(signal.SIGTERM, old)


def _main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def _cmd_run(args: argparse.Namespace) -> int:
    from .atomic import ensure_writable_dir
    from .report.schema import load
    from .timeouts import budget

    out = ensure_writable_dir(args.out)           # before any work: a run must not be lost at the end
    baseline = _baseline_for(args)
    previous, stages = None, args.stage
    if args.resume:
        previous = load(out / "results.json") if (out / "results.json").is_file() else None
        if previous is None or not previous.meta.get("incomplete"):
            raise NothingToResume(f"nothing to resume: {out / 'results.json'} is "
                                  f"{'absent' if previous is None else 'a complete run'}")
        if previous.meta.get("profile") != args.profile:
            raise NothingToResume(f"the interrupted run used profile {previous.meta.get('profile')!r}, not "
                                  f"{args.profile!r}; resume it with the same options")
        from .stages import STAGES

        wanted = (previous.meta.get("selection") or {}).get("stages") or list(STAGES)
        done = set(previous.meta.get("finished_stages") or [])
        stages = [n for n in wanted if n not in done]
        if args.seed is None and previous.meta.get("seed") is not None:
            args.seed = previous.meta["seed"]

    def run(on_done):
        with budget(args.timeout):
            return execute(command="run", profile_name=args.profile, stages=stages, context=_context(args),
                           progress=Progress(), on_done=on_done, **_executor_options(args))

    report = _interruptible(run, out, command="run", profile=args.profile, stages=args.stage, previous=previous)
    if isinstance(report, int):
        return report
    if previous is not None:
        report = _merge_resumed(previous, report)
    return _finish(report, out, baseline)


def _merge_resumed(previous: Report, rest: Report) -> Report:
    """The interrupted run's finished stages followed by the resumed ones: one complete report."""
    merged = Report(meta=dict(rest.meta))
    merged.extend(previous)
    merged.extend(rest)
    merged.meta["stages"] = list(previous.meta.get("stages") or []) + list(rest.meta.get("stages") or [])
    merged.meta["selection"] = previous.meta.get("selection")
    merged.meta["resumed"] = True
    for key in ("incomplete", "finished_stages"):
        merged.meta.pop(key, None)
    return merged


def _load_file(path: Path) -> Any:
    """The module in the file ``path`` itself — not whatever module of the same name is importable (a
    ``types.py`` or a second ``lagged.py`` elsewhere); its folder is put on ``sys.path`` for its own
    imports of neighbouring modules."""
    import importlib.util

    path = path.resolve()
    if not path.is_file():
        raise BadTarget(f"{path} does not exist")
    name = f"verimono_target_{abs(hash(str(path))):x}_{path.stem}"
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise BadTarget(f"cannot load {path} as a Python module")
    module = importlib.util.module_from_spec(spec)
    if str(path.parent) not in sys.path:
        sys.path.insert(0, str(path.parent))
    sys.modules[name] = module           # dataclasses, pickling and relative lookups need it registered
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        sys.modules.pop(name, None)
        raise BadTarget(f"cannot import {path}: {type(exc).__name__}: {exc}") from None
    return module


def load_target(spec: str) -> Any:
    """Import ``MODULE:OBJECT`` (``MODULE`` may be a dotted name or a ``.py`` path; ``OBJECT`` dotted)."""
    module_name, sep, attr = spec.partition(":")
    if not sep or not module_name or not attr:
        raise BadTarget(f"expected MODULE:OBJECT (e.g. mypackage.solvers:my_stepper), got {spec!r}")
    if module_name.endswith(".py"):
        obj: Any = _load_file(Path(module_name))
    else:
        if "" not in sys.path and os.getcwd() not in sys.path:
            sys.path.insert(0, os.getcwd())
        try:
            obj = importlib.import_module(module_name)
        except ImportError as exc:
            raise BadTarget(f"cannot import {module_name!r}: {exc}") from None
    for part in attr.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            raise BadTarget(f"{module_name!r} has no attribute {attr!r}") from None
    return obj


#: second-parameter names that mark a callable as a resolvent ``J(x, lam, t)``, not a stepper ``(problem, t_grid)``
_STEP_NAMES = {"lam", "lamb", "lmbda", "lambda_", "lmb", "gamma", "tau", "step", "h", "mu", "alpha", "rho", "eta"}


def _looks_like_resolvent(fn: Any) -> str | None:
    """Why ``fn`` looks like a resolvent or prox ``f(x, lam[, t])`` rather than a stepper, or ``None``."""
    try:
        params = [p for p in inspect.signature(fn).parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    except (TypeError, ValueError):
        return None
    if len(params) >= 2 and params[1].name.lower() in _STEP_NAMES:
        names = ", ".join(p.name for p in params)
        return (f"looks like a resolvent or proximal operator ({names}), not a stepper(problem, t_grid): its "
                f"second parameter {params[1].name!r} is a step size")
    return None


def attr_of(spec: str) -> str:
    return spec.partition(":")[2] or spec


def _cmd_check(args: argparse.Namespace) -> int:
    obj = load_target(args.target)
    if hasattr(obj, "resolvent") and hasattr(obj, "dim") and not isinstance(obj, type):
        stages, ctx = ["operator_laws"], _context(args, operators=[(args.target, obj)])
        kind = "operator"
    elif callable(obj) and not isinstance(obj, type):
        hint = _looks_like_resolvent(obj)
        if hint:
            raise BadTarget(f"{args.target} {hint}: wrap it as an operator, e.g. in your module "
                            f"`my_op = verimono.operator_from_resolvent({attr_of(args.target)}, dim=n)`, and check "
                            f"MODULE:my_op")
        obj = with_claim(obj, args.scheme, args.order)
        stages, ctx = ["convergence", "trajectory_laws"], _context(args, stepper=obj)
        kind = "stepper" + ("" if claim_of(obj).proximal else f" claiming {claim_of(obj).describe()}")
    else:
        raise BadTarget(f"{args.target} is neither an operator (with .dim and .resolvent) nor a stepper "
                        "callable(problem, t_grid)")
    from .atomic import ensure_writable_dir
    from .timeouts import budget

    out = ensure_writable_dir(args.out)           # before any work
    if getattr(args, "executor", None) not in (None, "serial"):
        from .executors import ship_by_value

        ship_by_value(obj)  # its module need not be importable on the workers
    print(f"verimono: checking {args.target} as a {kind}", file=sys.stderr)

    def run(on_done):
        with budget(args.timeout):
            return execute(command="check", profile_name=args.profile, stages=stages, context=ctx,
                           target=args.target, progress=Progress(), on_done=on_done, **_executor_options(args))

    report = _interruptible(run, out, command="check", profile=args.profile, stages=stages)
    if isinstance(report, int):
        return report
    report.meta.setdefault("target", args.target)
    if report.results and all(r.status == SKIPPED for r in report.results):
        _finish(report, out, None)
        print(f"verimono: no {kind} battery could run here: " +
              "; ".join(r.message for r in report.results), file=sys.stderr)
        return EXIT_UNDECIDED
    return _finish(report, out, _baseline_for(args))


def _cmd_baseline(args: argparse.Namespace) -> int:
    from .atomic import ensure_writable_file
    from .report.schema import load

    ensure_writable_file(args.out)                # before any work
    if args.from_results:
        report = load(args.from_results)
        if report.meta.get("incomplete"):
            raise NothingToResume(f"{args.from_results} is an interrupted run (marked incomplete): finish it "
                                  "with `verimono run --resume` before recording it as a baseline")
    else:
        report = execute(command="run", profile_name=args.profile, stages=args.stage, context=_context(args),
                         progress=Progress(), **_executor_options(args))
    report.trajectories = []  # plot samples only: the gate never reads them, and they are half the size
    path = report.save(args.out)
    print(f"verimono: baseline of {report.summary()} (profile {report.meta.get('profile')}) written to {path}")
    if not report.ok:
        print("verimono: warning: the baseline records failing checks; the gate will only catch new ones",
              file=sys.stderr)
    return EXIT_OK


def _cmd_gate(args: argparse.Namespace) -> int:
    from .gate import gate

    try:
        comparison = gate(args.baseline, args.results)
    except VerimonoError:
        raise
    except Exception as exc:   # the gate fails closed: a document it cannot compare is never a regression
        print(f"verimono gate: cannot compare {args.baseline} with {args.results} ({type(exc).__name__}: "
              f"{exc})", file=sys.stderr)
        return EXIT_UNDECIDED
    for c in comparison.regressions:
        print(f"  {c}")
    if args.verbose:
        for c in comparison.others:
            print(f"  {c}")
    print(f"verimono gate: {comparison.summary()} against {args.baseline}")
    return EXIT_OK if comparison.ok else EXIT_FAILED


def _cmd_report(args: argparse.Namespace) -> int:
    from .report.html import render
    from .report.schema import load

    report = load(args.results)
    changes = _changes(load(args.baseline), report) if args.baseline else None
    from .atomic import ensure_writable_file, write_text

    out = ensure_writable_file(args.out)
    write_text(out, render(report, changes=changes))
    print(f"verimono: wrote {out}")
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    from .stages import STAGES

    parser = argparse.ArgumentParser(prog="verimono", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    def run_options(p: argparse.ArgumentParser) -> None:
        p.add_argument("--profile", choices=PROFILES, default=active_profile() if active_profile() in PROFILES
                       else "dev", help="effort and hypothesis profile (default: ci when $CI is set, else dev)")
        p.add_argument("--stage", action="append", choices=list(STAGES), metavar="NAME",
                       help="run only this stage (repeatable); stages: " + ", ".join(STAGES))
        p.add_argument("--seed", type=int, default=None, help="seed for the randomized batteries")
        p.add_argument("--data", default=None, help="shared data folder (Siconos references); default ../shared")
        p.add_argument("--reference", action="append", metavar="NAME",
                       help="use only this analytic reference (repeatable; default: the whole catalog)")
        p.add_argument("--timeout", type=float, default=None, metavar="S",
                       help="seconds per unit of work (one law on one operator, one check of one stepper) "
                            "before it is stopped and recorded as failed (default: the profile's)")
        p.add_argument("--executor", default=None, metavar="SPEC",
                       help="where the stages' independent units run: serial, auto (every core, at most 4 "
                            "worker processes; the default of run, $VERIMONO_EXECUTOR overrides), process:N (N "
                            "worker processes), or a dask.distributed scheduler address such as tcp://host:8786")
        p.add_argument("--unit-timeout", type=float, default=None, metavar="SECONDS",
                       help="with --executor: a stage unit (a subject's battery) still running after this long "
                            "becomes a failed record")

    run = sub.add_parser("run", help="run the whole verification and write the report")
    run_options(run)
    run.set_defaults(executor=os.environ.get("VERIMONO_EXECUTOR") or "auto")
    run.add_argument("--out", default="reports", help="output folder (default reports/)")
    run.add_argument("--baseline", default=None, help="show changes against this baseline (default "
                     "reports/baseline.json when present)")
    run.add_argument("--resume", action="store_true", help="continue the interrupted run whose incomplete "
                     "results.json is in --out: run only the stages it lacks")
    run.set_defaults(func=_cmd_run)

    check = sub.add_parser("check", help="run the operator or stepper battery on MODULE:OBJECT")
    check.add_argument("target", metavar="MODULE:OBJECT")
    run_options(check)
    check.add_argument("--out", default="reports/check", help="output folder (default reports/check/)")
    check.add_argument("--baseline", default=None, help="show changes against this baseline")
    check.add_argument("--scheme", choices=SCHEMES, default=None,
                       help="what a stepper claims: 'proximal' (the paper's scheme: every law applies; the default "
                            "for a bare callable) or 'any' (it only converges with --order)")
    check.add_argument("--order", type=float, default=None,
                       help="the convergence order a --scheme any stepper claims (default 1)")
    check.set_defaults(func=_cmd_check, stage=None)

    base = sub.add_parser("baseline", help="record the current results as the gate's baseline")
    run_options(base)
    base.add_argument("--out", default="reports/baseline.json")
    base.add_argument("--from", dest="from_results", default=None, metavar="RESULTS",
                      help="copy this results.json instead of running")
    base.set_defaults(func=_cmd_baseline)

    g = sub.add_parser("gate", help="exit 1 on a regression against the baseline, 2 if undecidable")
    g.add_argument("--baseline", required=True)
    g.add_argument("--results", default="reports/results.json")
    g.add_argument("-v", "--verbose", action="store_true", help="also list changes that are not regressions")
    g.set_defaults(func=_cmd_gate)

    rep = sub.add_parser("report", help="render report.html from a results.json")
    rep.add_argument("--results", default="reports/results.json")
    rep.add_argument("--out", default="reports/report.html")
    rep.add_argument("--baseline", default=None)
    rep.set_defaults(func=_cmd_report)
    return parser


#: BLAS threads for a verification run: every matrix here is small, so extra BLAS threads only contend
#: for the cores; on the 2-core reference machine, under load, threaded OpenBLAS made the catalog's
#: convergence studies vary from 0.4 s to 31 s, against a steady 0.4 s single-threaded
BLAS_THREADS = 1


def main(argv: list[str] | None = None) -> int:
    from threadpoolctl import threadpool_limits

    args = build_parser().parse_args(argv)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
            return func(args)
    except VerimonoError as exc:
        print(f"verimono {args.command}: {exc}", file=sys.stderr)
        return EXIT_UNDECIDED


if __name__ == "__main__":
    sys.exit(main())
