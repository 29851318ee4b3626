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
        self.width = min(shutil.get_terminal_size((100, 20)).columns, 120)
        self.interval = interval
        self._last_line = time.monotonic()

    def start(self, stage: Any, index: int, total: int) -> None:
        self.stage, self.index, self.total = stage.name, index, total
        self._last_line = time.monotonic()
        self.within(0, 1, "")

    def within(self, done: int, total: int, label: str) -> None:
        if not self.tty:
            now = time.monotonic()
            if total and 0 < done < total and now - self._last_line >= self.interval:
                self._last_line = now
                self.stream.write(f"[{self.index + 1}/{self.total}] {self.stage}: {done}/{total} units done"
                                  + (f", at {label}" if label else "") + "\n")
                self.stream.flush()
            return
        frac = (self.index + (done / total if total else 1.0)) / self.total
        bar_w = 24
        fill = int(round(frac * bar_w))
        text = (f"\r[{'#' * fill}{'-' * (bar_w - fill)}] {frac * 100:3.0f}%  stage {self.index + 1}/{self.total} "
                f"{self.stage}  {done}/{total} units  {label}")
        self.stream.write(text[: self.width - 1].ljust(self.width - 1))
        self.stream.flush()

    def done(self, stage: Any, report: Report, info: dict) -> None:
        line = (f"[{self.index + 1}/{self.total}] {stage.name}: {info['status']} — "
                f"{info['records']} records, {info['duration']:.1f} s"
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
