"""The process-level limit behind :func:`verimono.execution.timeouts.time_limit`: a call blocked in native code.

``SIGALRM`` interrupts Python code where it is, but a call into native code (``os.system``, a C extension, a
``ctypes`` call that retries on ``EINTR``) runs the Python handler only once it returns: the timer fires and
nothing happens.  This module watches for that.  :func:`time_limit` registers each timer it arms
(:func:`limit`); one daemon thread per process (started with the first limit) knows the deadline of the
innermost one, and when the main thread is still inside it :func:`grace` seconds after that deadline —
``max(GRACE_MIN, GRACE_FRACTION x budget)``, 2 s for budgets up to 4 s, half the budget above — the
interrupt did not get through: the call is blocked in native code, and the thread hands a :class:`Hang`
(which call, its budget, how long it has run, the Python line it is stuck at) to the innermost handler
(:func:`on_hang`).  The ``SIGALRM`` path stays the normal one: Python code is stopped at its deadline, and
the watchdog only acts on a call the timer could not stop.

A thread cannot unblock the main thread, so a handler ends the process; only processes that verimono owns
install one:

* a ``process:N`` worker (:mod:`verimono.execution.executors`) sends the parent the records of its unit finished so
  far plus a failed record naming the hung call (:func:`hang_report`) and exits; the parent replaces it and
  the run goes on with the other units;
* ``verimono check`` / ``verimono run`` (:func:`verimono.run.execute.interruptible`) write the stages finished so far
  and the current stage's finished records, with the failed record, to the results file marked incomplete,
  name the call and the file in one line, and exit with status 1.

Either ends the subject's own child processes (an ``os.system`` command that would outlive the process and
keep its output pipes open; Linux, through ``/proc``) before it exits.  The *backstop* is for a
native call that blocks while holding the GIL, which stops this thread too: while a handler is installed,
:mod:`faulthandler` (a C thread that needs no GIL) ends the process with status 1 and the Python tracebacks
on standard error at ``budget + 2 x grace`` (to half a grace later: one timer serves the limits that follow one
another while it fires in that window of each, :func:`_arm_backstop`), without writing anything (a worker's parent then reports its
unit as a dead worker; a ``verimono`` command leaves its in-progress mark, which the gate refuses), and a
handler, which calls :func:`ending` first, gets :data:`ENDING_SECONDS` to write before it does the same.
The child processes of a call that holds the GIL are not ended (nothing in Python runs to find them).

In a process where no handler is installed — the Python API (``check_stepper``, ``check_operator``) in the
user's interpreter — the watchdog never ends the process: it prints one warning naming the blocked call and
the way to bound it (running the battery in worker processes, ``executor="process:N"``), and the call goes
on until it returns.

:func:`scope` and :func:`finished` keep what the handlers write: the records finished so far by the units
and checks running in the main thread (:func:`verimono.execution.timeouts.run_unit` and the runners add theirs).
"""

from __future__ import annotations

import dataclasses
import math
import os
import signal
import sys
import threading
import time
from contextlib import contextmanager
from typing import Any, Callable, Iterator

from ..records.results import FAILED, CheckResult, Report
from ..records.verdicts import new_record

#: the grace after a limit's deadline before its call counts as blocked in native code:
#: ``max(GRACE_MIN, GRACE_FRACTION x budget)``
GRACE_MIN = 2.0
GRACE_FRACTION = 0.5
#: the name of the watchdog's thread: it lives as long as its process, asleep on a condition between deadlines
#: (no CPU, no GIL), so nothing waits for it to end (:func:`verimono.run.performance._quiet_process`)
THREAD_NAME = "verimono-watchdog"
#: the check name of a record that stands for a unit (as :data:`verimono.execution.executors.UNIT_CHECK`)
UNIT_CHECK = "unit"
#: ``details`` key of the failed record of a call blocked in native code
HANG_DETAIL = "native_hang"


def grace(seconds: float) -> float:
    """Seconds after a limit of ``seconds`` expired before its call counts as blocked in native code."""
    return max(GRACE_MIN, GRACE_FRACTION * float(seconds))


