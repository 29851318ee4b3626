"""Speed verdicts that hold on a busy machine: the clock, the estimator, the decision rule, and the machine probes.

Everything here is small and dependency-free (the calibration workload is :mod:`verimono.execution.calibration`'s), so that
:mod:`verimono.run.performance` (the timed records), :mod:`verimono.run.gate` (timing comparisons with a baseline)
and :mod:`verimono.execution.timeouts` (budgets in calibration units) share one definition of each.

**The clock.**  A timed call's *own time* is its wall time minus the time its thread spent runnable but
waiting for a CPU (the scheduler's run-queue delay, ``/proc/thread-self/schedstat``, field 2).  On a busy
machine that wait is the other processes' time, not the code's: measured on this 2-core machine with two
CPU spinners and a memory-bandwidth hog beside it, wall-clock ratios of the same code moved by up to 2x
(a speed-up looked twice as large because only the longer side got preempted) while own-time ratios stayed
within 3% of the idle ones.  Own time still counts what the code itself does off the CPU (sleeping,
blocking on I/O or a lock), so a regression that waits is not hidden.  Where schedstat is not readable the
clock falls back to the thread's CPU time (:func:`time.thread_time`), which also drops the wait but misses
the code's own blocking; :data:`CLOCK` names the clock in use and every record states it.  Contention that
slows the code *while it runs* (cache and memory-bandwidth sharing) stays in either clock; the estimator
and the interval below deal with what is left.

**The estimator.**  Subject and baseline run in *rounds*, interleaved and alternating which goes first
(a drift of the machine's speed hits both sides of a round alike, and neither side always runs on the
other's warm caches).  Each round gives one ratio ``subject/baseline``; the estimate is the **median of
the per-round ratios**.  A contention spike inflates one side of one round, so it moves one ratio up or
down, and the median ignores a minority of such rounds (the mean or a single round does not).

**The confidence bound.**  Order statistics of the per-round ratios (the sign-test interval for a median,
as ``asv`` computes its ``ci_99`` by ``quantile_ci``): for ``n`` rounds, assumed independent given the
machine, the ``k``-th smallest ratio is below the median with probability ``P(Bin(n, 1/2) >= k)``, so
``[r_(k), r_(n-k+1)]`` with ``P(Bin(n, 1/2) <= k-1) <= alpha`` bounds the median from below and from above,
each end at one-sided level ``1 - alpha``.  Distribution-free: timing noise is skewed and heavy-tailed
(normal-theory intervals, as in hyperfine's mean ± σ, assume what it is not), and a bootstrap of a median
from 9 rounds is a resampling of 9 numbers.

**The decision** (:func:`judge`), for a target on the ratio (``<=``; a speed-up target ``>=`` is the same
rule on ``baseline/subject``): *passed* when the upper bound meets the target, *failed* when the lower bound
exceeds it — a target exceeded with confidence — else the interval straddles the target and the record is
measured again with more rounds, once, up to ``max_rounds`` (the stated budget: at most that many rounds
per record).  Still straddling, it is *undecided* with ``details["undecided_reason"] = "timing noise"``
(:data:`NOISE_REASON`) and the evidence: the interval, the spread of the rounds, how much of the time the
process waited for a CPU, the load average and the calibration before and after.  Two looks at the data
(optional stopping) are paid for with Bonferroni: each look uses ``ALPHA / 2`` per side, so a wrong
verdict, pass or fail, has probability at most ``ALPHA`` = 5% when the true median sits on the target,
and far less away from it.

**An early look** (``judge(..., early=6)``, what :mod:`verimono.run.performance` asks for): before the
planned rounds, the same rule looks once at ``early`` rounds with the error those two looks leave unspent.
The union bound is over the looks' *attained* levels (the order statistics are discrete: at 9 rounds
``r_(2)``/``r_(8)`` attain ``P(Bin(9, 1/2) <= 1)`` = 1.95%, at 27 ``r_(8)``/``r_(20)`` attain 0.96%, against
the nominal 2.5% each), so the early look gets ``ALPHA`` minus those, 2.09%, and at 6 rounds its rank is 1: the
minimum and maximum, attained ``2**-6`` = 1.56%.  In words: *all six per-round ratios on one side of the
target decide the record at six rounds*; otherwise it goes on to the planned rounds and then the budget,
where the bounds are the same order statistics at the same levels as without the early look.  A wrong verdict
(pass or fail, per side) then has probability at most 1.56 + 1.95 + 0.96 = 4.47% ≤ ``ALPHA`` when the true
median sits on the target (:func:`look_plan` computes it; a plan that cannot fit an early look drops it).

**Calibration** (:mod:`verimono.execution.calibration`, re-exported here): a fixed NumPy-and-Python workload, best of
``repeats``; stage times are stated in its units (``verimono gate``), and so are the time budgets of
:mod:`verimono.execution.timeouts` (:func:`calibration` measures it once per process and caches it);
:func:`calibrate_both` times it on both clocks.

**Machine probes** (:class:`MachineProbe`): the fraction of wall time during which some task on the
machine was runnable but waiting for a CPU (Linux PSI, ``/proc/pressure/cpu``, ``some``), the share of the
machine's CPU used by processes outside this run, and the load average — the evidence the gate uses to
decide whether a grown stage time can be judged at all.
"""

