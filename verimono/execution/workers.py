"""What runs on a worker process: a shipped unit, the worker's loop, how a unit is shipped and how workers
start.

A unit travels as ``cloudpickle.dumps((config, fn, args, limits, stage, label))`` (``_ship``): closures,
lambdas and a ``verimono check`` target loaded from a file travel by value, with the run configuration
(:mod:`verimono.execution.config`) and the run's calibration; :func:`run_payload` runs it under them and
answers ``("ok", report)``, ``("error", ...)`` or, from a worker whose unit blocked in native code,
``("hang", report)``.  Workers are forked where that is safe, else spawned (:func:`start_method`).
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import time
import traceback
from typing import Any, Iterator

from . import config as _config
from . import watchdog
from .calibration import calibration, set_calibration
from .lifetime import die_with, quiet_signals
from .config import RunConfig
from ..core.errors import BadExecutor
from .profiles import load_hypothesis_profile
from ..records.results import UNDECIDED, Report
from .units import Unit, config_for, raised, unit_failure, unit_record
from ..records.verdicts import SUBJECT_EXITS

#: BLAS threads for a verification run, in its process and its workers: every matrix here is small, so extra
#: BLAS threads only contend for the cores; on the 2-core reference machine, under load, threaded OpenBLAS made
#: the catalog's convergence studies vary from 0.4 s to 31 s, against a steady 0.4 s single-threaded
BLAS_THREADS = 1


@functools.cache
def _one_blas_thread() -> None:
    """:data:`BLAS_THREADS` in this process, as in the ``verimono run`` process (once: threadpoolctl inspects
    every loaded library, 1.3 ms a call here)."""
    try:
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=BLAS_THREADS, user_api="blas")
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        pass


@contextlib.contextmanager
def blas_limited() -> Iterator[None]:
    """:data:`BLAS_THREADS` for the BLAS libraries loaded now, and their own limits again after: what
    ``verimono run`` and ``verimono check`` hold for their whole process, for one battery called from a user's
    Python (:func:`verimono.check_operator`, :func:`verimono.check_stepper`).  The subject's own calls in the
    battery run under it too, as under the command line.  Measured on the 2-core machine under load (branch
    bigop2, docs/speed.md): ``check_operator`` at n = 10^5 took 63-74 s of CPU with OpenBLAS's default threads
    against 10 s with one; limiting only verimono's own row arithmetic gave 58.6 s (most threaded products are
    the laws' norms and the subject's own)."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        yield
        return
    with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
        yield


def _prepare_worker(cfg: RunConfig) -> None:
    """The run's hypothesis profile (loaded again for every unit: a unit may load another; a user's own
    profile is not registered in a fresh worker, so only verimono's) and one BLAS thread."""
    if cfg.effort is not None:
        load_hypothesis_profile(cfg.profile)
    _one_blas_thread()


def run_payload(payload: bytes) -> bytes:
    """Run one shipped unit: ``payload`` is ``cloudpickle.dumps((config, fn, args, limits, stage, label))``
    (``config``: the run configuration, :mod:`verimono.execution.config` — profile, explicit budget, seed —
    under which the unit runs here; ``limits``: the sending process's calibration, the unit of the profile's
    budgets — :func:`_limits` — applied here too, so a worker's budgets are the run's); the answer is
    :func:`run_job`'s.  A payload that cannot be read here (a module the worker cannot import) is a limit of
    the executor: undecided, never the subject's failure."""
    import cloudpickle

    try:
        job = cloudpickle.loads(payload)
    except Exception as exc:  # noqa: BLE001 - the executor's limit, said in the record
        return cloudpickle.dumps(("error", UNDECIDED, f"the unit could not be read on its worker process "
                                  f"({type(exc).__name__}: {exc})", type(exc).__name__, traceback.format_exc(limit=8),
                                  0.0))
    return run_job(*job)