@dataclasses.dataclass
class Hang:
    """A call still inside its time limit :func:`grace` seconds after the limit expired."""

    call: str                    #: the unit the limit names ("contraction on my_stepper on moving box")
    budget: float                #: its budget, seconds
    elapsed: float               #: seconds since the limit started
    where: str = ""              #: the Python line the main thread is blocked at ("file.py:12 in fn")
    check: str | None = None     #: the record the call belongs to (innermost :func:`scope` naming one)
    subject: str | None = None
    stage: str | None = None     #: the executor unit it runs in, if known
    label: str | None = None

    def message(self) -> str:
        at = f" at {self.where}" if self.where else ""
        return (f"did not return: {self.call} was still running {self.elapsed:.1f} s after it started, past its "
                f"time budget of {self.budget:g} s and {grace(self.budget):g} s of grace; blocked in native "
                f"code{at} (a call that the time limit's interrupt cannot stop until it returns to Python)")

    def record(self) -> CheckResult:
        """The failed record of the hung call: ``check[subject]`` of its :func:`verimono.execution.timeouts.run_unit`
        when it ran in one, else ``unit[<stage>: <label>]`` of its executor unit, else ``unit[<call>]``."""
        if self.check is not None:
            check, subject = self.check, self.subject or self.call
        elif self.stage is not None:
            check, subject = UNIT_CHECK, f"{self.stage}: {self.label}"
        else:
            check, subject = UNIT_CHECK, self.call
        details = {"timeout": self.budget, "elapsed": self.elapsed,
                   HANG_DETAIL: {"call": self.call, "where": self.where, "grace": grace(self.budget)}}
        return new_record(check, subject, FAILED, message=self.message(), duration=self.elapsed, details=details)


# -- what the main thread is running ---------------------------------------------------------------------

class _Frame:
    """One :func:`scope`: what it runs (``check``/``subject``, ``stage``/``label``) and what finished in it."""

    def __init__(self, info: dict[str, Any]) -> None:
        self.info = info
        self.items: list[Any] = []     # CheckResult or Report, in the order they finished


_FRAMES: list[_Frame] = []


def _main() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextmanager
def scope(**info: Any) -> Iterator[_Frame | None]:
    """Within the block, :func:`finished` records go to this scope; they are dropped when it ends (its
    caller then passes on the outcome).  ``info`` names what runs in it: ``check=``/``subject=`` (a record)
    or ``stage=``/``label=`` (an executor unit) — a :class:`Hang` inside takes the innermost.  Main thread
    only (elsewhere a no-op yielding ``None``)."""
    if not _main():
        yield None
        return
    frame = _Frame(info)
    _FRAMES.append(frame)
    try:
        yield frame
    finally:
        if _FRAMES and _FRAMES[-1] is frame:
            _FRAMES.pop()
        elif frame in _FRAMES:      # pragma: no cover - scopes always nest
            _FRAMES.remove(frame)


def finished(item: CheckResult | Report) -> None:
    """A record (or a unit's report) finished in the innermost :func:`scope` (main thread only)."""
    if _FRAMES and _main():
        _FRAMES[-1].items.append(item)


def collected() -> Report:
    """Everything finished so far in the open scopes, outermost first (convergence studies included)."""
    report = Report()
    for frame in list(_FRAMES):
        for item in list(frame.items):
            if isinstance(item, Report):
                report.extend(item)
            else:
                report.add(item)
                if getattr(item, "study", None) is not None:
                    report.studies.append(item.study)
    return report


def hang_report(hang: Hang) -> Report:
    """:func:`collected` followed by the failed record of the hung call."""
    report = collected()
    report.add(hang.record())
    return report


def _context() -> dict[str, Any]:
    out: dict[str, Any] = {}
    for frame in reversed(list(_FRAMES)):
        if "check" not in out and frame.info.get("check") is not None:
            out.update(check=frame.info["check"], subject=frame.info.get("subject"))
        if "stage" not in out and frame.info.get("stage") is not None:
            out.update(stage=frame.info["stage"], label=frame.info.get("label"))
    return out


