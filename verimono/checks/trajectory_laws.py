"""Laws of the discrete solutions on one partition: contraction, membership in the domain, selections.

Each is a decorated evaluator ``check_<law>(stepper, problem, t, **kw) -> Outcome`` judged on every
partition of the battery by :func:`verimono.checks.partitions.run_on_grids`, which shrinks a failure to its
shortest failing prefix; the public ``check_<law>(stepper, problem, *, grids=None, seed=0, ...)`` returns
one record whose ``worst`` is the largest observed ``lhs / (rhs + tol)`` (``bound = 1``).

* ``contraction`` — the uniqueness argument (monotonicity of ``F(t,·)``, (A1)) and the Gronwall estimate
  of the Lipschitz theorem of Section 6: ``|x_k - x'_k| ≤ g_k |x_{k-1} - x'_{k-1}|`` with
  ``g_k = max(e^{L h_k}, 1/(1 - L h_k))`` (``L = 0`` without ``f``; the input ``u`` cancels).
* ``in_domain`` — ``x_k ∈ cl dom F(t_k,·)`` (``e:x k+1 props.1``); for a scheme claiming only
  ``scheme="any"``, a distance to the domain vanishing at the claimed order (:func:`domain_vanishing`).
* ``selections`` — ``eq:iteration``: ``y_{k+1} = (x_k + h f(x_k) + ∫u - x_{k+1})/h_{k+1} ∈
  F(t_{k+1}, x_{k+1})``, tested with ``operator.contains`` and with the resolvent characterisation
  ``J_μ(x + μy) = x`` at ``μ ≤ h/2`` (a different step than the scheme's: :func:`witness_steps`).

* ``initial_value`` — ``x_0 = x0``: the initial condition of ``eq:incGen`` (``x(0) = x0``), which ``eq:iteration``
  starts from; also when ``x0 ∉ cl dom F(0)`` (``initial_jump``: the scheme jumps in its first step, ``x_0`` is
  still ``x0``, as :func:`verimono.solve` returns it).
* ``trajectory_immutable`` — what a stepper returned is its caller's: it never changes when the stepper runs again,
  and the stepper neither writes into the partition or ``problem.x0`` it was given nor returns their memory.

What each binds (:mod:`verimono.core.claims`): ``selections`` only the proximal scheme; ``contraction`` steppers
claiming it; ``in_domain`` every scheme, in the form its claim allows; ``initial_value`` and
``trajectory_immutable`` every stepper, whatever it claims.
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from ..core.arrays import as_float64, to_numpy
from ..core.claims import claim_of, steps_tolerance
from ..core.errors import NotApplicable, VerimonoError
from ..core.grids import uniform_grid
from ..core.operator_protocol import accepts_times, resolvent_kernel
from ..core.operators import NormalCone
from ..core.problem import Problem
from ..core.sets import ConvexSet
from ..core.stepping import Trajectory
from ..core.tolerances import DOMAIN_ORDER_SLACK, current_data_scale, current_precision, judged_precision, row_tolerances, tolerance
from ..records.results import FAILED, PASSED, UNDECIDED
from .core import CONTRACTION_CLAIM, PROXIMAL_CLAIM, Holds, Member, Outcome
from .partitions import battery_grids, claimed_grids, default_grids, run_stepper, stepper_law
from .shared_runs import fingerprint, remembered_value, run_serial

#: cells of the refinement levels of the vanishing-distance form of ``in_domain``
DOMAIN_LEVELS = (10, 40, 160)
#: the vanishing-distance form of ``in_domain`` fits its constant only on levels where the claimed order predicts a
#: fall of at least ``DOMAIN_POWER · DOMAIN_ORDER_SLACK`` to the finest: a distance that does not shrink then fails
#: by at least this factor (:func:`domain_vanishing`)
DOMAIN_POWER = 2.0
#: the finest level (cells) :func:`domain_vanishing` refines to (4-fold steps from ``DOMAIN_LEVELS``) when its
#: largest coarse distance is on a level too close to the finest for the claimed order
DOMAIN_MAX_CELLS = 2560


def norms(a: np.ndarray) -> np.ndarray:
    """Euclidean norms along the last axis (one pass, no squared copy of ``a``: at n = 10^5 the copy and its
    sum were 3x the time)."""
    a = np.asarray(a, dtype=float)
    return np.sqrt(np.einsum("...i,...i->...", a, a))


#: at most this many numbers of a temporary are formed at once by the row-wise helpers below (rows in blocks;
#: one row when a row is longer): a trajectory-sized temporary at n = 10^6 (a 161-node run is 1.3 GB) costs a
#: page fault per 4 KiB, about 1 s, where the same arithmetic in a reused block costs 0.1-0.2 s
ROW_BLOCK = 1 << 16


def _row_step(a: np.ndarray) -> int:
    return max(1, ROW_BLOCK // max(1, int(np.prod(a.shape[1:]))))


def diff_norms(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``norms(a - b)`` row by row, the difference formed :data:`ROW_BLOCK` numbers at a time (the same numbers
    as ``norms(a - b)``: the same subtraction and the same sum per row)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.ndim < 2 or a.size <= ROW_BLOCK:
        return norms(a - b)
    out = np.empty(a.shape[:-1])
    step = _row_step(a)
    for i in range(0, len(a), step):
        out[i:i + step] = norms(a[i:i + step] - b[i:i + step])
    return out


def step_norms(a: np.ndarray) -> np.ndarray:
    """``norms(np.diff(a, axis=0))`` without the trajectory-sized difference (:func:`diff_norms`)."""
    return diff_norms(a[1:], a[:-1])


def row_absmax(a: np.ndarray) -> np.ndarray:
    """``max_j |a[k, j]|`` for each row ``k`` (``initial = 0``), without ``np.abs``'s copy: the larger of the row's
    maximum and minus its minimum (the same number)."""
    a = np.asarray(a, dtype=float)
    a = a.reshape(a.shape[0], -1)
    if a.shape[1] == 0:
        return np.zeros(a.shape[0])
    return np.maximum(np.maximum(a.max(axis=1), -a.min(axis=1)), 0.0)


# -- contraction ------------------------------------------------------------------------------------

def lipschitz_of(problem: Problem) -> float:
    """The Lipschitz constant of ``f`` the problem states (0 without ``f``); :class:`NotApplicable` when ``f``
    comes without one."""
    if problem.f is None:
        return 0.0
    if problem.lipschitz is None:
        raise NotApplicable("f is given without its Lipschitz constant (Problem(lipschitz=...)); the bound "
                            "e^{L t} needs L")
    return float(problem.lipschitz)


def _states_lipschitz(problem: Problem) -> str | None:
    try:
        lipschitz_of(problem)
    except NotApplicable as exc:
        return str(exc)
    return None


def perturbed_starts(problem: Problem, seed: int = 0, scales: Sequence[float] = (1e-2, 1e-1, 1.0)
                     ) -> list[np.ndarray]:
    """Second initial points ``x0'`` at distances ``~ s (1 + |x0|)`` in ``cl dom F(0,·)``.

    Projected with ``project_domain`` (or mapped into ``dom F(0,·)`` by a resolvent when the operator has
    no projection); unconstrained when the problem starts with the catching-up jump.
    """
    rng = np.random.default_rng(seed)
    x0, op = problem.x0, problem.operator
    scale = 1.0 + float(np.linalg.norm(x0))
    out = []
    for s in scales:
        d = rng.standard_normal(x0.shape)
        z = x0 + s * scale * d / np.linalg.norm(d)
        if not problem.initial_jump:
            try:
                z = as_float64(op.project_domain(z, 0.0))
            except NotImplementedError:
                z = as_float64(op.resolvent(z, 1e-3 * problem.T, 0.0))
        if np.linalg.norm(z - x0) > tolerance(x0, z) * 10:
            out.append(z)
    return out


def step_growth(L: float, h: np.ndarray) -> np.ndarray:
    """``max(e^{Lh}, 1/(1 - Lh))`` per step (``e^{Lh}`` where ``Lh ≥ 1``): see :func:`check_contraction`."""
    lh = L * np.asarray(h, dtype=float)
    implicit = np.divide(1.0, 1.0 - lh, out=np.zeros_like(lh), where=lh < 1.0)
    return np.maximum(np.exp(lh), implicit)


def run_starts(stepper: Callable, problem: Problem, starts: Sequence[np.ndarray], grid: np.ndarray,
               x: np.ndarray) -> list[np.ndarray]:
    """The stepper's trajectories from every point of ``starts`` (``x``: its trajectory from ``problem.x0``).

    A stepper that declares ``batched = True`` (:func:`verimono.solve`: ``x0`` of shape ``(B, n)`` gives
    values ``(K+1, B, n)``) runs ``x0`` and all starts in one vectorized call; the batch is used only when
    its first row reproduces ``x`` bit for bit (an operator whose resolvent mishandles a batch of points
    changes it), else every start runs on its own.
    """
    if getattr(stepper, "batched", False) and starts:
        try:
            xs = as_float64(stepper(problem.replace(x0=np.stack([problem.x0, *starts])), grid))
        except (VerimonoError, ArithmeticError, ValueError, TypeError, IndexError):
            xs = None
        if (xs is not None and xs.shape == (len(grid), len(starts) + 1) + problem.x0.shape
                and np.array_equal(xs[:, 0], x) and np.all(np.isfinite(xs))):
            return [xs[:, i + 1] for i in range(len(starts))]
    return [run_stepper(stepper, problem.replace(x0=z), grid) for z in starts]


@stepper_law("contraction", "uniqueness argument and the Lipschitz theorem (Section 6)", CONTRACTION_CLAIM,
             Holds(_states_lipschitz), study_grids=True)
def check_contraction(stepper: Callable, p: Problem, t: np.ndarray, *, seed: int = 0,
                      x0_primes: Any = None) -> Outcome:
    """Two discrete solutions never move apart faster than ``e^{L t}`` (uniqueness argument, Section 6).

    Checks ``|x_k - x'_k| ≤ g_k |x_{k-1} - x'_{k-1}|`` step by step; ``L = 0`` (nonexpansive resolvents)
    without ``f``.  The per-step factor ``g_k`` is ``e^{L h_k}`` for the paper's explicit treatment of ``f``
    (``x_{k+1} = J(x_k + h f(x_k))``: ``1 + hL ≤ e^{hL}``), or ``1/(1 - L h_k)`` when larger (``hL < 1``: a
    stepper treating ``f`` implicitly, ``x_{k+1} = J(x_k + h f(x_{k+1}))``); both give ``e^{L t_k}`` as
    ``h → 0``.

    Claim: ``contracts`` — the proximal scheme contracts (its resolvents are nonexpansive); a scheme
    claiming only convergence need not contract step by step, so it must say so (``contracts=True``).
    """
    L = lipschitz_of(p)
    starts = perturbed_starts(p, seed) if x0_primes is None else [np.asarray(z, float) for z in x0_primes]
    if not starts:
        raise NotApplicable("no second initial point distinct from x0 in cl dom F(0)")
    x = run_stepper(stepper, p, t)
    growth = step_growth(L, np.diff(t))
    inexact = 2.0 * steps_tolerance(claim_of(stepper), np.diff(t))    # each run's step within ε(h) (Inexact)
    worst, best, glob = -np.inf, None, 0.0
    for z, y in zip(starts, run_starts(stepper, p, starts, t, x)):
        d = diff_norms(x, y)
        tol = tolerance(x, y)
        ratio = d[1:] / (growth * d[:-1] + inexact + tol)
        glob = max(glob, float(np.max(d / (np.concatenate([[1.0], np.cumprod(growth)]) * d[0] + tol))))
        bad = np.flatnonzero(ratio > 1.0)
        k = int(bad[0]) + 1 if bad.size else int(np.argmax(ratio)) + 1
        r = float(np.max(ratio))
        if r > worst:
            worst = r
            # rows copied: a view would hold the whole trajectory in the record
            best = {"x0_prime": z, "k": k, "t_k": t[k], "x_k": x[k].copy(), "x_prime_k": y[k].copy(),
                    "x_k_minus_1": x[k - 1].copy(), "x_prime_k_minus_1": y[k - 1].copy(),
                    "lhs": d[k], "rhs": growth[k - 1] * d[k - 1], "L": L,
                    "message": f"|x_k - x'_k| = {d[k]:.6g} > g_k |x_(k-1) - x'_(k-1)| = "
                               f"{growth[k - 1] * d[k - 1]:.6g} at k = {k}, t_k = {t[k]:.6g}"}
    return Outcome(worst, best["k"], best, {"global_ratio": glob, "pairs": len(starts), "L": L},
                   message="|x_k - x'_k| <= g_k |x_{k-1} - x'_{k-1}| at every step (g_k = max(e^{L h}, 1/(1 - L h)))")


# -- domain -----------------------------------------------------------------------------------------

def domain_distances(stepper: Callable, p: Problem, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(x, dist(x_k, cl dom F(t_k)))`` along ``stepper``'s solution on ``t`` (0 at ``k = 0`` after a jump)."""
    x = run_stepper(stepper, p, t)
    d = np.zeros(len(t))
    for k in range(1 if p.initial_jump else 0, len(t)):
        d[k] = float(np.linalg.norm(as_float64(p.operator.project_domain(x[k], float(t[k]))) - x[k]))
    return x, d


