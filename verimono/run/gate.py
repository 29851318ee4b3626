"""Regression gating: compare a run's records with a committed baseline.

``compare(baseline, current)`` lists every :class:`Change`; those with ``regression=True`` make
``verimono gate`` exit 1.  A regression is

* **status** — a record that passed (or was an expected failure) now fails, or a record that passed is
  now skipped (a battery that stopped running verifies nothing), or a record that passed is now ``xfail``
  without a declaration (``details["xfail_declared"]``, set for the xfails of ``expected_failed_checks``
  and of Theorem ``thm:main``'s (LG)-or-(YB) alternative; a declared one is a change, not a regression);
* **removed** — a record of the baseline is absent now;
* **count** — the number of executed (non-skipped) records of a check, or in total, shrinks;
* **order** — a convergence order estimate falls below its theoretical order (interval's upper end plus
  ``ORDER_SLACK`` below the expected order) where the baseline's study was not below it (one that was is a
  change: a baseline recording failing checks lets the gate catch only new ones, as ``verimono baseline``
  warns), below the baseline's estimate by more than the wider of the
  two intervals' half-widths and ``ORDER_DROP_FLOOR``, or a study exact at the nodes no longer is;
* **error** — an error against a reference (each grid of a convergence study; a record's
  ``details["error"]``, e.g. Siconos agreement) grows by more than ``ERROR_GROWTH``;
* **non-finite** — an error or order estimate is now ``nan``, ``inf`` or ``null`` where the baseline's
  was finite (reported as an error / order regression: NaN compares false against every threshold);
* **non-finite figure** — a record that passes with a ``worst``, ``bound`` or ``details["error"]`` that is
  ``nan`` or ``inf`` (a NaN ratio satisfies no bound: such a pass was never earned);
* **undecided** — a record that passed and is now ``undecided`` (it verifies nothing);
* **study** — a convergence study of the baseline that is absent now while its record remains (the
  record's order claim is no longer backed by any errors);
* **incomplete** — results marked ``meta.incomplete`` (an interrupted run) are refused: exit status 2;
* **timing** — a slowdown of 2x or more that the measurement supports (see *Timing* below), busy machine or
  not; stage times are compared only between runs on the same executor (``meta.executor``: serial,
  process:N, ...).

*Timing.*  Load on a shared machine inflates wall time without bound and unevenly, so stage times are judged
by **CPU time** (:mod:`verimono.run.stages.registry`: each unit's CPU time in the process that ran it, with the
children it reaped, and the part spent in the subject's calls, :class:`verimono.execution.timing.TimedStepper`,
which ``verimono check`` wraps its stepper in).  A wait for a CPU is no CPU time; what load does to code as it
runs (caches refilled after every switch, memory bandwidth: 1.5-2.6x here beside other test runs) inflates it,
and is measured in the same run, beside the work: after each unit, in the same process, slices of the
calibration workload (:func:`verimono.execution.calibration.slices_after`, ``stages[i]["calibration_cpu"]``).
So:

* a stage's CPU time (``"cpu"``) and the subject's part of it (``"subject_cpu"``), in units of the **mean** of
  the stage's calibration samples (:func:`calibration_mean`: the samples fall in two groups on a loaded
  machine, contended and not, and the mean follows their share as the stage's CPU time does), regress when
  they grew by more than ``TIMING_GROWTH`` and the **least** growth the two runs' intervals allow (Student's,
  one-sided ``TIMING_ALPHA`` each) is still above it — whether the machine was busy or not.  Where the
  samples' spread cannot tell, the growth is listed as a change, "not judged", with the figures;
* the subject over the whole run too: its CPU time in all stages over all their samples (more samples, a
  narrower interval than any one stage's): ``"<target> in all stages"``;
* figures below ``TIMING_MIN_UNITS`` calibrations or ``TIMING_MIN_CPU`` seconds are start-up noise, not judged;
* a stage's **wall** time in calibration units (the run's ``meta.calibrations``, taken at its slower one,
  the baseline's at its faster) regresses when it grew beyond ``TIMING_GROWTH`` on a quiet machine only:
  with its CPU time unchanged that is time spent off the CPU (sleeping, waiting), which CPU time does not
  see.  On a busy machine — some task waited for a CPU more than ``BUSY_WAITING`` of the stage's time
  (Linux PSI) and processes outside the run used more than ``BUSY_FOREIGN`` of the machine's CPU — or
  between calibrations that drift by more than ``CALIBRATION_DRIFT``, or where a run measured one calibration
  (a run with no timed record — ``verimono check`` — measures none at its end), such growth is listed as not
  judged.  Stages that ran at once (``"overlapped"``: their units in one queue, :mod:`verimono.execution.schedule`)
  have no wall time of their own: they are judged together, by the wall time of their group
  (``"group_duration"``; a baseline run one stage after another: the sum of the same stages' walls), and the
  busy signs of the busiest of them;
* a record's same-job ratio (``details["timing_ratio"]``, larger is worse) regresses when it grew by more than
  ``TIMING_GROWTH`` *with confidence*: the lower end of its interval (``details["timing_interval"]``, the
  order-statistics bound of the median per-round ratio, :mod:`verimono.execution.timing`) exceeds ``TIMING_GROWTH``
  times the baseline's ratio (a record without an interval compares its ratio itself); one that passed and
  is now ``undecided`` because timing noise kept its speed from being judged
  (``details["undecided_reason"] == "timing noise"``) is a change, not a regression.

Measured with ``tools/gate_speed_trial.py`` (a stepper doing its work three times against the same stepper,
5 runs each, ``verimono check`` on ``process:2``): beside other helpers' runs (load average 9-10 on 2
cores) and under ``stress -n 2`` with them, every 3x-slower run regressed "in all stages" (least growth
2.11-2.39x) and no unchanged run did.  A baseline with stage times but no calibration or no CPU figures
(:func:`baseline_uncalibrated`) is refused — exit 2 — never gated with its timing check turned off.

Baseline and results must come from the same kind of run (command, target, profile and the selected
stages and references), be well-formed documents of a readable schema version
(:mod:`verimono.records.schema` type-checks every field the gate reads), and the baseline must hold at
least one executed record; otherwise :class:`IncompatibleBaseline` / ``SchemaError`` — the gate fails
closed with exit status 2.  It fails closed too (the inputs cannot fool it) when

* a document repeats a record key ``check[subject]`` (either copy could be "the" record: a failure
  would hide behind a pass) — ``SchemaError`` naming the key;
* a figure the baseline vouches for is not a finite number — a study's error in a gated norm, and, of a
  record that passed, its ``worst``, ``bound``, ``details["error"]`` or ``details["timing_ratio"]`` (or
  a pass it claimed with a non-finite worst ratio, ``details["unearned_pass"]``): NaN compares false
  against every threshold, so such a baseline would let any result pass — :class:`IncompatibleBaseline`;
* a record *passed* with its worst ratio above its bound (:func:`check_passes_earned`: no check of verimono's
  writes one; a pass that contradicts its own figures cannot be trusted) — ``SchemaError``;
* the baseline has stage times but no calibration to judge them by (:func:`baseline_uncalibrated`) —
  :class:`IncompatibleBaseline`;
* the results (or baseline) file carries the in-progress mark of a run that never completed
  (:func:`verimono.records.atomic.in_progress`: killed, or stopped by an error, after older files were there) —
  :class:`IncompatibleResults`.
"""

