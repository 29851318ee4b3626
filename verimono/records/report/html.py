"""The HTML report: one self-contained file (inline CSS and SVG, no scripts, no network).

Sections, in order (each a ``<section id=...>``): ``summary`` (counts and stages), ``changes`` (against
the baseline), ``convergence`` (log-log plots per reference), ``work_precision`` (error against work of
several steppers, :mod:`.work_precision`), ``trajectories`` (scheme against exact
solution), ``laws`` (every check with its worst ratio and bound), ``failures`` (counterexample and a
copy-paste reproduction each), ``timings`` and ``environment``.

The renderer knows no producers: it reads records and ``meta`` only (it imports :mod:`verimono.records.results`
and its own plots).  Reproductions are what the producers handed over in ``details``: ``reproduce`` (a
complete text), ``example`` (a hypothesis ``@example``), ``reproduce_python`` (a script using ``stepper``,
bound here to the run's target), ``stage`` and ``reference`` (the options of the command that reruns it).
"""

from __future__ import annotations

import json
import keyword
import math
import re
import shlex
from collections import Counter, defaultdict
from html import escape
from typing import Any

from ..environment import environment
from ..results import FAILED, PASSED, SKIPPED, STATUSES, UNDECIDED, XFAIL, CheckResult, Report, to_jsonable
from . import work_precision
from .plots import convergence_plot, trajectory_plot

SECTIONS = ("summary", "changes", "convergence", "work_precision", "trajectories", "laws", "failures", "performance",
            "timings", "environment")
_TITLES = {"summary": "Summary", "changes": "Changes against the baseline", "convergence": "Convergence orders",
           "work_precision": "Work–precision",
           "trajectories": "Trajectories against exact solutions", "laws": "Laws and checks",
           "failures": "Failures and how to reproduce them", "performance": "Performance", "timings": "Timings",
           "environment": "Environment"}

CSS = """
:root { --ok:#2e7d32; --bad:#c62828; --skip:#757575; --xf:#b26a00; --ink:#1d2330; --mute:#5b6475;
        --line:#dde1e8; --bg:#f6f7f9; }
* { box-sizing: border-box; }
body { margin:0; font: 14px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif;
       color:var(--ink); background:var(--bg); }
header { background:#1d2330; color:#fff; padding:18px 32px 12px; }
header h1 { margin:0 0 4px; font-size:22px; font-weight:600; }
header .sub { color:#c3c9d6; font-size:13px; }
nav { position:sticky; top:0; z-index:5; background:#fff; border-bottom:1px solid var(--line); padding:8px 32px; }
nav a { color:#1f5fbf; text-decoration:none; margin-right:18px; font-size:13px; white-space:nowrap; }
main { padding:8px 32px 48px; max-width:1500px; }
section { background:#fff; border:1px solid var(--line); border-radius:8px; padding:16px 20px; margin:18px 0; }
h2 { margin:0 0 12px; font-size:18px; }
h3 { font-size:15px; margin:18px 0 8px; }
p.note { color:var(--mute); margin:4px 0 10px; }
.verdict { font-size:17px; font-weight:600; padding:10px 14px; border-radius:6px; margin-bottom:14px; }
.verdict.ok { background:#e8f5e9; color:var(--ok); } .verdict.bad { background:#ffebee; color:var(--bad); }
.cards { display:flex; gap:12px; flex-wrap:wrap; margin-bottom:14px; }
.card { min-width:130px; padding:10px 16px; border-radius:8px; border:1px solid var(--line); background:#fafbfc; }
.card .n { font-size:28px; font-weight:700; } .card .l { color:var(--mute); font-size:12px; text-transform:uppercase; letter-spacing:.04em; }
.card.passed .n { color:var(--ok); } .card.failed .n { color:var(--bad); } .card.skipped .n { color:var(--skip); }
.card.xfail .n { color:var(--xf); } .card.regressions .n { color:var(--bad); } .card.undecided .n { color:var(--bad); }
table { border-collapse:collapse; width:100%; font-size:13px; }
th, td { text-align:left; padding:5px 8px; border-bottom:1px solid var(--line); vertical-align:top; }
th { background:#f0f2f5; font-weight:600; position:sticky; top:37px; }
td.num, th.num { text-align:right; font-variant-numeric:tabular-nums; white-space:nowrap; }
tr.failed td { background:#fff5f5; }
.badge { display:inline-block; padding:1px 7px; border-radius:10px; font-size:11px; font-weight:600; color:#fff; text-transform:uppercase; }
.badge.passed { background:var(--ok); } .badge.failed, .badge.error, .badge.regression { background:var(--bad); }
.badge.skipped { background:var(--skip); } .badge.xfail { background:var(--xf); } .badge.undecided { background:#8e24aa; } .badge.change { background:#1f5fbf; }
.grid { display:grid; grid-template-columns:repeat(auto-fill, minmax(420px, 1fr)); gap:14px; }
figure { margin:0; border:1px solid var(--line); border-radius:6px; padding:6px; background:#fff; }
figure svg { width:100%; height:auto; display:block; }
figcaption { font-size:12px; color:var(--mute); padding:4px 4px 0; }
figcaption b.passed { color:var(--ok); } figcaption b.failed { color:var(--bad); } figcaption b.undecided { color:#8e24aa; }
pre { background:#f3f4f7; border:1px solid var(--line); border-radius:6px; padding:8px 10px; overflow-x:auto;
      font: 12px/1.4 ui-monospace, SFMono-Regular, Menlo, Consolas, monospace; white-space:pre; }
details { margin:6px 0; } summary { cursor:pointer; color:#1f5fbf; }
.failure { border-left:4px solid var(--bad); padding:6px 12px; margin:12px 0; background:#fffafa; }
.failure h3 { margin:2px 0 6px; }
.bar { background:#eceff3; border-radius:3px; height:8px; width:110px; display:inline-block; vertical-align:middle; }
.bar span { display:block; height:8px; border-radius:3px; }
.kv td:first-child { color:var(--mute); width:220px; }
.muted { color:var(--mute); }
"""


