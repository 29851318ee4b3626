"""Notebooks: readable ``repr`` and ``_repr_html_`` of Report, CheckResult and ConvergenceStudy (the HTML
report's own sections and plots, its stylesheet scoped to the output), and ``ConvergenceStudy.plot()``."""

from __future__ import annotations

import math
import re
from html.parser import HTMLParser

import numpy as np
import pytest

import verimono as vm
from verimono.checks.orders import check_convergence_order
from verimono.reference import get
from verimono.records.report.notebook import SCOPE, scoped_css

from zoo_steppers import drops_input


@pytest.fixture(scope="module")
def good():
    rec = check_convergence_order(vm.solve, get("t|x| (n=1)"))
    return rec, rec.study


@pytest.fixture(scope="module")
def bad():
    """The stepper that forgets the input u(t): order 0 on the reference with an input (a failure)."""
    rec = check_convergence_order(drops_input, get("Lipschitz field and input"))
    assert rec.status == "failed"
    return rec, rec.study


class _Tags(HTMLParser):
    """Checks that every opened element is closed in order (void elements aside)."""

    VOID = {"br", "meta", "img", "input", "hr", "link", "path", "use", "rect", "circle", "stop"}

    def __init__(self):
        super().__init__()
        self.stack, self.errors, self.tags = [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.tags.append(tag)

    def handle_endtag(self, tag):
        if tag in self.VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.errors.append((tag, list(self.stack[-3:])))
        else:
            self.stack.pop()


def fragment(html: str) -> _Tags:
    p = _Tags()
    p.feed(html)
    assert not p.errors and not p.stack, (p.errors[:3], p.stack[-3:])
    assert {"html", "body", "head", "script"}.isdisjoint(p.tags)          # a fragment, no script
    assert html.startswith(f'<div class="{SCOPE}">')
    css = re.search(r"<style>(.*?)</style>", html, re.S).group(1)
    selectors = [s.strip() for sel in re.findall(r"([^{}]+)\{", css) for s in sel.split(",")]
    assert selectors and all(s.startswith(f".{SCOPE}") for s in selectors)  # nothing styles the notebook
    return p


def test_scoped_css_confines_every_selector():
    css = ":root { --a:1; } body { margin:0 } h2, .card .n { color:red } * { box-sizing:border-box; }"
    assert scoped_css(css, "s") == (".s { --a:1; }\n.s { margin:0 }\n.s h2, .s .card .n { color:red }\n"
                                    ".s * { box-sizing:border-box; }")


def test_record_repr_is_one_readable_line(good, bad):
    rec, _ = good
    text = repr(rec)
    assert text.startswith("CheckResult(passed convergence_order[solve on t|x| (n=1)], worst ")
    assert "≤ bound 1:" in text and "expected 1" in text and "\n" not in text
    assert len(text) < 300 and "'study'" not in text                 # the study dict stays out of it
    assert "> bound 1:" in repr(bad[0]) and repr(bad[0]).startswith("CheckResult(failed ")


def test_report_repr_and_html(good, bad):
    report = vm.Report([good[0], bad[0]], [good[1], bad[1]])
    lines = repr(report).splitlines()
    assert lines[0] == "Report(1 passed, 1 failed, 0 skipped, 0 xfail)"
    assert lines[1] == "  2 records of 1 checks, 2 convergence studies"
    assert lines[2].startswith("  FAILED  convergence_order[drops_input on Lipschitz field and input] worst=9.9")
    html = report._repr_html_()
    p = fragment(html)
    assert p.tags.count("svg") == 2                                     # one log-log plot per study
    assert "1 check failed" in html and "Failures and how to reproduce them" in html
    assert "print(check_convergence_order(" in html                    # the reproduction snippet
    assert "Laws and checks" in html


def test_record_html_shows_the_failure_and_its_study(bad):
    html = bad[0]._repr_html_()
    p = fragment(html)
    assert p.tags.count("svg") == 1 and "Reproduce" in html and "badge failed" in html
    # the reproduction calls the notebook's own stepper, not verimono's solve
    assert "check_convergence_order(drops_input, get(&#x27;Lipschitz field and input&#x27;))" in html
    assert "import solve" not in html


def test_study_repr_tabulates_errors_and_orders(good):
    _, study = good
    lines = repr(study).splitlines()
    assert lines[0] == "ConvergenceStudy(solve on t|x| (n=1); expected order 1; reference: exact solution)"
    rows = [line.split() for line in lines[2:2 + len(study.mesh)]]
    assert [int(r[1]) for r in rows] == study.steps
    assert np.allclose([float(r[2]) for r in rows], study.errors["sup"], rtol=1e-3)
    assert lines[-2].split()[:4] == ["order", *str(study.order).split()]
    assert lines[-1].startswith("  verdict: reaches the expected order")
    html = study._repr_html_()
    assert fragment(html).tags.count("svg") == 1 and str(study.order) in html


def test_study_repr_says_when_the_order_is_missed(bad):
    assert repr(bad[1]).splitlines()[-1].startswith("  verdict: MISSES the expected order")


def _line(ax, label_start):
    (line,) = [ln for ln in ax.get_lines() if str(ln.get_label()).startswith(label_start)]
    return np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)


def test_plot_returns_the_figure_with_the_fitted_and_expected_slopes(good):
    from matplotlib.figure import Figure

    _, study = good
    fig = study.plot()
    assert isinstance(fig, Figure) and type(fig.canvas).__name__ == "FigureCanvasAgg"
    (ax,) = fig.axes
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    h, e = _line(ax, "sup error")
    assert np.array_equal(h, study.mesh) and np.array_equal(e, study.errors["sup"])   # the data, unaltered
    # the drawn fit and expected lines have, in log-log, exactly the fitted and the expected slope
    for label, slope in (("fit slope", study.order.slope), ("expected slope", study.expected.value)):
        x, y = _line(ax, label)
        measured = (math.log(y[-1]) - math.log(y[0])) / (math.log(x[-1]) - math.log(x[0]))
        assert measured == pytest.approx(slope, rel=1e-9)
    fig.savefig(__import__("io").BytesIO(), format="png")               # renders on Agg, no display needed


def test_plot_draws_on_a_given_axes(good):
    from matplotlib.figure import Figure

    fig = Figure()
    ax = fig.add_subplot(1, 2, 2)
    assert good[1].plot(ax=ax) is fig and len(ax.get_lines()) >= 3