from __future__ import annotations

import dataclasses
import math
import statistics
from collections import Counter
from pathlib import Path
from typing import Any

from ..records.atomic import in_progress
from ..core.convergence import ORDER_SLACK
from ..core.errors import IncompatibleBaseline, IncompatibleResults, SchemaError
from ..records.results import FAILED, PASSED, SKIPPED, UNDECIDED, UNEARNED_PASS, XFAIL, XFAIL_DECLARED, Report, load
from ..execution.timing import BUSY_FOREIGN, BUSY_WAITING, is_noise_undecided

#: smallest drop of a fitted slope that counts as a regression when both intervals are narrower: slopes
#: are refitted on the same grids, so they reproduce to round-off on one machine and to ~1e-3 across
#: platforms, while a lost order drops the slope by 0.5 or more
ORDER_DROP_FLOOR = 0.05
#: allowed growth of an error against a reference on the same grid: errors are deterministic, so only
#: round-off (near the floor) or a QP tolerance change moves them, by far less than 1.5x; a stepper
#: bug that keeps the order (wrong time of evaluation, dropped input) changes the constant by more
ERROR_GROWTH = 1.5
#: errors below this absolute size are round-off in every study and are not compared
ERROR_IGNORE_BELOW = 1e-11
#: allowed growth of a duration relative to the calibration workload of the same job: on a shared
#: 2-core runner these ratios vary by up to ~40% between runs (measured); 2x flags real slowdowns such
#: as a lost vectorisation or a per-step re-validation, which cost 3x and more
TIMING_GROWTH = 2.0
#: stages shorter than this (seconds, in both runs) are not timed by their wall time: start-up noise dominates
TIMING_MIN_SECONDS = 0.5
#: CPU figures below this many calibrations (in either run) are not judged: about 0.13 s of CPU idle
TIMING_MIN_UNITS = 2.0
#: ... nor below this many CPU seconds (a busy machine's inflated calibration cannot make tiny work count)
TIMING_MIN_CPU = 0.1
#: one-sided level of the interval of the mean of a stage's calibration samples (each run's): the least growth
#: a regression needs is bounded with both runs' intervals, so a wrong verdict needs both to miss
TIMING_ALPHA = 0.025
#: the largest ratio between a run's two calibrations (start, end) for which its stage times are judged:
#: best-of-3 calibrations agree within ~10% on a quiet machine (0.057/0.057 s here), while load that comes or
#: goes during a run moves one end by 1.4x and more
CALIBRATION_DRIFT = 1.25
#: the norms whose order estimates are gated against the baseline (the final-time error of several
#: references sits at round-off on some grids, so its slope is not a stable statistic)
GATED_NORMS = ("sup", "l2")
#: how many regressions ``verimono run`` and ``verimono check`` list before pointing to ``verimono gate``
LISTED_REGRESSIONS = 10
#: run facts that must agree between a baseline and the results it gates (``selection``: the stages and
#: references chosen with --stage / --reference; a battery that is selected but skipped still regresses)
COMPATIBLE_KEYS = ("command", "target", "profile", "selection")


@dataclasses.dataclass
class Change:
    """One difference between baseline and results; ``regression`` ones fail the gate."""

    kind: str
    key: str
    message: str
    regression: bool

    def __str__(self) -> str:
        tag = "REGRESSION" if self.regression else "change"
        return f"{tag:10s} {self.kind:8s} {self.key}: {self.message}"


