"""Atomic, consistent output files.

Every file verimono writes (``results.json``, ``report.html``, a baseline) is written to a temporary file
in the same folder, flushed to disk, and renamed over the target (``os.replace``, atomic on POSIX and
Windows): a full disk, a crash or an interrupt leaves either the previous file or the new one, never a
truncated mix.  :func:`replace_all` writes several files that belong together (the results and the
report of one run, which carry the same ``run_id``) — all temporaries first, then all renames, with
SIGINT/SIGTERM held back during the renames so an interrupt cannot fall between them.

Rules:

* a written file gets the mode a plain ``open(path, "w")`` would give it: the existing file's mode when
  it is replaced, else ``0o666`` less the process umask (``tempfile.mkstemp`` alone would make it 0600);
* any ``OSError`` while writing (a full disk, a read-only or unwritable folder) is raised as
  :class:`verimono.OutputNotWritable` (still an ``OSError``, with its ``errno``) whose one-line message
  names the file and says the previous one is unchanged;
* a run marks its results file *in progress* (:func:`mark_in_progress`: ``results.json.in-progress``
  next to it, holding the run id) before it starts and removes the mark once its own pair is in place
  (:func:`clear_in_progress`); a mark left behind (a run killed, or stopped by an error) says that the
  files beside it are not that run's, and the gate refuses them (:func:`in_progress`);
* a run's finished stages are saved as each finishes to ``results.json.partial`` next to the results
  (:func:`partial_path`), never over them: a run killed outright (``SIGKILL``, which no handler sees) leaves
  the previous results and report as they were, beside its mark and its partial file (``--resume`` reads it);
  the partial file goes with the mark once the run's own pair is in place (:func:`clear_in_progress`);
* :func:`keep_elsewhere` saves a document that could not be written where asked in the temporary folder.
"""

from __future__ import annotations

import json
import os
import signal
import stat
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator, Mapping

from ..core.errors import OutputNotWritable


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


def not_writable(path: Path, exc: OSError, what: str = "") -> OutputNotWritable:
    """:class:`OutputNotWritable` for ``exc`` while writing ``path``: one line naming the file, the
    reason, and ``what`` (e.g. that the previous file is unchanged); ``errno`` and ``filename`` kept."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    err = OutputNotWritable(f"cannot write {path}: {reason}" + (f"; {what}" if what else ""))
    err.errno, err.filename = exc.errno, str(path)
    return err


def replace_all(files: Mapping[str | os.PathLike, str]) -> list[Path]:
    """Write every ``path → text`` atomically and together: all temporaries, then all renames.

    On any error while writing the temporaries (``ENOSPC``, permissions) every temporary is removed and
    no target is touched, so the previous files stay intact; the error is an :class:`OutputNotWritable`
    naming the file.  Parents must exist.
    """
    targets = [Path(p) for p in files]
    temps: list[Path] = []
    path = targets[0] if targets else Path(".")
    try:
        for path, text in zip(targets, files.values()):
            temps.append(_temp_for(path, text))
    except BaseException as exc:
        for t in temps:
            _unlink(t)
        if isinstance(exc, OSError) and not isinstance(exc, OutputNotWritable):
            raise not_writable(path, exc, "the previous file there is unchanged") from None
        raise
    done = 0
    try:
        with _signals_held(), _folder_lock(targets[0].parent if len(targets) > 1 else None):
            for tmp, path in zip(temps, targets):
                os.replace(tmp, path)
                done += 1
    except OSError as exc:
        for t in temps[done:]:
            _unlink(t)
        if isinstance(exc, OutputNotWritable):
            raise
        raise not_writable(path, exc, "the previous file there is unchanged" if done == 0 else
                           f"{', '.join(str(p) for p in targets[:done])} already replaced") from None
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


# -- a run in progress -----------------------------------------------------------------------------------

#: suffix of the mark a run leaves next to its results file while it runs (``results.json.in-progress``)
IN_PROGRESS_SUFFIX = ".in-progress"


def in_progress_path(results: str | os.PathLike) -> Path:
    """Where the in-progress mark of the results file ``results`` lives."""
    results = Path(results)
    return results.with_name(results.name + IN_PROGRESS_SUFFIX)


def mark_in_progress(results: str | os.PathLike, run_id: str, **facts: object) -> Path:
    """Mark ``results`` as being (re)written by the run ``run_id`` (``facts``: command, started, pid, ...),
    before the run does any work; :class:`OutputNotWritable` if the mark cannot be written."""
    mark = in_progress_path(results)
    write_text(mark, json.dumps({"run_id": run_id, **facts}, default=str, indent=1))
    return mark


def in_progress(results: str | os.PathLike) -> dict | None:
    """The facts of the run marked in progress over ``results`` (``{"run_id": ...}`` at least), or
    ``None`` when no run is; a mark that cannot be read still counts as one (run id ``"?"``)."""
    mark = in_progress_path(results)
    if not os.path.lexists(mark):
        return None
    try:
        if mark.stat().st_size > 1 << 20:
            raise ValueError("too large")
        facts = json.loads(mark.read_text(encoding="utf-8"))
        if not isinstance(facts, dict):
            raise ValueError("not an object")
    except (OSError, ValueError):
        return {"run_id": "?", "mark": str(mark)}
    facts.setdefault("run_id", "?")
    facts["mark"] = str(mark)
    return facts


def clear_in_progress(results: str | os.PathLike, run_id: str) -> bool:
    """Remove the in-progress mark of ``results`` if it is the run ``run_id``'s (another run that started
    since keeps its own), and that run's partial file (:func:`partial_path`); whether it was removed."""
    facts = in_progress(results)
    if facts is None or facts.get("run_id") != run_id:
        return False
    _unlink(partial_path(results))
    _unlink(in_progress_path(results))
    return True


#: suffix of the file a run saves its finished stages to while it runs (``results.json.partial``)
PARTIAL_SUFFIX = ".partial"


def partial_path(results: str | os.PathLike) -> Path:
    """Where a run saves its finished stages while it runs (``results.json.partial``): beside the results,
    never over them, so that a run killed outright leaves the previous results intact."""
    results = Path(results)
    return results.with_name(results.name + PARTIAL_SUFFIX)


def keep_elsewhere(text: str, name: str) -> Path:
    """Save ``text`` as ``name`` (made unique) in the temporary folder (``$TMPDIR``), with the mode of a
    new file; returns its path, or raises ``OSError`` when that fails too."""
    stem, dot, ext = name.rpartition(".")
    fd, tmp = tempfile.mkstemp(dir=tempfile.gettempdir(), prefix=f"{stem or name}-", suffix=f"{dot}{ext}" if stem else "")
    try:
        try:
            os.fchmod(fd, 0o666 & ~_umask())
        except (OSError, AttributeError):
            pass
        with open(fd, "w", encoding="utf-8", closefd=True) as fh:
            fh.write(text)
    except BaseException:
        _unlink(Path(tmp))
        raise
    return Path(tmp)


__all__ = ["OutputNotWritable", "replace_all", "write_text", "ensure_writable_dir", "ensure_writable_file",
           "file_mode", "not_writable", "in_progress_path", "mark_in_progress", "in_progress", "clear_in_progress", "partial_path", "PARTIAL_SUFFIX",
           "keep_elsewhere", "IN_PROGRESS_SUFFIX"]
