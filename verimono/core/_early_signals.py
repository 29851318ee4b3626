"""The ``verimono`` command before its :func:`verimono.cli.console_main` runs: its first imports (NumPy, SciPy,
hypothesis, the checks: about 2 s on a loaded machine) are not yet inside any handler, and Ctrl-C, SIGTERM or
SIGHUP there printed a raw ``KeyboardInterrupt`` traceback.  :func:`quiet_until_main` makes each of them one line
and exit status 130 (nothing has been written yet: the run marks its folder only once its options are read);
``console_main`` installs the command's own handlers when it begins.  Only the console script's process installs
it (``verimono/__init__.py``): importing verimono anywhere else changes no signal handler."""

from __future__ import annotations

import os
import signal
import threading

#: exit status of an interrupted command (the shell's convention for SIGINT)
EXIT_INTERRUPTED = 130


def _before_main(signum: int, frame: object) -> None:
    try:
        name = signal.Signals(signum).name
    except ValueError:  # pragma: no cover
        name = f"signal {signum}"
    try:
        os.write(2, f"\nverimono: interrupted ({name}) while starting; nothing was run or written\n".encode())
    except OSError:
        pass
    os._exit(EXIT_INTERRUPTED)


def quiet_until_main() -> None:
    """Ctrl-C, SIGTERM and SIGHUP end the process with one line and status 130 (main thread only)."""
    if threading.current_thread() is not threading.main_thread():   # pragma: no cover
        return
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None and signal.getsignal(sig) in (signal.default_int_handler, signal.SIG_DFL):
            signal.signal(sig, _before_main)


__all__ = ["EXIT_INTERRUPTED", "quiet_until_main"]