def _e(x: Any) -> str:
    return escape("" if x is None else str(x))


def _num(x: Any, fmt: str = ".4g") -> str:
    if x is None:
        return "–"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return _e(x)
    if not math.isfinite(v):
        return _e(v)
    return _unsigned_zero(format(int(v), fmt) if fmt == "d" else format(v, fmt))


def _unsigned_zero(text: str) -> str:
    """``-0``, ``-0.00``, ``-0e+00`` (a negative zero, or a tiny negative rounded away) as ``0...``."""
    try:
        return text[1:] if text.startswith("-") and float(text) == 0 else text
    except ValueError:
        return text


#: a list or object whose one-line form is at most this long is written on one line (lists of numbers
#: always are: a vector reads best as one row)
_INLINE_WIDTH = 100
_NON_FINITE = ("inf", "-inf", "nan")


def _compact(value: Any, level: int = 0) -> str:
    """JSON-like text of a counterexample (already :func:`to_jsonable`): numbers to 6 significant digits,
    vectors and short lists or objects on one line, the top-level object one key a line."""
    if isinstance(value, dict):
        items = [f"{json.dumps(str(k), ensure_ascii=False)}: {_compact(v, level + 1)}"
                 for k, v in value.items()]
        opening, closing = "{", "}"
    elif isinstance(value, list):
        items = [_compact(v, level + 1) for v in value]
        opening, closing = "[", "]"
    elif isinstance(value, bool) or value is None:
        return json.dumps(value)
    elif isinstance(value, int):
        return str(value)
    elif isinstance(value, float):
        return _unsigned_zero(format(value, ".6g"))
    elif isinstance(value, str) and value in _NON_FINITE:
        return value  # a non-finite number, as to_jsonable writes it
    else:
        return json.dumps(str(value), ensure_ascii=False)
    flat = opening + ", ".join(items) + closing
    scalars = isinstance(value, list) and not any(isinstance(v, (list, dict)) for v in value)
    if "\n" not in flat and level > 0 and (scalars or len(flat) <= _INLINE_WIDTH) or not items:
        return flat
    pad = " " * (level + 1)
    return opening + "\n" + ",\n".join(pad + it for it in items) + "\n" + " " * level + closing


def _badge(status: str) -> str:
    return f'<span class="badge {_e(status)}">{_e(status)}</span>'


