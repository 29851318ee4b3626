"""Atomic, consistent output files.

Every file verimono writes (``results.json``, ``report.html``, a baseline) is written to a temporary file
in the same folder, flushed to disk, and renamed over the target (``os.replace``, atomic on POSIX and
Windows): a full disk, a crash or an interrupt leaves either the previous file or the new one, never a
truncated mix.  :func:`replace_all` writes several files that belong together (the results and the
report of one run, which carry the same ``run_id``) — all temporaries first, then all renames, with
SIGINT/SIGTERM held back during the renames so an interrupt cannot fall between them.
"""

from __future__ import annotations

import os
import signal
import stat
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator, Mapping

from .errors import OutputNotWritable


def _umask() -> int:
    """The process umask, read without changing it where Linux says it (``/proc/self/status``); elsewhere
    by setting and restoring it."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def file_mode(path: Path) -> int:
    """The permission bits ``open(path, "w")`` would leave ``path`` with: its own when it exists (a regular
    file), else ``0o666`` less the umask."""
    try:
        st = os.stat(path)
        if stat.S_ISREG(st.st_mode):
            return stat.S_IMODE(st.st_mode)
    except OSError:
        pass
    return 0o666 & ~_umask()


def _temp_for(path: Path, text: str) -> Path:
    """Write ``text`` to a new temporary file next to ``path`` (same filesystem, the mode of
    :func:`file_mode`) and return its path."""
    fd, tmp = tempfile.mkstemp(dir=str(path.parent), prefix=f".{path.name}.", suffix=".tmp")
    try:
        try:
            os.fchmod(fd, file_mode(path))
        except (OSError, AttributeError):   # a filesystem without modes, or no fchmod: keep mkstemp's
            pass
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
    except BaseException:
        _unlink(Path(tmp))
        raise
    return Path(tmp)


def _unlink(p: Path) -> None:
    try:
        p.unlink()
    except OSError:
        pass


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold SIGINT/SIGTERM back (delivered on exit) in the main thread; a no-op elsewhere."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    held = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def replace_all(files: Mapping[str | os.PathLike, str]) -> list[Path]:
    """Write every ``path → text`` atomically and together: all temporaries, then all renames.

    On any error while writing the temporaries (``ENOSPC``, permissions) every temporary is removed and
    no target is touched, so the previous files stay intact.  Parents must exist.
    """
    targets = [Path(p) for p in files]
    temps: list[Path] = []
    try:
        for path, text in zip(targets, files.values()):
            temps.append(_temp_for(path, text))
    except BaseException:
        for t in temps:
            _unlink(t)
        raise
    with _signals_held(), _folder_lock(targets[0].parent if len(targets) > 1 else None):
        for tmp, path in zip(temps, targets):
            os.replace(tmp, path)
    return targets


@contextmanager
def _folder_lock(folder: Path | None) -> Iterator[None]:
    """An exclusive ``flock`` on ``folder/.verimono.lock`` while a pair is renamed: two runs writing into
    one folder rename their pairs one after the other, never interleaved (a no-op without ``fcntl``)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        fcntl = None
    if folder is None or fcntl is None:
        yield
        return
    with open(folder / ".verimono.lock", "a+") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (parents created); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return replace_all({path: text})[0]


def ensure_writable_dir(folder: str | os.PathLike) -> Path:
    """Create ``folder`` if needed and prove it writable by creating and removing a file in it;
    :class:`OutputNotWritable` otherwise.  Called before a run starts, not after its work is lost."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=str(folder), prefix=".verimono-probe.", suffix=".tmp")
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise OutputNotWritable(f"cannot write to the output folder {folder}: {exc.strerror or exc}") from None
    return folder


def ensure_writable_file(path: str | os.PathLike) -> Path:
    """:func:`ensure_writable_dir` on the parent of ``path``, and ``path`` is not a folder."""
    path = Path(path)
    if path.is_dir():
        raise OutputNotWritable(f"{path} is a folder, not a file")
    ensure_writable_dir(path.parent if str(path.parent) else Path("."))
    return path


__all__ = ["OutputNotWritable", "replace_all", "write_text", "ensure_writable_dir", "ensure_writable_file"]