def domain_vanishing(stepper: Callable, p: Problem, *, seed: int = 0,
                     levels: Sequence[int] = DOMAIN_LEVELS) -> Outcome:
    """``D(K) = max_k dist(x_k, cl dom F(t_k))`` on uniform partitions with ``K`` cells vanishes at order
    ``p = min(order, the order the problem's regularity allows)``: every convergent scheme has
    ``dist(x_k, cl dom F(t_k)) ≤ |x_k - x(t_k)| ≤ C (T/K)^p`` since ``x(t_k) ∈ cl dom F(t_k)``.

    The constant ``C`` is not known.  It is fitted on a coarse level ``K_j``, ``Ĉ = D(K_j) (K_j/T)^p``, and the
    prediction is checked on the finest ``K_m``:

        ``D(K_m) ≤ S · max_{j ∈ J} D(K_j) (K_j/K_m)^p + tol``,  ``S = DOMAIN_ORDER_SLACK``

    (the slack absorbs the drift of ``C`` between levels).  A distance that does not shrink has ratio
    ``g_j/S`` there, ``g_j = (K_m/K_j)^p`` the fall the order predicts: the check refutes it only where
    ``g_j > S``.  So ``J`` holds only the levels with ``g_j ≥ DOMAIN_POWER · S``: a distance that does not shrink
    fails by at least ``DOMAIN_POWER`` at every claimed order, one shrinking like ``h^p`` passes by ``S``.  (Fitted
    on ``K_{m-1}`` too, as before, the law could refute nothing at order 1/2: ``g = 4^{1/2} = 2 = S``, and distances
    0.411, 0.466, 0.460 passed.)  For 1/2 ≤ p < 1 that is the coarsest level of 10, 40, 160; for p ≥ 1 every level,
    as before.  When the largest coarse distance lies on a level outside ``J`` (a distance that grows before it
    falls, pre-asymptotically), the levels are refined 4-fold, up to ``DOMAIN_MAX_CELLS`` cells, until it is in
    ``J``; when ``J`` is still empty there (``p < 1/4``), the record is undecided: no level is coarse enough for the
    claimed order to predict a fall the slack does not swallow.  Distances within round-off (``tol``, relative to
    ``max(1, |x0|)``) fit no constant: they are not refined for, and a finest distance within it holds."""
    order = claim_of(stepper).order
    target = p.order.for_claim(order).value if p.order is not None else float(order)
    levels = [int(K) for K in levels]
    need = DOMAIN_POWER * DOMAIN_ORDER_SLACK * (1.0 - 1e-12)

    def fitting(m: int) -> list[int]:
        return [j for j in range(m) if (levels[m] / levels[j]) ** target >= need]

    D, where = [], []

    def measure(K: int) -> None:
        t = uniform_grid(p.T, steps=K)
        x, d = domain_distances(stepper, p, t)
        k = int(np.argmax(d))
        D.append(float(d[k]))
        where.append({"K": K, "k": k, "t_k": t[k], "x_k": x[k]})

    scale = max(1.0, float(np.max(np.abs(p.x0))))
    tol = tolerance(scale)
    for K in levels:
        measure(K)
    # refine while the largest coarse distance (beyond round-off: a constant to fit) is on a level too close to the
    # finest for the claimed order to predict a fall the slack does not swallow
    while (max(D[:-1]) > tol and int(np.argmax(D[:-1])) not in fitting(len(D) - 1)
           and 4 * levels[-1] <= DOMAIN_MAX_CELLS):
        levels.append(4 * levels[-1])
        measure(levels[-1])
    m = len(levels) - 1
    fit = fitting(m)
    details = {"levels": list(levels), "distances": D, "order": target, "claim": "any",
               "fitted_on": [levels[j] for j in fit]}
    shown = ", ".join(f"{d:.3g}" for d in D)
    if not fit and D[m] > tol:
        return Outcome(None, details=details, status=UNDECIDED,
                       message=f"order {target:g} claimed: no level up to K = {levels[-1]} is coarse enough for a "
                               f"fall (K_m/K_j)^{target:g} of {need:.3g} to the finest, so a distance to cl dom F(t_k) "
                               f"that does not vanish cannot be told from one that does (distances {shown} for "
                               f"K = {levels})")
    rhs = DOMAIN_ORDER_SLACK * max((D[j] * (levels[j] / levels[m]) ** target for j in fit), default=0.0)
    return Outcome(D[m] / (rhs + tol),
                   counter={"problem": p.name, "T": p.T, "x0": p.x0, "levels": list(levels), "distances": D,
                            "order": target, **where[m],
                            "message": f"dist(x_k, cl dom F(t_k)) does not vanish at order {target:g}: "
                                       f"{shown} for K = {list(levels)} (at most {rhs:.3g} at K = {levels[m]}: "
                                       f"{DOMAIN_ORDER_SLACK:g} times the fall the order predicts from K = "
                                       f"{[levels[j] for j in fit]})"},
                   details=details,
                   message=f"dist(x_k, cl dom F(t_k)) {D[0]:.3g} -> {D[m]:.3g} as K = {levels[0]} -> {levels[m]} "
                           f"(order {target:g} claimed; scheme='any')")