from __future__ import annotations

import dataclasses
import math
import os
import statistics
import threading
import time
from typing import Any, Callable, Sequence

from ..core.claims import Stepper, claim_of
from ..core.naming import subject_name

from .calibration import AGREEMENT, calibrate, calibration, set_calibration, workload

#: one-sided error of each verdict (pass or fail) when the true median ratio sits exactly on the target;
#: split between the two looks at the data (Bonferroni), ``ALPHA / LOOKS`` per look and side
ALPHA = 0.05
#: looks at the data: the planned rounds, then (when the interval straddles the target) ``max_rounds``
LOOKS = 2
#: ``details["undecided_reason"]`` of a timing record that could not be judged because of the machine
NOISE_REASON = "timing noise"
#: a stage ran on a *busy* machine when both exceed their limit: some task waited for a CPU (PSI ``some``)
#: more than BUSY_WAITING of its wall time — there was contention — and processes outside the run used more
#: than BUSY_FOREIGN of the machine's CPU capacity — it was not the run's own (:class:`MachineProbe`).
#: Measured on this 2-core machine: a quiet ``verimono run --profile ci`` (process:2) reads waiting 1-4% per
#: stage but 40% in its first, where its workers import beside the main process, and foreign 0-5%; beside
#: two CPU spinners and a memory hog, or other developers' test runs, waiting 85-100% and foreign 50-100%
BUSY_WAITING = 0.10
BUSY_FOREIGN = 0.10

_SCHEDSTAT = "/proc/thread-self/schedstat"
_PSI_CPU = "/proc/pressure/cpu"


# -- the clock -------------------------------------------------------------------------------------------


def _run_queue_ns() -> int | None:
    """Nanoseconds this thread has spent runnable but waiting for a CPU (schedstat field 2), or ``None``."""
    try:
        with open(_SCHEDSTAT, "rb") as f:
            return int(f.read().split()[1])
    except (OSError, ValueError, IndexError):
        return None


#: the clock in use: ``"own"`` (wall minus run-queue wait, schedstat) or ``"cpu"`` (thread CPU time)
CLOCK = "own" if _run_queue_ns() is not None else "cpu"
CLOCK_DESCRIPTION = {"own": "wall time minus run-queue wait (/proc/thread-self/schedstat)",
                     "cpu": "thread CPU time (schedstat unavailable)"}


@dataclasses.dataclass(frozen=True)
class Sample:
    """One timed call: ``own`` (the clock's seconds, see the module docstring), ``wall``, ``cpu`` (thread
    CPU seconds) and ``waited`` (seconds runnable but waiting for a CPU; 0 when unknown)."""

    own: float
    wall: float
    cpu: float
    waited: float