def _ratio(rec: CheckResult) -> float | None:
    try:
        w, b = float(rec.worst), float(rec.bound)
    except (TypeError, ValueError):
        return None
    if not math.isfinite(w) or not math.isfinite(b):
        return math.inf if w == math.inf else None
    return w / b if b > 0 else None


def _bar(ratio: float | None) -> str:
    if ratio is None:
        return ""
    frac = 1.0 if not math.isfinite(ratio) else max(0.0, min(ratio, 1.0))
    color = "#c62828" if ratio > 1 else "#2e7d32"
    return f'<span class="bar" title="worst/bound = {_num(ratio)}"><span style="width:{frac * 100:.0f}%;background:{color}"></span></span>'


def _table(head: list[str], rows: list[list[str]], num_cols: tuple[int, ...] = (), row_class=None) -> str:
    th = "".join(f'<th class="num">{h}</th>' if i in num_cols else f"<th>{h}</th>" for i, h in enumerate(head))
    body = []
    for k, r in enumerate(rows):
        cls = f' class="{row_class[k]}"' if row_class and row_class[k] else ""
        body.append(f"<tr{cls}>" + "".join(f'<td class="num">{c}</td>' if i in num_cols else f"<td>{c}</td>"
                                           for i, c in enumerate(r)) + "</tr>")
    return f"<table><thead><tr>{th}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def reproduction(rec: CheckResult, meta: dict[str, Any]) -> str:
    """A copy-paste reproduction of one record, from what the check handed over: its own
    ``details["reproduce"]`` (used as is), a hypothesis ``@example`` from ``details["example"]``, or a Python
    script ``details["reproduce_python"]`` using the free name ``stepper`` (bound here, after the script's
    imports, to the run's target); else the command with the record's seed and stage."""
    if rec.details.get("reproduce"):
        return str(rec.details["reproduce"])
    target = meta.get("target") or "verimono.stepping:solve"
    if rec.details.get("example"):
        return f"@example({rec.details['example']})  # add above the failing @given test, or:\n" + \
            _command(rec, meta)
    script = rec.details.get("reproduce_python")
    if script:
        lines = str(script).splitlines()
        k = next((i for i, line in enumerate(lines) if not line.startswith(("from ", "import "))), len(lines))
        body = "\n".join([*lines[:k], _import_stepper(str(target)), *lines[k:]])
        return f"python - <<'EOF'\n{body}\nEOF"
    return _command(rec, meta)


def _import_stepper(target: str) -> str:
    """Python binding ``stepper`` to ``MODULE:OBJECT``: a plain import for a dotted module and a single
    name, else :func:`verimono.cli.load_target` (``.py`` paths, dotted objects), as ``verimono check`` does."""
    module, _, obj = target.partition(":")
    if not module.endswith(".py") and all(p.isidentifier() and not keyword.iskeyword(p)
                                          for p in [*module.split("."), obj]):
        return f"from {module} import {obj} as stepper"
    return f"from verimono.cli import load_target\nstepper = load_target({target!r})"


def _command(rec: CheckResult, meta: dict[str, Any]) -> str:
    """The ``verimono`` command line reproducing ``rec``; every word passes through :func:`shlex.quote`
    (a results file is data: a target such as ``x; touch /tmp/x #`` must paste as one argument)."""
    cmd = ["verimono", str(meta.get("command") or "run")]
    if meta.get("command") == "check" and meta.get("target"):
        cmd.append(str(meta["target"]))
    cmd += ["--profile", str(meta.get("profile") or "ci")]
    seed = rec.seed if rec.seed is not None else meta.get("seed")
    if seed is not None:
        cmd += ["--seed", str(seed)]
    if rec.details.get("stage") and meta.get("command", "run") == "run":
        cmd += ["--stage", str(rec.details["stage"])]
    refs = (meta.get("selection") or {}).get("references")
    if isinstance(rec.details.get("reference"), str):
        refs = [rec.details["reference"]]  # the one reference the counterexample needs (the run says which)
    for name in refs or []:
        cmd += ["--reference", str(name)]
    return " ".join(shlex.quote(w) for w in cmd)


# -- sections --------------------------------------------------------------------------------------


