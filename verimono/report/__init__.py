"""Consumers of result records: the JSON schema (:mod:`.schema`), the HTML report (:mod:`.html`) and its
plots (:mod:`.plots`).  ``write(report, out_dir)`` writes ``results.json`` and ``report.html``.

Importing this package is cheap; matplotlib is imported only when a report is rendered.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .html import render


def write(report: Any, out_dir: str | Path, *, changes: Any = None) -> dict[str, Path]:
    """Write ``out_dir/results.json`` and ``out_dir/report.html``; returns their paths.

    ``changes`` (a :class:`verimono.gate.Comparison`, computed by the caller with
    :func:`verimono.gate.compare`: the report knows nothing of the gate) fill the report's "changes against
    the baseline" section.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    json_path = report.save(out / "results.json")
    html_path = out / "report.html"
    html_path.write_text(render(report, changes=changes), encoding="utf-8")
    return {"json": json_path, "html": html_path}


__all__ = ["write"]