@dataclasses.dataclass
class Comparison:
    """All changes between a baseline and a run, with what was compared."""

    changes: list[Change]
    compared: int
    baseline_meta: dict[str, Any]

    @property
    def regressions(self) -> list[Change]:
        return [c for c in self.changes if c.regression]

    @property
    def others(self) -> list[Change]:
        return [c for c in self.changes if not c.regression]

    @property
    def ok(self) -> bool:
        return not self.regressions

    def summary(self) -> str:
        n = len(self.regressions)
        head = (f"{n} regression{'s' if n != 1 else ''}" if n else "no regressions") + \
            f" ({self.compared} baseline records compared, {len(self.others)} other changes)"
        return head

    def wall_unjudged_line(self) -> str | None:
        """One line for the stages whose wall time grew beyond ``TIMING_GROWTH`` while the gate could not judge
        it (:func:`_compare_wall`: one calibration — a `verimono check` — a busy machine, drifting calibrations):
        no regression, but a subject that sleeps or waits shows nowhere else, so the commands print this in
        their normal output (the full changes stay under ``verimono gate -v``); ``None`` when there is none."""
        hits = [(c, c.wall_unjudged) for c in self.others if getattr(c, "wall_unjudged", None)]
        if not hits:
            return None
        grown = ", ".join(f"{c.key} up to {growth:.1f}x" for c, (growth, _) in hits)
        whys = "; ".join(_one_reason_each(why for _, (_, why) in hits))
        return (f"wall time grew beyond {TIMING_GROWTH:g}x the baseline's (time off the CPU: sleeping, waiting) "
                f"but was not judged: {grown} — {whys}")

    def to_dict(self) -> dict[str, Any]:
        return {"ok": self.ok, "compared": self.compared, "changes": [dataclasses.asdict(c) for c in self.changes]}

    def regression_lines(self, baseline: str | Path | None = None, results: str | Path | None = None,
                         limit: int = LISTED_REGRESSIONS) -> list[str]:
        """The first ``limit`` regressions as ``verimono gate`` prints them, then how many more and the
        ``verimono gate`` command that lists them all (``baseline``, ``results``: the two documents' paths)."""
        regs = self.regressions
        lines = [f"  {c}" for c in regs[:limit]]
        if len(regs) > limit:
            lines.append(f"  … and {len(regs) - limit} more; `verimono gate --baseline {baseline or 'BASELINE'} "
                         f"--results {results or 'RESULTS'}` lists all")
        return lines


def _one_reason_each(whys: Any) -> list[str]:
    """The stages' reasons for not judging, each kind said once: a reason is ``"; "``-separated parts, and a part's
    kind is what precedes its first ``":"`` (the same busy machine measured per stage differs only in its
    percentages); the first stage's wording of each kind is kept, and how many more stages gave that kind."""
    kinds: dict[str, list[Any]] = {}
    for why in whys:
        for part in str(why).split("; "):
            kind = part.split(":", 1)[0]
            if kind in kinds:
                kinds[kind][1] += 1
            else:
                kinds[kind] = [part, 0]
    return [part + (f" ({more} more stage{'s' if more != 1 else ''} likewise)" if more else "")
            for part, more in kinds.values()]


def check_unique_keys(report: Report, what: str = "the results") -> None:
    """Raise ``SchemaError`` naming the key when two records of ``report`` share a key ``check[subject]``:
    records are matched by key, so a repeated one makes the comparison ambiguous (a failed copy would
    hide behind a passed one)."""
    seen: dict[str, int] = {}
    dupes: list[str] = []
    for i, r in enumerate(report.results):
        j = seen.setdefault(r.key, i)
        if j != i:
            dupes.append(f"{r.key!r} (records {j} and {i})")
    if dupes:
        more = f" and {len(dupes) - 3} more" if len(dupes) > 3 else ""
        raise SchemaError(f"{what}: the record key {', '.join(dupes[:3])}{more} occurs more than once; each "
                          "check[subject] must occur once (which copy would the gate compare?)")


def check_passes_earned(report: Report, what: str = "the results") -> None:
    """Raise ``SchemaError`` naming the records when ``report`` holds a record that *passed* with a worst
    ratio above its bound (both finite): no check of verimono's writes one (a law passes when ``worst <=
    bound``), so the document was edited or written by something else, and the gate cannot trust its
    verdicts — it refuses it (exit 2) rather than compare against it."""
    bad = [f"{r.key} (worst {r.worst:.4g} > bound {r.bound:.4g})" for r in report.results
           if r.status == PASSED and _figure_is_finite(r.worst) and _figure_is_finite(r.bound) and r.worst > r.bound]
    if bad:
        more = f" and {len(bad) - 3} more" if len(bad) > 3 else ""
        raise SchemaError(f"{what}: a record passed with its worst ratio above its bound, {', '.join(bad[:3])}"
                          f"{more}: a pass that contradicts its own figures is invalid")


def _figure_is_finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def baseline_nonfinite(baseline: Report) -> list[str]:
    """Every figure the gate compares against that the baseline holds as a non-finite number (or
    ``null``, a string): a study's errors in the gated norms; a passed record's ``worst``, ``bound``,
    ``details["error"]``, ``details["timing_ratio"]``; a pass claimed with a non-finite worst ratio."""
    bad: list[str] = []
    for r in baseline.results:
        if UNEARNED_PASS in r.details:
            bad.append(f"{r.key}: {r.details[UNEARNED_PASS]}")
        if r.status != PASSED:
            continue
        for name, v in (("worst", r.worst), ("bound", r.bound)):
            if v is not None and not _figure_is_finite(v):
                bad.append(f"{r.key}: {name} = {v!r}")
        for name in ("error", "timing_ratio"):
            if name in r.details and not _figure_is_finite(r.details[name]):
                bad.append(f"{r.key}: details[{name!r}] = {r.details[name]!r}")
    for st in baseline.studies:
        if not hasattr(st, "errors"):
            continue
        for norm in GATED_NORMS:
            for h, e in zip(st.mesh, st.errors.get(norm, [])):
                if not _figure_is_finite(e):
                    bad.append(f"{st.stepper} on {st.problem}: {norm} error at h={h:.3g} = {e!r}")
    return bad