def _where() -> str:
    """The innermost Python line of the main thread (where it called into native code)."""
    frame = sys._current_frames().get(threading.main_thread().ident or -1)
    if frame is None:
        return ""
    code = frame.f_code
    return f"{os.path.basename(code.co_filename)}:{frame.f_lineno} in {code.co_name}"


# -- the limits and the thread watching them -------------------------------------------------------------

@dataclasses.dataclass
class _Limit:
    call: str
    seconds: float
    start: float
    reported: bool = False

    @property
    def due(self) -> float:
        return self.start + self.seconds + grace(self.seconds)


_LIMITS: list[_Limit] = []
_HANDLERS: list[tuple[Callable[[Hang], None], bool]] = []
_COND = threading.Condition()
_THREAD: threading.Thread | None = None
#: when the watchdog thread wakes next by itself (``time.monotonic``; ``inf``: only when notified), under ``_COND``.
#: A limit whose deadline is not earlier needs no wake-up: the thread re-reads the innermost limit when it wakes, and
#: a limit that ended before then is simply no longer there (a notification per limit switched threads twice a law)
_WAKE_AT = float("inf")


@contextmanager
def limit(seconds: float, call: str) -> Iterator[None]:
    """Watch the block as a time limit of ``seconds`` (armed now in the main thread by
    :func:`verimono.execution.timeouts.time_limit`) naming ``call``.  Nested blocks: the innermost is watched."""
    global _THREAD
    if not _main():
        yield
        return
    entry = _Limit(call, float(seconds), time.monotonic())
    with _COND:
        _LIMITS.append(entry)
        if _THREAD is None or not _THREAD.is_alive():
            _THREAD = threading.Thread(target=_watch, name=THREAD_NAME, daemon=True)
            _THREAD.start()
        _arm_backstop()
        if entry.due < _WAKE_AT:        # the thread would wake too late for this limit (or not at all)
            _COND.notify_all()
    try:
        yield
    finally:
        with _COND:
            if entry in _LIMITS:
                _LIMITS.remove(entry)
            _arm_backstop()


def _watch() -> None:
    global _WAKE_AT
    while True:
        with _COND:
            while True:
                top = _LIMITS[-1] if _LIMITS else None
                if top is None or top.reported:
                    if _stale_backstop():           # no limit to back: cancel the timer before it fires
                        left = _BACKSTOP_AT - STALE_MARGIN - time.monotonic()
                        if left <= 0:
                            _cancel_backstop()
                            continue
                        _WAKE_AT = _BACKSTOP_AT - STALE_MARGIN
                        _COND.wait(left)
                        continue
                    _WAKE_AT = math.inf
                    _COND.wait()
                    continue
                left = top.due - time.monotonic()
                if left <= 0:
                    break
                _WAKE_AT = top.due
                _COND.wait(left)
            _WAKE_AT = math.inf
            top.reported = True
            hang = Hang(top.call, top.seconds, time.monotonic() - top.start, where=_where(), **_context())
            handler = _HANDLERS[-1][0] if _HANDLERS else _warn
        try:
            handler(hang)
        except BaseException as exc:   # pragma: no cover - a handler must not kill the watchdog silently
            print(f"verimono: the handler of a call blocked in native code failed ({type(exc).__name__}: "
                  f"{exc})", file=sys.stderr, flush=True)


def _warn(hang: Hang) -> None:
    """No handler (the Python API in the user's interpreter): say so once, never end the process."""
    at = f" at {hang.where}" if hang.where else ""
    print(f"verimono: warning: {hang.call} has run {hang.elapsed:.1f} s, past its time budget of "
          f"{hang.budget:g} s: it is blocked in native code{at}, which the time limit stops only when it "
          "returns to Python. verimono does not end your interpreter: the call goes on until it returns. "
          "To bound it, run the battery in worker processes: check_stepper(..., executor=\"process:N\"), "
          "check_operator(..., executor=\"process:1\") or `verimono check --executor process:N`.",
          file=sys.stderr, flush=True)