def timed(fn: Callable[[], Any]) -> tuple[Any, Sample]:
    """``(fn(), Sample)``.  The schedstat reads sit outside the wall-clock window (they cost ~10 µs each)."""
    q0 = _run_queue_ns() if CLOCK == "own" else None
    c0, w0 = time.thread_time(), time.perf_counter()
    out = fn()
    w1, c1 = time.perf_counter(), time.thread_time()
    q1 = _run_queue_ns() if q0 is not None else None
    wall, cpu = w1 - w0, max(c1 - c0, 0.0)
    if q0 is not None and q1 is not None:
        waited = min(max((q1 - q0) * 1e-9, 0.0), wall)
        own = max(wall - waited, cpu)          # never below the CPU time the call used
    else:
        waited, own = max(wall - cpu, 0.0), cpu
    return out, Sample(own, wall, cpu, waited)


def cpu_now() -> float:
    """CPU seconds of this process so far, with those of its children it has waited for (a process pool a
    convergence study forks and closes): :func:`time.process_time` plus :func:`os.times`' children's."""
    t = os.times()
    return time.process_time() + t.children_user + t.children_system


# -- the subject's own CPU time ----------------------------------------------------------------------------

_SUBJECT_LOCK = threading.Lock()
_SUBJECT = {"cpu": 0.0, "calls": 0, "active": 0, "since": 0.0}


def subject_cpu() -> tuple[float, int]:
    """``(CPU seconds, calls)`` spent so far in this process inside calls of a :class:`TimedStepper`: the
    subject's own work, apart from the harness's around it (measured while at least one call is active, so
    that nested and concurrent calls count once)."""
    with _SUBJECT_LOCK:
        extra = cpu_now() - _SUBJECT["since"] if _SUBJECT["active"] else 0.0
        return _SUBJECT["cpu"] + extra, _SUBJECT["calls"]


class TimedStepper(Stepper):
    """A stepper whose calls add their CPU time to :func:`subject_cpu` — the subject's part of a stage, which
    the gate judges apart from the harness's (``verimono check`` wraps its target: a stepper made 3x slower
    grows a stage by only 2x where the checks' own work is half of it).  Its claim, name, ``batched`` and
    ``fn`` are the stepper's own (``fn`` is the wrapped callable, as a :class:`Stepper`'s)."""

    def __init__(self, stepper: Any) -> None:
        super().__init__(stepper, name=subject_name(stepper))
        self.claim = claim_of(stepper)
        self.batched = bool(getattr(stepper, "batched", False) or getattr(self.fn, "batched", False))

    def __call__(self, problem: Any, t_grid: Any) -> Any:
        with _SUBJECT_LOCK:
            if not _SUBJECT["active"]:
                _SUBJECT["since"] = cpu_now()
            _SUBJECT["active"] += 1
            _SUBJECT["calls"] += 1
        try:
            return self.fn(problem, t_grid)
        finally:
            with _SUBJECT_LOCK:
                _SUBJECT["active"] -= 1
                if not _SUBJECT["active"]:
                    _SUBJECT["cpu"] += cpu_now() - _SUBJECT["since"]

    def __reduce__(self):   # picklable as a Stepper is: by reference to fn
        return (_rebuild_timed, (self.fn, self.claim, self.__name__, self.batched))


def _rebuild_timed(fn: Callable, claim: Any, name: str, batched: bool) -> TimedStepper:
    s = TimedStepper(Stepper(fn, name=name))
    s.claim, s.batched = claim, batched
    return s


# -- the estimator and its confidence bound ----------------------------------------------------------------


def _binom_cdf_half(n: int, k: int) -> float:
    """``P(Bin(n, 1/2) <= k)``."""
    if k < 0:
        return 0.0
    return sum(math.comb(n, j) for j in range(min(k, n) + 1)) / 2.0 ** n


def order_rank(n: int, alpha: float) -> int:
    """The largest ``k >= 1`` with ``P(Bin(n, 1/2) <= k - 1) <= alpha``: ``r_(k)`` is a lower and
    ``r_(n-k+1)`` an upper one-sided ``1 - alpha`` confidence bound of the median of ``n`` i.i.d. draws;
    0 when ``n`` is too small for any (``2**-n > alpha``)."""
    k = 0
    while k < n // 2 + 1 and _binom_cdf_half(n, k) <= alpha:
        k += 1
    return k


