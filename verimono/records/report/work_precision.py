"""The report's work–precision section: the diagram (log–log error against CPU time with the time intervals,
and against the number of steps) and the table of verdicts.

It reads the set as the records carry it (``details["work_precision"]`` of a ``work_precision`` record, the
dict of :meth:`verimono.run.work_precision.WorkPrecisionSet.to_dict`): the report knows no producer.
"""

from __future__ import annotations

from html import escape
from typing import Any

import numpy as np

from ..results import FAILED, CheckResult, Report
from .plots import COLORS, _decade, _figure, _legend_html, _svg

MARKERS = "osd^v<>"


def sets_of(report: Report) -> list[dict[str, Any]]:
    """The work–precision sets the records carry, once each (by problem and steppers)."""
    seen, out = set(), []
    for r in report.results:
        d = r.details.get("work_precision") if isinstance(r.details, dict) else None
        if not isinstance(d, dict) or "curves" not in d:
            continue
        key = (d.get("problem"), tuple(c.get("stepper") for c in d["curves"]))
        if key not in seen:
            seen.add(key)
            out.append(d)
    return out


def _num(v: Any) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def work_precision_figure(d: dict[str, Any], ax: Any = None, *, legend: bool = True) -> Any:
    """Error against CPU time (horizontal bars: the bounds of the median time) and against the number of
    steps, log–log, one curve per stepper; two axes of one figure, or drawn on ``ax`` (time only)."""
    from matplotlib.ticker import FuncFormatter, NullLocator

    if ax is None:
        fig = _figure(8.8, 3.3)
        axes = [fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)]
        fig.subplots_adjust(left=0.09, right=0.98, bottom=0.17, top=0.88, wspace=0.25)
    else:
        fig, axes = ax.figure, [ax]
    norm = d.get("norm", "sup")
    for k, c in enumerate(d["curves"]):
        color, marker = COLORS[k % len(COLORS)], MARKERS[k % len(MARKERS)]
        e = np.array([_num(v) for v in c["errors"][norm]])
        e = np.where(e > 0, e, _num(d.get("floor")))
        for j, (axis, kind) in enumerate(zip(axes, ("time", "steps"))):
            if kind == "time":
                w = np.array([_num(v) for v in c["seconds"]])
                lo, hi = np.array([_num(v) for v in c["low"]]), np.array([_num(v) for v in c["high"]])
                xerr = np.vstack([np.clip(w - lo, 0, None), np.clip(hi - w, 0, None)])
                xerr[~np.isfinite(xerr)] = 0.0
            else:
                w, xerr = np.array([float(v) for v in c["steps"]]), None
            order = np.argsort(w)
            axis.plot(w[order], e[order], color=color, lw=1.1, marker=marker, ms=4.5,
                      label=f"{c['stepper']} ({c['control']}s)" if j == 0 else None)
            if xerr is not None:
                axis.errorbar(w, e, xerr=xerr, fmt="none", ecolor=color, elinewidth=0.9, capsize=2.5, alpha=0.8)
    for axis, kind in zip(axes, ("time", "steps")):
        lo, hi = axis.dataLim.x0, axis.dataLim.x1
        axis.set_xscale("log")
        if lo > 0 and hi > lo:      # a few labelled ticks across the data, as plain text (no crowded minor labels)
            ticks = np.geomspace(lo, hi, 4)
            axis.set_xticks(ticks, [f"{v:.2g}" for v in ticks])
            axis.xaxis.set_minor_locator(NullLocator())
        axis.set_yscale("log")
        axis.yaxis.set_major_formatter(FuncFormatter(_decade))
        axis.yaxis.set_minor_locator(NullLocator())
        axis.set_xlabel("CPU time per run (s, own time)" if kind == "time" else "number of steps")
        axis.set_ylabel(f"{norm} error")
        axis.grid(True, which="major", alpha=0.3)
    axes[0].set_title(f"{d['problem']}: error against work", fontsize=10, y=1.0)
    if legend:
        axes[0].legend(fontsize=6.5, loc="best", framealpha=0.85)
    return fig


def work_precision_plot(d: dict[str, Any]) -> str:
    """The diagram as an inline ``<svg>`` with its legend in HTML."""
    fig = work_precision_figure(d, legend=False)
    return _svg(fig) + _legend_html(fig.axes[0])


def _badge(status: str) -> str:
    return f'<span class="badge {escape(status)}">{escape(status)}</span>'


def section(report: Report) -> str:
    """The section's HTML: per set its diagram, then the verdicts of the first stepper against the others."""
    sets = sets_of(report)
    if not sets:
        return ('<p class="note">No work–precision comparison in this run (<code>verimono compare MODULE:A '
                "MODULE:B ... --problem MODULE:OBJECT</code>, or <code>verimono.work_precision</code>).</p>")
    figs = [_figure_html(d) for d in sets]
    table = _rows([(r.subject, "CPU time" if r.check == "work_precision" else "steps", r.status, r.message)
                   for r in records_of(report)])
    return ('<p class="note">Each stepper over its step sizes or tolerances: error at its own nodes against the '
            "exact solution, against the work it took. The first stepper is judged against each other one: "
            "<i>passed</i> — at least as accurate for the same work with the timing noise against it; "
            "<i>failed</i> — less accurate even with the noise in its favour; <i>undecided</i> — the noise cannot "
            "tell (not a failure).</p>" + "".join(figs) + table)


def _figure_html(d: dict[str, Any]) -> str:
    return (f'<figure style="max-width:900px">{work_precision_plot(d)}<figcaption>{escape(str(d["problem"]))}: '
            f"{escape(str(d.get('norm', 'sup')))} error against CPU time (median own time over "
            f"{d.get('rounds')} interleaved rounds; bars: its order-statistics bounds) and against the "
            "number of steps, one point per step size or tolerance.</figcaption></figure>")


def _rows(items: list[tuple[str, str, str, str]]) -> str:
    rows = "".join(f'<tr class="{"failed" if status == FAILED else ""}"><td>{escape(subject)}</td><td>{work}</td>'
                   f"<td>{_badge(status)}</td><td>{escape(message)}</td></tr>"
                   for subject, work, status, message in items)
    return ("<table><thead><tr><th>comparison</th><th>work</th><th>status</th><th>verdict</th></tr></thead>"
            f"<tbody>{rows}</tbody></table>")


def set_html(d: dict[str, Any]) -> str:
    """One set (a notebook's display): its diagram and the verdicts it carries."""
    items = [(v["subject"], "CPU time" if v["work"] == "time" else "steps", v["status"], v["message"])
             for v in d.get("verdicts") or []]
    return f"<h3>Work–precision on {escape(str(d['problem']))}</h3>" + _figure_html(d) + _rows(items)


def records_of(report: Report) -> list[CheckResult]:
    return [r for r in report.results if r.check in ("work_precision", "work_precision_steps")]


__all__ = ["section", "set_html", "sets_of", "records_of", "work_precision_figure", "work_precision_plot"]
