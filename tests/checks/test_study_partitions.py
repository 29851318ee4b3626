"""The step laws judge the stepper on the convergence study's grids too (issue 32, item 6): its finest grid and the
grids where its errors fell short are partitions the battery computed.  A stepper that leaves the proximal scheme
only on grids finer than the battery's own partitions (at most 160 cells: a "fast path" for long grids) passed
``selections`` although the study ran it there; it fails now, in ``check_stepper`` and in ``verimono check``."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks.partitions import LIMIT_LEVELS
from verimono.reference import get
from zoo_steppers import _scheme


def long_grid_path(cells, bump=0.05):
    """The proximal scheme, except on grids of more than ``cells`` cells, where each step's result is moved by
    ``bump · h²`` (an O(h) change of the limit's error: it still converges at order 1): the discrete velocities
    are no selections there."""
    def post(problem, t, k, z, x):
        return x + bump * (t[k + 1] - t[k]) ** 2 * np.ones_like(x)

    def step(problem, t_grid):
        t = np.asarray(t_grid, dtype=float)
        return _scheme(problem, t, post=post if len(t) - 1 > cells else None)
    step.__name__ = f"deviates above {cells} cells"
    return step


@pytest.mark.parametrize("name, cells", [("t|x| (n=1)", 400), ("linear x' = -Mx", 1000),
                                         ("translating ball", 500)])
def test_a_stepper_off_only_on_long_grids_fails_selections(name, cells):
    p = get(name)
    assert cells > max(LIMIT_LEVELS) and cells < max(int(round(p.T / h)) for h in p.steps)
    rep = vm.check_stepper(long_grid_path(cells), problems=[p], laws=["selections"])
    sel = next(r for r in rep if r.check == "selections")
    assert sel.status == "failed", sel.message
    worst = max(sel.details["worst_by_grid"], key=sel.details["worst_by_grid"].get)
    assert worst.startswith("study K=") and int(worst.split("=")[1]) > cells
    # without the study's grids (laws only), the battery's partitions never see it: the study is what finds it
    alone = vm.check_stepper(long_grid_path(cells), problems=[p], laws=["selections"], orders=False)
    assert next(r for r in alone if r.check == "selections").status == "passed"


def test_the_proximal_scheme_holds_on_the_study_grids_too():
    """Control: ``verimono.solve`` passes every step law on the study's grids (they are judged: named there)."""
    p = get("linear x' = -Mx")
    rep = vm.check_stepper(vm.solve, problems=[p], laws=["selections", "in_domain", "contraction", "bounds_yb"])
    assert rep.ok, [str(r) for r in rep.failures]
    for r in rep:
        if r.check in ("selections", "in_domain", "contraction", "bounds_yb") and r.status == "passed":
            assert "study K=3200" in r.details["worst_by_grid"], (r.check, list(r.details["worst_by_grid"]))


def test_the_grids_where_the_errors_paused_are_judged():
    """A stepper answering exactly the study's finest recommended grid with the previous grid's solution
    (interpolated): its errors pause there and resume on the finer grids the study adds — the convergence order
    passes as pre-asymptotic — but the paused grid is one the step laws judge, and ``selections`` fails there."""
    p = get("t|x| (n=1)")
    finest = max(int(round(p.T / h)) for h in p.steps)

    def pauses(problem, t):
        if len(t) - 1 != finest:
            return vm.solve(problem, t).x
        coarse = vm.uniform_grid(problem.T, steps=finest // 2)
        xc = vm.solve(problem, coarse).x
        return np.stack([np.interp(t, coarse, xc[:, j]) for j in range(xc.shape[1])], -1)

    rep = vm.check_stepper(pauses, problems=[p], laws=["selections"])
    order = next(r for r in rep if r.check == "convergence_order")
    assert order.status == "passed" and "paused" in order.message, order.message
    sel = next(r for r in rep if r.check == "selections")
    assert sel.status == "failed" and f"study K={finest}" in sel.details["worst_by_grid"]


@pytest.mark.slow
def test_verimono_check_judges_the_study_grids(tmp_path):
    """The command line: the convergence stage's study grids reach the trajectory-law units (other processes)."""
    from verimono.cli import main
    from verimono.records.results import load

    mod = tmp_path / "deviant.py"
    mod.write_text("import sys\nsys.path.insert(0, %r)\nfrom test_study_partitions import long_grid_path\n"
                   "stepper = long_grid_path(1000)\n" % str(__import__("pathlib").Path(__file__).parent))
    out = tmp_path / "out"
    code = main(["check", f"{mod}:stepper", "--reference", "linear x' = -Mx", "--out", str(out)])
    assert code == 1
    rec = next(r for r in load(out / "results.json").results if r.check == "selections")
    assert rec.status == "failed" and "study K=3200" in rec.details["worst_by_grid"]