@stepper_law("in_domain", "e:x k+1 props.1", Member("project_domain"), any_scheme=domain_vanishing, every_grid=True,
             study_grids=True)
def check_in_domain(stepper: Callable, p: Problem, t: np.ndarray, *, seed: int = 0) -> Outcome:
    """``x_k ∈ cl dom F(t_k,·)`` for every node (``e:x k+1 props.1``; from ``k = 1`` after a jump).

    That is a property of the proximal scheme's iterates (``x_k = J(...)`` lies in ``dom F(t_k)``).  A
    stepper claiming only ``scheme="any"`` with order ``p`` is held to what every convergent scheme obeys
    instead — ``dist(x_k, cl dom F(t_k)) ≤ |x_k - x(t_k)|`` vanishes at order ``p``
    (:func:`domain_vanishing`).

    Witnesses first: a resolvent's value lies in ``dom F`` (``range J_μ = dom F``, the operator law
    ``resolvent_in_domain``), so ``dist(x_k, cl dom F(t_k)) ≤ |x_k - J_μ(x_k + μ y_k)|`` — the points
    :func:`resolvent_witnesses` gives (and ``selections`` judges; computed once for both).  A node where
    that bound is within the tolerance holds, with the bound as its distance; every other node (``x_0``,
    and any whose witness is far) is measured exactly with ``project_domain``, which decides it."""
    x = run_stepper(stepper, p, t)
    ratios, dists = np.zeros(len(t)), np.zeros(len(t))
    first = 1 if p.initial_jump else 0
    exact = np.ones(len(t), dtype=bool)
    exact[:first] = False
    try:
        w = witness_rows(stepper, p, t, x)
    except Exception:  # noqa: BLE001 - no witness: every node is measured exactly, as the law states
        w = None
    if w is not None:
        # row_tolerances(x[1:], back) of the per-row maxima the witnesses' pass measured
        bound = w["distance"]
        tol = current_precision().rtol * (1.0 + np.maximum(np.maximum(w["x_max"][1:], w["back_max"]), current_data_scale()))
        near = bound <= tol
        dists[1:][near], ratios[1:][near] = bound[near], bound[near] / tol[near]
        exact[1:] &= ~near
    # an inexact resolvent's result is within ε(h_k) of the exact one, which lies in dom F(t_k) (Inexact)
    eps = np.concatenate([[0.0], steps_tolerance(claim_of(stepper), np.diff(t))])
    for k in np.flatnonzero(exact):
        q = as_float64(p.operator.project_domain(x[k], float(t[k])))
        dists[k] = float(np.linalg.norm(q - x[k]))
        ratios[k] = dists[k] / (tolerance(x[k], q) + eps[k])
    bad = np.flatnonzero(ratios > 1.0)
    k = int(bad[0]) if bad.size else int(np.argmax(ratios))
    worst = float(np.max(ratios))
    counter = {"k": k, "t_k": t[k], "x_k": x[k].copy(), "distance": dists[k]}
    if not worst <= 1.0:     # a failure (a NaN too) shows the projection (a QP for some operators) and says where
        counter["projection"] = p.operator.project_domain(x[k], float(t[k]))
        counter["message"] = (f"x_k = {np.array2string(x[k], precision=6)} is at distance {dists[k]:.3g} "
                              f"from cl dom F(t_k) at k = {k}, t_k = {t[k]:.6g}")
    return Outcome(worst, k, counter, {"max_distance": float(np.max(dists)), "measured_nodes": int(np.sum(exact))},
                   message="x_k in cl dom F(t_k) at every node")


