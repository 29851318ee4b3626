"""Order verdicts rest on the asymptotic slopes (issue 42, item 4): a claimed order is met only when the finest
local slopes reach it; a claim one order above the scheme's never passes.

The subjects are explicit Runge–Kutta schemes one step per cell on the smooth references whose field is single-valued
(tests/zoo_integrators.py): explicit Euler (order 1), Heun (2), Bogacki–Shampine (3), the classical RK4 (4), each
claimed at its order and one above.  Before, on the smooth manufactured problem (its study starts from the ladder
of 3 to 50 cells, the coarse end far from asymptotic), Heun claimed as order 3 passed — "measured 3.617 [1.656,
5.577], claimed 3 (pre-asymptotic: local slopes, coarse to fine: 6.95, 4.20, 2.00, 1.96)" —, and so did Bosh3
claimed as 4 (slopes 7.84, 3.02, 3.14, 3.09), RK4 claimed as 5 (6.96, 4.19, 4.11, 4.07) and Euler claimed as 2; on
the grids of a step range, Heun claimed as 3 passed on slopes 6.14, 2.25, 2.02: a fit over a pre-asymptotic range
averages the coarse end with the fine end, and its wide interval "reached" the claim."""

from __future__ import annotations

import re

import pytest

import verimono as vm
import zoo_integrators as zi
from verimono.core.convergence import convergence_study
from verimono.reference import get, linear

SCHEMES = {"euler": (zi.euler_on_grid, 1), "heun": (zi.heun_on_grid, 2), "bosh3": (zi.bosh3_on_grid, 3),
           "rk4": (zi.rk4_on_grid, 4)}
def _problem(name, request):
    return request.getfixturevalue("manufactured") if name == "manufactured" else get(name)


MEASURED = re.compile(r"order (\d+\.\d\d) measured, (\d+) claimed")


def _study(scheme, order, problem, **kw):
    fn, _ = SCHEMES[scheme]
    return convergence_study(vm.Stepper(fn, scheme="any", order=order), problem, **kw)


@pytest.mark.parametrize("name", ["manufactured", "linear x' = -Mx", "Lipschitz field and input"])
@pytest.mark.parametrize("scheme", list(SCHEMES))
def test_a_claim_one_order_up_fails_and_the_true_order_passes(scheme, name, request):
    """Claimed at its order ``q``: passed.  Claimed at ``q + 1``: failed, naming the order of its finest slopes
    (within 0.3 of ``q``), with a ratio above 1."""
    p = _problem(name, request)
    q = SCHEMES[scheme][1]
    right = _study(scheme, q, p).decision()
    assert right.status == "passed", right.message
    over = _study(scheme, q + 1, p).decision()
    assert over.status == "failed", over.message
    m = MEASURED.search(over.message)
    assert m and int(m.group(2)) == q + 1 and abs(float(m.group(1)) - q) < 0.3, over.message
    assert over.worst > 1.0


def test_the_finest_slopes_decide_not_the_fit_over_a_pre_asymptotic_range(manufactured):
    """Heun on the manufactured problem: the fit over 3 to 50 cells is 3.6 with an interval reaching 5.6, the
    finest slopes are 2.00 and 1.96 — order 2, and the message says so."""
    d = _study("heun", 3, manufactured).decision()
    assert d.fit is not None and d.fit.reaches(3.0), d.fit           # the fit alone would have passed it
    assert d.status == "failed" and "at the fine end" in d.message
    assert float(MEASURED.search(d.message).group(1)) == pytest.approx(2.0, abs=0.1)


def test_on_the_grids_of_a_step_range_an_overclaim_never_passes():
    """x' = -Mx with a rotation (M = [[0.5, 4], [-4, 0.5]], T = 3.5) on the grids of h in [T/64, T/8] (8 to 64
    cells): Heun's slopes 6.14, 2.25, 2.02.  Claimed 3: failed; claimed 2: passed.  Euler's slopes 2.38, 3.31, 2.43
    (far from its order 1 on these grids): claimed 1, the slopes' whole interval lies above 1 (passed); claimed 2,
    nothing shows where they settle and no finer grid may be tried — undecided, never passed."""
    p = linear.linear(M=[[0.5, 4.0], [-4.0, 0.5]], x0=(2.0, 1.0), T=3.5)
    kw = {"step_range": (p.T / 64, p.T / 8)}
    assert _study("heun", 3, p, **kw).decision().status == "failed"
    assert _study("heun", 2, p, **kw).decision().status == "passed"
    assert _study("euler", 1, p, **kw).decision().status == "passed"
    euler2 = _study("euler", 2, p, **kw).decision()
    assert euler2.status == "undecided" and "still move" in euler2.message, euler2.message
