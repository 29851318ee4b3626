"""The console a command prints to, which never costs the run its results (issue 41, item 2).

``verimono check ... | head -c 20``, a closed stdout or stderr (``>&-``, ``2>&-``), a terminal that went away
(SSH dropped), a full disk under a redirection: the first write that fails (``BrokenPipeError``, any ``OSError``,
a stream closed or absent, ``sys.stderr is None``) ends *printing* — that stream's later writes are dropped, and
its file descriptor is pointed at ``/dev/null`` so that the interpreter's own flush at exit does not fail again —
while the run goes on: its results and report are written (they are written before the console is told
anything, :func:`verimono.cli._finish`) and its exit status is the verdict's, as it would have been on a
terminal.  Forked workers inherit the guarded streams.

:func:`guarded` installs the guard on ``sys.stdout`` and ``sys.stderr`` for the length of a command and puts the
streams it found back afterwards (the command line is also called in-process, from tests and notebooks).
"""

from __future__ import annotations

import contextlib
import os
import sys
from typing import Any, Iterator


class GuardedStream:
    """``stream`` (or nothing: ``None``) whose writes and flushes never raise: the first failure silences it."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream
        #: why printing ended on this stream (``None`` while it works)
        self.lost: str | None = None if stream is not None else "the stream is closed"

    @property
    def wrapped(self) -> Any:
        return self._stream

    def _lose(self, exc: BaseException) -> None:
        self.lost = f"{type(exc).__name__}: {exc}"
        try:                  # the interpreter's flush at exit writes the buffer's rest: into /dev/null, not a pipe
            fd = self._stream.fileno()
            null = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(null, fd)
            finally:
                os.close(null)
        except (AttributeError, OSError, ValueError):
            pass

    def write(self, text: str) -> int:
        if self.lost is None:
            try:
                return self._stream.write(text)
            except (OSError, ValueError) as exc:      # ValueError: I/O operation on a closed file
                self._lose(exc)
        return len(text)

    def flush(self) -> None:
        if self.lost is None:
            try:
                self._stream.flush()
            except (OSError, ValueError) as exc:
                self._lose(exc)

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def isatty(self) -> bool:
        if self.lost is not None:
            return False
        try:
            return bool(self._stream.isatty())
        except (OSError, ValueError):
            return False

    def writable(self) -> bool:
        return True

    @property
    def closed(self) -> bool:
        return False

    def fileno(self) -> int:
        if self._stream is None:
            raise OSError("the stream is closed")
        return self._stream.fileno()

    def __getattr__(self, name: str) -> Any:        # encoding, errors, buffer, ... of the stream it guards
        if self._stream is None:
            raise AttributeError(name)
        return getattr(self._stream, name)


@contextlib.contextmanager
def guarded() -> Iterator[tuple[GuardedStream, GuardedStream]]:
    """``sys.stdout`` and ``sys.stderr`` guarded (:class:`GuardedStream`) inside the block, flushed at its end
    through the guard, and the streams found put back."""
    found = sys.stdout, sys.stderr
    out = found[0] if isinstance(found[0], GuardedStream) else GuardedStream(found[0])
    err = found[1] if isinstance(found[1], GuardedStream) else GuardedStream(found[1])
    sys.stdout, sys.stderr = out, err         # type: ignore[assignment]
    try:
        yield out, err
    finally:
        out.flush()
        err.flush()
        if sys.stdout is out:
            sys.stdout = found[0]
        if sys.stderr is err:
            sys.stderr = found[1]


__all__ = ["GuardedStream", "guarded"]
