"""Inline SVG plots for the HTML report, drawn with matplotlib's object API (no pyplot global state).

Every function returns an ``<svg>`` element as a string: no XML prolog, no metadata, no external
references, element ids salted per figure so several plots can share one HTML document.
"""

from __future__ import annotations

import io
import itertools
import math
import os
import re
import threading
from typing import Any

import numpy as np

_COUNTER = itertools.count()
#: colours of the norms / components (matplotlib's default cycle, readable on white and in grey print)
COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e")


def _svg(fig: Any) -> str:
    import matplotlib

    buf = io.StringIO()
    salt = f"vm{os.getpid()}x{next(_COUNTER)}"      # unique in a document whichever process drew the plot
    with matplotlib.rc_context({"svg.hashsalt": salt, "svg.fonttype": "none"}):
        fig.savefig(buf, format="svg",
                    metadata={"Creator": None, "Date": None, "Format": None, "Type": None})
    text = buf.getvalue()
    text = text[text.index("<svg"):]                       # drop the XML prolog and DOCTYPE
    text = re.sub(r"<metadata>.*?</metadata>", "", text, flags=re.S)
    # give ids that matplotlib does not salt (figure_1, axes_1, patch_1, ...) a per-figure prefix
    text = re.sub(r'id="((?:figure|axes|patch|line2d|text|legend|matplotlib|xtick|ytick|'
                  r'PolyCollection|FillBetween|LineCollection)[^"]*)"', rf'id="{salt}-\1"', text)
    text = re.sub(r'<svg ', '<svg role="img" class="plot" ', text, count=1)
    return text


# -- drawn ahead: a run whose units run on worker processes draws its plots while it waits for them ---------

#: ``id(subject) -> (subject, svg)``: plots drawn ahead (:func:`draw_ahead`); the subject is held so its id
#: cannot be reused while the entry lives (:func:`forget` empties it once a report is written)
_DRAWN: dict[int, tuple[Any, str]] = {}
#: one figure drawn at a time, and a plot drawn once: the cache is consulted and filled under it
_DRAWING = threading.Lock()


def _figure(width: float = 4.4, height: float = 3.1) -> Any:
    """A figure on the Agg canvas, outside pyplot (no global state, no GUI backend)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=96)
    FigureCanvasAgg(fig)
    fig.subplots_adjust(left=0.16, right=0.97, bottom=0.2, top=0.9)
    return fig


#: the report's axes, one per kind of plot, drawn on again and again under :data:`_DRAWING` (a new figure's axes
#: and ticks were a third of each plot's time); :func:`_reused_axes` empties them first
_REUSED: dict[str, Any] = {}


def _reused_axes(kind: str) -> Any:
    """The report's axes for plots of ``kind``, emptied of the previous plot's artists (the figure functions
    set every scale, limit, locator, label and title they use, so the drawing is the fresh figure's: a test
    compares them)."""
    ax = _REUSED.get(kind)
    if ax is None:
        ax = _REUSED[kind] = _figure().add_subplot()
    else:
        for artist in [*ax.lines, *ax.collections, *ax.texts, *ax.patches, *ax.images]:
            artist.remove()
        ax.relim()
    return ax


#: the names of this process's own background threads (:func:`warm_up`'s, :func:`draw_ahead`'s): they end by
#: themselves, so a fork guard waits for them rather than spawning (:meth:`verimono.execution.schedule.SharedQueue.fork_guard`)
WARM_UP_THREAD, PLOTS_THREAD = "verimono-report-warm-up", "verimono-report-plots"


def warm_up() -> None:
    """Import matplotlib's figure and Agg canvas: about 0.4 s that the drawer (or a run on worker processes, in a
    background thread of its otherwise waiting process) spends before the first plot is asked for.  Nothing is
    drawn: a throwaway figure cost 0.1 s and spared the first real plot 10 ms (measured here)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: F401
    from matplotlib.figure import Figure  # noqa: F401


def _decade(v: float, _pos: Any = None) -> str:
    """A log-axis tick label as plain text (``1e-06``), not mathtext (parsed by pyparsing on every draw)."""
    return f"{v:.0e}" if v > 0 else ""


def _num(v: Any) -> float:
    return float(v) if isinstance(v, (int, float, str)) else math.nan


def _drawn_once(subject: Any, draw: Any) -> str:
    with _DRAWING:
        hit = _DRAWN.get(id(subject))
        if hit is None and _DRAWER is not None:
            hit = _DRAWER.take(subject)
            if hit is not None:
                _DRAWN[id(subject)] = hit        # a plot shown twice is fetched once
        if hit is not None and hit[0] is subject:
            return hit[1]
        svg = draw()
        _DRAWN[id(subject)] = (subject, svg)
        return svg


# -- drawn elsewhere: the command line's drawer process (verimono.records.report.drawer) ------------------------------

