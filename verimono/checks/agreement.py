"""The limit of a stepper against the solution's, on a problem without an exact solution (Theorem ``thm:main``).

Without an exact solution a convergence study measures a stepper against a fine-grid solution of its own:
self-convergence, which a scheme converging to a wrong limit (a field ``f`` dropped, an input dropped, a term
scaled) passes.  The solution is the limit of :func:`verimono.solve` — the proximal scheme, which converges to it
(Theorem ``thm:main``) — so :func:`limit_agreement` compares the two *limits*, each estimated from its own 4-fold
uniform refinements ``K_m = 10, 40, 160, …`` (the levels of ``unique_limit``, :data:`LIMIT_LEVELS`, whose runs a
battery shares):

* ``c_m`` — the sup distance at the nodes of ``K_m`` between the runs on ``K_m`` and ``K_{m+1}`` (nested grids);
* the tail — the distance of the finest run to its own limit, ``LIMIT_TAIL_SAFETY · c r/(1 − r)`` from the last
  two differences (:func:`verimono.checks.limits.own_trend_tail`), ``r`` at least ``4^{-p}`` — ``p`` the order
  the stepper claims (1 for a proximal claim), 1 for ``solve``: a fall faster than the scheme's order between
  coarse levels is pre-asymptotic and does not extrapolate;
* ``D`` — the sup distance between the stepper's and ``solve``'s finest runs at their nodes.

With ``τ_s``, ``τ_r`` the two tails and ``tol`` the two round-off floors:

* **failed** when ``D > τ_s + τ_r + tol``: the limits are provably apart, by at least ``D − τ_s − τ_r``;
* **passed** when ``D + τ_s + τ_r ≤ LIMIT_RESOLUTION · scale + tol``: the limits are within that (and the
  round-off) of each other (``|lim_s − lim_r| ≤ τ_s + D + τ_r``);
* else the next 4-fold level for both (up to :data:`MAX_AGREEMENT_CELLS` cells and :data:`MAX_LEVEL_NUMBERS`
  numbers a run), and **undecided** when those are spent: the estimates cannot
  tell the limits apart nor bring them within the resolution — never a pass.

A wrong limit is thus caught whatever order the stepper claims, once both tails fall below its offset; an
offset below ``LIMIT_RESOLUTION · scale`` may pass (the record states the resolution it was judged at).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..core.claims import claim_of
from ..core.grids import uniform_grid
from ..core.problem import Problem
from ..core.stepping import solve
from ..core.tolerances import LIMIT_RATIO_FLOOR, roundoff_floor
from ..execution.timeouts import note_progress
from ..records.results import FAILED, PASSED, UNDECIDED
from .limits import own_trend_tail
from .partitions import LIMIT_LEVELS, run_stepper

#: two limits within ``LIMIT_RESOLUTION · max(1, max |x|)`` of each other (the stepper's own tail, their distance
#: and solve's tail summed) agree.  A resolution has to be stated: a limit ``δ`` off shows only once both tails fall
#: below ``δ``, and no finite refinement gets there for every ``δ``.  ``1e-3``: the catalog's order-1 schemes reach
#: tails of ``1e-4 … 5e-4`` by K = 640 … 2560 on unit-size problems of horizon 2 (measured, docs/checks.md), so a
#: correct scheme is decided within the levels, and an offset of ``1e-3`` or more is never within it
LIMIT_RESOLUTION = 1e-3
#: the finest level: unique_limit's 10, 40, 160 refined 4-fold up to 40960 cells.  An order-1 scheme's tail
#: ``4/3 · c`` reaches ``1.5e-4 … 2.5e-4`` there on unit-size problems of horizon 2 whose step-10 errors are
#: ``0.1 … 0.2`` (docs/checks.md), so two such tails and their distance fit within the resolution; 10240 left
#: correct order-1 schemes undecided on those (tails 6e-4 … 1e-3 each)
MAX_AGREEMENT_CELLS = 40960
#: a level's run holds at most this many numbers ``(K + 1)·n`` (256 MB in float64): beyond it the law is undecided,
#: never a run of gigabytes (n = 10^6 has 32 cells)
MAX_LEVEL_NUMBERS = 1 << 25


def _sup_distance(a: np.ndarray, b: np.ndarray) -> float:
    """``max_k |a_k − b_k|``: the sup distance at the nodes of two runs on the same grid (states of any shape)."""
    return float(np.max(np.linalg.norm((a - b).reshape(len(a), -1), axis=1)))


def _node_distance(fine: np.ndarray, coarse: np.ndarray) -> float:
    """The sup distance at the coarse grid's nodes between a run on it and one on its 4-fold refinement."""
    return _sup_distance(fine[::4], coarse)