def _summary(report: Report, changes: Any) -> str:
    c = report.counts
    ok = report.ok
    nreg = len(changes.regressions) if changes is not None else None
    if ok:
        verdict = "All checks hold"
    elif c[FAILED]:
        verdict = f"{c[FAILED]} check{'s' if c[FAILED] != 1 else ''} failed"
    elif not report.verified:              # nothing evaluated held: never shown as a pass
        verdict = f"Nothing verified: none of the {len(report)} record{'s' if len(report) != 1 else ''} passed"
    else:
        verdict = "No check failed"
    if c.get(UNDECIDED):
        verdict += f" · {c[UNDECIDED]} undecided (a limitation of the harness: nothing verified there)"
    if report.meta.get("incomplete"):
        verdict = "INCOMPLETE run (interrupted; resume with verimono run --resume) · " + verdict
    if nreg:
        verdict += f" · {nreg} regression{'s' if nreg != 1 else ''} against the baseline"
    cards = "".join(f'<div class="card {s}"><div class="n">{c[s]}</div><div class="l">{s}</div></div>'
                    for s in STATUSES)
    if changes is not None:
        cls = "regressions" if nreg else "passed"
        cards += f'<div class="card {cls}"><div class="n">{nreg}</div><div class="l">regressions</div></div>'
    stages = report.meta.get("stages") or []
    rows = [[_e(s.get("name")), _badge(s.get("status", "")), _num(s.get("records"), "d"),
             _num(s.get("duration"), ".2f"), _e(s.get("message"))] for s in stages]
    stage_html = ("<h3>Stages</h3>" + _table(["stage", "status", "records", "seconds", "outcome"], rows, (2, 3))
                  if rows else "")
    return (f'<div class="verdict {"ok" if ok and not nreg else "bad"}">{_e(verdict)}</div>'
            f'<div class="cards">{cards}</div>{stage_html}')


def _subject(key: str) -> str:
    """The subject a change is about: ``convergence_order[solve on box]`` and ``solve on box`` alike."""
    m = re.fullmatch(r"[^\[\]]+\[(.*)\]", key)
    return m.group(1) if m else key


def _grouped(changes: list[Any], badge: str) -> str:
    """One row per subject: how many changes of which rule, and every message (long lists folded)."""
    groups: dict[str, list[Any]] = defaultdict(list)
    for c in changes:
        groups[_subject(c.key)].append(c)
    rows = []
    for subject, cs in groups.items():
        kinds = ", ".join(f"{k} ×{n}" if n > 1 else k for k, n in Counter(c.kind for c in cs).items())
        word = "regression" if badge == "regression" else "change"
        head = f"{len(cs)} {word}{'s' if len(cs) != 1 else ''}: {kinds}"
        items = [f"<li>{_e(c.key + ': ' if c.key != subject else '')}{_e(c.message)}</li>" for c in cs]
        shown, folded = (items, []) if len(items) <= 4 else (items[:3], items[3:])
        more = f"<details><summary>{len(folded)} more</summary><ul>{''.join(folded)}</ul></details>"
        shown = "<ul>" + "".join(shown) + "</ul>" + (more if folded else "")
        rows.append([_badge(badge), _e(subject), _e(head), shown])
    return _table(["", "subject", "rules", "what changed"], rows)


def _changes(changes: Any) -> str:
    if changes is None:
        return ('<p class="note">No baseline was given, so nothing is compared. '
                "<code>verimono run --baseline reports/baseline.json</code> fills this section; "
                "<code>verimono gate</code> fails a CI job on a regression.</p>")
    meta = changes.baseline_meta or {}
    head = (f'<p class="note">Baseline created {_e(meta.get("created"))}, profile {_e(meta.get("profile"))}, '
            f"verimono {_e(((meta.get('environment') or {}).get('versions') or {}).get('verimono'))}. "
            f"{_e(changes.summary())}{', one row per subject' if changes.changes else ''}.</p>")
    out = head
    if changes.regressions:
        out += _grouped(changes.regressions, "regression")
    else:
        out += '<p><b style="color:var(--ok)">No regressions.</b></p>'
    if changes.others:
        out += (f"<details><summary>{len(changes.others)} other changes (new records, improvements)</summary>"
                + _grouped(changes.others, "change") + "</details>")
    return out