#: the drawer this process sends its plots to (:func:`verimono.records.report.drawer.drawer_pipe`), or ``None``: an object
#: with ``ask(kind, subject)``, ``take(subject) -> (subject, html) | None`` and ``forget()``
_DRAWER: Any = None


def use_drawer(drawer: Any) -> None:
    """Send :func:`draw_ahead`'s plots to ``drawer`` (``None``: draw them here again)."""
    global _DRAWER
    _DRAWER = drawer


def draw_ahead(studies: Any = (), samples: Any = ()) -> threading.Thread | None:
    """Draw the convergence plots of ``studies`` and the trajectory plots of ``samples`` ahead of the report
    (:func:`convergence_plot` and :func:`trajectory_plot` then return them): what a run whose units run on
    worker processes does with its waiting (``verimono run``/``check`` with ``--executor process:N``,
    ``auto``).  With a drawer (:mod:`verimono.records.report.drawer`) they are sent there and drawn on its core; else they
    are drawn by a background thread of this process (returned).  A plot the report needs before the
    drawer or thread reached it is waited for, or drawn there, once.  A plot that cannot be drawn ahead is
    left to the report, which says why."""
    studies, samples = list(studies), list(samples)
    if _DRAWER is not None:
        with _DRAWING:
            for kind, subjects in (("convergence", studies), ("trajectory", samples)):
                for s in subjects:
                    if id(s) not in _DRAWN:
                        _DRAWER.ask(kind, s)
        return None

    def draw() -> None:
        try:
            for s in studies:
                convergence_plot(s)
            for s in samples:
                trajectory_plot(s)
        except Exception:  # noqa: BLE001 - the report draws it again and reports the error there
            pass

    # not a daemon: a script exiting as ``execute`` returns would finalize the interpreter under it while it is in
    # matplotlib's Agg (pybind11), which aborts the process ("terminate called without an active exception",
    # status 134); the exit now waits for the plots being drawn (tests/run/test_schedule_safety.py)
    thread = threading.Thread(target=draw, name=PLOTS_THREAD, daemon=False)
    thread.start()
    return thread


def forget() -> None:
    """Drop the plots drawn ahead (after a report is written), and those still asked of the drawer."""
    with _DRAWING:
        _DRAWN.clear()
        if _DRAWER is not None:
            _DRAWER.forget()


def drawing_elsewhere() -> bool:
    """Whether :func:`draw_ahead` sends its plots to a drawer process (this process then needs no matplotlib)."""
    return _DRAWER is not None


def _swatch(handle: Any) -> str:
    """A legend key as inline-styled HTML: the handle's line (colour, dashes) and marker, or a band's fill."""
    from matplotlib.colors import to_hex
    from matplotlib.lines import Line2D

    if not isinstance(handle, Line2D):                      # a filled band (fill_between)
        rgba = handle.get_facecolor()
        rgba = rgba[0] if len(np.shape(rgba)) == 2 else rgba
        r, g, b = (int(round(255 * c)) for c in rgba[:3])
        return (f'<span style="display:inline-block;width:18px;height:8px;'
                f'background:rgba({r},{g},{b},{rgba[3]:g})"></span>')
    color, alpha = to_hex(handle.get_color()), handle.get_alpha()
    opacity = "" if alpha is None else f"opacity:{alpha:g};"
    out = ""
    style = {"-": "solid", "--": "dashed", ":": "dotted", "-.": "dashed"}.get(handle.get_linestyle())
    if style:
        out += (f'<span style="display:inline-block;width:16px;border-top:2px {style} {color};'
                f'vertical-align:middle;{opacity}"></span>')
    hollow = str(handle.get_markerfacecolor()).lower() == "none"
    mark = {"o": "○" if hollow else "●", "s": "□" if hollow else "■", "d": "◇" if hollow else "◆"}.get(
        str(handle.get_marker()))
    if mark:
        out += f'<span style="color:{color};font-size:10px;line-height:1;{opacity}">{mark}</span>'
    return out


def _legend_html(ax: Any) -> str:
    """The axes' legend as HTML text under its plot (inline styles: the report and a notebook alike).  Drawn
    by matplotlib it cost 28% of a report's plotting time (its layout is measured text, box by box)."""
    from html import escape

    keys = "".join(f'<span style="display:inline-flex;align-items:center;gap:3px">{_swatch(h)}{escape(label)}</span>'
                   for h, label in zip(*ax.get_legend_handles_labels()))
    return ('<div class="legend" style="display:flex;flex-wrap:wrap;gap:1px 12px;font-size:11px;color:#3a4150;'
            f'padding:2px 4px 0">{keys}</div>')


def _plot_html(fig: Any) -> str:
    return _svg(fig) + _legend_html(fig.axes[0])


