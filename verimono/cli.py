"""Command line of verimono (``verimono --version``: the installed version).

    verimono run [--profile dev|ci|thorough] [--out DIR] [--stage NAME ...] [--seed N] [--data DIR]
                 [--baseline FILE] [--timeout S] [--resume] [--executor serial|process:N|tcp://host:port]
                 [--unit-timeout S]
        The whole verification (every registered stage, see ``verimono.run.stages``); writes DIR/results.json
        and DIR/report.html (DIR defaults to reports/).  Exit 0 when every check holds, 1 when one fails,
        2 when nothing failed but a check was undecided (a limitation of the harness) — except a speed the machine
        was too noisy to judge (a timing record undecided for "timing noise"), which exits 0 and says so.
        The output folder is checked writable before any work; both files are written atomically with one
        run id.  An interrupt (Ctrl-C, SIGTERM, SIGHUP) writes the finished stages to a results file marked
        incomplete (the gate refuses it, exit 2) and exits 130; ``--resume`` runs the stages that file lacks
        and completes it (it names the run id it continues; the result records it in ``meta.resumed_from``).
        ``--timeout S``: seconds per unit of work (one law on one operator, one check of one stepper;
        default: the profile's), beyond which the unit is stopped while the run goes on: undecided when all it
        evaluated held, failed when a call never returns or a sample was violated.  ``--timeout`` and
        ``--unit-timeout`` are numbers of seconds > 0 or ``inf`` (no limit), checked before any work (exit 2
        otherwise: ``nan``, 0, negatives).  A call blocked in native code (``os.system``, a C extension),
        which the budget's interrupt cannot stop, is stopped by a process-level limit (``verimono.execution.watchdog``)
        once the budget and a grace of max(2 s, half the budget) are over: under ``--executor process:N``
        its worker answers a failed record naming the call and is replaced, and the run goes on; in this
        process (``--executor serial``) the run ends — the finished stages and a failed record for the call
        are written marked incomplete, one line names the call, its time and the file — with exit 1.
        Before any work the run marks DIR/results.json in progress (``results.json.in-progress``, with its
        run id) and removes the mark once its pair is written: files beside a mark that stays (a run killed,
        or stopped by an error) are not that run's, and the gate refuses them (exit 2).  Its finished stages
        are saved as each finishes to ``results.json.partial`` beside the results, never over them: a run
        killed outright (SIGKILL) leaves the previous pair intact, and ``--resume`` continues from that file.  When the pair
        cannot be written (a full disk, an unwritable folder) the previous pair stays, the results are kept
        in the temporary folder, and a one-line message names both paths (exit 2).
    verimono check MODULE:OBJECT [--profile P] [--out DIR] [--seed N] [run's --timeout, --executor, ...]
        The operator battery on an operator, or the stepper battery on a stepper ``f(problem, t_grid)``;
        MODULE is a dotted module name or a ``.py`` file (anything else: exit 2).  ``--problem MODULE:OBJECT``
        adds the user's problems to the references; ``--only`` runs exactly the problems named with
        ``--problem`` (and ``--reference``): no catalog, no generated problems.  A stepper raising
        ``verimono.NotApplicable`` on a problem it does not handle (an ODE integrator on a set-valued ``F``) gets
        counted skips with its reason there, never failures.  Its units run on every
        core as ``run``'s do (``--executor serial``: in this process).  Its files are marked and
        written as ``run``'s; after an interrupt, run the same command again (it has no ``--resume``).
    verimono compare MODULE:A MODULE:B ... (--problem MODULE:OBJECT | --reference ID)... [--out DIR]
                 [--rounds N] [--norm sup|l2|final]
        Work–precision of the steppers (fixed-grid ``Stepper``s over the problem's step sizes, ``Adaptive``
        ones over their tolerances) on each problem (``verimono.run.work_precision``): the records
        ``work_precision[A vs B on P]`` (CPU time) and ``work_precision_steps[...]`` of the first stepper
        against each other, and the diagram in DIR/report.html (default reports/compare/).  Exit 0 when A is
        at least as accurate as every other for the same work, 1 when it is not, 2 when nothing failed but a
        comparison could not be decided (work ranges that do not overlap; timing noise alone exits 0).
    verimono baseline [--out reports/baseline.json] [--from RESULTS] [run options]
        Record the current results (runs the verification, or copies RESULTS) as the gate's baseline.
    verimono gate --baseline FILE [--results reports/results.json]
        Exit 1 and print why on a regression; exit 2 when either file is missing, garbled, incompatible,
        repeats a record key, is not a regular file or is larger than the document limit
        (``$VERIMONO_MAX_DOCUMENT_MIB``, default 256), when the baseline holds a non-finite figure, or when
        the results are those of a run that never completed (see ``verimono.run.gate``).
    verimono report [--results reports/results.json] [--out reports/report.html] [--baseline FILE]
        Re-render the HTML report from a results file.

Exit status 2 always means "could not decide" (bad usage, unreadable input); it is never a pass.  Exit 0 only
when the results were written and passed: what a subject raises — ``sys.exit()`` and ``GeneratorExit`` included —
is a failed record of it (exit 1); a closed pipe or stream ends the printing, never the run (its results are
written first and the status is the verdict's: ``verimono.run.console``).  docs/run.md tabulates the statuses.
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
from pathlib import Path
from typing import Any, Callable

from .core.claims import SCHEMES, claim_of, with_claim
from .core.errors import BadTarget, InvalidCheckArgument, NothingToResume, OutputNotWritable, SchemaError, VerimonoError
from .execution.config import RunConfig, from_environment
from .execution.config import using as using_config
from .execution.profiles import PROFILES
from .run.progress import Progress
from .records.results import FAILED, SKIPPED, Report
from .records.verdicts import SUBJECT_EXITS
from .run.execute import (EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_UNDECIDED, execute, exit_status, interruptible, merge_resumed)
from .run.targets import load_target


# -- running -----------------------------------------------------------------------------------------


def _context(args: argparse.Namespace, **kw: Any) -> Any:
    from .run.stages import RunContext, StageUnavailable, locate_data

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
    extra = [p for spec in getattr(args, "problem", None) or [] for p in _load_problems(spec)]
    # --problem adds to the references (the catalog, or those chosen with --reference): it never replaces them,
    # except under --only: then exactly the problems named (--problem, --reference), no catalog, no generated ones
    if getattr(args, "only", False):
        if not extra and not problems:
            raise BadTarget("--only runs exactly the problems named with --problem (or --reference): name at least one")
        problems = problems or []
    return RunContext(seed=getattr(args, "seed", None), data_dir=data, problems=problems, extra_problems=extra, **kw)


def _load_problems(spec: str) -> list[Any]:
    """``--problem MODULE:OBJECT``: a :class:`verimono.Problem` (or a list of them), remembered as loaded from
    ``spec`` so that reproduction lines name it."""
    from .core.problem import Problem, with_origin

    obj = load_target(spec)
    found = list(obj) if isinstance(obj, (list, tuple)) else [obj]
    if not found or not all(isinstance(p, Problem) for p in found):
        raise BadTarget(f"--problem {spec}: expected a verimono.Problem (or a list of them), got "
                        f"{type(obj).__name__} (build one with verimono.Problem(...) or "
                        "verimono.manufactured_problem(...))")
    return [with_origin(p, spec) for p in found]


def resolve_profile(args: argparse.Namespace) -> None:
    """``--profile``, or the environment's default when it was left out (:func:`verimono.execution.config.
    from_environment`; ``dev`` when ``$HYPOTHESIS_PROFILE`` names a profile of the user's own): the one choice
    of the run, recorded with where it came from (``args.profile_source``)."""
    if getattr(args, "profile", None) is not None:
        args.profile_source = "--profile"
        return
    default = from_environment()
    known = default.profile in PROFILES
    args.profile, args.profile_source = (default.profile, default.source) if known else ("dev", "default")


def run_config(args: argparse.Namespace) -> RunConfig:
    """The run configuration the options choose: profile, explicit budget (``--timeout``), seed, executor."""
    return RunConfig(profile=args.profile, budget=args.timeout, seed=args.seed, executor=getattr(args, "executor", None),
                     source=getattr(args, "profile_source", "--profile"))


def _executor_options(args: argparse.Namespace) -> dict[str, Any]:
    """What :func:`verimono.run.execute.execute` takes from the options: the executor, its unit timeout, and the
    calibration :func:`main` started before its imports."""
    spec = getattr(args, "executor", None)
    return {"executor": None if spec in (None, "serial") else spec, "unit_timeout": getattr(args, "unit_timeout", None),
            "calibration": getattr(args, "calibration", None)}


def _baseline_for(args: argparse.Namespace) -> Report | None:
    """The baseline to show changes against: ``--baseline`` (must load) or reports/baseline.json if present."""
    from .records.results import load

    path = getattr(args, "baseline", None)
    if path:
        baseline = load(path)
        baseline.source = str(path)   # named in the `verimono gate` command _finish suggests
        return baseline
    default = Path("reports/baseline.json")
    if default.is_file():
        try:
            baseline = load(default)
            baseline.source = str(default)
            return baseline
        except VerimonoError as exc:
            print(f"verimono: ignoring {default}: {exc}", file=sys.stderr)
    return None


def _expected_costs(baseline: Report | None, profile: str) -> dict:
    """Each unit's wall seconds in the baseline, when it was made under ``profile``: the order of the run's
    shared queue of units, longest first (:attr:`verimono.run.stages.RunContext.expected`).  The baseline is
    the run's committed record of the same work (CI has it; a previous ``results.json`` may be another
    machine's or another profile's); a unit it lacks, or a figure gone stale, costs speed only."""
    if baseline is None or baseline.meta.get("profile") != profile:
        return {}
    from .run.stages.registry import expected_costs

    return expected_costs(baseline)


def _changes(baseline: Report | None, report: Report) -> Any:
    if baseline is None:
        return None
    from .run.gate import IncompatibleBaseline, check_runs_compatible, compare

    try:
        check_runs_compatible(baseline, report)
        return compare(baseline, report)
    except (IncompatibleBaseline, SchemaError) as exc:   # shown only; `verimono gate` decides (exit 2)
        print(f"verimono: not comparing with the baseline: {exc}", file=sys.stderr)
        return None


def order_table(report: Report) -> list[str]:
    """One line per convergence study: reference, expected order, measured sup-norm order with its 95%
    interval, verdict (``MISSED`` when the stepper does not reach the expected order, ``UNDECIDED`` when the study
    could not decide, ``FAILED`` when its record failed for another reason: a limit that is not the solution's)."""
    failed = {(r.details["study"].problem, r.details["study"].stepper) for r in report.results
              if r.check == "convergence_order" and r.status == FAILED and hasattr(r.details.get("study"), "problem")}
    rows = []
    for s in report.studies:
        exp = "-" if s.expected is None else ("exact" if s.expected.exact else f"{s.expected.value:g}")
        ok = None if hasattr(s, "decision") else s.verdict()[0]
        status = s.decision().status if hasattr(s, "decision") else {None: "undecided", True: "passed"}.get(ok, "failed")
        verdict = {"failed": "MISSED", "undecided": "UNDECIDED"}.get(status, "FAILED" if (s.problem, s.stepper) in failed
                                                                      else "ok")
        rows.append((s.problem, exp, str(s.order), verdict))
    if not rows:
        return []
    head = ("reference", "expected", "measured sup-norm order [95%]", "verdict")
    w = [max(len(r[i]) for r in rows + [head]) for i in range(4)]
    fmt = "  {:<%d}  {:<%d}  {:<%d}  {}" % (w[0], w[1], w[2])
    return [fmt.format(*head)] + [fmt.format(*r) for r in rows]


def _start(out: Path, command: str, resumes: str | None = None) -> str:
    """Mark ``out/results.json`` in progress for a new run (before any work) and return its run id."""
    import datetime as dt
    import socket

    from .records.atomic import mark_in_progress
    from .records.report import new_run_id

    run_id = new_run_id()
    mark_in_progress(out / "results.json", run_id, command=command, pid=os.getpid(), host=socket.gethostname(),
                     started=dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"), resumes=resumes)
    return run_id


def _inexact_arg(text: str) -> tuple[float, float]:
    """``--inexact C:Q``: ``ε(h) = C h^Q``."""
    try:
        C, q = (float(v) for v in text.replace(",", ":").split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected C:Q (eps(h) = C h^Q), got {text!r}") from None
    if not (0 < C < float("inf") and 0 < q < float("inf")):
        raise argparse.ArgumentTypeError(f"C and Q must be positive and finite, got {text!r}")
    return C, q


def _step_range(text: str) -> tuple[float, float]:
    """``--step-range H_MIN:H_MAX``: two positive finite step sizes (either order), checked before any work."""
    parts = text.replace(",", ":").split(":")
    try:
        lo, hi = (float(v) for v in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be two step sizes H_MIN:H_MAX, got {text!r}") from None
    if not all(0.0 < v < float("inf") for v in (lo, hi)) or lo == hi:
        raise argparse.ArgumentTypeError(f"must be two distinct positive finite step sizes H_MIN:H_MAX, got {text!r}")
    return min(lo, hi), max(lo, hi)


def _seconds(text: str) -> float:
    """``--timeout`` / ``--unit-timeout``: a number of seconds > 0, or ``inf`` for no limit (``nan``, 0 and
    negatives are refused before any work, exit 2)."""
    try:
        seconds = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0 (or inf: no limit), got {text!r}") from None
    if not seconds > 0:          # nan compares false
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0 (or inf: no limit), got {text!r}")
    if seconds == float("inf") and text.strip().lower().lstrip("+") not in ("inf", "infinity"):
        raise argparse.ArgumentTypeError(f"{text!r} overflows to infinity: write inf for no limit, or a number of "
                                         "seconds")
    return seconds


def _whole_number(text: str, least: int, what: str) -> int:
    """An integer ``>= least`` from the command line, or the parser's error ``must be {what}``."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
    if value < least:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}")
    return value


def _seed(text: str) -> int:
    """``--seed``: a non-negative integer, checked before any work (a bad seed is misuse, never a failure
    charged to the subject)."""
    return _whole_number(text, 0, "a non-negative integer")


def _rounds(text: str) -> int:
    """``--rounds``: a whole number of timed rounds >= 1, checked before any work (exit 2)."""
    return _whole_number(text, 1, "a whole number of rounds >= 1")


def _finish(report: Report, out: Path, baseline: Report | None, run_id: str | None = None) -> int:
    from .records.report import write

    changes = _changes(baseline, report)
    paths = write(report, out, changes=changes, run_id=run_id)
    for line in order_table(report):
        print(line)
    for r in report.failures:
        print(f"  {r}")
    line = f"verimono: {report.summary()}"
    from .execution.timing import is_noise_undecided

    noisy = [r for r in report.undecided if is_noise_undecided(r)]
    if noisy:
        line += (f"; speed could not be judged here: {len(noisy)} timing record{'s' if len(noisy) != 1 else ''} "
                 "undecided, the machine too noisy (not a failure)")
    if changes is not None:
        for ln in changes.regression_lines(getattr(baseline, "source", None), paths["json"]):
            print(ln)
        if changes.wall_unjudged_line():
            print(f"verimono: {changes.wall_unjudged_line()}")
        line += f"; against the baseline: {changes.summary()}"
    print(line)
    print(f"verimono: wrote {paths['html']} and {paths['json']}")
    for r in report.undecided:
        print(f"  {r}")
    return exit_status(report)


def _cmd_run(args: argparse.Namespace) -> int:
    from .records.atomic import ensure_writable_dir, in_progress, partial_path
    from .records.results import load
    out = ensure_writable_dir(args.out)           # before any work: a run must not be lost at the end
    previous, stages = None, args.stage
    if args.resume:
        results, killed = out / "results.json", in_progress(out / "results.json")
        previous = load(results) if results.is_file() else None
        saved = partial_path(results)    # the stages a run killed outright saved beside the previous results
        if killed is not None and saved.is_file():
            candidate = load(saved)
            if candidate.meta.get("incomplete") and candidate.meta.get("run_id") == killed.get("run_id"):
                previous, results = candidate, saved
        if previous is None or not previous.meta.get("incomplete"):
            what = "absent" if previous is None else f"the complete run {previous.meta.get('run_id')}"
            if killed is not None:
                raise NothingToResume(f"nothing to resume: run {killed.get('run_id')} (started "
                                      f"{killed.get('started') or '?'}) never completed and recorded no finished "
                                      f"stage (it was killed or stopped by an error); {results} is {what}, "
                                      "not that run's: run again without --resume")
            raise NothingToResume(f"nothing to resume: {results} is {what}")
        print(f"verimono: resuming run {previous.meta.get('run_id')} (finished: "
              f"{', '.join(previous.meta.get('finished_stages') or []) or 'none'})", file=sys.stderr)
        if previous.meta.get("profile") != args.profile:
            raise NothingToResume(f"the interrupted run used profile {previous.meta.get('profile')!r}, not "
                                  f"{args.profile!r}; resume it with the same options")
        from .run.stages import default_stages

        wanted = (previous.meta.get("selection") or {}).get("stages") or default_stages()
        done = set(previous.meta.get("finished_stages") or [])
        stages = [n for n in wanted if n not in done]
        if args.seed is None and previous.meta.get("seed") is not None:
            args.seed = previous.meta["seed"]

    # over a previous run's files, the mark before anything that takes time (reading the baseline, building the
    # references, importing the checks): a run killed from here on leaves it, and the gate refuses those files;
    # over none, after the options are checked (bad references or data: exit 2, nothing written)
    resumes = None if previous is None else previous.meta.get("run_id")
    run_id = getattr(args, "run_id", None) if previous is None else None
    run_id = run_id or (_start(out, "run", resumes=resumes) if (out / "results.json").exists() else None)
    baseline = _baseline_for(args)
    ctx = _context(args)
    ctx.expected = _expected_costs(baseline, args.profile)
    if previous is not None:     # the finished convergence stage's grids and costs, which later stages read
        from .run.stages.builtin import restore_convergence

        restore_convergence(previous, ctx)
    run_id = run_id or _start(out, "run", resumes=resumes)

    def run(on_done):
        with using_config(run_config(args)):
            return execute(command="run", profile_name=args.profile, stages=stages, context=ctx,
                           progress=Progress(), on_done=on_done, **_executor_options(args))

    report = interruptible(run, out, command="run", profile=args.profile, stages=args.stage, previous=previous,
                           run_id=run_id, checkpoint=True)
    if isinstance(report, int):
        return report
    if previous is not None:
        report = merge_resumed(previous, report)
    return _finish(report, out, baseline, run_id)


def _cmd_check(args: argparse.Namespace) -> int:
    from .checks.subjects import kind_of
    from .core.adaptive import Adaptive
    from .records.atomic import ensure_writable_dir

    # over a previous check's files, the mark before anything that takes time (importing the target and the
    # checks): a check killed from here on leaves it, and the gate refuses those files
    run_id = getattr(args, "run_id", None) or _mark_if_stale(args.out, "check")
    obj = load_target(args.target)
    user = obj
    try:
        kind = kind_of(obj)
    except InvalidCheckArgument as exc:
        raise BadTarget(f"{args.target}: {exc}") from None
    if kind == "operator":
        from .core.naming import subject_name

        # the operator's own name, as the API and pytest call it: one record key whatever the entry point
        stages, ctx = ["operator_laws"], _context(args, operators=[(subject_name(obj), obj)])
    elif isinstance(obj, Adaptive):
        # a stepper choosing its own steps: its rate in the tolerance and the laws on its own partitions (a grid
        # stepper's convergence study would call it with a grid it does not take)
        stages, ctx = ["adaptive"], _context(args, stepper=obj)
        kind = f"adaptive stepper ({obj.describe()})"
    elif kind == "stepper":
        from .execution.timing import TimedStepper

        # its calls are timed apart from the checks around them: the gate judges the subject's own CPU time
        obj = TimedStepper(with_claim(obj, args.scheme, args.order, solve_tol=args.solve_tol,
                                      grids=getattr(args, "grids", None), inexact=getattr(args, "inexact", None)))
        stages, ctx = ["convergence", "trajectory_laws"], _context(args, stepper=obj,
                                                                    step_range=getattr(args, "step_range", None))
        kind = "stepper" + ("" if claim_of(obj).proximal else f" claiming {claim_of(obj).describe()}")
    else:
        raise BadTarget(f"{args.target} is a problem: `verimono check` takes an operator or a stepper")
    out = ensure_writable_dir(args.out)           # before any work
    run_id = run_id or _start(out, "check")
    baseline = _baseline_for(args)                # a baseline that cannot be read: exit 2 before the work
    if getattr(args, "executor", None) not in (None, "serial"):
        from .execution.executors import ship_by_value

        ship_by_value(user)  # its module need not be importable on the workers
    print(f"verimono: checking {args.target} as {'an' if kind[0] in 'aeiou' else 'a'} {kind}", file=sys.stderr)

    def run(on_done):
        with using_config(run_config(args)):
            return execute(command="check", profile_name=args.profile, stages=stages, context=ctx,
                           target=args.target, progress=Progress(), on_done=on_done, **_executor_options(args))

    again = shlex.join(["verimono", *getattr(args, "argv", ["check", args.target])])
    report = interruptible(run, out, command="check", profile=args.profile, stages=stages, run_id=run_id,
                           advice=f"`verimono check` has no --resume: run the same command again (`{again}`)")
    if isinstance(report, int):
        return report
    report.meta.setdefault("target", args.target)
    if report.results and all(r.status == SKIPPED for r in report.results):
        _finish(report, out, None, run_id)
        print(f"verimono: no {kind} battery could run here: " +
              "; ".join(dict.fromkeys(r.message for r in report.results)), file=sys.stderr)
        return EXIT_UNDECIDED
    return _finish(report, out, baseline, run_id)


def _cmd_compare(args: argparse.Namespace) -> int:
    from .core.adaptive import Adaptive
    from .checks.subjects import kind_of
    from .records.atomic import ensure_writable_dir

    steppers = []
    for spec in args.targets:
        obj = load_target(spec)
        if not isinstance(obj, Adaptive):
            try:
                kind = kind_of(obj)
            except InvalidCheckArgument as exc:
                raise BadTarget(f"{spec}: {exc}") from None
            if kind != "stepper":
                raise BadTarget(f"{spec} is {'an' if kind[0] in 'aeiou' else 'a'} {kind}: `verimono compare` takes steppers (a Stepper, a callable "
                                "stepper(problem, t_grid), or a verimono.Adaptive)")
        steppers.append(obj)
    if len(steppers) < 2:
        raise BadTarget("`verimono compare` needs at least two steppers")
    ctx = _context(args)          # --problem adds to --reference (RunContext.extra_problems), as for run and check
    problems = list(ctx.problems or []) + list(ctx.extra_problems)
    if not problems:
        raise BadTarget("`verimono compare` needs a problem: --problem MODULE:OBJECT or --reference NAME")
    out = ensure_writable_dir(args.out)
    run_id = _start(out, "compare")
    from .run.work_precision import compare_report

    print(f"verimono: comparing {', '.join(args.targets)} on {len(problems)} problem"
          f"{'s' if len(problems) != 1 else ''}", file=sys.stderr)
    report = compare_report(steppers, problems, rounds=args.rounds, max_rounds=max(args.rounds, 3 * args.rounds),
                            norm=args.norm)
    report.meta.update({"command": "compare", "target": " ".join(args.targets), "profile": None})
    # the report's "Reproduce" line: this command as given (compare has no --profile, and its targets and problems
    # are what it compares), which runs as printed from the same folder
    again = shlex.join(["verimono", *getattr(args, "argv", ["compare", *args.targets])])
    for rec in report.results:
        rec.details.setdefault("reproduce", again)
    return _finish(report, out, None, run_id)


def _cmd_baseline(args: argparse.Namespace) -> int:
    from .records.atomic import ensure_writable_file
    from .records.results import load

    ensure_writable_file(args.out)                # before any work
    if args.from_results:
        from .run.gate import check_completed

        from .core.errors import IncompatibleResults
        from .records.results import MISSING_RECORDS
        from .run.gate import check_baseline, check_passes_earned

        check_completed(args.from_results)        # the files of a run that never completed: exit 2
        report = load(args.from_results)
        if report.meta.get("incomplete"):
            raise NothingToResume(f"{args.from_results} is an interrupted run (marked incomplete): finish it "
                                  "with `verimono run --resume` before recording it as a baseline")
        missing = report.meta.get(MISSING_RECORDS) or {}
        if any(missing.get(k) for k in ("crashed", "hidden")):
            lost = list(missing.get("crashed") or []) + list(missing.get("hidden") or [])
            why = "a worker crashed while running" if missing.get("crashed") else "a runner kept the records of"
            raise IncompatibleResults(f"{args.from_results} is short: {why} {len(lost)} test(s) (e.g. {lost[0]}), "
                                      "whose records are missing; run the session again before recording a baseline")
        check_passes_earned(report, str(args.from_results))   # a pass that contradicts its figures: exit 2
        check_baseline(report, str(args.from_results))        # empty, uncalibrated or non-finite: exit 2
    else:
        from .execution.watchdog import on_hang

        with using_config(run_config(args)), on_hang(_baseline_hang):
            report = execute(command="run", profile_name=args.profile, stages=args.stage, context=_context(args),
                             progress=Progress(), **_executor_options(args))
    report.trajectories = []  # plot samples only: the gate never reads them, and they are half the size
    try:
        path = report.save(args.out)
    except OutputNotWritable as exc:
        if args.from_results:                     # its records are in the file it was copied from
            raise
        from .records.atomic import keep_elsewhere

        try:
            kept = f"the baseline's records are kept in {keep_elsewhere(report.to_json(), 'verimono-baseline.json')}"
        except OSError as again:
            kept = f"the baseline's records could not be kept elsewhere either ({again.strerror or again})"
        raise OutputNotWritable(f"{exc}; {kept}") from None
    print(f"verimono: baseline of {report.summary()} (profile {report.meta.get('profile')}) written to {path}")
    if not report.ok:
        print("verimono: warning: the baseline records failing checks; the gate will only catch new ones",
              file=sys.stderr)
    return EXIT_OK


def _baseline_hang(hang: Any) -> None:
    """``verimono baseline``: a call blocked in native code in this process ends it (nothing is written)."""
    from .run.execute import ISOLATE_ADVICE
    from .execution.watchdog import end_process, ending

    ending()
    print(f"\nverimono baseline: {hang.call} is blocked in native code ({hang.where or 'where unknown'}): still "
          f"running {hang.elapsed:.1f} s after it started, past its time budget of {hang.budget:g} s; no baseline "
          f"written; {ISOLATE_ADVICE}", file=sys.stderr)
    end_process(EXIT_FAILED)


def _cmd_gate(args: argparse.Namespace) -> int:
    from .run.gate import gate

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
    elif comparison.wall_unjudged_line():
        print(f"verimono gate: {comparison.wall_unjudged_line()}")
    print(f"verimono gate: {comparison.summary()} against {args.baseline}")
    return EXIT_OK if comparison.ok else EXIT_FAILED


def _cmd_report(args: argparse.Namespace) -> int:
    from .records.report.html import render
    from .records.results import load

    report = load(args.results)
    changes = _changes(load(args.baseline), report) if args.baseline else None
    from .records.atomic import ensure_writable_file, write_text

    out = ensure_writable_file(args.out)
    write_text(out, render(report, changes=changes))
    print(f"verimono: wrote {out}")
    return EXIT_OK


def _version() -> str:
    """The installed distribution's version (``importlib.metadata``: what pip installed, not a copy of it)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("verimono")
    except PackageNotFoundError:           # run from a source tree that was never installed
        from . import __version__

        return f"{__version__} (not installed)"


class _StageNames:
    """The registered stages' names for ``--stage``, read when a ``--stage`` is given or the help is printed:
    importing the stages imports the checks, the LCS tools and SciPy (0.5-0.8 s CPU here), which ``verimono
    gate``, ``baseline``, ``report`` and ``--version`` never use; ``check`` and ``run`` import them when the run
    begins.  ``str()``: the list the help prints (a stage run only on request says so)."""

    def _stages(self) -> dict[str, Any]:
        from .run.stages import STAGES

        return STAGES

    def __contains__(self, name: object) -> bool:
        return name in self._stages()

    def __iter__(self):
        return iter(list(self._stages()))

    def __len__(self) -> int:
        return len(self._stages())

    def __str__(self) -> str:
        return ", ".join(n if s.default else f"{n} (on request)" for n, s in self._stages().items())


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="verimono", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"verimono {_version()}",
                        help="print the installed version of verimono and exit")
    sub = parser.add_subparsers(dest="command", required=True)

    def run_options(p: argparse.ArgumentParser) -> None:
        p.add_argument("--profile", choices=PROFILES, default=None,
                       help="effort and hypothesis profile: the examples per law, the scale sweep and the time budget "
                            "of every unit (default: $HYPOTHESIS_PROFILE when it names one of these, else ci when "
                            "$CI is set, else dev)")
        stage = p.add_argument("--stage", action="append", choices=_StageNames(), metavar="NAME",
                               help="run only this stage (repeatable); stages: %(stage_names)s")
        stage.stage_names = stage.choices     # argparse formats a help with the action's attributes
        p.add_argument("--seed", type=_seed, default=None, help="seed for the randomized batteries")
        p.add_argument("--data", default=None, help="Siconos data (DIR/siconos/{refs,lcp}); default: the packaged data")
        p.add_argument("--reference", action="append", metavar="ID",
                       help="use only this analytic reference, by its id (tnorm-1, example-ramp, ...) or its display "
                            "name (repeatable; default: the whole catalog)")
        p.add_argument("--timeout", type=_seconds, default=None, metavar="S",
                       help="seconds per unit of work (one law on one operator, one check of one stepper) "
                            "before it is stopped while the run goes on: undecided when all it evaluated held, "
                            "failed when a call never returns or a sample was violated (default: the profile's; "
                            "inf: no limit)")
        p.add_argument("--executor", default=None, metavar="SPEC",
                       help="where the stages' independent units run: serial, auto (every core, at most 4 "
                            "worker processes; the default, $VERIMONO_EXECUTOR overrides), process:N (N "
                            "worker processes), or a dask.distributed scheduler address such as tcp://host:8786")
        p.add_argument("--unit-timeout", type=_seconds, default=None, metavar="SECONDS",
                       help="with --executor: a stage unit (a subject's battery) still running after this long "
                            "becomes a failed record (inf: no limit)")

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
    check.set_defaults(executor=os.environ.get("VERIMONO_EXECUTOR") or "auto")
    check.add_argument("--out", default="reports/check", help="output folder (default reports/check/)")
    check.add_argument("--baseline", default=None, help="show changes against this baseline")
    check.add_argument("--scheme", choices=SCHEMES, default=None,
                       help="what a stepper claims: 'proximal' (the paper's scheme: every law applies; the default "
                            "for a bare callable) or 'any' (it only converges with --order)")
    check.add_argument("--order", type=float, default=None,
                       help="the convergence order a --scheme any stepper claims (default 1)")
    check.add_argument("--problem", action="append", default=None, metavar="MODULE:OBJECT",
                       help="check a stepper on this Problem (or list of them) too, e.g. one from "
                            "verimono.manufactured_problem (repeatable; with --reference, both)")
    check.add_argument("--only", action="store_true",
                       help="run exactly the problems named with --problem (and --reference): not the reference "
                            "catalog, not the generated problems")
    check.add_argument("--solve-tol", type=float, default=None, metavar="TAU",
                       help="the accuracy of the stepper's inner solve per step (relative to 1 + |x|): errors at "
                            "what it accumulates pass as exact to it")
    check.add_argument("--grids", choices=("any", "uniform"), default=None,
                       help="the partitions a stepper runs on: 'uniform' judges every law on uniform partitions "
                            "only (t_n = n T/K), never failing or skipping it for the others (default 'any')")
    check.add_argument("--inexact", type=_inexact_arg, default=None, metavar="C:Q",
                       help="the stepper's resolvent is within eps(h) = C h^Q of the exact one: the laws allow it "
                            "and the expected order is min(p, Q - 1) (docs/checks.md)")
    check.add_argument("--step-range", type=_step_range, default=None, metavar="H_MIN:H_MAX",
                       help="run every convergence study on uniform grids with steps in [H_MIN, H_MAX] only (by "
                            "default each study chooses its grids for the claimed order: docs/convergence.md)")
    check.set_defaults(func=_cmd_check, stage=None)

    comp = sub.add_parser("compare", help="work-precision of several steppers on a problem, with the diagram")
    comp.add_argument("targets", nargs="+", metavar="MODULE:OBJECT", help="the steppers; the first is judged "
                      "against each other")
    comp.add_argument("--problem", action="append", default=None, metavar="MODULE:OBJECT",
                      help="a Problem with an exact solution (or a list of them); repeatable")
    comp.add_argument("--reference", action="append", metavar="ID", help="a reference of the catalog, by its "
                      "id (tnorm-1, ...) or its display name")
    comp.add_argument("--out", default="reports/compare", help="output folder (default reports/compare/)")
    comp.add_argument("--rounds", type=_rounds, default=9, help="timed rounds per run (default 9; up to 3x that when "
                      "the noise cannot decide)")
    comp.add_argument("--norm", choices=("sup", "l2", "final"), default="sup", help="the error compared")
    comp.set_defaults(func=_cmd_compare)

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


#: the commands that run the verification, whose first calibration :func:`main` starts before its imports
CALIBRATED_COMMANDS = ("run", "check", "baseline")
#: the commands whose report's plots are drawn by that copy (``baseline`` writes no report)
DRAWN_COMMANDS = ("run", "check")


#: the commands whose output folder is marked in progress before the parser (and the stages it lists) is built
MARKED_COMMANDS = {"run": "reports", "check": "reports/check"}


def _early_mark(command: str | None, given: list[str]) -> str | None:
    """Mark ``--out``/results.json in progress before anything else when a previous run's results are there
    (the command line's first imports and the parser: 0.4-1 s on a loaded machine, during which a killed run would
    leave those files unmarked, and the gate would read them as this run's); its run id, or ``None`` — not a
    marked command, ``--help``, ``--resume`` (the interrupted run's own results are marked incomplete: its
    mark is read first, then this run's written, :func:`_cmd_run`), no results there
    (:func:`_mark_if_stale`)."""
    if command not in MARKED_COMMANDS or {"-h", "--help"} & set(given):
        return None
    pre = argparse.ArgumentParser(add_help=False)
    pre.add_argument("--out", default=MARKED_COMMANDS[command])
    pre.add_argument("--resume", action="store_true")
    try:
        known, _ = pre.parse_known_args(given[given.index(command) + 1:])
    except SystemExit:           # malformed: the real parser says why
        return None
    if known.resume:
        return None
    return _mark_if_stale(known.out, command)


def _mark_if_stale(out: str | os.PathLike, command: str) -> str | None:
    """Mark ``out``/results.json in progress now, and return the run id, when a results file is there — the
    files a killed run would leave for the gate to take as its own; ``None`` when there is none (nothing
    stale: the mark is written after the options and the target are checked, so that bad usage creates
    nothing) or the folder cannot be written (the command fails on it with its usual message)."""
    from .records.atomic import ensure_writable_dir

    if not (Path(out) / "results.json").exists():
        return None
    try:
        return _start(ensure_writable_dir(out), command)
    except VerimonoError:
        return None


def main(argv: list[str] | None = None) -> int:
    """The command line: the exit status of the command ``argv`` (default ``sys.argv[1:]``).  Its console is
    guarded (:mod:`verimono.run.console`): a broken pipe or a closed stream ends printing, never the run."""
    from .run.console import guarded

    with guarded():
        try:
            return _main(argv)
        except KeyboardInterrupt as exc:
            # an interrupt outside the run's own handler (reading the options, importing the target, building
            # the references, writing the report): one line, never a traceback; a folder marked in progress
            # stays marked (the gate refuses what is there), and the previous results are untouched
            print(f"\nverimono: interrupted ({interrupt_name(exc)}) before the run finished; no results of "
                  "this run were written", file=sys.stderr)
            return EXIT_INTERRUPTED


def interrupt_name(exc: BaseException) -> str:
    """What interrupted: ``Ctrl-C`` or the signal raised as a :class:`KeyboardInterrupt` (``SIGTERM``, ...)."""
    return str(exc.args[0]) if exc.args and str(exc.args[0]).startswith("SIG") else "Ctrl-C"


def terminating_signals() -> list[Any]:
    """The signals that end a command as Ctrl-C does: SIGTERM and, where it exists, SIGHUP (a closed terminal)."""
    import signal

    return [getattr(signal, n) for n in ("SIGTERM", "SIGHUP") if hasattr(signal, n)]


def _as_interrupt(signum: int, frame: Any) -> None:
    import signal

    raise KeyboardInterrupt(signal.Signals(signum).name)


def _main(argv: list[str] | None) -> int:
    from threadpoolctl import threadpool_limits

    from .execution.calibration import PendingCalibration
    from .execution.executors import BLAS_THREADS
    from .records.report import drawer

    given = list(sys.argv[1:] if argv is None else argv)
    command = next((a for a in given if not a.startswith("-")), None)
    if command is not None and not {"-h", "--help", "--version"} & set(given):
        try:
            os.getcwd()
        except OSError as exc:       # deleted under the shell: relative paths (--out, a target file) mean nothing
            print(f"verimono {command}: the current working directory no longer exists ({exc.strerror or exc}); "
                  "cd to an existing folder and run the command again", file=sys.stderr)
            return EXIT_UNDECIDED
    with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
        # the run's first calibration is measured on the other core while this process imports the checks
        # and reads its target (about 0.4 s; the measurement takes 0.2 s): it is not waited for; the copy
        # that measures it then imports matplotlib and draws the report's plots as the stages deliver them
        # (report.drawer), so that this process only runs the stages
        pending = None
        if command in CALIBRATED_COMMANDS and not {"-h", "--help"} & set(given):
            serve_it, connect = drawer.drawer_pipe() if command in DRAWN_COMMANDS else (None, None)
            pending = PendingCalibration(then=serve_it)
            if connect is not None:
                connect(pending.forked)
        try:
            run_id = _early_mark(command, given)
            args = build_parser().parse_args(argv)
            if hasattr(args, "profile"):
                resolve_profile(args)
            args.argv = given                          # the command as given (advice after an interrupt)
            args.calibration = pending
            if run_id is not None:
                args.run_id = run_id
            func: Callable[[argparse.Namespace], int] = args.func
            try:
                return func(args)
            except VerimonoError as exc:
                print(f"verimono {args.command}: {exc}", file=sys.stderr)
                return EXIT_UNDECIDED
            except SUBJECT_EXITS as exc:
                # a sys.exit() from code the command ran outside any check (every check records its own): never
                # the command's status — no verdict was reached, and the files (if any) stay marked in progress
                print(f"verimono {args.command}: ended by {type(exc).__name__}({getattr(exc, 'code', '')!r}) raised "
                      "outside any check; no verdict", file=sys.stderr)
                return EXIT_UNDECIDED
        finally:
            drawer.disconnect()                        # the drawer ends, then its process is reaped
            if pending is not None:
                pending.close()


def console_main() -> int:
    """The ``verimono`` command: :func:`main`, and an exit that does not collect the garbage of every module.

    Before the interpreter ends, every object left is moved to the collector's permanent generation
    (``gc.freeze``): the exit's collections then skip NumPy's, SciPy's and the run's objects, 80 ms of a
    2-second ``verimono check`` here, 20 ms after.  The exit is otherwise the usual one (atexit handlers,
    modules cleared, files flushed and closed); :func:`main` itself, called in-process, frees nothing less."""
    import gc
    import signal

    # the command's own handlers (replacing those of its first imports, verimono.core._early_signals): Ctrl-C,
    # SIGTERM and SIGHUP are one KeyboardInterrupt, answered by the run (its finished stages, marked
    # incomplete) or by main (one line): exit 130, never a traceback
    signal.signal(signal.SIGINT, signal.default_int_handler)
    for sig in terminating_signals():
        signal.signal(sig, _as_interrupt)
    try:
        status = main()
    except KeyboardInterrupt:       # between main's end and here
        status = EXIT_INTERRUPTED
    gc.freeze()
    return status


if __name__ == "__main__":
    sys.exit(console_main())