def _convergence(report: Report) -> str:
    studies = [s for s in report.studies if hasattr(s, "fits")]
    if not studies:
        return '<p class="note">No convergence studies in this run.</p>'
    figs, rows = [], []
    for s in studies:
        decision = s.decision()
        status, msg = decision.status, decision.message
        figs.append(f"<figure>{convergence_plot(s)}<figcaption><b class=\"{status}\">{status.upper()}</b> "
                    f"{_e(s.stepper)} — {_e(msg)}. Reference: {_e(s.reference)}.</figcaption></figure>")
        f = s.fits["sup"]
        rows.append([_e(s.problem), _e(s.expected), _e(f), _e(s.fits["l2"]), _e(s.fits["final"]),
                     "yes" if f.pre_asymptotic else "", _badge(status)])
    table = _table(["reference", "expected", "sup-norm order [95%]", "L2 order", "final-time order",
                    "pre-asymptotic", "verdict"], rows)
    return ('<p class="note">Least-squares slope of log error against log mesh, with its 95% Student-t '
            "interval (shaded) and the order the theory predicts (dashed). Errors at the round-off floor "
            "(dotted) are not fitted.</p>" + table + f'<div class="grid" style="margin-top:14px">{"".join(figs)}</div>')


def _trajectories(report: Report) -> str:
    if not report.trajectories:
        return '<p class="note">No trajectory samples in this run.</p>'
    figs = [f"<figure>{trajectory_plot(s)}<figcaption>{_e(s.get('stepper'))} on the coarsest grid of the "
            f"study (markers) against the exact solution (lines).</figcaption></figure>"
            for s in report.trajectories]
    return f'<div class="grid">{"".join(figs)}</div>'


def _error(rec: CheckResult) -> float | None:
    """``details["error"]``: the absolute error against a reference (e.g. Siconos) the gate compares."""
    e = rec.details.get("error") if isinstance(rec.details, dict) else None
    return float(e) if isinstance(e, (int, float)) and not isinstance(e, bool) else None


def _worst(recs: list[CheckResult]) -> tuple[CheckResult | None, float | None]:
    rated = [(r, _ratio(r)) for r in recs if _ratio(r) is not None]
    return max(rated, key=lambda p: p[1]) if rated else (None, None)


def _laws(report: Report) -> str:
    if not report.results:
        return '<p class="note">No records.</p>'
    groups: dict[str, list[CheckResult]] = defaultdict(list)
    for r in report.results:
        groups[r.check].append(r)
    rows, classes, detail_blocks = [], [], []
    for check, recs in groups.items():
        counts = {s: sum(r.status == s for r in recs) for s in STATUSES}
        # the worst ratio among records that had to hold; expected failures are shown apart
        worst_rec, worst_ratio = _worst([r for r in recs if r.status in (PASSED, FAILED)])
        xf_rec, _ = _worst([r for r in recs if r.status == XFAIL])
        errors = [e for e in map(_error, recs) if e is not None]
        rows.append([f'<a href="#law-{_e(check)}">{_e(check)}</a>', _num(len(recs), "d"),
                     _num(counts[PASSED], "d"), _num(counts[FAILED], "d"), _num(counts[SKIPPED], "d"),
                     _num(counts[XFAIL], "d"),
                     _num(worst_rec.worst) if worst_rec else "–", _num(worst_rec.bound) if worst_rec else "–",
                     _bar(worst_ratio), _e(worst_rec.subject) if worst_rec else "",
                     _num(max(errors)) if errors else "",
                     (f'{_badge(XFAIL)} <span class="muted">{_num(xf_rec.worst)} / {_num(xf_rec.bound)} '
                      f"{_e(xf_rec.subject)}</span>") if xf_rec else ""])
        classes.append("failed" if counts[FAILED] else "")
        sub = [[_e(r.subject), _badge(r.status), _num(r.worst), _num(r.bound), _bar(_ratio(r)),
                _num(_error(r)) if _error(r) is not None else "",
                _num(r.seed, "d") if r.seed is not None else "", _e(r.message)] for r in recs]
        detail_blocks.append(
            f'<details id="law-{_e(check)}"><summary>{_e(check)}: {len(recs)} records</summary>'
            + _table(["subject", "status", "worst", "bound", "worst/bound", "error", "seed", "message"], sub,
                     (2, 3, 5, 6), ["failed" if r.status == FAILED else "" for r in recs]) + "</details>")
    table = _table(["check (law)", "records", "passed", "failed", "skipped", "xfail", "worst observed",
                    "bound", "worst/bound", "worst subject", "error (max)", "worst expected failure"],
                   rows, (1, 2, 3, 4, 5, 6, 7, 10), classes)
    return ('<p class="note">A check passes when its worst observed ratio stays within its bound. One row per '
            "law: the worst ratio among passed and failed records; expected failures (xfail) are listed "
            "apart. <i>error</i> is the absolute error against a reference (e.g. Siconos) that the gate "
            "compares with the baseline's. Open a law below for every record.</p>" + table +
            "<h3>Every record</h3>" + "".join(detail_blocks))