def run_job(cfg: RunConfig, fn: Any, args: tuple, limits: dict, stage: str, label: str) -> bytes:
    """Run one unit here, under the run configuration ``cfg`` and the run's calibration (``limits``); the
    answer is ``cloudpickle.dumps(("ok", report))`` or ``("error", status, message, exception type,
    traceback, seconds)`` (the exception judged here, :func:`raised`; records that cannot be pickled back
    are undecided) — never an exception, so a unit's own error is told apart from the worker's death.  (A
    ``process:N`` worker whose unit blocks in native code answers ``("hang", report)`` instead and exits:
    :func:`_process_worker`.)"""
    import cloudpickle

    start = time.perf_counter()
    try:
        _prepare_worker(cfg)
        if limits.get("calibration"):
            set_calibration(limits["calibration"])
        with watchdog.scope(stage=stage, label=label), _config.using(cfg):
            out = fn(*args)
        if not isinstance(out, Report):
            raise TypeError(f"a unit returned {type(out).__name__}, expected a verimono.Report")
    except (Exception, *SUBJECT_EXITS) as exc:
        status, message = raised(exc)     # judged here, where the exception is
        return cloudpickle.dumps(("error", status, message, type(exc).__name__, traceback.format_exc(limit=8),
                                  time.perf_counter() - start))
    try:
        return cloudpickle.dumps(("ok", out))
    except Exception as exc:  # noqa: BLE001 - its records cannot travel back: the executor's limit
        return cloudpickle.dumps(("error", UNDECIDED, f"its records could not be sent back from its worker process "
                                  f"({type(exc).__name__}: {exc})", type(exc).__name__, None,
                                  time.perf_counter() - start))


def _decode(unit: Unit, answer: bytes) -> Report:
    return _decode_answer(unit, answer)[0]


def _decode_answer(unit: Unit, answer: bytes) -> tuple[Report, bool]:
    """The report an answer stands for, and whether its worker has ended (a unit blocked in native code:
    the records it finished and the failed record of the hung call)."""
    import cloudpickle

    try:
        out = cloudpickle.loads(answer)
    except Exception as exc:
        return unit_failure(unit, f"its result could not be read back ({type(exc).__name__}: {exc})"), False
    if out[0] == "ok":
        return out[1], False
    if out[0] == "hang":
        return out[1], True
    _, status, message, exception, traceback_text, duration = out
    return unit_record(unit, status, message, exception=exception, traceback_text=traceback_text,
                       duration=duration), False


#: seconds a new worker process may take to import verimono and say it is ready
WORKER_START_TIMEOUT = 300.0


#: exit status of a worker that ended itself on a unit blocked in native code (after answering for it)
HANG_EXIT = 3


def _process_worker(conn: Any, job: tuple | None = None, leader: int | None = None, kernel: bool = True) -> None:
    """Loop of a ``process:N`` worker: say ``ready`` once verimono is imported (so a unit's timeout does
    not count the worker's start), then receive a payload and answer, until an empty message.  With ``job``
    (the arguments of :func:`run_job`, in the memory of a forked process: nothing of it was pickled) it runs
    that one unit, answers and returns: a unit that cannot be pickled (:mod:`verimono.execution.executors`).

    A call of the unit blocked in native code past its time budget (:mod:`verimono.execution.watchdog`) cannot be
    interrupted: the watchdog thread answers for the unit instead — ``("hang", report)``, the records the
    unit finished and the failed record of the hung call — ends the call's child processes and exits
    (status :data:`HANG_EXIT`); the parent replaces the worker.  One answer per payload, whichever comes
    first (``lock``).

    ``leader``: the pid of the process that started it: the worker ends when that process ends, however it
    ends — ``SIGKILL`` included (:func:`verimono.execution.lifetime.die_with`; ``kernel``: it was started from
    the leader's main thread, so the kernel may watch) — and has a helper's signal dispositions
    (:func:`verimono.execution.lifetime.quiet_signals`: Ctrl-C is the leader's; SIGTERM and SIGHUP end it
    quietly)."""
    import threading

    quiet_signals()
    if leader is not None:
        die_with(leader, kernel=kernel)

    import cloudpickle
    import scipy.linalg  # noqa: F401  (with numpy and verimono, imported here: what every unit needs)

    # spawn passed the connection as an inheritable descriptor: a child process of the unit's (os.system)
    # would hold it open, and the parent would not see this worker's end until that child's
    os.set_inheritable(conn.fileno(), False)
    lock, state = threading.Lock(), {"busy": False}

    def on_hang(hang: watchdog.Hang) -> None:
        with lock:
            if not state["busy"]:     # pragma: no cover - the unit returned meanwhile: nothing to answer
                return
            watchdog.ending()
            try:
                conn.send_bytes(cloudpickle.dumps(("hang", watchdog.hang_report(hang))))
            except Exception:  # noqa: BLE001 - the parent then sees a dead worker, which it reports too
                pass
            watchdog.end_process(HANG_EXIT)

    conn.send_bytes(b"ready")
    with watchdog.on_hang(on_hang):
        if job is not None:
            state["busy"] = True
            answer = run_job(*job)
            with lock:
                state["busy"] = False
                conn.send_bytes(answer)
            return
        while True:
            try:
                payload = conn.recv_bytes()
            except (EOFError, OSError):
                return
            if not payload:
                return
            state["busy"] = True
            answer = run_payload(payload)
            with lock:
                state["busy"] = False
                conn.send_bytes(answer)


