"""Notebook rendering: what ``Report``, ``CheckResult`` and ``ConvergenceStudy`` show in Jupyter.

``_repr_html_`` gives a fragment of the HTML report — the same sections, tables and plots
(:mod:`.html`, :mod:`.plots`) — inside ``<div class="vm-nb">`` with the report's stylesheet scoped to that
``div``, so a notebook's own style is left alone.  The renderers are registered in
:mod:`verimono.core.display`, through which the records and studies reach them (imports stay one-way).
"""

from __future__ import annotations

import re
from typing import Any

from ...core.display import register
from ..results import FAILED, CheckResult, Report, to_jsonable
from . import html
from .plots import convergence_figure, convergence_plot
from .work_precision import set_html, work_precision_figure as wp_figure

SCOPE = "vm-nb"
#: rules the notebook needs on top of the report's: no sticky header rows inside a cell, and headings in
#: the report's ink whatever colour the notebook gives its own (measured: a notebook ``h2`` colour leaked)
_EXTRA_CSS = (".vm-nb { font: 13px/1.45 system-ui, sans-serif; color:#1d2330; }"
              " .vm-nb h2, .vm-nb h3 { color:#1d2330; font-family:inherit; }"
              " .vm-nb th { position:static; } .vm-nb section { margin:10px 0; overflow-x:auto; }"
              " .vm-nb .grid { grid-template-columns:repeat(auto-fill, minmax(360px, 1fr)); }")


def scoped_css(css: str, scope: str = SCOPE) -> str:
    """``css`` with every selector confined to ``.scope`` (``:root`` and ``body`` become ``.scope``)."""
    out = []
    for selectors, body in re.findall(r"([^{}]+)\{([^{}]*)\}", css):
        scoped = []
        for sel in selectors.split(","):
            sel = sel.strip()
            if sel in (":root", "body"):
                scoped.append(f".{scope}")
            elif sel:
                scoped.append(f".{scope} {sel}")
        out.append(", ".join(scoped) + " {" + body + "}")
    return "\n".join(out)


def _wrap(body: str) -> str:
    return f'<div class="{SCOPE}"><style>{scoped_css(html.CSS)}\n{_EXTRA_CSS}</style>{body}</div>'


def _section(title: str, body: str) -> str:
    return f"<section><h2>{title}</h2>{body}</section>"


@register("report_html")
def report_html(report: Report) -> str:
    """The report as a notebook fragment: summary, convergence plots, trajectories, failures, laws and
    performance — the HTML report's own sections (those with something to show)."""
    parts = [_section("verimono report", html._summary(report, None))]
    if any(hasattr(s, "fits") for s in report.studies):
        parts.append(_section("Convergence orders", html._convergence(report)))
    if report.trajectories:
        parts.append(_section("Trajectories against exact solutions", html._trajectories(report)))
    if report.failures:
        parts.append(_section("Failures and how to reproduce them", html._failures(report)))
    if report.results:
        parts.append(_section("Laws and checks", html._laws(report)))
    if any(r.check.startswith("performance_") for r in report.results):
        parts.append(_section("Performance", html._performance(report)))
    return _wrap("".join(parts))


@register("record_html")
def record_html(rec: CheckResult) -> str:
    """One record: status, key, worst observed ratio against its bound, message, counterexample and, for
    a failure, the command that reproduces it."""
    rows = [["status", html._badge(rec.status)], ["check", html._e(rec.check)], ["subject", html._e(rec.subject)]]
    if rec.worst is not None or rec.bound is not None:
        rows.append(["worst / bound", f"{html._num(rec.worst)} / {html._num(rec.bound)} {html._bar(html._ratio(rec))}"])
    if rec.seed is not None:
        rows.append(["seed", html._num(rec.seed, "d")])
    if rec.duration is not None:
        rows.append(["seconds", html._num(rec.duration, ".3f")])
    if rec.message:
        rows.append(["message", html._e(rec.message)])
    body = '<table class="kv">' + "".join(f"<tr><td>{k}</td><td>{v}</td></tr>" for k, v in rows) + "</table>"
    if rec.counterexample:
        body += f"<b>Counterexample</b><pre>{html._e(html._compact(to_jsonable(rec.counterexample)))}</pre>"
    study = rec.study
    if rec.status == FAILED:
        body += f"<b>Reproduce</b><pre>{html._e(_reproduction(rec, study))}</pre>"
    if study is not None:
        body += study_figure_html(study)
    cls = "failure" if rec.status == FAILED else ""
    return _wrap(f'<div class="{cls}" style="padding:6px 10px"><h3 style="margin:2px 0 6px">{html._e(rec.key)}</h3>'
                 f"{body}</div>")


@register("work_precision_html")
def work_precision_html(d: dict) -> str:
    """A work–precision set (its dict): the report's diagram and its verdicts."""
    return _wrap(set_html(d))


@register("work_precision_figure")
def work_precision_figure(d: dict, ax: Any = None) -> Any:
    """The report's work–precision diagram as a matplotlib ``Figure``."""
    return wp_figure(d, ax)


@register("study_figure")
def study_figure(study: Any, ax: Any = None) -> Any:
    """The report's log-log plot of ``study`` as a matplotlib ``Figure`` (Agg canvas), or drawn on ``ax``."""
    return convergence_figure(study, ax)


def _reproduction(rec: CheckResult, study: Any) -> str:
    """The report's reproduction, except for the order of a stepper of the notebook's own (no
    ``MODULE:OBJECT`` names it): then the call to run in the notebook itself."""
    stepper = getattr(study, "stepper", None)
    if rec.check == "convergence_order" and stepper and stepper != "solve" and not rec.details.get("reproduce"):
        return ("from verimono.reference import get\n"
                "from verimono.checks.orders import check_convergence_order\n"
                f"check_convergence_order({stepper}, get({study.problem!r}))   # {stepper}: the stepper "
                "defined in this notebook")
    return html.reproduction(rec, {})


def study_figure_html(study: Any) -> str:
    decision = study.decision()
    status, msg = decision.status, decision.message
    return (f'<figure style="max-width:560px">{convergence_plot(study)}<figcaption><b class="{status}">'
            f"{status.upper()}</b> {html._e(study.stepper)} — {html._e(msg)}. Reference: "
            f"{html._e(study.reference)}.</figcaption></figure>")


@register("study_html")
def study_html(study: Any) -> str:
    """A study: its log-log plot (the report's), errors per grid and the fitted order in each norm."""
    norms = list(study.errors)
    rows = [[html._num(h, ".4g"), html._num(k, "d")] + [html._num(study.errors[n][i], ".3e") for n in norms]
            for i, (h, k) in enumerate(zip(study.mesh, study.steps))]
    rows.append(["order [95%]", ""] + [html._e(study.fits[n]) for n in norms])
    table = html._table(["mesh |Δ|", "steps"] + [f"{n} error" for n in norms], rows,
                        tuple(range(len(norms) + 2)))
    exp = "none stated" if study.expected is None else html._e(study.expected)
    head = (f"<h3 style='margin:2px 0 6px'>Convergence of {html._e(study.stepper)} on {html._e(study.problem)}"
            f"</h3><p class='note'>expected order: {exp}; reference: {html._e(study.reference)}</p>")
    return _wrap(head + '<div style="display:flex;gap:14px;flex-wrap:wrap;align-items:flex-start">'
                 + study_figure_html(study) + f'<div style="flex:1;min-width:320px">{table}</div></div>')


__all__ = ["report_html", "record_html", "study_html", "study_figure", "scoped_css"]