def median_interval(values: Sequence[float], alpha: float) -> tuple[float, float, float]:
    """``(median, low, high)``: the median of ``values`` and its one-sided ``1 - alpha`` bounds by order
    statistics (``0`` / ``inf`` when there are too few values to bound it)."""
    xs = sorted(float(v) for v in values)
    if not xs:
        return math.nan, 0.0, math.inf
    k = order_rank(len(xs), alpha)
    med = statistics.median(xs)
    if k == 0:
        return med, 0.0, math.inf
    return med, xs[k - 1], xs[len(xs) - k]


@dataclasses.dataclass
class Judgement:
    """A speed verdict and its evidence.

    ``status``: ``passed``/``failed``/``undecided``; ``ratio`` (oriented as the target: ``subject/baseline``
    for a ``<=`` target, ``baseline/subject`` for a ``>=`` speed-up), ``low``/``high`` its bounds, ``level``
    their one-sided confidence; ``timing_ratio``/``timing_interval`` the same oriented so that larger is
    worse (``subject/baseline``); ``subject``/``baseline`` the own times of every round, ``looks`` how many
    times the rule looked at them."""

    status: str
    ratio: float
    low: float
    high: float
    level: float
    target: float
    speedup: bool
    subject: list[float]
    baseline: list[float]
    looks: int

    @property
    def rounds(self) -> int:
        return len(self.subject)

    @property
    def per_round(self) -> list[float]:
        """Per-round ratios ``subject/baseline`` (larger is worse)."""
        return [s / b for s, b in zip(self.subject, self.baseline)]

    @property
    def timing_ratio(self) -> float:
        return 1.0 / self.ratio if self.speedup else self.ratio

    @property
    def timing_interval(self) -> list[float]:
        if self.speedup:
            return [1.0 / self.high if self.high > 0 else 0.0, 1.0 / self.low if self.low > 0 else math.inf]
        return [self.low, self.high]

    @property
    def spread(self) -> float:
        """Interquartile range of the per-round ratios over their median (0 for one round)."""
        r = self.per_round
        if len(r) < 2:
            return 0.0
        q = statistics.quantiles(r, n=4, method="inclusive")
        return (q[2] - q[0]) / statistics.median(r)


def decide(subject: Sequence[float], baseline: Sequence[float], *, target: float, speedup: bool = False,
           alpha: float = ALPHA) -> tuple[str, float, float, float]:
    """``(status, ratio, low, high)`` of one look: ``passed`` when the bound on the worse side meets
    ``target``, ``failed`` when the bound on the better side misses it, else ``straddles``."""
    pairs = [(s, b) for s, b in zip(subject, baseline) if s > 0 and b > 0]
    worse = [s / b for s, b in pairs]                        # larger is worse
    med, lo, hi = median_interval(worse, alpha)
    tgt = 1.0 / target if speedup else target
    status = "passed" if hi <= tgt else ("failed" if lo > tgt else "straddles")
    if speedup:   # orient as the target: speed-up = baseline/subject
        med = statistics.median([b / s for s, b in pairs]) if pairs else math.nan
        lo, hi = (1.0 / hi if hi > 0 else 0.0), (1.0 / lo if lo > 0 else math.inf)
    return status, med, lo, hi


def attained(n: int, alpha: float) -> float:
    """The error one side of :func:`median_interval` at level ``alpha`` on ``n`` rounds actually attains,
    ``P(Bin(n, 1/2) <= k - 1)`` for ``k = order_rank(n, alpha)`` (0 when there is no bound): at most ``alpha``."""
    k = order_rank(n, alpha)
    return _binom_cdf_half(n, k - 1) if k else 0.0


def look_plan(rounds: int, max_rounds: int | None = None, *, early: int | None = None,
              alpha: float = ALPHA) -> list[tuple[int, float]]:
    """The looks of :func:`judge` as ``(rounds so far, per-side level)``: ``rounds`` at ``alpha / looks`` and,
    when ``max_rounds > rounds``, ``max_rounds`` at the same level (Bonferroni, as without an early look); then,
    when ``0 < early < rounds`` and the error those looks leave unspent by their attained levels
    (:func:`attained`) gives ``early`` rounds an order-statistics bound, a first look at ``early`` rounds with that
    error.  The attained levels of the plan add up to at most ``alpha`` per side."""
    max_rounds = max(rounds, max_rounds or rounds)
    looks = 1 if max_rounds == rounds else LOOKS
    plan = [(rounds, alpha / looks)] + ([(max_rounds, alpha / looks)] if looks > 1 else [])
    if early is not None and 0 < early < rounds:
        rest = alpha - sum(attained(n, a) for n, a in plan)
        if rest > 0 and order_rank(early, rest) >= 1:
            plan.insert(0, (early, rest))
    return plan


