"""The engine's overhead per evaluation of an operator law against the subject's own cost (issue 43, item 1).

``check_operator`` (ci profile) on cheap catalog operators in R^3, on PyProximal's box projection (a NumPy prox
library) and on a PyTorch soft thresholding (skipped without torch): the CPU time split into the subject's own
(inside its resolvent, :class:`engine_overhead.SubjectClock`) and verimono's (the rest), per law evaluation,
and the search resolution the records state (``details["searched"]``, :func:`engine_overhead.cells`) per CPU
second.  The numbers land in ``benchmark.extra_info``; the code before the issue is measured by the same
module run as a script under its own venv (docs/speed.md, "The engine's overhead per evaluation").

Gates (timed runs): verimono's own time per evaluation at most ``OWN_OVER_SUBJECT`` times the subject's (the
goal is 1; measured 2.9–7.5 on a loaded 2-core machine, 5–10 before), no failed record; un-timed, the sanity
factor of the conftest on the same gate.
"""

from __future__ import annotations

import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(__file__))
import engine_overhead as eo  # noqa: E402 - the measurement module next to this file

#: verimono's own time per evaluation over the subject's, at most: a regression alarm (goal: 1; measured 2.9-7.5)
OWN_OVER_SUBJECT = 10.0


def _run(gate, op, clock) -> dict:
    rounds = gate.rounds(3, 1)
    got = []
    gate.benchmark.pedantic(lambda: got.append(eo.measure(op, seed=len(got), clock=clock)), rounds=rounds,
                            iterations=1, warmup_rounds=0)
    while len(got) < rounds:
        got.append(eo.measure(op, seed=len(got), clock=clock))
    best = sorted(got, key=lambda d: d["own_over_subject"])[len(got) // 2]     # the median round
    gate.benchmark.extra_info.update(best)
    assert all(d["failed"] == 0 for d in got), got
    assert best["own_over_subject"] <= gate.bound(OWN_OVER_SUBJECT), best
    return best


@pytest.mark.parametrize("name", list(eo.catalog()))
def test_engine_overhead_on_the_catalog(gate, name):
    op, clock, undo = eo.timed_catalog(name)
    try:
        _run(gate, op, clock)
    finally:
        undo()


def test_engine_overhead_on_a_numpy_prox_library(gate):
    pytest.importorskip("pyproximal")
    op, clock = eo.pyproximal_box()
    _run(gate, op, clock)


def test_engine_overhead_on_a_torch_prox(gate):
    pytest.importorskip("torch")
    op, clock = eo.torch_soft_threshold()
    _run(gate, op, clock)