def convergence_plot(study: Any) -> str:
    """:func:`convergence_figure` as an inline ``<svg>`` followed by its legend in HTML."""
    return _drawn_once(study, lambda: _plot_html(convergence_figure(study, _reused_axes("convergence"), legend=False)))


def convergence_figure(study: Any, ax: Any = None, *, legend: bool = True) -> Any:
    """Log-log errors against ``|Δ|`` for each norm, the fitted sup-norm slope with its 95% interval as a
    shaded wedge, the expected slope dashed, and the round-off floor dotted; drawn on ``ax`` (default: a
    new Agg figure), with its legend unless ``legend=False`` (the report puts it under the plot, in HTML).
    Returns the matplotlib ``Figure``."""
    from matplotlib.ticker import FuncFormatter, NullLocator

    if ax is None:
        fig = _figure()
        ax = fig.add_subplot()
    fig = ax.figure
    h = np.asarray(study.mesh, float)
    floor = float(study.floor)
    ax.set_xscale("log")        # once, before the lines: ``loglog`` would set both scales (and their locators)
    ax.set_yscale("log")        # again for every line
    positive = []
    for (norm, errs), color, marker in zip(study.errors.items(), COLORS, "osd"):
        e = np.asarray([_num(v) for v in errs])
        if not np.any(e > 0):
            ax.plot([], [], ls="none", marker=marker, color=color, label=f"{norm} error: 0 on every grid")
            continue
        positive.append(e[e > 0])
        shown = np.where(e > 0, e, np.nan)  # exact zeros cannot be drawn on a log axis
        ax.plot(h, shown, marker=marker, color=color, lw=1.0 if norm == "sup" else 0.8,
                  alpha=1.0 if norm == "sup" else 0.55, ms=5 if norm == "sup" else 4, label=f"{norm} error")
    fit = study.fits["sup"]
    e = np.asarray([_num(v) for v in study.errors["sup"]])
    used = [i for i in fit.used if e[i] > 0]
    hh = np.geomspace(h.min(), h.max(), 50)
    if used and not fit.exact and math.isfinite(fit.slope):
        lh, le = np.log(h[used]), np.log(e[used])
        ch, ce = lh.mean(), le.mean()  # the fit passes through the centroid of the used points
        line = np.exp(ce + fit.slope * (np.log(hh) - ch))
        label = f"fit slope {fit.slope:.3f}"
        if math.isfinite(fit.low) and math.isfinite(fit.high):
            label += f" [{fit.low:.3f}, {fit.high:.3f}]"
            lo = np.exp(ce + fit.low * (np.log(hh) - ch))
            hi = np.exp(ce + fit.high * (np.log(hh) - ch))
            ax.fill_between(hh, np.minimum(lo, hi), np.maximum(lo, hi), color=COLORS[0], alpha=0.15, lw=0,
                            label="95% interval")
        ax.plot(hh, line, color="black", lw=1.2, label=label)
        exp = study.expected
        if exp is not None and exp.value is not None and not exp.exact:
            ax.plot(hh, np.exp(ce + exp.value * (np.log(hh) - ch)), color="#555555", ls="--", lw=1.2,
                      label=f"expected slope {exp.value:g}")
    elif fit.exact:
        ax.text(0.04, 0.9, "exact at the nodes: every error at round-off", transform=ax.transAxes,
                fontsize=8, color="#2ca02c")
    lo = min((float(p.min()) for p in positive), default=floor) / 3
    hi = max((float(p.max()) for p in positive), default=floor) * 3
    if fit.exact or floor >= lo / 10:  # the floor matters here: show it
        ax.axhline(floor, color="#888888", ls=":", lw=1.0, label=f"round-off floor {floor:.1e}")
        lo, hi = min(lo, floor / 3), max(hi, floor * 3)
    ax.yaxis.set_major_formatter(FuncFormatter(_decade))   # plain text: mathtext costs most of the drawing
    ax.yaxis.set_minor_locator(NullLocator())
    ax.set_ylim(lo, hi)
    ax.set_xlim(h.min() / 1.25, h.max() * 1.25)
    ax.set_xticks(h, [f"{v:.2g}" for v in h])  # label the studied meshes themselves
    ax.xaxis.set_minor_locator(NullLocator())
    for label in ax.get_xticklabels():
        label.set_rotation(30)
        label.set_fontsize(7.5)
    ax.set_xlabel("mesh |Δ| = max step")
    ax.set_ylabel("error")
    ax.set_title(study.problem, fontsize=10, y=1.0)   # a fixed y: no search of the tick labels above
    ax.grid(True, which="major", alpha=0.3)
    if legend:
        ax.legend(fontsize=6.5, loc="lower right", framealpha=0.85)
    return fig