def judge(more: Callable[[int], tuple[Sequence[float], Sequence[float]]], *, target: float, speedup: bool = False,
          rounds: int, max_rounds: int | None = None, alpha: float = ALPHA, early: int | None = None) -> Judgement:
    """The sequential rule of the module docstring: ``more(k)`` runs ``k`` more interleaved rounds and returns
    their ``(subject_times, baseline_times)``.  Look at ``rounds`` rounds; when the interval straddles the
    target and ``max_rounds > rounds``, run up to ``max_rounds`` and look again; still straddling: undecided.
    Each look uses ``alpha / looks`` per side (``looks`` = 2 when a second look is planned, else 1).  ``early``:
    a first look at that many rounds with the error left unspent (:func:`look_plan`; the module docstring)."""
    plan = look_plan(rounds, max_rounds, early=early, alpha=alpha)
    subj: list[float] = []
    base: list[float] = []
    looks = 0
    for need, a in plan:
        if need > len(subj):
            s, b = more(need - len(subj))
            subj += [float(x) for x in s]
            base += [float(x) for x in b]
        looks += 1
        status, ratio, lo, hi = decide(subj, base, target=target, speedup=speedup, alpha=a)
        if status != "straddles":
            break
    return Judgement("undecided" if status == "straddles" else status, ratio, lo, hi, 1 - a, target, speedup,
                     subj, base, looks)


def is_noise_undecided(record: Any) -> bool:
    """Whether ``record`` (a :class:`verimono.CheckResult`) is undecided only because timing noise kept its
    speed from being judged: such a record must not make a correct run fail."""
    return getattr(record, "status", None) == "undecided" and \
        (getattr(record, "details", None) or {}).get("undecided_reason") == NOISE_REASON


# -- calibration -------------------------------------------------------------------------------------------


def calibrate_both(repeats: int = 3, *, agreeing_with: dict[str, float] | None = None) -> dict[str, float]:
    """The calibration workload on both clocks, best of ``repeats``: ``{"wall": s, "own": s, "repeats": k}``.  On a
    busy machine the wall figure grows with the load and the own figure (:func:`timed`) does not; both growing
    means the code itself ran slower (cache and memory-bandwidth contention, a slower CPU clock).

    ``agreeing_with``: an earlier ``calibrate_both`` of the same process; the repeats end at the first whose best
    figures so far are both within :data:`verimono.execution.calibration.AGREEMENT` (5%) of it — the rule of
    :func:`verimono.execution.calibration.calibrate_times` for the run's end calibration.  A second calibration is
    there to tell whether the machine's speed changed; a first repeat that agrees has told it (the drift between
    the two, ``max/min`` per clock, is then at most 1.05), and more repeats could only move the minima by the noise
    they would be repeated to remove.  A repeat that disagrees is repeated as before; ``k`` says how many ran."""
    samples: list[Sample] = []
    for _ in range(repeats):
        samples.append(timed(workload)[1])
        best = {"wall": min(s.wall for s in samples), "own": min(s.own for s in samples)}
        if agreeing_with is not None and all(agreeing_with.get(c, 0) > 0 and
                                             abs(best[c] / agreeing_with[c] - 1.0) <= AGREEMENT for c in ("wall", "own")):
            break
    return {**best, "repeats": len(samples)}


# -- machine probes --------------------------------------------------------------------------------------------


def _psi_some_us() -> int | None:
    """Microseconds (since boot) during which some task waited for a CPU (Linux PSI), or ``None``."""
    try:
        with open(_PSI_CPU) as f:
            for line in f:
                if line.startswith("some"):
                    return int(line.rsplit("total=", 1)[1])
    except (OSError, ValueError, IndexError):
        pass
    return None