def _failures(report: Report) -> str:
    bad = [r for r in report.results if r.status == FAILED]
    if not bad:
        return '<p><b style="color:var(--ok)">No failures.</b></p>'
    out = []
    for r in bad:
        ce = _compact(to_jsonable(r.counterexample)) if r.counterexample is not None else "—"
        tb = r.details.get("traceback")
        out.append(
            f'<div class="failure"><h3>{_e(r.key)}</h3><p>{_e(r.message)}</p>'
            f"<p class=\"muted\">worst {_num(r.worst)} against bound {_num(r.bound)}"
            f"{'' if r.seed is None else f', seed {r.seed}'}</p>"
            f"<b>Counterexample</b> <span class=\"muted\">(6 significant digits; full precision in "
            f"results.json)</span><pre>{_e(ce)}</pre>"
            f"<b>Reproduce</b><pre>{_e(reproduction(r, report.meta))}</pre>"
            + (f"<details><summary>traceback</summary><pre>{_e(tb)}</pre></details>" if tb else "") + "</div>")
    return "".join(out)


def _performance(report: Report) -> str:
    recs = [r for r in report.results if r.check.startswith("performance_") and "ratio" in r.details]
    if not recs:
        return ('<p class="note">No performance records in this run (<code>verimono run --stage performance'
                "</code>).</p>")
    rows = []
    for r in recs:
        d = r.details
        speedup = d.get("direction") == ">="
        unit = "x speed-up" if speedup else "x"
        rounds = [b / s if speedup else s / b for s, b in zip(d.get("subject_s") or [], d.get("baseline_s") or [])
                  if isinstance(s, (int, float)) and isinstance(b, (int, float)) and s > 0 and b > 0]
        spread = f"{_num(min(rounds), '.3g')} – {_num(max(rounds), '.3g')}" if len(rounds) > 1 else "–"
        if "subject_bytes" in d:
            spread = f"{_num(d['subject_bytes'] / 2**20, '.2f')} / {_num(d['baseline_bytes'] / 2**20, '.2f')} MiB"
        iv = d.get("interval")
        bounds = (f"{_num(iv[0], '.3g')} – {_num(iv[1], '.3g')}" if isinstance(iv, list) and len(iv) == 2 else "–")
        rows.append([_e(r.check.removeprefix("performance_")), _e(r.subject), _badge(r.status),
                     _num(d.get("ratio"), ".3g") + unit, f"{'≥' if speedup else '≤'} {_num(d.get('target'))}",
                     bounds, spread, _num(d.get("rounds"), "d"), _num(d.get("timing_ratio"), ".3g"), _bar(_ratio(r))])
    return ('<p class="note">verimono against a bare baseline doing the same work, timed in this job on each '
            "call's own time (wall time minus its wait for a CPU), interleaved round by round; the median "
            "per-round ratio's order-statistics bounds meet its target (passed), miss it (failed), or straddle it "
            "after every round the budget allows (undecided: the machine too noisy to judge a speed; not a "
            "failure). The gate compares the gated ratio (larger is worse) with the baseline's, never absolute "
            "seconds. Memory: peak traced bytes of a streamed study over one trajectory's.</p>"
            + _table(["check", "subject", "status", "measured", "target", "bounds", "per-round range", "rounds",
                      "gated ratio", "measured/target"], rows, (3, 4, 5, 6, 7, 8),
                     ["failed" if r.status == FAILED else "" for r in recs]))


