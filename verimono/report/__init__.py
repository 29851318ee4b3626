"""Consumers of result records: the JSON schema (:mod:`.schema`), the HTML report (:mod:`.html`) and its
plots (:mod:`.plots`).  ``write(report, out_dir)`` writes ``results.json`` and ``report.html``.

Importing this package is cheap; matplotlib is imported only when a report is rendered.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..atomic import ensure_writable_dir, replace_all
from .html import render


def write(report: Any, out_dir: str | Path, *, changes: Any = None) -> dict[str, Path]:
    """Write ``out_dir/results.json`` and ``out_dir/report.html``; returns their paths.

    ``changes`` (a :class:`verimono.gate.Comparison`, computed by the caller with
    :func:`verimono.gate.compare`: the report knows nothing of the gate) fill the report's "changes against
    the baseline" section.
    """
    out = ensure_writable_dir(out_dir)
    # one run id in both files; both rendered in memory, written to temporaries, then renamed together
    # (verimono.atomic): a full disk or an interrupt leaves the previous pair or the new pair, never a mix
    report.meta["run_id"] = new_run_id()
    json_path, html_path = out / "results.json", out / "report.html"
    text = report.to_json()
    html = render(report, changes=changes)
    replace_all({json_path: text, html_path: html})
    return {"json": json_path, "html": html_path}


def new_run_id() -> str:
    """A fresh identifier shared by the ``results.json`` and ``report.html`` of one write."""
    import uuid

    return uuid.uuid4().hex[:16]


def html_run_id(html: str) -> str | None:
    """The run id a ``report.html`` was rendered for (``None`` if it carries none)."""
    import re

    m = re.search(r'<meta name="verimono-run-id" content="([0-9a-f]+)"', html)
    return m.group(1) if m else None


__all__ = ["write", "new_run_id", "html_run_id"]