def _limits() -> dict[str, float | None]:
    """What a worker needs besides the run configuration to bound a unit as this process would: this
    process's calibration (the unit of the profile's budgets)."""
    return {"calibration": calibration()}


SHIP_ATTEMPTS = 3


def _ship(unit: Unit, profile: RunConfig | str | None) -> bytes:
    """``unit`` pickled for a worker.  A ``RuntimeError`` while pickling (a dict the pickler walks changed size
    under it: another thread importing, a collection run by a weakref callback) may be transient, so it is tried
    again, up to ``SHIP_ATTEMPTS`` times in all; any other error, or the same one every time, goes to the caller,
    which runs the unit where nothing is pickled and says why.  (A long-lived pytest-xdist worker met "dictionary
    changed size during iteration" at every attempt on a locked module, whose own error is "cannot pickle": which
    dict changes is not known yet, docs/tests.md.)"""
    import cloudpickle

    _register_targets_by_value()
    payload = (config_for(profile), unit.fn, unit.args, _limits(), unit.stage, unit.label)
    for attempt in range(SHIP_ATTEMPTS):
        try:
            return cloudpickle.dumps(payload)
        except RuntimeError:
            if attempt == SHIP_ATTEMPTS - 1:
                raise
    raise AssertionError("unreachable")  # pragma: no cover


def _register_targets_by_value() -> None:
    """A ``verimono check`` target loaded from a ``.py`` file lives in a module no worker can import:
    ship that module's functions by value."""
    import sys

    import cloudpickle

    for name, module in list(sys.modules.items()):
        if name.startswith("verimono_target_") and module is not None:
            try:
                cloudpickle.register_pickle_by_value(module)
            except ValueError:  # pragma: no cover - already registered
                pass


def ship_by_value(obj: Any) -> None:
    """Let workers that cannot import ``obj``'s module still run it: a module of the user's (not verimono's,
    not an installed distribution's) is shipped by value with every unit (``cloudpickle``)."""
    import sys

    import cloudpickle

    module = sys.modules.get(getattr(obj, "__module__", None) or "")
    path = getattr(module, "__file__", None) or ""
    if module is None or module.__name__.split(".")[0] in ("verimono", "__main__") or "-packages" in path:
        return
    try:
        cloudpickle.register_pickle_by_value(module)
    except ValueError:  # pragma: no cover - a module cloudpickle refuses: it ships by reference
        pass


# -- how workers start ----------------------------------------------------------------------------------

#: modules whose native threads or devices do not survive ``fork`` (their own documentation says so): while
#: one is loaded, workers are spawned
FORK_UNSAFE = ("jax", "torch", "tensorflow", "cupy", "numba", "mxnet", "ray", "distributed", "grpc")


def start_method() -> str:
    """How the next worker process starts: ``fork`` — a copy of this process, ready at once, with verimono and
    the subject already imported — where that is safe: Linux, no other Python thread running (a thread
    holding a lock at the fork would leave it held in the copy forever) and none of :data:`FORK_UNSAFE`
    imported; ``spawn`` (a fresh interpreter importing verimono, about 0.8 s on a 2-core machine) otherwise.
    ``$VERIMONO_START_METHOD`` (``fork`` or ``spawn``) decides instead.  NumPy's OpenBLAS threads are safe:
    OpenBLAS stops them around a fork (``pthread_atfork``)."""
    import threading

    chosen = os.environ.get("VERIMONO_START_METHOD", "").strip().lower()
    if chosen in ("fork", "spawn"):
        return chosen
    if chosen:
        raise BadExecutor(f"$VERIMONO_START_METHOD must be fork or spawn, got {chosen!r}")
    safe = (sys.platform.startswith("linux") and threading.active_count() == 1
            and not any(name in sys.modules for name in FORK_UNSAFE))
    return "fork" if safe else "spawn"


__all__ = ["BLAS_THREADS", "blas_limited", "FORK_UNSAFE", "HANG_EXIT", "WORKER_START_TIMEOUT", "run_payload", "run_job", "ship_by_value",
           "start_method"]
