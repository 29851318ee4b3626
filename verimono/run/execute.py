"""Running the verification: the stages of a run under a profile and an executor, interrupts, resuming.

:func:`execute` runs stages with a context and returns the merged, annotated report (the run's facts in
``report.meta``: command, profile, seed, selection, executor, calibration, duration, environment);
:func:`interruptible` turns an interrupt (Ctrl-C, SIGTERM) — or a call of the subject blocked in native code
past its time budget, which no interrupt can stop (:mod:`verimono.execution.watchdog`) — into a results file of the
finished stages marked incomplete; :func:`merge_resumed` completes such a run.  The command line
(:mod:`verimono.cli`) is a thin layer over these.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any, Callable

from ..execution import watchdog
from ..records.atomic import partial_path, write_text
from ..records.environment import environment
from ..execution.executors import BLAS_THREADS, ProcessRunner, make_runner
from ..execution.config import RunConfig
from ..execution.config import using as using_config
from ..execution.profiles import get_profile, load_hypothesis_profile
from ..execution.timeouts import budget_source
from .progress import Progress
from ..records.report import write
from ..records.report.plots import PLOTS_THREAD, WARM_UP_THREAD, draw_ahead, drawing_elsewhere, warm_up
from ..records import schema
from ..records.results import STATUSES, Report, to_jsonable
from ..execution.calibration import PendingCalibration, calibrate_times, cpu_seconds, set_calibration
from ..execution.timing import MachineProbe, is_noise_undecided

EXIT_OK, EXIT_FAILED, EXIT_UNDECIDED = 0, 1, 2


def execute(*, command: str, profile_name: str, stages: list[str] | None, context: Any, target: str | None = None,
            progress: Progress | None = None, executor: Any = None, unit_timeout: float | None = None,
            on_done: Callable | None = None, calibration: PendingCalibration | None = None,
            config: RunConfig | None = None) -> Report:
    """Run ``stages`` with ``context`` under a profile and return the merged, fully annotated report.

    ``executor`` (``"process:N"``, a dask scheduler address or ``Client``; ``None``: serial) is where the
    stages' independent units run (:mod:`verimono.execution.executors`); ``unit_timeout`` bounds each unit there.
    ``on_done(stage, report, info)`` is called after each stage (the interrupt handler keeps them).
    ``calibration``: the run's first calibration, started earlier (the command line starts it before its
    imports); measured here, before any worker starts, when not given.  ``config``: the run configuration
    the entry point chose (:mod:`verimono.execution.config`; default: the current one), which ``profile_name``,
    the context's seed and ``executor`` complete; everything the stages run — the search, the budgets, the
    workers — reads it, and ``report.meta["config"]`` records it with the unit budget it gave."""

    from threadpoolctl import threadpool_limits

    from .stages import prepare_stages, run_stages   # the checks and what they need (scipy): once a run begins

    profile = get_profile(profile_name)
    load_hypothesis_profile(profile_name)
    progress = progress or Progress(enabled=False)
    context.progress = progress.within
    runner = make_runner(executor, timeout=unit_timeout)
    if executor is not None and context.executor is None:
        print(f"verimono: units run on {runner.spec}", file=sys.stderr)
    context.executor = context.executor if context.executor is not None else runner
    if hasattr(runner, "prestart"):   # what forked workers then inherit instead of importing (the generated
        # problems, drawn through hypothesis: no time budget read), drawn while the command line's first
        # calibration may still be measured in its copy on the other core (0.4 s waited for here at load 5)
        prepare_stages(stages, profile, context)
    cal, cal_cpus = calibration.times() if calibration is not None else calibrate_times()  # before any worker
    set_calibration(cal)              # the unit of this process's time budgets (verimono.execution.timeouts)
    if hasattr(runner, "prestart"):   # the workers import while this process builds the catalog
        runner.prestart()
    waits_on_workers = getattr(runner, "workers", 1) >= 2
    own_threads: list = []            # this call's threads in this process: the warm-up, the plots drawn ahead
    if waits_on_workers and drawing_elsewhere() and hasattr(runner, "on_report"):
        # each unit's plots go to the drawer as the unit comes back (not when its whole stage has)
        runner.on_report = lambda rep: draw_ahead(rep.studies, rep.trajectories) if rep.studies or rep.trajectories else None
    elif waits_on_workers and not drawing_elsewhere():   # this process waits on the workers and draws the
        import threading                                 # plots itself: matplotlib's import and font cache now

        # not a daemon: a script whose ``execute`` ends within the import (a short run) exited with the thread in
        # matplotlib's C extensions, finalized under it (the abort a daemon thread in a C++ extension risks at
        # exit, "terminate called ..."; tests/run/test_api_interrupt.py); its exit now waits for the import's end
        own_threads.append(threading.Thread(target=warm_up, name=WARM_UP_THREAD, daemon=False))
        own_threads[-1].start()
    start = time.perf_counter()
    probe = MachineProbe()

    def done(stage, rep, info):
        info.update(probe.lap())      # how busy the machine was during the stage: the gate's evidence
        # the report's plots, while the workers run on; or, with a drawer process (the command line's), on its
        # core while this process runs the next stages itself (a serial run drew them all at the end: 0.6 s of
        # the README stepper's check on a 2-core machine)
        if (waits_on_workers or drawing_elsewhere()) and (rep.studies or rep.trajectories):
            thread = draw_ahead(rep.studies, rep.trajectories)
            if thread is not None:
                own_threads.append(thread)
        if on_done is not None:       # saved (the checkpoint) before the console says the stage finished
            on_done(stage, rep, info)
        progress.done(stage, rep, info)

    try:
        # BLAS_THREADS for the BLAS libraries the checks loaded too (SciPy's OpenBLAS is not NumPy's): the command
        # line limited those loaded when it began, and SciPy's two threads spun 0.5 s of a core in a serial run
        with threadpool_limits(limits=BLAS_THREADS, user_api="blas"), \
                using_config(config, profile=profile_name, seed=context.seed, executor=executor) as cfg:
            unit_budget = budget_source()
            report = run_stages(stages, profile, context, on_start=progress.start, on_done=done)
    except BaseException:
        # interrupted (or failed): the workers are killed, not asked to finish their units — a worker busy with
        # one answered the polite request only at that unit's end, and ``close`` waited up to 5 s for each
        # (:meth:`ProcessRunner._stop`) before the user's script got its KeyboardInterrupt
        _close(runner, kill=True)
        # and this call's own threads end before the interrupt reaches the script: one still running when it
        # reaches the top made the script exit with status 1, not Ctrl-C's 130 (-SIGINT), in about half the tries —
        # CPython (3.11) notes an unhandled KeyboardInterrupt in a flag every eval()/exec() of a string resets,
        # and the exit waits for non-daemon threads, whose plotting (matplotlib's imports: dataclasses,
        # namedtuples) evals strings (tests/run/test_api_interrupt.py)
        _join_through_interrupts(own_threads)
        raise
    else:
        runner.close()
    duration = time.perf_counter() - start
    # once more at the end, when a record of the run is timed (:func:`has_timed_records`): one calibration
    # (best of 3 x 0.1 s) samples one moment of a shared machine and read 0.08-0.16 s here within an hour; noise
    # only slows a workload down, so the faster of the two ends is the steadier unit, in the baseline and in the
    # run gated against it alike (and the two ends' drift tells the gate whether the machine was quiet enough
    # to judge stage times at all: a first repeat that agrees with the start's is enough to say it was).  A run
    # with no timed record (`verimono check`'s stages) keeps its start's alone: its stages' CPU verdicts read
    # the slices beside each unit, not it, and the gate lists its stages' wall growth as not judged
    # (``gate._stage_unjudged``: one calibration, no drift known) — 0.07-0.2 s of the command saved
    cals, cal_cpus_list = [cal], [cpu_seconds(cal_cpus)]
    if has_timed_records(report):
        end, end_cpus = calibrate_times(agreeing_with=cal)
        cals, cal_cpus_list = [cal, end], [cpu_seconds(cal_cpus), cpu_seconds(end_cpus)]
    selection = {"stages": stages, "references": None if context.problems is None else
                 [p.name for p in context.problems]}
    if getattr(context, "extra_problems", None):
        selection["problems"] = [p.name for p in context.extra_problems]
    report.meta.update({"command": command, "target": target, "profile": profile_name, "seed": context.seed,
                        "selection": selection, "executor": getattr(runner, "spec", type(runner).__name__),
                        "calibrations": cals,
                        "calibration": min(cals), "duration": duration,
                        "config": {**cfg.to_dict(), "unit_budget": unit_budget},
                        "calibrations_cpu": cal_cpus_list,
                        "data_dir": None if context.data_dir is None else str(context.data_dir),
                        "environment": environment()})
    return report


def _join_through_interrupts(threads: list) -> None:
    """Join ``threads`` — and every report thread of this process (:data:`WARM_UP_THREAD`, :data:`PLOTS_THREAD`: one
    whose start the interrupt broke was never handed back) — however often Ctrl-C is pressed meanwhile (the
    interrupt already on its way is the user's)."""
    import threading

    threads = list(threads) + [t for t in threading.enumerate() if t.name in (WARM_UP_THREAD, PLOTS_THREAD)
                               and t not in threads and t is not threading.current_thread()]
    for t in threads:
        for _ in range(1000):
            try:
                t.join()
                break
            except KeyboardInterrupt:
                continue
            except RuntimeError:      # started a moment ago, not yet running: join() refuses it for now
                time.sleep(0.01)


def _close(runner: Any, kill: bool) -> None:
    """``runner.close(kill=kill)`` where the runner takes ``kill`` (:class:`ProcessRunner`), else ``close()``."""
    if isinstance(runner, ProcessRunner):
        runner.close(kill=kill)
    else:
        runner.close()


def has_timed_records(report: Report) -> bool:
    """Whether a record of ``report`` is timed: a same-job timing ratio (``details["timing_ratio"]``, the
    performance stage's), which the gate judges against the baseline's — the run's end calibration is measured
    only then (:func:`execute`)."""
    return any(isinstance(r.details, dict) and "timing_ratio" in r.details for r in report.results)


def exit_status(report: Report) -> int:
    """1 when a check failed; else 2 when one was undecided (nothing failed, but not everything was
    verified: a limitation of the harness is never a pass); else 0.  A timing record undecided because the
    machine was too noisy to judge a speed (:func:`verimono.execution.timing.is_noise_undecided`) does not count: the
    machine's load is not the code's defect, and the summary line says that speed was not judged."""
    if report.failures:
        return EXIT_FAILED
    if any(not is_noise_undecided(r) for r in report.undecided) or report.meta.get("incomplete"):
        return EXIT_UNDECIDED
    return EXIT_OK


#: exit status of an interrupted run (the shell's convention for SIGINT)
EXIT_INTERRUPTED = 130
#: ``details`` key of a record of a stage that did not finish (written with a native hang; a resumed run
#: runs that stage again, so :func:`merge_resumed` drops them)
UNFINISHED_STAGE = "unfinished_stage"
#: what isolates a subject that blocks in native code (printed when a serial run has to end on one)
ISOLATE_ADVICE = ("`--executor process:N` runs each unit in a worker process, so that such a call ends its worker "
                  "only (a failed record) and the run goes on")


def interruptible(run: Callable[[Callable], Report], out: Path, *, command: str, profile: str,
                   stages: list[str] | None, previous: Report | None = None, run_id: str | None = None,
                   advice: str | None = None, checkpoint: bool = False) -> Report | int:
    """``run(on_done)`` with SIGTERM and SIGHUP treated as an interrupt; on an interrupt write the stages finished so
    far (with ``previous``'s, when resuming) to ``out`` marked ``incomplete`` (as the run ``run_id``) and
    return the exit status.  ``advice``: how to go on, printed after the interrupt (default: ``verimono
    run --resume``, which only ``run`` has).

    A call of the subject blocked in native code in this process (the serial executor), which no interrupt
    reaches, ends the process from :mod:`verimono.execution.watchdog`'s thread once its budget and grace are over:
    the same file, plus the records the current stage finished (``details["unfinished_stage"]``) and a
    failed record naming the hung call, one line naming the call, its time, the file and
    :data:`ISOLATE_ADVICE`, and exit status 1 (:data:`EXIT_FAILED`: a call that does not return is a failure
    of the subject).  Only here — a command of verimono's — is the process ended on a native hang; the Python
    API leaves the user's interpreter running (:mod:`verimono.execution.watchdog`)."""
    import signal

    finished: list[tuple[Report, dict]] = []
    stage_scope: list = []
    saved = _Checkpoint(previous)

    def on_done(stage, rep, info):
        finished.append((rep, info))
        if stage_scope and stage_scope[0] is not None:
            stage_scope[0].items.clear()        # the scope keeps only the current stage's finished units
        if checkpoint:
            saved.add(rep)
            save_checkpoint()

    def save_checkpoint() -> None:
        """The stages finished so far, on disk as each finishes (``results.json.partial``, marked incomplete,
        with this run's id; the in-progress mark stays): a run killed with SIGKILL, which no handler sees,
        leaves them for ``--resume`` — beside the previous results and report, which stay as they were until
        this run's own pair replaces them (:func:`verimono.records.atomic.partial_path`).  A checkpoint that
        cannot be written costs the run nothing but that.  Each stage's records are made JSON values once, as it
        ends (:class:`_Checkpoint`), not again at every later checkpoint."""
        partial, _ = partial_report()
        partial.meta["run_id"] = run_id
        where = partial_path(out / "results.json")
        try:
            write_text(where, saved.text(partial.meta))
        except OSError as exc:  # OutputNotWritable too: the final write says it again, with what it keeps
            print(f"verimono: could not save the finished stages to {where} "
                  f"({getattr(exc, 'strerror', None) or exc}); the run goes on", file=sys.stderr)

    def partial_report() -> tuple[Report, list[str]]:
        partial = Report(meta=dict(previous.meta) if previous is not None else {})
        partial.meta["stages"] = list(previous.meta.get("stages") or []) if previous is not None else []
        if previous is not None:
            partial.extend(previous)
        for rep, info in finished:
            partial.extend(rep)
            partial.meta["stages"].append(info)
        done = [s["name"] for s in partial.meta.get("stages") or []]
        partial.meta.update({"command": command, "profile": profile, "incomplete": True,
                             "finished_stages": done,
                             "selection": partial.meta.get("selection") or {"stages": stages, "references": None}})
        if previous is not None and previous.meta.get("run_id"):
            partial.meta["resumed_from"] = previous.meta["run_id"]
        return partial, done

    def on_hang(hang: watchdog.Hang) -> None:
        watchdog.ending()
        try:
            partial, done = partial_report()
            current = watchdog.hang_report(hang)
            for rec in current.results:
                rec.details[UNFINISHED_STAGE] = True
            partial.results.extend(current.results)      # their studies stay in each record's details
            partial.meta["native_hang"] = {"call": hang.call, "budget": hang.budget, "elapsed": hang.elapsed,
                                           "where": hang.where, "grace": watchdog.grace(hang.budget)}
            try:
                where = str(write(partial, out, run_id=run_id)["json"])
            except Exception as exc:  # noqa: BLE001 - the process ends either way; say what was lost
                where = f"no file ({type(exc).__name__}: {exc})"
            print(f"\nverimono: {hang.call} is blocked in native code ({hang.where or 'where unknown'}): still "
                  f"running {hang.elapsed:.1f} s after it started, past its time budget of {hang.budget:g} s; "
                  f"ended the run. The {len(done)} finished stage(s) ({', '.join(done) or 'none'}), the "
                  f"{len(current) - 1} record(s) the current stage finished and a failed record for the hung call "
                  f"are in {where}, marked incomplete; {ISOLATE_ADVICE}", file=sys.stderr)
        finally:
            watchdog.end_process(EXIT_FAILED)

    def term(signum, frame):
        raise KeyboardInterrupt(signal.Signals(signum).name)

    # SIGTERM and SIGHUP (a terminal closed, an SSH session dropped) as Ctrl-C
    held = [getattr(signal, n) for n in ("SIGTERM", "SIGHUP") if hasattr(signal, n)] if _main_thread() else []
    old = {sig: signal.signal(sig, term) for sig in held}
    try:
        with watchdog.scope() as root, watchdog.on_hang(on_hang):
            stage_scope.append(root)
            return run(on_done)
    except KeyboardInterrupt:
        partial, done = partial_report()
        paths = write(partial, out, run_id=run_id)
        print(f"\nverimono: interrupted; the {len(done)} finished stage(s) ({', '.join(done) or 'none'}) are in "
              f"{paths['json']}, marked incomplete; "
              f"{advice or f'continue with `verimono {command} --resume`'}", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)


class _Checkpoint:
    """The JSON text of a run's finished stages (``results.json.partial``), made as they end: each stage's records,
    studies and trajectories are written as JSON text once, when the stage is added, and each checkpoint joins
    those pieces under the partial report's header and meta — the document :meth:`Report.to_json` of the whole
    partial report writes (:func:`verimono.records.schema.document`, its keys in the same order), compact.

    Made again from all the finished stages at each of the seven checkpoints of a ci run, the partial report cost
    0.85-1.0 s of the parent between stages (two runs, calibration 0.064 s), while both workers waited for the
    next stage's units."""

    LISTS = ("results", "studies", "trajectories")

    def __init__(self, previous: Report | None) -> None:
        self.pieces: dict[str, list[str]] = {k: [] for k in self.LISTS}
        self.counts: dict[str, int] = {}
        self.environment: dict | None = None
        if previous is not None:
            self.add(previous)

    def add(self, rep: Report) -> None:
        for key, values in (("results", [r.to_dict() for r in rep.results]),
                            ("studies", to_jsonable(rep.studies)), ("trajectories", to_jsonable(rep.trajectories))):
            if values:
                self.pieces[key].append(json.dumps(values, allow_nan=False)[1:-1])   # the items, no brackets
        for r in rep.results:
            self.counts[r.status] = self.counts.get(r.status, 0) + 1

    def text(self, meta: dict) -> str:
        if self.environment is not None:
            meta.setdefault("environment", self.environment)
        doc = schema.document(meta, {s: self.counts.get(s, 0) for s in STATUSES}, [], [], [], converted=True)
        self.environment = meta["environment"]
        return "{" + ", ".join(
            f"{json.dumps(k)}: " + ("[" + ", ".join(self.pieces[k]) + "]" if k in self.pieces
                                    else json.dumps(v, allow_nan=False))
            for k, v in doc.items()) + "}"


def _main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def merge_resumed(previous: Report, rest: Report) -> Report:
    """The interrupted run's finished stages followed by the resumed ones: one complete report
    (``meta.resumed_from``: the run id of the interrupted run it continues)."""
    merged = Report(meta=dict(rest.meta))
    finished = Report([r for r in previous.results if not r.details.get(UNFINISHED_STAGE)],
                      studies=previous.studies, trajectories=previous.trajectories)
    merged.extend(finished)
    merged.extend(rest)
    merged.meta["stages"] = list(previous.meta.get("stages") or []) + list(rest.meta.get("stages") or [])
    merged.meta["selection"] = previous.meta.get("selection")
    merged.meta["resumed"] = True
    merged.meta["resumed_from"] = previous.meta.get("run_id")
    for key in ("incomplete", "finished_stages", "native_hang"):
        merged.meta.pop(key, None)
    return merged


__all__ = ["execute", "exit_status", "interruptible", "merge_resumed", "EXIT_OK", "EXIT_FAILED", "EXIT_UNDECIDED",
           "EXIT_INTERRUPTED", "UNFINISHED_STAGE", "ISOLATE_ADVICE"]