#: how many points a figure's line needs: one per pixel column of the report's axes (4.4 in at 96 dpi, 81% of it
#: the axes: 342 columns), a line's each column then drawn from its first, lowest and highest point
LINE_POINTS = 342
#: how many markers a trajectory plot draws per component, evenly spaced (plus the extremes between them)
MARKERS = 60


def keep_extrema(y: Any, count: int) -> np.ndarray:
    """Indices of ``y`` to draw at about ``count`` points: every ``ceil((n-1)/count)``-th point and the last,
    and, between two such neighbours ``a < b``, the lowest and the highest point of ``y[a:b]`` where it reaches
    below or above both ends.  Every segment ``y[a..b]`` between kept neighbours therefore has its minimum and
    its maximum among the kept points: a spike between two evenly spaced points is drawn, not stepped over
    (NaN, a gap in the line, is never a segment's extreme)."""
    y = np.asarray(y, float)
    n = len(y)
    if n <= count + 1:
        return np.arange(n)
    every = -(-(n - 1) // count)
    base = np.arange(0, n, every)
    if base[-1] != n - 1:
        base = np.append(base, n - 1)
    rows = -(-n // every)
    pad = np.full(rows * every, np.nan)
    pad[:n] = y
    block = pad.reshape(rows, every)[: len(base) - 1]          # row k: y[base[k] : base[k] + every]
    hi = np.where(np.isnan(block), -np.inf, block)
    lo = np.where(np.isnan(block), np.inf, block)
    i_hi, i_lo = hi.argmax(axis=1), lo.argmin(axis=1)
    rows_k = np.arange(len(block))
    top, bot = hi[rows_k, i_hi], lo[rows_k, i_lo]
    ends_hi = np.fmax(y[base[:-1]], y[base[1:]])
    ends_lo = np.fmin(y[base[:-1]], y[base[1:]])
    extra = np.concatenate([(base[:-1] + i_hi)[top > np.where(np.isnan(ends_hi), -np.inf, ends_hi)],
                            (base[:-1] + i_lo)[bot < np.where(np.isnan(ends_lo), np.inf, ends_lo)]])
    return np.unique(np.concatenate([base, extra]))


def trajectory_plot(sample: dict[str, Any]) -> str:
    """:func:`trajectory_figure` as an inline ``<svg>`` followed by its legend in HTML."""
    return _drawn_once(sample, lambda: _plot_html(trajectory_figure(sample, _reused_axes("trajectory"), legend=False)))


def trajectory_figure(sample: dict[str, Any], ax: Any = None, *, legend: bool = True) -> Any:
    """The discrete solution (markers) against the exact one (lines), component by component (≤ 4), drawn on
    ``ax`` (default: a new Agg figure); the legend drawn in the figure unless ``legend=False`` (the report puts
    it under the plot, in HTML).  Returns the matplotlib ``Figure``."""
    from matplotlib.ticker import MaxNLocator

    if ax is None:
        ax = _figure().add_subplot()
    fig = ax.figure
    t = np.asarray(sample["t"], float)
    x = np.asarray([[_num(v) for v in np.atleast_1d(row)] for row in sample["x"]])
    ncomp = min(x.shape[1], 4)
    exact = sample.get("exact")
    te = np.asarray(sample.get("t_exact") or [], float)
    ex = np.asarray([[_num(v) for v in np.atleast_1d(row)] for row in exact]) if exact else None
    for j in range(ncomp):
        color = COLORS[j % len(COLORS)]
        if ex is not None:          # a long line drawn at the axes' resolution, each pixel column's extremes kept
            k = keep_extrema(ex[:, j], LINE_POINTS) if len(te) > 2 * LINE_POINTS else slice(None)
            ax.plot(te[k], ex[k, j], color=color, lw=1.4, alpha=0.8, label=f"exact x{j + 1}" if ncomp > 1 else "exact")
        k = keep_extrema(x[:, j], MARKERS)      # ~60 markers, evenly spaced, and any extreme between them
        ax.plot(t[k], x[k, j], ls="none", marker="o", ms=3.2, mfc="none", color=color,
                label=f"scheme x{j + 1}" if ncomp > 1 else "scheme")
    ax.set_xlabel("t")
    ax.set_ylabel("x(t)")
    ax.set_title(f"{sample['problem']} (h = {float(sample['h']):.3g})", fontsize=10, y=1.0)
    ax.grid(True, alpha=0.3)
    ax.xaxis.set_major_locator(MaxNLocator(5))      # a handful of ticks: their layout is most of the drawing
    ax.yaxis.set_major_locator(MaxNLocator(5))
    if legend:
        ax.legend(fontsize=6.5, loc="best", framealpha=0.85, ncol=2 if ncomp > 2 else 1)
    return fig


__all__ = ["convergence_plot", "convergence_figure", "trajectory_plot", "trajectory_figure", "warm_up", "draw_ahead",
           "forget", "use_drawer", "drawing_elsewhere", "keep_extrema"]