# -- selections -------------------------------------------------------------------------------------

def _quadrature_allowance(p: Problem, t: np.ndarray) -> np.ndarray | None:
    """Per cell, what the velocities' ``∫u`` may be off by: ``None`` when it is exact (the problem states the
    primitive ``U``, or has no ``u``); else twice the 3-point Gauss rule of :meth:`Problem.input_increments` against
    itself on the two half cells (Euclidean norm per row).  The paper's scheme holds with the exact integral, which
    a correct stepper may compute better than the harness: on the graded ``K = 10`` partition of ``Lipschitz field
    and input`` (``u = cos 2t``, a cell of 0.39) the rule is off by ``3e-8``, 11× the law's round-off tolerance
    (branch probe6).  The estimate is ``(1 - 2^-6)`` of a smooth ``u``'s error; the factor 2 covers a rougher ``u``."""
    if getattr(p, "U", None) is not None or p.u is None or len(t) < 2:
        return None
    coarse = p.input_increments(t)
    fine = np.empty(2 * len(t) - 1)
    fine[0::2], fine[1::2] = t, 0.5 * (t[:-1] + t[1:])
    halves = p.input_increments(fine)
    d = np.asarray(coarse, dtype=float) - (halves[0::2] + halves[1::2])
    return 2.0 * np.sqrt(np.sum(d * d, axis=1))


@stepper_law("selections", "eq:iteration", PROXIMAL_CLAIM, every_grid=True, study_grids=True)
def check_selections(stepper: Callable, p: Problem, t: np.ndarray, *, seed: int = 0) -> Outcome:
    """``y_{k+1} = (z_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})`` (``eq:iteration``), ``z_k = x_k + h f(x_k)
    + ∫u``: through ``operator.contains`` and through ``J_μ(x_{k+1} + μ y_{k+1}) = x_{k+1}`` at the
    :func:`witness_steps` ``μ ∈ (h/4, h/2]``.

    A failure names the discrete velocity it tested with the terms the problem has (``f``, ``u``) and their
    values, and says first when ``x_{k+1}`` lies outside ``cl dom F(t_{k+1},·)`` — where ``F`` is empty and no
    velocity can be a selection.

    Tolerance: that of a difference quotient, :func:`verimono.core.tolerances.quotient_tolerance` (it divides the
    round-off of the states by ``h``), computed for every step at once with ``row_tolerances``.

    Claim: ``proximal`` — the discrete velocities of the paper's scheme are selections; another scheme's
    (the midpoint rule, the exact solution sampled) are not, and need not be.
    """
    x = run_stepper(stepper, p, t)
    w = witness_rows(stepper, p, t, x)
    h = np.diff(t)
    op = p.operator
    eps = steps_tolerance(claim_of(stepper), h)
    rtol = current_precision().rtol
    # an inexact resolvent (x_{k+1} within ε of J_h(z_k)): the witness is within 2ε (Inexact), and membership is
    # judged by the distance to the exact resolvent instead (a point ε outside dom F has no selection to test)
    # (row_tolerances(x[1:], μ y, x[:-1]) of the per-row maxima the witnesses' pass measured)
    xm = np.maximum(w["x_max"], current_data_scale())     # the operator's own scale: one more magnitude (tolerances.py)
    # the harness's own ∫u error (_quadrature_allowance): moves y by at most q/h, the witness x + μy by q/2 (μ ≤ h/2)
    q = _quadrature_allowance(p, t)
    qa = 0.0 if q is None else q
    ratios = w["distance"] / (rtol * (1.0 + np.maximum(np.maximum(xm[1:], w["muy_max"]), xm[:-1])) + 2.0 * eps + qa)
    member = np.ones(len(h), dtype=bool)
    contains_available = op.provides("contains") if hasattr(op, "provides") else callable(getattr(op, "contains", None))
    contains_available = contains_available and not eps.any()
    inexact = (_inexact_distances(p, t, x, Trajectory(t, x, p).selections, eps) if eps.any() else None)
    if inexact is not None:
        ratios = np.maximum(ratios, inexact["ratios"])
    if contains_available:
        # row_tolerances(x[:-1], x[1:], h y) / h, the discrete velocities formed one at a time
        tols = rtol * (1.0 + np.maximum(np.maximum(xm[:-1], xm[1:]), w["hy_max"])) / h + qa / h
        try:
            if _cone_rows(op) and x.ndim == 2 and x.dtype == np.float64 and x.shape[1] > 0:
                for a, b, Y in _velocity_blocks(p, t, x, h):
                    member[a:b] = _cone_members(op.S, x[a + 1:b + 1], Y, t[a + 1:b + 1], tols[a:b])
            else:
                for k, yk in _velocities(p, t, x, h):
                    member[k] = op.contains(x[k + 1], yk, float(t[k + 1]), tol=float(tols[k]))
        except NotImplementedError:
            contains_available = False
            member[:] = True
    worst = float(np.max(ratios))
    if contains_available and not member.all():
        worst = max(worst, 1.0 + float(np.sum(~member)))   # membership is boolean: count the misses
    bad = np.flatnonzero((ratios > 1.0) | ~member)
    k = int(bad[0]) if bad.size else int(np.argmax(ratios))
    velocity, terms = _velocity(p, t, x, k)
    details = {"contains_used": contains_available, "misses": int(np.sum(~member)), "velocity": velocity}
    if q is not None:        # what the velocities' ∫u was allowed (the harness's quadrature, not the subject's)
        details["input_quadrature_allowance"] = float(np.max(q, initial=0.0))
    if inexact is not None:
        details["inexact"] = {"tolerance": claim_of(stepper).inexact.describe(),
                              "max_ratio": float(np.max(inexact["ratios"])),
                              "max_distance": float(np.max(inexact["distances"]))}
    message = (f"the discrete velocity {velocity} in F(t_(k+1), x_(k+1)) at every step"
               + (f" to the stated resolvent tolerance: |x_(k+1) - J_hF(z_k)| <= ε(h) = "
                  f"{claim_of(stepper).inexact.describe()}" if inexact is not None else
                  "" if contains_available else " (resolvent characterisation only: no contains)"))
    if worst <= 1.0:         # held: the counterexample is never shown
        return Outcome(worst, k + 1, {"k": k + 1}, details, message=message)
    yk = velocity_row(p, t, x, k)
    counter = {"k": k + 1, "t_k": t[k + 1], "x_k": x[k].copy(), "x_k_plus_1": x[k + 1].copy(), "h": h[k],
               "selection": yk,
               "velocity": velocity, **terms,
               "contains": bool(member[k]) if contains_available else None, "resolvent_residual_ratio": ratios[k]}
    # what each test said: membership only where the operator provides ``contains`` (no "contains: True"
    # for one that has none: it was never asked)
    said = (f"contains: {bool(member[k])}, " if contains_available else "the operator has no contains; ")
    outside = _outside_domain(op, x[k + 1], float(t[k + 1])) if bad.size else None
    msg = (f"the discrete velocity y = {velocity} = {np.array2string(yk, precision=6)} is not in "
           f"F(t_(k+1), x_(k+1)) at k+1 = {k + 1}, t = {t[k + 1]:.6g}"
           + "".join(f", {name} = {np.array2string(v, precision=6)}" for name, v in terms.items())
           + f" ({said}|J(x + mu y) - x|/tol = {ratios[k]:.3g})")
    if inexact is not None and inexact["ratios"][k] > 1.0:     # the stated tolerance is what was violated
        msg = (f"|x_(k+1) - J_{{hF(t_(k+1))}}(z_k)| = {inexact['distances'][k]:.3g} exceeds the stated resolvent "
               f"tolerance ε(h) = {claim_of(stepper).inexact.describe()} = {eps[k]:.3g} at k+1 = {k + 1}, "
               f"h = {h[k]:.6g}, t = {t[k + 1]:.6g} (z_k = x_k + h f(x_k) + ∫u); " + msg)
        counter["resolvent_distance"], counter["stated_tolerance"] = inexact["distances"][k], eps[k]
        outside = None
    if outside is not None:     # the real cause first: no velocity is a selection outside dom F
        counter["distance_to_domain"] = outside
        msg = (f"x_(k+1) = {np.array2string(x[k + 1], precision=6)} lies outside cl dom F(t_(k+1), ·) (distance "
               f"{outside:.3g}) at k+1 = {k + 1}, t = {t[k + 1]:.6g}, where F is empty; so " + msg)
    counter["message"] = msg
    return Outcome(worst, k + 1, counter, details, message=message)