@contextmanager
def on_hang(handler: Callable[[Hang], None], *, backstop: bool = True) -> Iterator[None]:
    """Within the block, a call blocked in native code is handed to ``handler(hang)`` (from the watchdog
    thread; it should end the process: see the module docstring).  ``backstop``: also arm the
    :mod:`faulthandler` backstop for a call that holds the GIL (install it only in a process verimono owns)."""
    entry = (handler, backstop)
    with _COND:
        _HANDLERS.append(entry)
        _arm_backstop()
    try:
        yield
    finally:
        with _COND:
            if entry in _HANDLERS:
                _HANDLERS.remove(entry)
            _arm_backstop()


_BACKSTOP_ARMED = False
#: when the armed backstop fires (``time.monotonic``; ``inf``: not armed), under ``_COND``
_BACKSTOP_AT = math.inf
#: set by :func:`ending`: the process is being ended, the limits no longer move the backstop
_ENDING = False
#: seconds a handler has, from :func:`ending`, to write what finished before the backstop ends the process
ENDING_SECONDS = 120.0
#: the backstop's slack, a fraction of the limit's grace: it is armed at ``budget + (2 + BACKSTOP_SLACK) x grace``
#: and kept for every later limit whose ``budget + 2 x grace`` it does not precede (see :func:`_arm_backstop`)
BACKSTOP_SLACK = 0.5
#: seconds before a backstop that no limit needs any more fires at which the watchdog thread cancels it (it fires
#: at least ``(2 + BACKSTOP_SLACK) x GRACE_MIN`` = 5 s after the last limit opened)
STALE_MARGIN = GRACE_MIN


def _backstop_in(seconds: float) -> None:
    global _BACKSTOP_ARMED, _BACKSTOP_AT
    import faulthandler

    try:
        seconds = max(seconds, 0.1)
        faulthandler.dump_traceback_later(seconds, exit=True, file=sys.__stderr__ or 2)
        _BACKSTOP_ARMED, _BACKSTOP_AT = True, time.monotonic() + seconds
    except (ValueError, RuntimeError, OSError, AttributeError):   # pragma: no cover - no usable stderr
        pass


def _cancel_backstop() -> None:
    global _BACKSTOP_ARMED, _BACKSTOP_AT
    import faulthandler

    if _BACKSTOP_ARMED:
        faulthandler.cancel_dump_traceback_later()
    _BACKSTOP_ARMED, _BACKSTOP_AT = False, math.inf


def _wants_backstop() -> bool:
    return bool(_HANDLERS) and _HANDLERS[-1][1]


def _stale_backstop() -> bool:
    """An armed backstop that no limit needs (with ``_COND``): none is open.  (One whose limit has been reported
    stays armed, as before: the handler ends the process, :func:`ending` re-arming it first.)"""
    return _BACKSTOP_ARMED and not _ENDING and not _LIMITS


def _arm_backstop() -> None:
    """(Re)arm :mod:`faulthandler`'s timer for the innermost limit while a handler asks for it (with ``_COND``).

    Each arming starts a C thread and each cancel joins it, holding the GIL until that thread has run: with every
    core busy (a run's workers) the join waits for a core, ~1-4 ms of the main thread's wall, once per limit
    (~1,700 limits in a ``ci`` run's untimed stages).  So the timer is armed at ``budget + (2 + BACKSTOP_SLACK) x
    grace`` of the innermost limit and kept while it fires no earlier than ``budget + 2 x grace`` of the limit
    open now (the limits of a law's phases follow one another within the slack, at least 1 s): the backstop ends a
    process blocked with the GIL held at ``budget + 2 x grace`` to ``budget + 2.5 x grace``, never earlier.  When no
    limit is open the timer is left armed, and the watchdog thread cancels it :data:`STALE_MARGIN` seconds before
    it fires if still no limit needs it (:func:`_watch`); a fork cancels it first (:func:`_before_fork`).  A
    handler removed, or a limit reported as a hang, cancels it at once, as :func:`ending` re-arms it at once."""
    if _ENDING:
        return
    if _wants_backstop() and _LIMITS and not _LIMITS[-1].reported:
        top = _LIMITS[-1]
        g = grace(top.seconds)
        earliest = top.start + top.seconds + 2 * g
        if not (_BACKSTOP_ARMED and earliest <= _BACKSTOP_AT <= earliest + BACKSTOP_SLACK * g):
            _backstop_in(earliest + BACKSTOP_SLACK * g - time.monotonic())
    elif _BACKSTOP_ARMED and not (_wants_backstop() and not _LIMITS):
        _cancel_backstop()