def _timings(report: Report) -> str:
    cal = report.meta.get("calibration")
    stages = report.meta.get("stages") or []
    rows = [[_e(s.get("name")), _num(s.get("duration"), ".3f"),
             _num(s["duration"] / cal, ".1f") if isinstance(cal, (int, float)) and cal > 0 else "–",
             _num(s.get("records"), "d")] for s in stages]
    out = (f'<p class="note">Calibration workload (fixed NumPy loop, same job): {_num(cal, ".4f")} s. The gate '
           "compares durations as multiples of it, never absolute seconds.</p>")
    if rows:
        out += _table(["stage", "seconds", "× calibration", "records"], rows, (1, 2, 3))
    timed = sorted((r for r in report.results if isinstance(r.duration, (int, float))),
                   key=lambda r: -r.duration)[:12]
    if timed:
        out += "<h3>Slowest records</h3>" + _table(
            ["record", "seconds"], [[_e(r.key), _num(r.duration, ".3f")] for r in timed], (1,))
    studies = [s for s in report.studies if hasattr(s, "timings")]
    if studies:
        srows = [[_e(s.problem), ", ".join(str(k) for k in s.steps), _num(sum(s.timings), ".3f")] for s in studies]
        out += "<h3>Convergence studies</h3>" + _table(["reference", "steps per grid", "solve seconds"], srows, (2,))
    return out


def _environment(report: Report) -> str:
    env = report.meta.get("environment") or {}
    versions = env.get("versions") or {}
    machine = env.get("machine") or {}
    run = {k: report.meta.get(k) for k in ("command", "target", "profile", "seed", "selection", "created",
                                           "duration", "data_dir")}
    if isinstance(run["selection"], dict):
        run["selection"] = _compact(to_jsonable(run["selection"]), 1)
    if isinstance(run["duration"], (int, float)):
        run["duration"] = f"{run['duration']:.1f} s"
    kv = lambda d: '<table class="kv">' + "".join(  # noqa: E731
        f"<tr><td>{_e(k)}</td><td>{_e(v if v is not None else '—')}</td></tr>" for k, v in d.items()) + "</table>"
    blas = {f"BLAS {i + 1}" if len(env.get("blas") or []) > 1 else "BLAS":
            f"{b.get('internal_api')} {b.get('version')} ({b.get('architecture')}, {b.get('threading_layer')}, "
            f"{b.get('num_threads')} threads) {b.get('prefix')}"
            for i, b in enumerate(b for b in env.get("blas") or [] if isinstance(b, dict))}
    return (f'<div class="grid"><div><h3>Run</h3>{kv(run)}</div><div><h3>Versions</h3>{kv(versions)}</div>'
            f"<div><h3>Machine</h3>{kv({**machine, **blas})}</div></div>")


def render(report: Report, *, changes: Any = None, title: str = "verimono report") -> str:
    """The complete HTML document for ``report`` (``changes``: a :class:`verimono.run.gate.Comparison`)."""
    if "environment" not in report.meta:
        report.meta["environment"] = environment()
    bodies = {
        "summary": _summary(report, changes), "changes": _changes(changes),
        "convergence": _convergence(report), "work_precision": work_precision.section(report),
        "trajectories": _trajectories(report), "laws": _laws(report),
        "failures": _failures(report), "performance": _performance(report), "timings": _timings(report),
        "environment": _environment(report),
    }
    nav = "".join(f'<a href="#{s}">{_TITLES[s]}</a>' for s in SECTIONS)
    sections = "".join(f'<section id="{s}"><h2>{_TITLES[s]}</h2>{bodies[s]}</section>' for s in SECTIONS)
    m = report.meta
    sub = " · ".join(_e(x) for x in (
        f"verimono {m.get('command') or ''} {m.get('target') or ''}".strip(), f"profile {m.get('profile')}",
        m.get("created") or "", report.summary(), f"run {m['run_id']}" if m.get("run_id") else "") if x)
    return ('<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            + (f'<meta name="verimono-run-id" content="{_e(m["run_id"])}">' if m.get("run_id") else "")
            + f"<title>{_e(title)}</title><style>{CSS}</style></head><body>"
            f"<header><h1>{_e(title)}</h1><div class=\"sub\">{sub}</div></header><nav>{nav}</nav>"
            f"<main>{sections}</main></body></html>\n")


__all__ = ["render", "reproduction", "SECTIONS"]
