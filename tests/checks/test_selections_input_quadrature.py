"""``selections`` judges ``y_{k+1} = (x_k + h f(x_k) + ∫u - x_{k+1})/h`` with ``∫u`` from
:meth:`verimono.Problem.input_increments`: 3-point Gauss–Legendre when the problem states no primitive ``U``.  On a
coarse cell that rule is off by more than the law's round-off tolerance (``Lipschitz field and input``,
``u = cos 2t``, the cell ``[1.08, 1.47]`` of the graded ``K = 10`` partition: ``3e-8``), so the paper's scheme computed
with the exact ``∫u`` was failed at ratio 11.5 (branch probe6).  The law allows the rule's own error, estimated per
cell (the rule against itself on the two half cells); a scheme off by more than that is still failed."""

from __future__ import annotations

import math

import numpy as np

from verimono.checks.trajectory_laws import check_selections
from verimono.reference import get

OMEGA = 2.0      # linear.lipschitz_input's u = cos(ωt): ∫u = (sin ωb - sin ωa)/ω in closed form


def _scheme(shift: float = 0.0, rule: str = "exact"):
    """The paper's scheme on ``x' = -mx + f(x) + u``, ``∫u`` exact (``rule="exact"``) or the right-point rule
    ``h u(t_{k+1})`` (an error ``O(h^2)`` per cell); ``shift``: every state moved by that relative amount."""
    def stepper(problem, t_grid):
        t = np.asarray(t_grid, dtype=float)
        m = float(problem.operator.M(0.0)[0, 0])
        x = [np.array(problem.x0, dtype=float)]
        for k in range(len(t) - 1):
            h = t[k + 1] - t[k]
            iu = ((math.sin(OMEGA * t[k + 1]) - math.sin(OMEGA * t[k])) / OMEGA if rule == "exact"
                  else h * math.cos(OMEGA * t[k + 1]))
            z = x[-1] + h * np.asarray(problem.f(x[-1]), dtype=float) + iu
            x.append(z / (1.0 + h * m) * (1.0 + shift))
        return np.array(x)
    return stepper


def test_the_scheme_with_the_exact_input_integral_passes_selections():
    p = get("Lipschitz field and input")
    assert p.U is None and p.u is not None
    rec = check_selections(_scheme(), p, seed=0)
    assert rec.status == "passed", str(rec)


def test_a_scheme_off_by_more_than_the_quadrature_error_still_fails():
    p = get("Lipschitz field and input")
    assert check_selections(_scheme(rule="right point"), p, seed=0).status == "failed"
    assert check_selections(_scheme(shift=1e-6), p, seed=0).status == "failed"