def ending(seconds: float = ENDING_SECONDS) -> None:
    """A handler calls this first: the process is being ended, and the backstop now ends it ``seconds``
    from now should the handler itself get stuck (a write that blocks on what the hung call holds)."""
    global _ENDING
    with _COND:
        _ENDING = True
        _backstop_in(seconds)


def kill_descendants() -> int:
    """SIGKILL every descendant process of this one (an ``os.system`` command the blocked call started);
    how many.  Linux (``/proc/<pid>/task/<tid>/children``); elsewhere nothing is killed."""
    found: list[int] = []
    todo = [os.getpid()]
    while todo:
        pid = todo.pop()
        try:
            tasks = os.listdir(f"/proc/{pid}/task")
        except OSError:
            continue
        for tid in tasks:
            try:
                with open(f"/proc/{pid}/task/{tid}/children") as fh:
                    kids = [int(k) for k in fh.read().split()]
            except (OSError, ValueError):
                continue
            found += kids
            todo += kids
    for pid in found:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    return len(found)


def end_process(status: int) -> None:
    """Flush the standard streams, end the descendants (:func:`kill_descendants`) and ``os._exit(status)``."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # noqa: BLE001 - a closed stream must not keep the process alive
            pass
    kill_descendants()
    os._exit(status)


def _after_fork_in_child() -> None:
    """A forked child (a process pool of a convergence study) runs none of its parent's limits, handlers or
    scopes, and has no watchdog thread or backstop timer of its own yet."""
    global _COND, _THREAD, _BACKSTOP_ARMED, _ENDING, _WAKE_AT, _BACKSTOP_AT
    _LIMITS.clear()
    _HANDLERS.clear()
    _FRAMES.clear()
    _COND, _THREAD, _BACKSTOP_ARMED, _ENDING = threading.Condition(), None, False, False
    _WAKE_AT = math.inf             # the parent's thread's wake-up time is not the child's (it has no thread yet)
    _BACKSTOP_AT = math.inf


#: whether :func:`_before_fork` cancelled a backstop that an open limit needs (re-armed after the fork)
_REARM_AFTER_FORK = False


def _before_fork() -> None:
    """The backstop is cancelled before a fork: the child would inherit :mod:`faulthandler`'s state of a timer whose
    thread it has not got, and its own first arming would wait for that thread for ever (seen: a child forked
    with a timer armed hangs in its first ``dump_traceback_later``).  The parent re-arms it after the fork if a limit still needs
    it (:func:`_after_fork_in_parent`); a backstop that no limit needs is simply gone."""
    global _REARM_AFTER_FORK
    with _COND:
        _REARM_AFTER_FORK = False
        if _BACKSTOP_ARMED and not _ENDING:
            _REARM_AFTER_FORK = not _stale_backstop()
            _cancel_backstop()


def _after_fork_in_parent() -> None:
    global _REARM_AFTER_FORK
    with _COND:
        if _REARM_AFTER_FORK:
            _REARM_AFTER_FORK = False
            _arm_backstop()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(before=_before_fork, after_in_parent=_after_fork_in_parent,
                        after_in_child=_after_fork_in_child)


__all__ = ["Hang", "grace", "limit", "on_hang", "scope", "finished", "collected", "hang_report", "ending",
           "kill_descendants", "end_process", "GRACE_MIN", "GRACE_FRACTION", "HANG_DETAIL", "UNIT_CHECK"]