def _inexact_distances(p: Problem, t: np.ndarray, x: np.ndarray, y: np.ndarray, eps: np.ndarray) -> dict:
    """``|x_{k+1} − J_{h_k F(t_{k+1})}(z_k)|`` with ``z_k = x_{k+1} + h_k y_k`` (the scheme's argument,
    ``eq:iteration``) against the stated ``ε(h_k)`` plus the round-off of ``z_k`` (a resolvent is nonexpansive:
    it passes that round-off on unamplified)."""
    h = np.diff(t)
    z = x[1:] + h[:, None] * y
    step = resolvent_kernel(p.operator, np.asarray(p.x0, dtype=float))
    J = np.array([as_float64(step(z[k], float(h[k]), float(t[k + 1]))) for k in range(len(h))]).reshape(z.shape)
    d = norms(x[1:] - J)
    return {"distances": d, "ratios": d / (eps + row_tolerances(x[1:], z, J, x[:-1]))}


def witness_steps(t: np.ndarray) -> np.ndarray:
    """The resolvent steps ``μ_k`` of :func:`resolvent_witnesses`: the power of two in ``(h_k/4, h_k/2]``.

    Any ``μ > 0`` characterises ``y ∈ F(x)`` by ``J_μ(x + μy) = x``.  Below ``h_k`` it is a different step
    than the scheme's (at ``μ = h_k``, ``x_{k+1} + μ y_k`` is the scheme's own argument); at most ``h_k/2``,
    the round-off of ``μ y_k`` (a difference quotient over ``h_k``) stays within that of the states; and a
    power of two is shared by the cells of every partition within an octave, so an operator whose
    resolvent factorises per step (the complementarity systems') factorises a few times, not once per cell
    (on the paper's Example, 290 fewer factorisations per problem: ``in_domain`` 0.13 → 0.095 s)."""
    return np.exp2(np.floor(np.log2(0.5 * np.diff(t))))