def limit_agreement(stepper: Callable, study: Any, problem: Problem) -> tuple[str, str, dict]:
    """``(status, message, details)``: whether ``stepper`` converges to the limit of :func:`verimono.solve` on
    ``problem`` (the module docstring); ``study`` is the stepper's convergence study (its round-off floor)."""
    claim = claim_of(stepper)
    order = 1.0 if claim.proximal or not claim.order else float(claim.order)
    floor_s = 4.0 ** -order                 # the claimed order on 4-fold refinements
    n = int(np.prod(problem.x0.shape)) if problem.x0.shape else 1
    levels = list(LIMIT_LEVELS)
    runs: dict[str, list[np.ndarray]] = {"stepper": [], "solve": []}
    diffs: dict[str, list[float]] = {"stepper": [], "solve": []}
    scale = [max(1.0, float(np.max(np.abs(problem.x0))))]
    ran = [0]

    def add_level(K: int) -> None:
        grid = uniform_grid(problem.T, steps=K)
        for name, fn in (("stepper", stepper), ("solve", solve)):
            x = run_stepper(fn, problem, grid)
            ran[0] += 1
            note_progress(ran[0], True, "runs of the stepper and of verimono.solve")
            scale[0] = max(scale[0], float(max(x.max(), -x.min())))
            if runs[name]:
                diffs[name].append(_node_distance(x, runs[name][-1]))
            runs[name] = [x]            # only the finest run is kept

    for K in levels:
        add_level(K)
    while True:
        tol = float(study.floor) + roundoff_floor(scale[0])
        tail_s, r_s = own_trend_tail(diffs["stepper"][-2], diffs["stepper"][-1], tol, floor_s)
        tail_r, r_r = own_trend_tail(diffs["solve"][-2], diffs["solve"][-1], tol, LIMIT_RATIO_FLOOR)
        D = _sup_distance(runs["stepper"][0], runs["solve"][0])
        resolution = LIMIT_RESOLUTION * scale[0]
        upper = D + tail_s + tail_r
        if D > tail_s + tail_r + tol:
            status = FAILED
        elif upper <= resolution + tol:
            status = PASSED
        else:
            status = UNDECIDED
        nxt = 4 * levels[-1]
        if nxt > MAX_AGREEMENT_CELLS:
            stop = f"K = {levels[-1]} is the finest level (MAX_AGREEMENT_CELLS = {MAX_AGREEMENT_CELLS})"
        elif (nxt + 1) * n > MAX_LEVEL_NUMBERS:
            stop = (f"the next level, K = {nxt}, was not run: (K + 1)·n = {(nxt + 1) * n:.3g} numbers at n = {n}, "
                    f"more than a run may hold (MAX_LEVEL_NUMBERS = {MAX_LEVEL_NUMBERS:.3g}, "
                    f"{MAX_LEVEL_NUMBERS * 8 >> 20} MB in float64) — a limit of the harness at this dimension")
        else:
            stop = None
        if status != UNDECIDED or stop is not None:
            break
        levels.append(nxt)
        add_level(nxt)
    K = levels[-1]
    info = {"levels": levels, "stopped": stop, "distance": D, "bound": tail_s + tail_r + tol, "upper": upper,
            "resolution": resolution, "stepper_tail": tail_s, "solve_tail": tail_r,
            "stepper_differences": diffs["stepper"], "solve_differences": diffs["solve"],
            "stepper_ratio": r_s, "solve_ratio": r_r, "stepper_ratio_floor": floor_s, "round_off": tol,
            "criterion": "limits from own 4-fold refinements (own-trend tails)"}
    said = (f"on K = {K} (levels {', '.join(map(str, levels))}) it is {D:.3g} from verimono.solve, its own limit "
            f"within {tail_s:.3g} (differences {', '.join(f'{c:.3g}' for c in diffs['stepper'])}), solve's within "
            f"{tail_r:.3g} (differences {', '.join(f'{c:.3g}' for c in diffs['solve'])})")
    if status == PASSED:
        return status, (f"its limit agrees with verimono.solve's within {upper:.3g} ≤ {resolution:.3g} "
                        f"(resolution {LIMIT_RESOLUTION:g} x scale): {said}"), info
    if status == FAILED:
        return status, (f"converges, but not to the solution: {said} — the limits are at least "
                        f"{D - tail_s - tail_r:.3g} apart (verimono.solve is the proximal scheme, whose limit is the "
                        "solution, thm:main): self-convergence alone does not show the limit"), info
    return status, (f"its limit is not resolved against verimono.solve's: {said}; the limits may be up to {upper:.3g} "
                    f"apart, more than the resolution {resolution:.3g} ({LIMIT_RESOLUTION:g} x scale), and the "
                    f"levels up to K = {K} cannot separate them; {stop}"), info


__all__ = ["limit_agreement", "LIMIT_RESOLUTION", "MAX_AGREEMENT_CELLS", "MAX_LEVEL_NUMBERS"]
