"""Consumers of result records: the JSON schema (:mod:`.schema`), the HTML report (:mod:`.html`) and its
plots (:mod:`.plots`).  ``write(report, out_dir)`` writes ``results.json`` and ``report.html``.

Importing this package is cheap; matplotlib is imported only when a report is rendered.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..atomic import clear_in_progress, ensure_writable_dir, keep_elsewhere, replace_all
from ...core.errors import OutputNotWritable
from .html import render
from .plots import forget


def write(report: Any, out_dir: str | Path, *, changes: Any = None, run_id: str | None = None) -> dict[str, Path]:
    """Write ``out_dir/results.json`` and ``out_dir/report.html``; returns their paths.

    ``changes`` (a :class:`verimono.run.gate.Comparison`, computed by the caller with
    :func:`verimono.run.gate.compare`: the report knows nothing of the gate) fill the report's "changes against
    the baseline" section.  ``run_id``: the id of the run that marked ``results.json`` in progress
    (:func:`verimono.records.atomic.mark_in_progress`; default a fresh one); once the pair is in place that mark
    is removed.  When the pair cannot be written (a full disk, an unwritable folder) the previous pair
    stays, the results are kept in the temporary folder, and :class:`verimono.OutputNotWritable` names
    both paths in one line.
    """
    # one run id in both files; both rendered in memory, written to temporaries, then renamed together
    # (verimono.records.atomic): a full disk or an interrupt leaves the previous pair or the new pair, never a mix
    report.meta["run_id"] = run_id = run_id or new_run_id()
    json_path, html_path = Path(out_dir) / "results.json", Path(out_dir) / "report.html"
    text = report.to_json()
    try:
        out = ensure_writable_dir(out_dir)
        html = render(report, changes=changes)
        forget()                                  # the plots drawn ahead for this report
        replace_all({json_path: text, html_path: html})
    except OutputNotWritable as exc:
        try:
            kept = f"this run's results are kept in {keep_elsewhere(text, f'verimono-results-{run_id}.json')}"
        except OSError as again:
            kept = f"this run's results could not be kept elsewhere either ({again.strerror or again})"
        err = OutputNotWritable(f"{exc}; {kept}")
        err.errno, err.filename = exc.errno, exc.filename
        raise err from None
    clear_in_progress(out / "results.json", run_id)
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