def baseline_uncalibrated(baseline: Report) -> str | None:
    """What a baseline with stage times lacks to have them judged, or ``None``: a calibration
    (``meta.calibration``, the unit of wall times) and, for each stage, its CPU time and the calibration's CPU
    time measured beside it (``cpu``, ``calibration_cpu``: written since schema 1.3).  A baseline without
    stages (a pytest session's) times nothing and lacks nothing."""
    stages = [st for st in baseline.meta.get("stages") or [] if isinstance(st, dict)]
    if not stages:
        return None
    if not _calibrations(baseline.meta):
        return f"no calibration (meta.calibration = {baseline.meta.get('calibration')!r})"
    bare = [st.get("name") for st in stages if not (_number(st.get("cpu")) and _slices(st) is not None)]
    if bare:
        return (f"no CPU time measured beside its stage{'s' if len(bare) > 1 else ''} {', '.join(map(str, bare))} "
                f"(stages[].cpu and calibration_cpu; written since schema 1.3)")
    return None


def check_baseline(baseline: Report, what: str = "the baseline") -> None:
    """Raise :class:`IncompatibleBaseline` unless ``baseline`` is usable: it has executed (non-skipped)
    records (a baseline without any vouches for nothing, and every run would pass against it), and every
    figure the gate compares against is finite (:func:`baseline_nonfinite`); ``SchemaError`` when it
    repeats a record key (:func:`check_unique_keys`)."""
    if not any(r.status != SKIPPED for r in baseline.results):
        raise IncompatibleBaseline(f"the baseline has no executed records ({len(baseline.results)} records, "
                                   "all skipped or none); regenerate it with `verimono baseline`")
    check_unique_keys(baseline, what)
    uncalibrated = baseline_uncalibrated(baseline)
    if uncalibrated:
        raise IncompatibleBaseline(f"{what} has stage times but {uncalibrated}: its stage times could not be "
                                   "judged, and a slowdown would pass unseen; regenerate it with `verimono baseline`")
    bad = baseline_nonfinite(baseline)
    if bad:
        more = f"; and {len(bad) - 3} more" if len(bad) > 3 else ""
        raise IncompatibleBaseline(f"{what} is unusable: it holds non-finite figures that no result could "
                                   f"exceed ({'; '.join(bad[:3])}{more}); regenerate it with `verimono baseline`")


def check_runs_compatible(baseline: Report, current: Report) -> None:
    """Raise :class:`IncompatibleBaseline` if the baseline is empty (:func:`check_baseline`) or the two
    reports are not the same kind of run."""
    check_baseline(baseline)
    diffs = [f"{k}: baseline {baseline.meta.get(k)!r}, results {current.meta.get(k)!r}"
             for k in COMPATIBLE_KEYS if baseline.meta.get(k) != current.meta.get(k)]
    if diffs:
        raise IncompatibleBaseline("baseline and results come from different runs (" + "; ".join(diffs) +
                                   "); regenerate the baseline with the same command and profile")


def _fmt(x: Any) -> str:
    return f"{x:.4g}" if isinstance(x, float) else str(x)


