"""A battery called from a user's Python holds BLAS to ``BLAS_THREADS`` as the command line does, and gives the
caller's own limits back after (``verimono.execution.workers.blas_limited``)."""

import numpy as np
import pytest

threadpoolctl = pytest.importorskip("threadpoolctl")

import verimono as vm  # noqa: E402
from verimono.checks import operator_battery  # noqa: E402
from verimono.core.sets import Ball  # noqa: E402
from verimono.execution.workers import BLAS_THREADS  # noqa: E402


def _blas_threads() -> dict[str, int]:
    """Each loaded BLAS library's threads, by its file."""
    return {i["filepath"]: i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"}


def _seen_by(seen: list):
    def shrink(x, lam, t):
        if not seen:                      # once: threadpoolctl inspects every loaded library
            seen.append(_blas_threads())
        return np.asarray(x, dtype=float) / (1.0 + lam)
    return shrink


def _stepper(seen: list):
    def step(problem, t_grid):
        if not seen:
            seen.append(_blas_threads())
        return vm.solve(problem, t_grid)
    return step


@pytest.mark.parametrize("battery", ["operator", "stepper"])
def test_a_battery_holds_blas_to_one_thread_and_restores_the_callers(battery, monkeypatch):
    seen: list = []
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        # the libraries that took two threads (one may not: a library loaded single-threaded by an earlier test)
        before = {f: n for f, n in _blas_threads().items() if n == 2}
        if not before:
            pytest.skip("no loaded BLAS library takes two threads here")
        if battery == "operator":
            op = vm.operator_from_resolvent(_seen_by(seen), 1, name="shrink")
            battery_checks = operator_battery.operator_checks     # one law: the battery's frame is what is tested
            monkeypatch.setattr(operator_battery, "operator_checks",
                                lambda *a, **k: [c for c in battery_checks(*a, **k) if c[0] == "monotone"])
            rep = vm.check_operator(op, seed=0, examples=1, profile="dev")
        else:
            problem = vm.Problem(vm.NormalCone(Ball(np.zeros(2), 1.0)), np.array([0.5, 0.0]), 1.0)
            rep = vm.check_stepper(_stepper(seen), [problem], orders=False, generated=0, laws=["in_domain"],
                                   seed=0, profile="dev")
        after = _blas_threads()
    assert len(rep) and not [r for r in rep.results if r.status == "failed"]
    # the caller's limits given back to every library loaded before the battery (one loaded during it, SciPy's
    # own OpenBLAS, starts at its own default: blas_limited limits the libraries loaded when it begins)
    assert {f: after[f] for f in before} == before
    assert seen and {f: seen[0][f] for f in before} == dict.fromkeys(before, BLAS_THREADS)   # the subject's calls