def resolvent_witnesses(stepper: Callable, p: Problem, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(x, y, J)``: the stepper's states on ``t``, its discrete velocities ``y_k = (z_k - x_{k+1})/h_k``
    (``eq:iteration``, :attr:`verimono.Trajectory.selections`) and ``J_k = J_{μ_k F(t_{k+1},·)}(x_{k+1} + μ_k y_k)``
    at the :func:`witness_steps` ``μ_k`` — equal to ``x_{k+1}`` exactly when ``y_k ∈ F(t_{k+1}, x_{k+1})``, and in
    ``dom F(t_{k+1})`` always.  Within :func:`verimono.checks.shared_runs.shared_runs` computed once per
    (stepper, problem, partition) for ``selections`` and ``in_domain`` both."""
    x = run_stepper(stepper, p, t)

    def compute() -> tuple[np.ndarray, np.ndarray]:
        y = Trajectory(t, x, p).selections
        mu = witness_steps(t)
        # the operator's resolvent kernel (its own resolvent's values, validated once: 2-4x fewer microseconds
        # a node on the catalog's operators; a user's operator has none and is called as it is)
        step = resolvent_kernel(p.operator, np.asarray(p.x0, dtype=float))
        back = np.empty(y.shape)      # filled row by row: no list of K arrays copied again into one
        for k in range(len(mu)):
            back[k] = np.reshape(as_float64(step(x[k + 1] + mu[k] * y[k], float(mu[k]), float(t[k + 1]))),
                                 y.shape[1:])
        return y, back

    # the states are in the key: a run dropped from the block and made again by a stepper that is not
    # deterministic gets its own witnesses, never another run's
    key = ("resolvent_witnesses", id(stepper), id(p), float(p.T), fingerprint(np.asarray(p.x0)), fingerprint(t),
           fingerprint(x))
    y, back = remembered_value(key, (stepper, p), compute)
    return x, y, back


def velocity_row(p: Problem, t: np.ndarray, x: np.ndarray, k: int) -> np.ndarray:
    """Row ``k`` of :attr:`verimono.Trajectory.selections` (``y_k = (z_k - x_{k+1})/h_{k+1}``), the same numbers,
    formed alone: the same operations on the same row."""
    h = float(t[k + 1] - t[k])
    z = x[k].copy()
    if p.f is not None:
        z += h * as_float64(p.f(x[k]))
    dU = p.input_increments(t[k:k + 2])
    if dU is not None:
        z += np.asarray(dU[0], dtype=float)
    z -= x[k + 1]
    z /= h
    return z


def velocity_rows(p: Problem, t: np.ndarray, x: np.ndarray):
    """The discrete velocities ``y_0, y_1, ...`` one at a time (:func:`velocity_row`), the input's increments
    computed once: O(n) memory whatever the number of nodes."""
    if p.f is None and p.input_increments(t[:2]) is None:
        for k in range(len(t) - 1):
            z = np.subtract(x[k], x[k + 1])
            z /= float(t[k + 1] - t[k])
            yield z
        return
    # the increments a block of rows at a time (at most _INCREMENT_BLOCK numbers): input_increments is cell by cell,
    # so a block's rows are the same numbers as one call per row (1340 calls of it were a third of the trajectory
    # laws on 'Lipschitz field and input'), the rows then formed as velocity_row forms them
    rows = max(1, _INCREMENT_BLOCK // max(int(np.prod(np.shape(p.x0))), 1))
    f = p.f
    base, dU = 0, None
    for k in range(len(t) - 1):
        if dU is None or k - base >= len(dU):
            base = k
            dU = p.input_increments(t[k:k + rows + 1])
            if dU is None:
                dU = [None] * (len(t) - 1)
        h = float(t[k + 1] - t[k])
        z = x[k].copy()
        if f is not None:
            z += h * as_float64(f(x[k]))
        if dU[k - base] is not None:
            z += np.asarray(dU[k - base], dtype=float)
        z -= x[k + 1]
        z /= h
        yield z


#: the most input increments :func:`velocity_rows` holds at a time (numbers; a block of cells of n each)
_INCREMENT_BLOCK = 1 << 16


def witness_rows(stepper: Callable, p: Problem, t: np.ndarray, x: np.ndarray) -> dict[str, np.ndarray]:
    """What ``in_domain`` and ``selections`` read of the :func:`resolvent_witnesses`, per row, in one pass that
    forms one node's arrays at a time (the witnesses' arrays were two trajectory-sized arrays, their
    differences and tolerances eight more: 13 s per 161-node run at n = 10^6):

    ``distance[k] = |J_k - x_{k+1}|``, ``back_max[k] = |J_k|_∞``, ``muy_max[k] = |μ_k y_k|_∞``,
    ``hy_max[k] = |h_{k+1} y_k|_∞`` (``k < K``) and ``x_max[k] = |x_k|_∞`` (``k ≤ K``) — the same numbers as
    ``norms(back - x[1:])`` and the per-row maxima ``row_tolerances`` takes.  Within
    :func:`verimono.checks.shared_runs.shared_runs` computed once per kept run (keyed by its serial number), the
    precision the operator computed in observed again on each reuse."""

    def compute() -> tuple[np.ndarray, ...]:
        mu = witness_steps(t)
        h = np.diff(t)
        step = resolvent_kernel(p.operator, np.asarray(p.x0, dtype=float))
        K = len(mu)
        if x.ndim == 2 and x.dtype == np.float64 and x.shape[1] > 0:
            return _witness_blocks(p, t, x, mu, h, step)
        dist, back_max, muy_max, hy_max = np.empty(K), np.empty(K), np.empty(K), np.empty(K)
        for k, yk in enumerate(velocity_rows(p, t, x)):
            # |μ y|_∞ and |h y|_∞ from |y|_∞: rounding is monotone and symmetric, so max_i |fl(c y_i)| =
            # fl(c max_i |y_i|) for c > 0 — the same numbers as the products' maxima, without forming h y
            ymax = _absmax(yk)
            muy_max[k], hy_max[k] = mu[k] * ymax, h[k] * ymax
            yk *= mu[k]
            yk += x[k + 1]
            back = np.reshape(as_float64(step(yk, float(mu[k]), float(t[k + 1]))), yk.shape)
            back_max[k] = _absmax(back)
            dist[k] = float(norms(back - x[k + 1]))
        return dist, back_max, muy_max, hy_max, row_absmax(x)

    serial = run_serial(x)
    if serial is None:        # not a kept run: nothing to share it with
        with judged_precision():
            value = compute()
    else:
        key = ("witness_rows", id(stepper), id(p), float(p.T), fingerprint(np.asarray(p.x0)), fingerprint(t), serial)
        value = remembered_value(key, (stepper, p), compute)
    return dict(zip(("distance", "back_max", "muy_max", "hy_max", "x_max"), value))


def _witness_blocks(p: Problem, t: np.ndarray, x: np.ndarray, mu: np.ndarray, h: np.ndarray,
                    step: Callable) -> tuple[np.ndarray, ...]:
    """:func:`witness_rows`' numbers for float64 states ``(K+1, n)``, formed a block of rows at a time (at most
    :func:`_velocity_blocks`' blocks): the
    same element-wise operations on the same rows as :func:`velocity_rows` and the loop of :func:`witness_rows`
    (``x_k + h f(x_k) + ∫u - x_{k+1}``, then ``/ h``, ``· μ``, ``+ x_{k+1}``), ``f`` and the resolvent called row
    by row in the same order, the maxima by :func:`row_absmax` (``max(max, -min, 0)`` of each row, the same
    number as :func:`_absmax`) and the distances by :func:`norms` of the block (``einsum`` reduces each row
    of a block as it reduces the row alone: checked bit for bit at n = 1..4097).  One Python pass per row
    less than the row loop: the trajectory laws' witnesses were a third of their stage's CPU."""
    K = len(mu)
    dist, back_max, muy_max, hy_max = np.empty(K), np.empty(K), np.empty(K), np.empty(K)
    for a, b, Y in _velocity_blocks(p, t, x, h):
        ymax = row_absmax(Y)
        muy_max[a:b], hy_max[a:b] = mu[a:b] * ymax, h[a:b] * ymax
        Y *= mu[a:b, None]
        Y += x[a + 1:b + 1]
        back = np.empty_like(Y)
        for i, (yi, mi, ti) in enumerate(zip(Y, mu[a:b].tolist(), t[a + 1:b + 1].tolist())):
            back[i] = np.reshape(as_float64(step(yi, mi, ti)), yi.shape)
        back_max[a:b] = row_absmax(back)
        back -= x[a + 1:b + 1]
        dist[a:b] = norms(back)
    return dist, back_max, muy_max, hy_max, row_absmax(x)


def _cone_rows(op: Any) -> bool:
    """Whether ``op.contains`` is :class:`verimono.NormalCone`'s own over a set whose ``project`` and ``contains``
    are the catalog's (:class:`verimono.core.sets.ConvexSet`'s ``contains``) and take a time per row bit for bit
    (``_accepts_times``): :func:`_cone_members` then answers a block of rows as the calls row by row do."""
    S = getattr(op, "S", None)
    return (type(op).contains is NormalCone.contains and "contains" not in getattr(op, "__dict__", {})
            and isinstance(S, ConvexSet) and type(S).contains is ConvexSet.contains and accepts_times(S))


def _cone_members(S: Any, X: np.ndarray, Y: np.ndarray, ts: np.ndarray, tols: np.ndarray) -> np.ndarray:
    """``NormalCone(S).contains(X[i], Y[i], ts[i], tol=tols[i])`` for every row, from one call of ``S.contains`` and
    one of ``S.project`` on the block, row ``i`` at ``ts[i]`` (:func:`_cone_rows`): ``X[i] ∈ S`` (``|proj X[i] −
    X[i]|_∞ ≤ tol``) and ``|proj(X[i] + Y[i]) − X[i]|_∞ ≤ tol`` — the same projections and maxima as the
    calls one row at a time (the second projection made for every row, also where the first test fails: it
    reads nothing of the answer there)."""
    inside = np.asarray(S.contains(X, ts, tols), dtype=bool)
    d = np.abs(np.asarray(S.project(X + Y, ts), dtype=float) - X)
    return inside & (d.max(axis=1) <= tols)


def _velocities(p: Problem, t: np.ndarray, x: np.ndarray, h: np.ndarray):
    """``(k, y_k)`` for every step: :func:`_velocity_blocks`' rows for float64 states ``(K+1, n)``, else
    :func:`velocity_rows`' (the same numbers)."""
    if x.ndim == 2 and x.dtype == np.float64 and x.shape[1] > 0:
        for a, _, Y in _velocity_blocks(p, t, x, h):
            yield from enumerate(Y, a)
    else:
        yield from enumerate(velocity_rows(p, t, x))