def _finite(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _why(rec: Any) -> str:
    if isinstance(rec.worst, (int, float)) and isinstance(rec.bound, (int, float)):
        rel = "exceeds" if rec.worst > rec.bound else "within"
        return f"worst {rec.worst:.4g} {rel} bound {rec.bound:.4g}"
    return "no message"


def _compare_records(base: Report, cur: Report, out: list[Change]) -> None:
    now = {r.key: r for r in cur.results}
    before = {r.key: r for r in base.results}
    for key, b in before.items():
        c = now.get(key)
        if c is None:
            out.append(Change("removed", key, f"was {b.status} in the baseline, absent now",
                              b.status != SKIPPED))
            continue
        if b.status in (PASSED, XFAIL) and c.status == FAILED:
            out.append(Change("status", key, f"{b.status} → failed: {c.message or _why(c)}", True))
        elif b.status == PASSED and c.status == SKIPPED:
            out.append(Change("status", key, f"passed → skipped: {c.message}", True))
        elif b.status == PASSED and c.status == XFAIL:
            declared = c.details.get(XFAIL_DECLARED)
            if isinstance(declared, str) and declared.strip():
                out.append(Change("status", key, f"passed → xfail, declared: {declared}", False))
            else:
                out.append(Change("status", key, f"passed → xfail without a declaration (no "
                                  f"details[{XFAIL_DECLARED!r}]): {c.message}", True))
        elif b.status in (PASSED, XFAIL) and c.status == UNDECIDED:
            noise = is_noise_undecided(c)   # the machine, not the code: a change (see Timing above)
            out.append(Change("status", key, f"{b.status} → undecided: {c.message}", not noise))
        elif b.status != c.status:
            out.append(Change("status", key, f"{b.status} → {c.status}", False))
        be, ce = b.details.get("error"), c.details.get("error")
        if _finite(be) and c.status != SKIPPED and not _finite(ce):  # a skipped record regresses above
            out.append(Change("error", key, f"error is now {ce!r}, not a finite number (baseline {be:.3g})",
                              True))
        elif _finite(be) and _finite(ce):
            if ce > ERROR_GROWTH * be and ce > ERROR_IGNORE_BELOW:
                out.append(Change("error", key, f"error grew from {be:.3g} to {ce:.3g} "
                                  f"(> {ERROR_GROWTH}x)", True))
        _compare_timing_ratio(key, b, c, out)
    for key, c in now.items():
        if key not in before:
            out.append(Change("new", key, f"new record ({c.status})", False))
        if c.status == PASSED:
            bad = [f"{name} = {v!r}" for name, v in (("worst", c.worst), ("bound", c.bound),
                                                    ("error", c.details.get("error")))
                   if v is not None and isinstance(v, (int, float)) and not math.isfinite(v)]
            if bad:
                out.append(Change("nonfinite", key, "passed with a non-finite figure (" + ", ".join(bad) +
                                  "): a nan/inf satisfies no bound", True))
    executed = lambda rep: Counter(r.check for r in rep.results if r.status != SKIPPED)  # noqa: E731
    bc, cc = executed(base), executed(cur)
    for check, n in bc.items():
        if cc.get(check, 0) < n:
            out.append(Change("count", check, f"executed records fell from {n} to {cc.get(check, 0)}", True))
    if sum(cc.values()) < sum(bc.values()):
        out.append(Change("count", "total", f"executed records fell from {sum(bc.values())} to "
                          f"{sum(cc.values())}", True))


def _below_theory(s: Any) -> bool:
    """Whether study ``s``'s sup-norm order lies below its theoretical order (its interval's upper end plus
    ``ORDER_SLACK``; a NaN interval is below)."""
    exp, fit = s.expected, s.fits["sup"]
    return (exp is not None and not exp.exact and exp.value is not None and not fit.exact
            and not (fit.high + ORDER_SLACK >= exp.value))


def _compare_studies(base: Report, cur: Report, out: list[Change]) -> None:
    now = {(s.problem, s.stepper): s for s in cur.studies if hasattr(s, "fits")}
    then = {(s.problem, s.stepper): s for s in base.studies if hasattr(s, "fits")}
    for s in cur.studies:
        if not hasattr(s, "fits") or not _below_theory(s):
            continue
        # below theory is a regression when it is new: a baseline recorded below it (`verimono baseline` warns
        # that the gate then catches only new failures) makes it a change, judged against that baseline below
        was = then.get((s.problem, s.stepper))
        known = was is not None and _below_theory(was)
        out.append(Change("order", f"{s.stepper} on {s.problem}",
                          f"sup-norm order {s.fits['sup']} below the theoretical order {s.expected.value:g}"
                          + (f", as in the baseline ({was.fits['sup']})" if known else ""), not known))
    for b in base.studies:
        if not hasattr(b, "fits"):
            continue
        s = now.get((b.problem, b.stepper))
        if s is None:
            # a study that vanished while its record stayed: the order claim has lost its evidence
            # (a vanished record is reported by the record rules)
            if any(r.check == "convergence_order" and r.subject == f"{b.stepper} on {b.problem}"
                   and r.status != SKIPPED for r in cur.results):
                out.append(Change("study", f"{b.stepper} on {b.problem}", "the convergence study of the "
                                  "baseline is absent from the results while its record remains", True))
            continue
        key = f"{b.stepper} on {b.problem}"
        for norm in GATED_NORMS:
            bf, cf = b.fits.get(norm), s.fits.get(norm)
            if bf is None or cf is None:
                continue
            if bf.exact and not cf.exact:
                out.append(Change("order", key, f"{norm}: exact at the nodes in the baseline, now {cf}", True))
                continue
            if not (bf.exact or cf.exact) and math.isfinite(bf.slope) and not math.isfinite(cf.slope):
                out.append(Change("order", key, f"{norm}-norm order is now {cf}, not a finite number "
                                  f"(baseline {bf})", True))
                continue
            if bf.exact or cf.exact or not all(map(math.isfinite, (bf.slope, cf.slope))):
                continue
            half = lambda f: (f.high - f.low) / 2 if math.isfinite(f.high - f.low) else 0.0  # noqa: E731
            allowed = max(half(bf), half(cf), ORDER_DROP_FLOOR)
            if cf.slope < bf.slope - allowed:
                out.append(Change("order", key, f"{norm}-norm order fell from {bf} to {cf} "
                                  f"(more than {allowed:.3g})", True))
        floor = max(ERROR_IGNORE_BELOW, float(s.floor or 0.0))
        for norm in GATED_NORMS:
            for h, be in zip(b.mesh, b.errors[norm], strict=True):  # lengths checked by the schema
                match = [i for i, hc in enumerate(s.mesh) if math.isclose(hc, h, rel_tol=1e-9)]
                if not match:
                    continue
                ce = s.errors[norm][match[0]]
                if math.isfinite(be) and not math.isfinite(ce):
                    out.append(Change("error", key, f"{norm} error at h={h:.3g} is now {ce}, not a finite "
                                      f"number (baseline {be:.3g})", True))
                elif ce > ERROR_GROWTH * be and ce > floor:
                    out.append(Change("error", key, f"{norm} error at h={h:.3g} grew from {be:.3g} to "
                                      f"{ce:.3g} (> {ERROR_GROWTH}x)", True))


def _number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _compare_timing_ratio(key: str, b: Any, c: Any, out: list[Change]) -> None:
    """A record's same-job timing ratio: a regression when the lower end of its interval (the ratio itself
    when it has none) exceeds ``TIMING_GROWTH`` x the baseline's ratio (module docstring, *Timing*)."""
    bt, ct = b.details.get("timing_ratio"), c.details.get("timing_ratio")
    if not (_number(bt) and _number(ct)) or not ct > TIMING_GROWTH * bt:
        return
    iv = c.details.get("timing_interval")
    low = iv[0] if isinstance(iv, (list, tuple)) and len(iv) == 2 and _number(iv[0]) else ct
    if low > TIMING_GROWTH * bt:
        bound = f" (its interval's lower end {low:.3g})" if low != ct else ""
        out.append(Change("timing", key, f"same-job timing ratio grew from {bt:.3g} to {ct:.3g}{bound} "
                          f"(> {TIMING_GROWTH}x with confidence)", True))
    else:
        out.append(Change("timing", key, f"same-job timing ratio {ct:.3g} is above {TIMING_GROWTH}x the baseline's "
                          f"{bt:.3g}, but its interval reaches down to {low:.3g}: growth not judged (timing noise)",
                          False))


def _calibrations(meta: dict[str, Any]) -> list[float]:
    """The run's calibrations (``meta.calibrations``, else ``[meta.calibration]``), the positive numbers only."""
    cals = meta.get("calibrations")
    if not isinstance(cals, list) or not cals:
        cals = [meta.get("calibration")]
    return [float(c) for c in cals if _number(c) and math.isfinite(c) and c > 0]


def _start_only(meta: dict[str, Any]) -> bool:
    """Whether a run measured its start's calibration alone (``meta.calibrations`` a list of one): a run with no
    timed record measures none at its end (:func:`verimono.run.execute.has_timed_records`).  A document from
    before ``meta.calibrations`` (``meta.calibration`` alone) is judged as it always was."""
    cals = meta.get("calibrations")
    return isinstance(cals, list) and len(_calibrations(meta)) == 1


def _stage_unjudged(cur_cals: list[float], stage: dict[str, Any], start_only: tuple[bool, bool] = (False, False)
                    ) -> str | None:
    """Why a stage's *wall* time in this run cannot support a regression (module docstring, *Timing*), or
    ``None``: the calibrations at its ends drift, or the machine was busy during the stage — or a run (this one,
    the baseline: ``start_only``, :func:`_start_only`) measured one calibration: its drift is unknown and its one
    figure, the start's (measured while the command line imports: up to 2x the end's), is no steadier unit than
    the faster of two."""
    why = []
    single = [who for who, one in zip(("this run", "the baseline"), start_only) if one]
    if single:
        why.append(f"{' and '.join(single)} measured one calibration (none at the end: no record of it is timed), "
                   "so its drift is unknown")
    drift = max(cur_cals) / min(cur_cals)
    if drift > CALIBRATION_DRIFT:
        why.append(f"the calibrations at the run's start and end differ by {drift:.2f}x (> {CALIBRATION_DRIFT}x)")
    waiting, foreign = stage.get("cpu_waiting"), stage.get("foreign_cpu")
    signs = [(x > limit, text.format(x)) for x, limit, text in (
        (waiting, BUSY_WAITING, "some task waited for a CPU {:.0%} of the stage's time"),
        (foreign, BUSY_FOREIGN, "processes outside the run used {:.0%} of the machine's CPU"))
        if _number(x)]
    if signs and all(busy for busy, _ in signs):
        why.append("the machine was busy: " + " and ".join(text for _, text in signs))
    return "; ".join(why) or None


def _slices(stage: dict[str, Any]) -> list[float] | None:
    """The calibration's CPU seconds measured beside the stage's work (``stage["calibration_cpu"]``), or
    ``None`` when the stage has none (a document from before CPU timing)."""
    cals = stage.get("calibration_cpu")
    if not isinstance(cals, list) or not cals:
        return None
    xs = [float(c) for c in cals if _number(c) and math.isfinite(c) and c > 0]
    return xs if len(xs) == len(cals) else None


def calibration_mean(samples: list[float], alpha: float = 0.025) -> tuple[float, float, float]:
    """``(mean, low, high)``: the mean of a stage's calibration samples and its two-sided ``1 - 2 alpha``
    interval (Student's t quantile by its Cornish-Fisher expansion to the third term: within 0.5% of the
    table from 5 samples, 3% low for 3); the samples' range when there are fewer than 3.

    The mean, not the median: a stage's CPU time is a sum over its work, inflated on average by what the load
    does to code as it runs, and the samples, taken after each unit and once more per 0.25 s of it, are
    spread over the stage's time as its work is.  On a loaded machine they fall in two groups (95 ms
    uncontended, 170-200 ms contended, here), and their median jumps from one to the other with the share of
    contended samples, while the mean follows that share: measured beside two CPU spinners, a memory hog and
    other test runs, the subject's CPU time over the mean read 2.81 and 3.16 for two runs of one stepper
    (over the median 2.56 and 3.62)."""
    n = len(samples)
    mean = statistics.fmean(samples)
    if n < 3:
        return mean, min(samples), max(samples)
    z, v = statistics.NormalDist().inv_cdf(1.0 - alpha), n - 1
    t = (z + (z ** 3 + z) / (4 * v) + (5 * z ** 5 + 16 * z ** 3 + 3 * z) / (96 * v ** 2)
         + (3 * z ** 7 + 19 * z ** 5 + 17 * z ** 3 - 15 * z) / (384 * v ** 3))
    half = t * statistics.stdev(samples) / math.sqrt(n)
    return mean, max(mean - half, min(samples)), min(mean + half, max(samples))


def cpu_units(stage: dict[str, Any], figure: str = "cpu") -> tuple[float, float, float] | None:
    """``(ratio, low, high)``: the stage's ``figure`` (``"cpu"``, its CPU seconds, or ``"subject_cpu"``,
    those spent in the subject's calls) over the calibration's CPU seconds measured beside it — the mean of
    its samples, :func:`calibration_mean` — with the bounds its interval allows; ``None`` when the stage
    lacks either figure."""
    x, cals = stage.get(figure), _slices(stage)
    if not (_number(x) and math.isfinite(x) and x >= 0) or cals is None:
        return None
    mean, lo, hi = calibration_mean(cals, TIMING_ALPHA)
    return x / mean, x / hi, x / lo


def _cpu_change(what: str, key: str, b: dict[str, Any], s: dict[str, Any], figure: str) -> tuple[str, Change | None]:
    """The CPU verdict on ``figure`` of stage ``s`` against the baseline's ``b``: ``("regression" | "not
    judged" | "ok" | "untimed", change)`` (module docstring, *Timing*)."""
    now, before = cpu_units(s, figure), cpu_units(b, figure)
    if now is None or before is None:
        return "untimed", None
    (rc, rc_lo, rc_hi), (rb, rb_lo, rb_hi) = now, before
    if min(rc, rb) < TIMING_MIN_UNITS or min(s[figure], b[figure]) < TIMING_MIN_CPU:
        return "untimed", None
    growth, least, most = rc / rb, rc_lo / rb_hi, rc_hi / rb_lo
    if most <= TIMING_GROWTH:
        return "ok", None
    cals = _slices(s) or []
    evidence = (f"{what} {rc:.1f}x the calibration's CPU time (mean {statistics.fmean(cals) * 1e3:.0f} ms of "
                f"{len(cals)} samples beside it), baseline {rb:.1f}x: {growth:.2f}x growth, between {least:.2f}x "
                f"and {most:.2f}x with the samples' spread ({s[figure]:.2f} s CPU now, {b[figure]:.2f} s before)")
    if least > TIMING_GROWTH:
        return "regression", Change("timing", key, f"{evidence} (> {TIMING_GROWTH}x)", True)
    return "not judged", Change("timing", key, f"{evidence}: not judged (the calibration's CPU time varied too "
                                               f"much beside this stage to tell {TIMING_GROWTH}x growth)", False)


def _compare_timings(base: Report, cur: Report, out: list[Change]) -> None:
    """Stage CPU times, and the subject's part of them, in calibration units against the baseline's; wall
    times only where the machine was quiet (module docstring, *Timing*)."""
    bcals, ccals = _calibrations(base.meta), _calibrations(cur.meta)
    if not (bcals and ccals):
        return
    bex, cex = base.meta.get("executor") or "serial", cur.meta.get("executor") or "serial"
    if bex != cex:   # a stage's times depend on how many workers ran its units: not comparable
        out.append(Change("timing", "stages", f"stage times not compared: the baseline's units ran on {bex}, "
                                              f"these on {cex}", False))
        return
    subject = cur.meta.get("target") or "the subject"
    before = {s["name"]: s for s in base.meta.get("stages") or [] if isinstance(s, dict)}
    both = [(before[s["name"]], s) for s in cur.meta.get("stages") or []
            if isinstance(s, dict) and s.get("name") in before]
    timed = [(b, s) for b, s in both if cpu_units(b, "subject_cpu") and cpu_units(s, "subject_cpu")]
    if len(timed) > 1:   # the subject over the whole run: its CPU time in all stages over all their samples
        pooled = [{"subject_cpu": sum(st["subject_cpu"] for st in side),
                   "calibration_cpu": [c for st in side for c in _slices(st) or []]} for side in zip(*timed)]
        _, change = _cpu_change("CPU time in its calls", f"{subject} in all stages", pooled[0], pooled[1],
                                "subject_cpu")
        if change is not None:
            out.append(change)
    groups: dict[tuple[str, ...], list[bool]] = {}
    for b, s in both:
        verdict, change = _cpu_change("CPU time", f"stage {s['name']}", b, s, "cpu")
        if change is not None:
            out.append(change)
        _, subject_change = _cpu_change("CPU time in its calls", f"{subject} in stage {s['name']}", b, s,
                                        "subject_cpu")
        if subject_change is not None:
            out.append(subject_change)
        if _overlapped(b) or _overlapped(s):   # no wall of its own: its group's, below
            group = tuple(sorted({s["name"], *(s.get("overlapped") or b.get("overlapped") or [])}))
            groups.setdefault(group, []).append(verdict in ("ok", "untimed") and verdict)
        elif verdict in ("ok", "untimed"):
            _compare_wall(b, s, bcals, ccals, out, cpu_judged=verdict == "ok",
                          start_only=(_start_only(cur.meta), _start_only(base.meta)))
    for group, verdicts in groups.items():
        sides = [_group_wall(group, side) for side in (before, {s["name"]: s for _, s in both})]
        if None not in sides and all(verdicts):
            _compare_wall(sides[0], sides[1], bcals, ccals, out, cpu_judged=all(v == "ok" for v in verdicts),
                          start_only=(_start_only(cur.meta), _start_only(base.meta)))


def _overlapped(stage: dict[str, Any]) -> bool:
    return bool(stage.get("overlapped"))


def _group_wall(group: tuple[str, ...], stages: dict[str, dict[str, Any]]) -> dict[str, Any] | None:
    """The stages ``group``, which ran at once in one run, as one stage of the gate's wall comparison: the wall
    of the group (``"group_duration"`` where they overlapped, else the sum of their walls, one after another)
    and the busy signs of the busiest of them; ``None`` when a stage of the group is missing, or when they
    overlapped without one wall of them all (a resumed run's: its stages came from two runs)."""
    if not all(n in stages for n in group):
        return None
    members = [stages[n] for n in group]
    spans = {m.get("group_duration") for m in members}
    if not any(_overlapped(m) for m in members):
        wall = sum(float(m.get("duration") or 0.0) for m in members)
    elif len(spans) == 1 and _number(next(iter(spans))):
        wall = float(next(iter(spans)))
    else:
        return None
    out: dict[str, Any] = {"name": " + ".join(group), "duration": wall}
    for key in ("cpu_waiting", "foreign_cpu"):
        xs = [m[key] for m in members if _number(m.get(key))]
        if xs:
            out[key] = max(xs)
    return out


def _compare_wall(b: dict[str, Any], s: dict[str, Any], bcals: list[float], ccals: list[float], out: list[Change],
                  cpu_judged: bool, start_only: tuple[bool, bool] = (False, False)) -> None:
    """A stage's wall time in calibration units (taken at the run's slower calibration, the baseline's at its
    faster): growth beyond ``TIMING_GROWTH`` regresses only on a quiet machine (:func:`_stage_unjudged`) — where
    its CPU time did not grow, it is time spent off the CPU (sleeping, waiting on I/O or a lock), which CPU time
    does not see.  On a busy machine, or between drifting calibrations, such growth is listed as not judged
    with the evidence (``cpu_judged``: the CPU time was judged and did not grow)."""
    if min(b.get("duration", 0), s.get("duration", 0)) < TIMING_MIN_SECONDS:
        return
    rb, rc, rc_most = b["duration"] / min(bcals), s["duration"] / max(ccals), s["duration"] / min(ccals)
    if rc_most <= TIMING_GROWTH * rb:
        return
    why = _stage_unjudged(ccals, s, start_only)
    if why is None and rc <= TIMING_GROWTH * rb:
        return
    if rc > TIMING_GROWTH * rb:
        what = (f"wall time {rc:.1f}x the calibration workload, baseline {rb:.1f}x (> {TIMING_GROWTH}x growth; "
                f"{s['duration']:.2f} s now)")
    else:
        what = (f"wall time {rc:.1f}x-{rc_most:.1f}x the calibration workload (the run's two calibrations), "
                f"baseline {rb:.1f}x (up to {rc_most / rb:.1f}x growth; {s['duration']:.2f} s now)")
    cpu = " while its CPU time did not grow" if cpu_judged else ""
    if why is None:
        out.append(Change("timing", f"stage {s['name']}", f"{what}{cpu}, on a quiet machine: time spent off the "
                          "CPU (sleeping, waiting)", True))
    else:
        change = Change("timing", f"stage {s['name']}", f"{what}{cpu}: time off the CPU not judged ({why})", False)
        change.wall_unjudged = (rc_most / rb, why)   # not a field: the documents' changes keep their keys
        out.append(change)


def compare(baseline: Report, current: Report) -> Comparison:
    """Every change from ``baseline`` to ``current`` (see the module docstring for what regresses);
    ``SchemaError`` when either repeats a record key, :class:`IncompatibleBaseline` when the baseline
    holds a non-finite figure (:func:`check_baseline`'s rules beyond emptiness)."""
    check_unique_keys(baseline, "the baseline")
    check_unique_keys(current, "the results")
    check_passes_earned(baseline, "the baseline")
    check_passes_earned(current, "the results")
    if baseline_nonfinite(baseline) or baseline_uncalibrated(baseline):
        check_baseline(baseline)        # raises, naming the figures or what is missing
    changes: list[Change] = []
    _compare_records(baseline, current, changes)
    _compare_studies(baseline, current, changes)
    _compare_timings(baseline, current, changes)
    return Comparison(changes, len(baseline.results), dict(baseline.meta))


def check_completed(path: str | Path, what: str = "results") -> None:
    """Raise :class:`IncompatibleResults` when ``path`` carries the in-progress mark of a run that has not
    completed (:func:`verimono.records.atomic.in_progress`): whatever ``path`` holds is not that run's output."""
    run = in_progress(path)
    if run is not None:
        started = f", started {run['started']}" if run.get("started") else ""
        pid = f", pid {run['pid']}" if run.get("pid") else ""
        raise IncompatibleResults(
            f"the {what} {path} are not the output of the last run there: run {run.get('run_id')} "
            f"(verimono {run.get('command') or '?'}{started}{pid}) marked them in progress and never completed "
            f"(killed, stopped by an error, or still running; its mark: {run['mark']}); gate the files of a "
            "run that completed")


def gate(baseline: str | Path | Report, results: str | Path | Report) -> Comparison:
    """Load both documents (fail closed: :class:`SchemaError` / :class:`IncompatibleBaseline` /
    :class:`IncompatibleResults`, see the module docstring) and compare."""
    docs = {}
    for what, doc in (("baseline", baseline), ("results", results)):
        if not isinstance(doc, Report):
            check_completed(doc, what)
        docs[what] = doc if isinstance(doc, Report) else load(doc)
        rep = docs[what]
        if rep.meta.get("incomplete"):
            raise IncompatibleResults(f"the {what} come from an interrupted run (finished stages: "
                                      f"{', '.join(rep.meta.get('finished_stages') or []) or 'none'}); finish it "
                                      "with `verimono run --resume` before gating")
        check_unique_keys(rep, f"the {what}" + ("" if isinstance(doc, Report) else f" {doc}"))
        check_passes_earned(rep, f"the {what}" + ("" if isinstance(doc, Report) else f" {doc}"))
    base, cur = docs["baseline"], docs["results"]
    check_baseline(base, "the baseline" + ("" if isinstance(baseline, Report) else f" {baseline}"))
    check_runs_compatible(base, cur)
    return compare(base, cur)


__all__ = ["Change", "Comparison", "compare", "gate", "check_baseline", "check_runs_compatible",
           "check_unique_keys", "check_passes_earned", "check_completed", "baseline_nonfinite", "baseline_uncalibrated", "cpu_units", "calibration_mean",
           "IncompatibleBaseline", "IncompatibleResults", "LISTED_REGRESSIONS", "ORDER_DROP_FLOOR", "ERROR_GROWTH",
           "TIMING_GROWTH", "TIMING_MIN_SECONDS", "CALIBRATION_DRIFT"]
