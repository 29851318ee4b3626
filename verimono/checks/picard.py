"""The Picard step of the Lipschitz-perturbation theorem of Section 6 (Step 1 of its proof).

For ``x' ∈ −F(t, x) + f(x) + u(t)`` with ``f`` ``L``-Lipschitz the proof iterates
``x_{ℓ+1}' ∈ −F(t, x_{ℓ+1}) + f(x_ℓ(t)) + u(t)``, ``x_0 ≡ x0``, and shows (label
``e: bound x l plus one to x l``)

    |x_{ℓ+1}(τ) − x_ℓ(τ)| ≤ (L τ)^ℓ / ℓ! · |x_1 − x_0|_∞        for all τ ∈ [0, T].

:func:`check_picard` builds the iterates with the stepper under test (by default :func:`verimono.solve`) on
one partition: iterate ``ℓ + 1`` is the stepper's solution of the problem without ``f`` whose input has the
primitive ``Φ_ℓ(t_k) = Σ_{j<k} h_j f(x^ℓ_j) + ∫_0^{t_k} u`` (passed as ``U``; ``f`` frozen at the left end
of each cell, as the scheme treats it).  The discrete iterates obey the same bound exactly: with a
nonexpansive resolvent (A1), ``e^{ℓ+1}_{k+1} ≤ e^{ℓ+1}_k + h_k L e^ℓ_k``, so ``e^{ℓ+1}_k ≤ L Σ_{j<k} h_j e^ℓ_j``,
and the left Riemann sum of the increasing ``(L s)^ℓ/ℓ!`` is below its integral.  Their limit is the
scheme's solution with the explicit ``f`` (reported as ``details["limit_gap"]``).  The record
``picard_step`` fails when some ``|x^{ℓ+1}_k − x^ℓ_k|`` exceeds the bound, or the step the bound is built
from, ``Δ^ℓ_k ≤ L Σ_{j<k} h_j Δ^{ℓ−1}_j`` (``Δ^ℓ = |x^{ℓ+1} − x^ℓ|``).  The estimate alone has little power:
its ratio to the truth is ``1/((ℓ+1)L^ℓ)`` on a rotation, so with 8 iterates only ``L < 0.743`` of the
true 1 was caught; the step is attained there (all ``Δ`` parallel), so the tightest ``L`` the data allow,
``L̂ = max Δ^ℓ_k / Σ_{j<k} h_j Δ^{ℓ−1}_j`` (over differences above ``RECURSION_FLOOR`` tolerances,
``details["L_hat"]``), is 1 and any understated ``L`` fails.  A Lipschitz constant that is
too small (the problem's ``lipschitz``, or ``L=``; seen failing at half the constant of the reference
``Lipschitz field and input``).  It is not a test of the stepper's step (``amplifier`` of the stepper zoo,
which multiplies each iterate by ``1 + 5h``, passes: the factor is common to consecutive iterates).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ..core.errors import NotApplicable
from ..core.grids import uniform_grid, validate_grid
from ..core.problem import Problem
from ..core.tolerances import tolerance
from .core import Outcome
from .partitions import run_stepper, stepper_law

#: Picard iterates built (the bound is checked for ℓ = 1, ..., PICARD_ITERATIONS − 1)
PICARD_ITERATIONS = 8
#: cells of the default uniform partition
PICARD_CELLS = 200
#: the tightest L the data allow (``details["L_hat"]``) is taken over differences above this many tolerances
RECURSION_FLOOR = 100.0


def _primitive(t: np.ndarray, values: np.ndarray) -> Callable[[float], np.ndarray]:
    """The piecewise-linear function through ``(t_k, values_k)`` (exact at the nodes)."""
    def U(s: float) -> np.ndarray:
        return np.array([np.interp(s, t, values[:, j]) for j in range(values.shape[1])])
    return U


@stepper_law("picard_step", "e: bound x l plus one to x l", over_grids=False, battery=False)
def check_picard(stepper: Callable, p: Problem, *, L: float | None = None, iterations: int = PICARD_ITERATIONS,
                 grid: np.ndarray | None = None) -> Outcome:
    """``picard_step``: ``e: bound x l plus one to x l`` on the Picard iterates built with ``stepper``
    (module docstring); ``L`` overrides the problem's Lipschitz constant."""
    L = p.lipschitz if L is None else float(L)
    if p.f is None or L is None:
        raise NotApplicable("needs a Lipschitz field f and its constant (the problem's lipschitz, or L=)")
    t = uniform_grid(p.T, steps=PICARD_CELLS) if grid is None else validate_grid(grid, p.T)
    h = np.diff(t)
    dU = p.input_increments(t)
    base = np.zeros((len(t), p.dim)) if dU is None else np.vstack([np.zeros((1, p.dim)), np.cumsum(dU, axis=0)])
    iterates = [np.repeat(p.x0[None, :], len(t), axis=0)]                      # x_0 ≡ x0
    for ell in range(iterations):
        xl = iterates[-1]
        fx = np.array([np.asarray(p.f(x), dtype=float) for x in xl[:-1]])
        Phi = base + np.vstack([np.zeros((1, p.dim)), np.cumsum(h[:, None] * fx, axis=0)])
        q = Problem(p.operator, p.x0, p.T, U=_primitive(t, Phi), name=f"{p.name} (Picard iterate {ell + 1})",
                    initial_jump=p.initial_jump, data=p.data)
        iterates.append(run_stepper(stepper, q, t))
    E = [np.linalg.norm(iterates[ell + 1] - iterates[ell], axis=1) for ell in range(iterations)]
    E0 = float(np.max(E[0]))
    scale = max(float(np.max(np.abs(x))) for x in iterates)
    tol = tolerance(scale, E0)
    worst, counter = 0.0, None
    # the one step the estimate is built from, with power: Δ^ℓ_k ≤ L Σ_{j<k} h_j Δ^{ℓ−1}_j (module docstring)
    L_hat, rec_worst, rec_counter = 0.0, 0.0, None
    for ell in range(1, iterations):
        S = np.concatenate([[0.0], np.cumsum(h * E[ell - 1][:-1])])
        ratio = E[ell] / (L * S + tol)
        k = int(np.argmax(ratio))
        if ratio[k] > rec_worst:
            rec_worst = float(ratio[k])
            rec_counter = {"problem": p.name, "L": L, "ell": ell, "k": k, "tau": float(t[k]), "diff": float(E[ell][k]),
                           "bound": float(L * S[k]), "form": "recursion", "grid": t}
        seen = E[ell] > RECURSION_FLOOR * tol
        if np.any(seen):
            L_hat = max(L_hat, float(np.max(E[ell][seen] / S[seen])))
    for ell in range(1, iterations):
        bound = (L * t) ** ell / math.factorial(ell) * E0
        ratio = E[ell] / (bound + tol)
        k = int(np.argmax(ratio))
        if ratio[k] > worst:
            worst = float(ratio[k])
            counter = {"problem": p.name, "L": L, "ell": ell, "k": k, "tau": float(t[k]), "diff": float(E[ell][k]),
                       "bound": float(bound[k]), "sup_x1_minus_x0": E0, "form": "estimate", "grid": t}
    if rec_worst > worst:
        worst, counter = rec_worst, rec_counter
    limit_gap = float(np.max(np.linalg.norm(iterates[-1] - run_stepper(stepper, p, t), axis=1)))
    details = {"L": L, "iterations": iterations, "sup_differences": [float(np.max(e)) for e in E],
               "limit_gap": limit_gap, "cells": len(h), "L_hat": L_hat, "recursion_ratio": rec_worst}
    c = counter or {"ell": 0, "diff": 0.0, "tau": 0.0, "bound": 0.0, "form": "estimate"}
    if c["form"] == "recursion":
        msg = (f"Picard iterates {c['ell'] + 1} and {c['ell']} differ by {c['diff']:.4g} at τ = {c['tau']:.4g} but L "
               f"Σ h_j |x_{c['ell']} − x_{c['ell'] - 1}|(t_j) = {c['bound']:.4g} with L = {L:g} (the step of e: bound x "
               f"l plus one to x l; the data need L ≥ {L_hat:.4g}): L is not a Lipschitz constant of f, or the step "
               "expands")
    else:
        msg = (f"Picard iterates {c['ell'] + 1} and {c['ell']} differ by {c['diff']:.4g} at τ = {c['tau']:.4g} but "
               f"(L τ)^l/l! |x_1 − x_0|_∞ = {c['bound']:.4g} with L = {L:g}, l = {c['ell']} (e: bound x l plus one to x "
               "l): L is not a Lipschitz constant of f, or the step expands")
    return Outcome(worst, counter={**c, "message": msg}, details=details,
                   message=f"|x_(l+1) − x_l| ≤ (L τ)^l/l! |x_1 − x_0|_∞ and ≤ L Σ h_j |x_l − x_(l−1)|(t_j) for l < "
                           f"{iterations} (L = {L:g}; the data need L ≥ {L_hat:.4g}; sup differences "
                           f"{', '.join(f'{d:.2g}' for d in details['sup_differences'])}; last iterate "
                           f"{limit_gap:.2g} from the scheme's solution)")


__all__ = ["check_picard", "PICARD_ITERATIONS", "PICARD_CELLS", "RECURSION_FLOOR"]