def _velocity_blocks(p: Problem, t: np.ndarray, x: np.ndarray, h: np.ndarray):
    """``(a, b, Y)``: the discrete velocities ``y_a .. y_{b-1}`` of float64 states ``(K+1, n)`` as a block ``Y`` of at
    most :data:`_VELOCITY_BLOCK` numbers (one row when a row is longer: a few rows of memory at any n), the
    input's increments asked for in :func:`velocity_rows`' blocks (the same calls): the same numbers as
    :func:`velocity_rows`, by the same element-wise operations on each row (``x_k + h f(x_k) + ∫u - x_{k+1}``,
    then ``/ h``), ``f`` called row by row in order."""
    K = len(h)
    f = p.f
    plain = f is None and p.input_increments(t[:2]) is None     # velocity_rows' own test, its call kept
    size = max(int(np.prod(np.shape(p.x0))), 1)
    rows, sub = max(1, _INCREMENT_BLOCK // size), max(1, _VELOCITY_BLOCK // size)
    for base in range(0, K, rows):
        dU = None if plain else p.input_increments(t[base:base + rows + 1])
        for a in range(base, min(K, base + rows), sub):
            b = min(K, base + rows, a + sub)
            hb = h[a:b, None]
            if plain:
                Y = np.subtract(x[a:b], x[a + 1:b + 1])
            else:
                Y = x[a:b].copy()
                if f is not None:
                    F = np.empty_like(Y)
                    for i in range(b - a):
                        F[i] = as_float64(f(x[a + i]))
                    Y += hb * F
                if dU is not None:
                    Y += np.asarray(dU[a - base:b - base], dtype=float)
                Y -= x[a + 1:b + 1]
            Y /= hb
            yield a, b, Y


#: the most numbers of :func:`_velocity_blocks`' block (its arrays a few times this): rows enough at small n to
#: leave Python's per-row work behind, one row at large n
_VELOCITY_BLOCK = 1 << 12


def _absmax(a: np.ndarray) -> float:
    return float(max(a.max(), -a.min(), 0.0)) if a.size else 0.0


def _velocity(p: Problem, t: np.ndarray, x: np.ndarray, k: int) -> tuple[str, dict[str, np.ndarray]]:
    """The discrete velocity ``selections`` tests, as a formula naming the terms this problem has
    (``f``, ``u``), and those terms' values in cell ``k``."""
    formula, terms = "(x_k", {}
    if p.f is not None:
        formula += " + h f(x_k)"
        terms["f(x_k)"] = as_float64(p.f(x[k]))
    dU = p.input_increments(t[k:k + 2])
    if dU is not None:
        formula += " + ∫u"
        terms["∫u"] = np.asarray(dU[0], dtype=float)
    return formula + " - x_(k+1))/h", terms


def _outside_domain(op: Any, x: np.ndarray, t: float) -> float | None:
    """The distance of ``x`` to ``cl dom F(t,·)`` when it is beyond the tolerance, else ``None`` (also when
    the operator cannot project onto its domain)."""
    try:
        q = as_float64(op.project_domain(x, t))
    except (NotImplementedError, VerimonoError, ArithmeticError, ValueError):
        return None
    d = float(np.linalg.norm(q - x))
    return d if d > tolerance(x, q) else None


# -- initial_value ----------------------------------------------------------------------------------

#: the smallest positive normal number of each precision: the absolute floor of ``initial_value``'s tolerance
#: (an ``x0`` below it is subnormal or 0 in that precision, with no relative accuracy left)
SMALLEST_NORMAL = {"float64": float(np.finfo(np.float64).tiny), "float32": float(np.finfo(np.float32).tiny),
                   "float16": float(np.finfo(np.float16).tiny), "bfloat16": float(np.finfo(np.float32).tiny)}


@stepper_law("initial_value", "eq:incGen (x(0) = x0)")
def check_initial_value(stepper: Callable, p: Problem, t: np.ndarray, *, seed: int = 0) -> Outcome:
    """``x_0 = x0``: every trajectory starts at the initial point of ``eq:incGen`` (``x(0) = x0``), which
    ``eq:iteration`` starts from — also when ``x0 ∉ cl dom F(0)`` (``initial_jump``): the catching-up scheme
    jumps to ``cl dom F`` in its first step, ``x_0`` is still ``x0`` (:func:`verimono.solve` returns it so, and the
    references' exact solutions have ``x(0) = x0``); a stepper returning the projection as ``x_0`` fails.

    Tolerance: ``|x_0 - x0|_∞ ≤ rtol · |x0|_∞ + tiny``, ``rtol`` the precision the stepper returned its states in
    (:func:`verimono.core.tolerances.rtol_for`: float32 judged as float32) and ``tiny`` that precision's smallest
    normal number.  ``x_0`` is a copy of ``x0`` in the subject's precision, off by at most half its ulp: relative to
    ``|x0|`` itself, not to ``1 + |x0|`` as the states' laws are, so a stepper starting at 0, or at ``1.2 x0``, fails
    whatever the size of ``x0 ≠ 0``.  Judged on the battery's default partitions (runs the battery makes anyway);
    a failure shrinks to the one-cell partition ``[0, t_1]``.

    Claim: every stepper, whatever it claims (the solution it approximates starts at ``x0``).
    """
    x = run_stepper(stepper, p, t)
    x0 = np.asarray(p.x0, dtype=float)
    precision = current_precision()
    tol = precision.rtol * float(np.max(np.abs(x0))) + SMALLEST_NORMAL[precision.name]
    d = float(np.max(np.abs(x[0] - x0)))
    counter = {"k": 0, "t_k": t[0], "x_k": x[0], "distance": d, "tolerance": tol,
               "message": f"x_0 = {np.array2string(x[0], precision=10)} is not x0 = "
                          f"{np.array2string(x0, precision=10)}: |x_0 - x0| = {d:.3g} > {tol:.3g} "
                          f"(rtol {precision.rtol:.2g} times |x0|)"}
    # k = 1: the shortest failing prefix is the one-cell partition [0, t_1] (a stepper needs a cell to run)
    return Outcome(d / tol, 1, counter, {"distance": d, "tolerance": tol},
                   message="x_0 = x0 (within rtol |x0| of the stepper's precision)")


# -- trajectory_immutable ---------------------------------------------------------------------------

#: cells of the two partitions ``trajectory_immutable`` runs the stepper on (of one length: a stepper keeping a
#: buffer per shape hands the same one out twice); what it judges is memory, not accuracy, so few cells do
#: (measured in check_stepper(verimono.solve): 2.5 s with 40 cells on a loaded machine, 0.38 s with 8)
IMMUTABLE_CELLS = 8


def _memory(value: Any) -> Any:
    """What ``value`` holds, as a NumPy array without copying where it can (a view of a NumPy array, a
    ``Trajectory``'s states, a CPU tensor's buffer): the memory a later call could write into."""
    try:
        return np.asarray(to_numpy(value))
    except Exception:  # noqa: BLE001 - a value NumPy cannot view shares no memory NumPy can see
        return None


def _shares(a: Any, b: np.ndarray) -> bool:
    return isinstance(a, np.ndarray) and np.may_share_memory(a, b) and np.shares_memory(a, b)


def _own_copy(p: Problem) -> Problem:
    """The stepper's own copy of ``p`` for :func:`check_trajectory_immutable`, its ``x0`` writeable there alone (a
    Problem's ``x0`` is read-only): a write into it is then seen and named, not an error NumPy raises."""
    q = p.replace(x0=np.array(p.x0, dtype=float))
    q.x0.flags.writeable = True
    return q


@stepper_law("trajectory_immutable", "a returned trajectory is the caller's (issue 42)", over_grids=False)
def check_trajectory_immutable(stepper: Callable, p: Problem, *, seed: int = 0, grids: Any = None) -> Outcome:
    """A trajectory a stepper returned never changes after later calls, and calling it changes nothing it was
    given.  The stepper runs on two partitions (uniform and random with ``IMMUTABLE_CELLS`` cells, or
    ``grids``; one given partition is run twice), each a fresh copy, on a copy of the problem (a stepper writing
    into ``problem.x0`` must not change the battery's problem).  It fails when

    * the array one call returned changed when a later call ran (one output buffer handed out twice), or two
      calls returned the same memory (caught even where both calls return the same values, at rest);
    * a call changed the partition ``t_grid`` or ``problem.x0`` it was given;
    * what a call returned lies in the memory of ``t_grid`` or ``problem.x0`` (a later change of the caller's
      array would change it).

    Exact: no tolerance — a returned array that changes in any bit has changed.  The laws judging the states
    take their own copy of every run (:func:`verimono.checks.partitions.run_stepper`), so a shared buffer never
    corrupts their verdicts; this law is where it is named.  Its two runs are its own: the
    battery's shared runs are copies, which cannot show a later write into the stepper's array (8 cells each).

    Claim: every stepper, whatever it claims.
    """
    parts = list(claimed_grids(stepper, default_grids(p, seed, IMMUTABLE_CELLS) if grids is None
                               else battery_grids(grids, p, seed), p.T)[0].values())    # grids="uniform": its kind
    if len(parts) == 1:     # one partition given: two calls on it (a buffer handed out twice is shared memory)
        parts = parts * 2
    q = _own_copy(p)
    x0 = q.x0.copy()
    returned: list[tuple[int, Any, Any, np.ndarray]] = []   # (call, value, its memory, a copy of its states)
    problems: list[str] = []
    for call, grid in enumerate(parts, start=1):
        given = np.array(grid, dtype=float)
        value = stepper(q, given)
        memory = _memory(value)
        states = np.array(as_float64(value), dtype=float, copy=True)
        if not np.array_equal(given, grid):
            k = int(np.flatnonzero(given != grid)[0])
            problems.append(f"call {call} changed the t_grid it was given: t_{k} = {grid[k]!r} became {given[k]!r}")
        if _shares(memory, given):
            problems.append(f"call {call} returned its states in the memory of t_grid")
        if _shares(memory, q.x0):
            problems.append(f"call {call} returned its states in the memory of problem.x0")
        if not np.array_equal(q.x0, x0):
            problems.append(f"call {call} changed problem.x0 it was given: {np.array2string(x0, precision=10)} "
                            f"became {np.array2string(q.x0, precision=10)}")
            q = _own_copy(p)                                      # the next call starts from x0 again
            x0 = q.x0.copy()
        for before, old, old_memory, old_states in returned:
            now = np.asarray(as_float64(old), dtype=float)
            if now.shape != old_states.shape or not np.array_equal(now, old_states, equal_nan=True):
                change = (f"by up to {float(np.max(np.abs(now - old_states))):.3g}" if now.shape == old_states.shape
                          else f"its shape to {now.shape}")
                problems.append(f"the array call {before} returned changed when call {call} ran ({change}): one "
                                "output buffer handed out twice")
            elif old_memory is not None and _shares(memory, old_memory):
                problems.append(f"call {call} returned its states in the memory of the array call {before} returned")
        returned.append((call, value, memory, states))
    if problems:
        counter = {"problem": p.name, "T": p.T, "x0": p.x0, "grids": parts, "findings": problems,
                   "message": "; ".join(problems)}
        return Outcome(None, counter=counter, details={"calls": len(parts)}, status=FAILED)
    return Outcome(None, details={"calls": len(parts)}, status=PASSED,
                   message=f"{len(parts)} calls: no returned array changed, no input written, no memory shared")


__all__ = ["check_contraction", "check_in_domain", "check_selections", "check_initial_value",
           "check_trajectory_immutable", "domain_vanishing", "perturbed_starts",
           "run_starts", "step_growth", "lipschitz_of", "norms", "domain_distances", "resolvent_witnesses",
           "witness_steps", "witness_rows", "velocity_row", "velocity_rows", "diff_norms", "step_norms", "row_absmax"]
