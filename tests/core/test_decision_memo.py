"""A convergence study's verdict is remembered with the data it was decided from (``ConvergenceStudy.decision``):
the worker that ran the study decides it, the command line's process reads that verdict from the pickled study
instead of fitting again (issue 43 item 3), and a study whose errors change is decided again."""

from __future__ import annotations

import pickle

import numpy as np
import verimono.core.convergence as convergence
from verimono.core.convergence import ConvergenceStudy
from verimono.core.problem import Order
from verimono.core.verdicts import decide


def _study(rate: float) -> ConvergenceStudy:
    mesh = [0.2 / 2 ** k for k in range(6)]
    errors = [0.3 * h ** rate for h in mesh]
    return ConvergenceStudy("p", "s", mesh, [int(round(1 / h)) for h in mesh], {"sup": errors}, {},
                            Order(1.0, "thm:main"), "exact", 1e-15, [0.0] * len(mesh))


def test_a_study_changed_in_place_is_decided_again():
    study = _study(1.0)
    assert study.decision().status == "passed"
    study.errors["sup"][:] = [0.3 * h ** 0.5 for h in study.mesh]   # the same list, other errors: order 1/2
    assert study.decision().status == decide(study.data()).status != "passed"


def test_the_pickled_study_carries_its_verdict(monkeypatch):
    study = _study(1.0)
    first = study.decision()
    copy = pickle.loads(pickle.dumps(study))

    def no_fit(data):
        raise AssertionError("decided again")

    monkeypatch.setattr(convergence, "decide", no_fit)
    again = copy.decision()
    assert (again.status, again.message, again.worst, again.window) == (first.status, first.message, first.worst,
                                                                        first.window)
    again.window.append(99)                                     # a caller's change is its own
    assert copy.decision().window == first.window
    assert "_decided" not in copy.to_dict() and copy == study   # not a field: the document and equality unchanged


def test_data_that_do_not_compare_equal_are_decided_afresh(monkeypatch):
    study = _study(1.0)
    study.mesh, study.steps, study.timings = study.mesh[:4], study.steps[:4], study.timings[:4]
    study.errors = {"sup": np.array([1e-2, 5e-3, 2.5e-3, 1.25e-3])}    # an array: `==` is ambiguous
    first = study.decision()
    calls = []
    monkeypatch.setattr(convergence, "decide", lambda d: calls.append(d) or decide(d))
    assert study.decision().status == first.status and len(calls) == 1