def loadavg() -> float | None:
    """The 1-minute load average, or ``None`` where the platform has none."""
    try:
        return round(os.getloadavg()[0], 2)
    except (OSError, AttributeError):
        return None


def _machine_busy_s() -> float | None:
    """CPU seconds (since boot) the whole machine spent busy — user, nice, system, irq, softirq and steal
    (the hypervisor's) — from ``/proc/stat``, or ``None``."""
    try:
        with open("/proc/stat") as f:
            fields = [int(x) for x in f.readline().split()[1:9]]
        return (fields[0] + fields[1] + fields[2] + fields[5] + fields[6] + fields[7]) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def _tree_cpu_s() -> float | None:
    """CPU seconds used so far by this process and its descendants (live ones from ``/proc/<pid>/stat``, with
    what they reaped; reaped ones from ``getrusage``), or ``None`` off Linux."""
    try:
        import resource

        tick = os.sysconf("SC_CLK_TCK")
        parent: dict[int, int] = {}
        times: dict[int, float] = {}
        for name in os.listdir("/proc"):
            if not name.isdigit():
                continue
            try:
                with open(f"/proc/{name}/stat") as f:
                    rest = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            parent[int(name)] = int(rest[1])
            times[int(name)] = sum(int(x) for x in rest[11:15]) / tick   # utime stime cutime cstime
        me, tree, frontier = os.getpid(), set(), [os.getpid()]
        while frontier:
            pid = frontier.pop()
            kids = [c for c, pp in parent.items() if pp == pid and c not in tree]
            tree.update(kids)
            frontier += kids
        own = resource.getrusage(resource.RUSAGE_SELF)
        reaped = resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + reaped.ru_utime + reaped.ru_stime + sum(times[p] for p in tree if p != me)
    except (OSError, ValueError, IndexError, ImportError):
        return None


class MachineProbe:
    """How busy the machine was between laps, and with what: ``lap()`` returns

    * ``cpu_waiting`` — the fraction of the wall time since the previous lap (or construction) during which
      some task was runnable but waiting for a CPU (Linux PSI ``some``); the run's own processes count too
      (its worker processes importing beside the main one read 40% in a quiet run's first stage);
    * ``foreign_cpu`` — the fraction of the machine's CPU capacity (wall time x cores) used by processes
      *outside* this process and its descendants (``/proc/stat`` busy time minus the tree's CPU time): 0-5%
      on a quiet machine, 60-100% with a CPU spinner per core beside the run;
    * ``loadavg`` — the 1-minute load average.

    ``None`` for what the platform does not expose."""

    def __init__(self) -> None:
        self._t, self._psi, self._busy, self._tree = time.perf_counter(), _psi_some_us(), _machine_busy_s(), _tree_cpu_s()

    def lap(self) -> dict[str, Any]:
        t, psi, busy, tree = time.perf_counter(), _psi_some_us(), _machine_busy_s(), _tree_cpu_s()
        dt = t - self._t
        waiting = foreign = None
        if psi is not None and self._psi is not None and dt > 0:
            waiting = round(min(max((psi - self._psi) * 1e-6 / dt, 0.0), 1.0), 4)
        if None not in (busy, self._busy, tree, self._tree) and dt > 0:
            foreign = round(min(max((busy - self._busy - (tree - self._tree)) / (dt * (os.cpu_count() or 1)), 0.0),
                                1.0), 4)
        self._t, self._psi, self._busy, self._tree = t, psi, busy, tree
        return {"cpu_waiting": waiting, "foreign_cpu": foreign, "loadavg": loadavg()}


__all__ = ["cpu_now", "subject_cpu", "TimedStepper", "ALPHA", "LOOKS", "NOISE_REASON", "BUSY_WAITING", "BUSY_FOREIGN", "CLOCK", "CLOCK_DESCRIPTION", "Sample", "timed",
           "order_rank", "median_interval", "Judgement", "decide", "attained", "look_plan", "judge", "is_noise_undecided", "calibrate",
           "calibrate_both",
           "calibration", "set_calibration", "loadavg", "MachineProbe"]
