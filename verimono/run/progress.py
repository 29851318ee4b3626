"""Progress of a run on the terminal: one redrawn line on a terminal, plain lines off one (or under CI)."""

from __future__ import annotations

import os
import shutil
import sys
import time
from typing import Any, TextIO

from ..records.results import Report


class Progress:
    """Progress of a run: on a terminal, one redrawn line (stage, units done / total within it, the
    current subject); otherwise — output not a terminal, or ``$CI`` set — quiet and line-oriented: one
    plain line per finished stage, and within a long stage at most one line every ``interval`` seconds."""

    def __init__(self, stream: TextIO | None = None, enabled: bool | None = None, interval: float = 60.0) -> None:
        self.stream = stream or sys.stderr
        if enabled is None:
            enabled = self.stream.isatty() and not _ci()
        self.tty = enabled
        self.stage, self.index, self.total = "", 0, 1
        self.running: dict[str, int] = {}     # the stages started and not yet done (several run at once)
        self._span = 1
        self.width = min(shutil.get_terminal_size((100, 20)).columns, 120)
        self.interval = interval
        self._last_line = time.monotonic()

    def start(self, stage: Any, index: int, total: int) -> None:
        self.running[stage.name] = index
        self.total = total
        self._running()
        self._last_line = time.monotonic()
        self.within(0, 1, "")

    def _running(self) -> None:
        """The stage(s) the line names: one, or ``"stages i-j"`` while several run at once (their units in one
        queue: the counts within are then over all of them)."""
        if not self.running:
            self._span = 1
            return
        first, last = min(self.running.values()), max(self.running.values())
        self.index = first
        self.stage = (next(iter(self.running)) if len(self.running) == 1 else
                      f"{', '.join(self.running)} at once")
        self._span = last - first + 1

    def within(self, done: int, total: int, label: str) -> None:
        if not self.tty:
            now = time.monotonic()
            if total and 0 < done < total and now - self._last_line >= self.interval:
                self._last_line = now
                self.stream.write(f"[{self.index + 1}/{self.total}] {self.stage}: {done}/{total} units done"
                                  + (f", at {label}" if label else "") + "\n")
                self.stream.flush()
            return
        frac = (self.index + self._span * (done / total if total else 1.0)) / self.total
        bar_w = 24
        fill = int(round(frac * bar_w))
        text = (f"\r[{'#' * fill}{'-' * (bar_w - fill)}] {frac * 100:3.0f}%  stage {self.index + 1}/{self.total} "
                f"{self.stage}  {done}/{total} units  {label}")
        self.stream.write(text[: self.width - 1].ljust(self.width - 1))
        self.stream.flush()

    def done(self, stage: Any, report: Report, info: dict) -> None:
        index = self.running.pop(stage.name, self.index)
        self._running()
        line = (f"[{index + 1}/{self.total}] {stage.name}: {info['status']} — "
                f"{info['records']} records, {info['duration']:.1f} s"
                # a span shared with other stages' units (docs/run.md: `overlapped`), not this stage's own time
                + (f" at once with {len(info['overlapped'])} other stage{'s' * (len(info['overlapped']) > 1)}"
                   if info.get("overlapped") else "")
                + (f" ({info['message']})" if info["status"] in ("skipped", "error") else f" ({report.summary()})"))
        if self.tty:
            self.stream.write("\r" + " " * (self.width - 1) + "\r")
        self.stream.write(line + "\n")
        self.stream.flush()


def _ci() -> bool:
    """``$CI`` set (non-empty, not ``0``/``false``/``no``), as CI services do."""
    ci = os.environ.get("CI", "").strip().lower()
    return bool(ci) and ci not in ("0", "false", "no")


__all__ = ["Progress"]
