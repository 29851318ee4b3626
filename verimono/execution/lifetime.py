"""Every process a run starts ends with it, however the run ends (issue 41, item 3).

A run's helper processes — its ``process:N`` workers (:mod:`verimono.execution.workers`) and the command line's
forked copy that measures the calibration and then draws the plots
(:class:`verimono.execution.calibration.PendingCalibration`) — must not outlive the process that started them.
A leader that ends normally, or on an interrupt it handles (Ctrl-C, SIGTERM, SIGHUP), stops them itself; one
that is killed outright (``SIGKILL``, the OOM killer, a crash in native code) cannot.  Waiting for a pipe to
close is not enough either: every forked copy inherits the ends of its siblings' pipes, so the workers and the
drawer kept each other alive — a ``SIGKILL`` of ``verimono run --profile ci`` 6 s in left three worker processes
asleep for 73 minutes.  So each helper watches its leader (:func:`die_with`):

* on Linux the kernel does: ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` (through ``ctypes``) sends the helper
  ``SIGKILL`` the moment the thread that started it ends — used only when the leader started it from its main
  thread (whose end is the process's end), so a helper started from a short-lived thread of the user's is not
  killed with that thread;
* elsewhere (or when ``prctl`` is refused, or the helper was started from another thread) a daemon thread
  polls ``os.getppid()`` every :data:`POLL` seconds and ends the process (``os._exit``) once it is no longer
  the leader's pid (the orphan was adopted by init or a subreaper);
* in both cases the leader may already be gone before the watch begins: checked once after arming.

:func:`quiet_signals` gives a helper the signal dispositions of a helper, not of its leader (a forked copy
inherits the leader's Python handlers, which turned SIGTERM into a ``KeyboardInterrupt`` and printed about
20 lines of traceback per process): Ctrl-C is the leader's to answer (``SIGINT`` ignored: the terminal sends it
to the whole process group, and the leader stops its helpers), ``SIGTERM`` and ``SIGHUP`` end the helper at
once, quietly (the default action).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

#: seconds between two looks at the parent pid by the portable watch
POLL = 0.5
#: ``PR_SET_PDEATHSIG`` (linux/prctl.h)
PR_SET_PDEATHSIG = 1
#: exit status of a helper that ended because its leader had gone
ORPHANED_EXIT = 4


def _prctl_deathsig() -> bool:
    """``prctl(PR_SET_PDEATHSIG, SIGKILL)`` on Linux; whether it was armed."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError, ValueError):  # pragma: no cover - no libc prctl: the portable watch
        return False


def _watch(parent: int) -> None:
    while True:
        time.sleep(POLL)
        if os.getppid() != parent:
            os._exit(ORPHANED_EXIT)


def die_with(parent: int, *, kernel: bool = True) -> str:
    """End this process when ``parent`` (the pid of the process that started it) ends: the kernel's
    ``PR_SET_PDEATHSIG`` where ``kernel`` (the parent started it from its main thread) and Linux allow, else a
    watch thread (see the module docstring).  Ends at once when ``parent`` is already gone.  Returns how it
    watches: ``"prctl"`` or ``"thread"``."""
    how = "prctl" if kernel and _prctl_deathsig() else "thread"
    if os.getppid() != parent:      # gone before the watch began
        os._exit(ORPHANED_EXIT)
    if how == "thread":
        threading.Thread(target=_watch, args=(parent,), name="verimono-leader-watch", daemon=True).start()
    return how


def quiet_signals() -> None:
    """A helper's dispositions (main thread only): ``SIGINT`` ignored (the leader answers Ctrl-C and stops
    its helpers), ``SIGTERM`` and ``SIGHUP`` the default (the helper ends quietly, no traceback)."""
    if threading.current_thread() is not threading.main_thread():   # pragma: no cover
        return
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None:
            signal.signal(sig, signal.SIG_DFL)


def started_from_main_thread() -> bool:
    """Whether the current thread is the main thread (so a helper started now may use the kernel's watch)."""
    return threading.current_thread() is threading.main_thread()


__all__ = ["ORPHANED_EXIT", "POLL", "die_with", "quiet_signals", "started_from_main_thread"]
