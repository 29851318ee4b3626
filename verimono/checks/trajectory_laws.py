"""Trajectory laws: properties every discrete solution of the paper's scheme must have.

A *stepper* is a callable ``stepper(problem, t_grid)`` returning ``x_0, ..., x_K`` (shape ``(K+1, n)``);
:func:`verimono.solve` is the reference one.  Each ``check_<law>(stepper, problem, ...)`` runs the stepper
on a few partitions and returns one :class:`~verimono.results.CheckResult` whose ``worst`` is the largest
observed ``lhs / (rhs + tol)`` (``bound = 1``) and whose ``counterexample`` reproduces a failure: the
problem, the partition (shrunk to the shortest prefix ``[0, t_k]`` that still fails, re-verified), the
initial points and the offending step.  :func:`reproduce` re-runs a law from a record.

Laws (labels of the paper, Camlibel–Iannelli–Tanwani):

* ``contraction`` — uniqueness argument (monotonicity of ``F(t,·)``, (A1)) and the Lipschitz-perturbation
  theorem of Section 6: ``|x_k - x'_k| ≤ e^{L h_k} |x_{k-1} - x'_{k-1}|``, hence
  ``|x_k - x'_k| ≤ e^{L t_k}|x_0 - x'_0|`` (``L = 0`` without ``f``; the scheme's explicit ``f`` gives
  the factor ``1 + hL ≤ e^{hL}``; the input ``u`` cancels).
* ``unique_limit`` — solutions on different (uniform, random, graded) partitions approach one limit as
  ``|Δ| → 0`` (the limit of ``x_Δ`` in Section 5.4 is the unique solution); no rate assumed: a Cauchy
  criterion with each refinement sequence's own geometric tail.
* ``in_domain`` — ``x_k ∈ cl dom F(t_k, ·)`` (``e:x k+1 props.1``).
* ``bounds_lg`` — lemma ``lem:bndSeq`` under (A3) and (LG): ``|x_k| ≤ β`` and
  ``|x_k - x_{k-1}| ≤ ψ(t_k) - ψ(t_{k-1})`` with ``β, ψ`` of ``e:only beta``, ``eq:defPsi``; with an
  input ``u``, applied to ``ξ_k = x_k - Φ(t_k)`` through lemma ``l:extinput`` (``φ̄ = φ + ∫|u|``,
  ``σ̄ = σ (1 + ∫_0^T |u|)``).
* ``bounds_yb`` — lemma ``lem:bndSeqYB`` under (YB): ``β = |x0| + αT``, ``ψ(t) = αt``,
  ``α = 2(θ(T) - θ(0)) + |F^0(0, x0)|``.
* ``psi_interpolation`` — lemma ``lem:bndEquiCont``: the ψ-interpolant ``x_Δ`` of ``e:x delta`` obeys
  ``|x_Δ(τ̄) - x_Δ(τ)| ≤ ψ(τ̄) - ψ(τ)``.
* ``selections`` — ``eq:iteration``: ``y_{k+1} = (x_k + h f(x_k) + ∫u - x_{k+1})/h_{k+1} ∈
  F(t_{k+1}, x_{k+1})``, tested with ``operator.contains`` and with the resolvent characterisation
  ``J_μ(x + μy) = x`` at ``μ = h/2`` (a different step than the scheme's).

Each law declares what it needs (:mod:`verimono.checks.core`), the stepper's claim among it
(:mod:`verimono.claims`): ``bounds_lg``, ``bounds_yb``, ``psi_interpolation`` and ``selections`` bind only
the proximal scheme; ``contraction`` binds steppers claiming it; ``unique_limit`` binds every convergent
scheme, and ``in_domain`` too, as a distance vanishing at the claimed order for ``scheme="any"``.
"""

from __future__ import annotations

import functools
import time
import warnings
from typing import Any, Callable, Iterable, Iterator, Sequence

import numpy as np
from scipy import integrate

from ..errors import OutsideDomain, VerimonoError
from ..grids import graded_grid, random_grid, uniform_grid, validate_grid
from ..operators import L1Subdifferential, Linear, NormalCone, NormSubdifferential, Operator
from ..problem import Problem
from ..claims import claim_of, with_claim
from ..convergence import _name as _convergence_name
from ..errors import InvalidCheckArgument
from ..timeouts import run_unit
from ..results import FAILED, PASSED, SKIPPED, CheckResult, Report
from ..stepping import Trajectory
from ..tolerances import (DOMAIN_ORDER_SLACK, LIMIT_EXTRA_LEVELS, LIMIT_RATIO_FLOOR, LIMIT_TAIL_SAFETY,
                          quotient_tolerance, tolerance)
from .core import (CONTRACTION_CLAIM, PROXIMAL_CLAIM, Holds, Member, NotApplicable, Outcome, law as _declare,
                   record, run as _run)
from .orders import check_convergence_order

#: cells of the default partitions (fine enough for the lemmas' bounds, fast enough for a battery)
DEFAULT_CELLS = 40
#: nonuniformity of the default random partition (cell lengths vary by a factor up to 4)
RANDOM_SPREAD = 0.6
#: cells of the three refinement levels of ``unique_limit`` (|Δ| shrinks 16-fold)
LIMIT_LEVELS = (10, 40, 160)

#: the trajectory laws, law name -> check function, in the order they run (filled by :func:`stepper_law`)
CHECKS: dict[str, Callable[..., CheckResult]] = {}


#: the law does not apply to this problem (the reason is the record's message)
_Skip = NotApplicable


# -- helpers ----------------------------------------------------------------------------------------

def _name(obj: Any) -> str:
    return getattr(obj, "__name__", None) or getattr(obj, "name", None) or type(obj).__name__


def with_changes(problem: Problem, **changes: Any) -> Problem:
    """Deprecated: ``problem.replace(**changes)`` (:meth:`verimono.Problem.replace`)."""
    warnings.warn("with_changes(problem, ...) is deprecated; use problem.replace(...)", DeprecationWarning,
                  stacklevel=2)
    return problem.replace(**changes)


def _single(problem: Problem) -> Problem:
    """The laws are stated per initial point: a batch is checked through its first row."""
    return problem.replace(x0=problem.x0[0]) if problem.batched else problem


def run_stepper(stepper: Callable, problem: Problem, grid: np.ndarray) -> np.ndarray:
    """``stepper(problem, grid)`` as a float array of shape ``(K+1, n)``, finite (else ValueError)."""
    x = np.asarray(stepper(problem, grid), dtype=float)
    if x.shape != (len(grid),) + problem.x0.shape:
        raise ValueError(f"stepper {_name(stepper)} returned shape {x.shape}, expected "
                         f"{(len(grid),) + problem.x0.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"stepper {_name(stepper)} returned non-finite states")
    return x


def default_grids(problem: Problem, seed: int = 0, cells: int = DEFAULT_CELLS) -> dict[str, np.ndarray]:
    """A uniform and a random (nonuniform) partition of ``[0, T]`` with ``cells`` cells."""
    return {"uniform": uniform_grid(problem.T, steps=cells),
            "random": random_grid(problem.T, cells, seed=seed, spread=RANDOM_SPREAD)}


def _as_grids(grids: Any, problem: Problem, seed: int) -> dict[str, np.ndarray]:
    if grids is None:
        return default_grids(problem, seed)
    if isinstance(grids, dict):
        return {k: validate_grid(g, problem.T) for k, g in grids.items()}
    return {f"grid{i}": validate_grid(g, problem.T) for i, g in enumerate(grids)}


def _norms(a: np.ndarray) -> np.ndarray:
    return np.sqrt(np.sum(np.asarray(a, dtype=float) ** 2, axis=-1))


def _vals(fn: Callable, t: Iterable[float]) -> np.ndarray:
    return np.array([float(fn(float(s))) for s in t])


def _cell_integrals(fn: Callable, t: np.ndarray) -> np.ndarray:
    """``∫_{t_k}^{t_{k+1}} fn`` on every cell (adaptive quadrature; ``fn`` may be non-smooth)."""
    return np.array([integrate.quad(lambda s: float(fn(s)), a, b, limit=100)[0] for a, b in zip(t[:-1], t[1:])])


def _cumulative(fn: Callable, t: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(_cell_integrals(fn, t))])


def _holds(*tests: Callable[[Problem], Any]) -> Holds:
    """A requirement met when every test passes on the (first row of the) problem; the reason is the
    :class:`NotApplicable` message of the first that does not."""
    def check(problem: Problem) -> str | None:
        p = _single(problem)
        for test in tests:
            try:
                test(p)
            except NotApplicable as exc:
                return str(exc)
        return None
    return Holds(check)


def _either(*tests: Callable[[Problem], Any]) -> Holds:
    """Met when at least one test passes (ψ of lem:bndSeq *or* of lem:bndSeqYB)."""
    def check(problem: Problem) -> str | None:
        reasons = [_holds(t).test(problem) for t in tests]
        return None if any(r is None for r in reasons) else "no ψ available — " + "; ".join(reasons)
    return Holds(check)


def stepper_law(name: str, label: str, *requires: Any) -> Callable:
    """Declare ``check_<name>(stepper, problem, **kw)`` as a trajectory law (:mod:`verimono.checks.core`):
    its requirements are judged before the stepper runs, and it runs under the core's driver."""
    def deco(fn: Callable) -> Callable:
        decl = _declare(name, label, subject="stepper", requires=requires)(fn).law

        @functools.wraps(fn)
        def check(stepper: Callable, problem: Problem, **kw: Any) -> CheckResult:
            return _run(decl, stepper, problem, stepper=stepper, problem=_single(problem), **kw)
        check.law = decl
        CHECKS[name] = check
        return check
    return deco


def _drive(law: str, stepper: Callable, problem: Problem, grids: dict[str, np.ndarray],
           evaluate: Callable[[Problem, np.ndarray], Outcome], *, shrink: bool = True,
           message_ok: str = "", extra: dict | None = None) -> CheckResult:
    """Run ``evaluate`` on every partition, keep the worst, shrink a failure to its shortest prefix."""
    subject = f"{_name(stepper)} on {problem.name}"
    start = time.perf_counter()
    try:
        problem = _single(problem)
        outcomes = {g: evaluate(problem, t) for g, t in grids.items()}
    except _Skip as exc:
        return CheckResult(law, subject, SKIPPED, message=str(exc), duration=time.perf_counter() - start)
    except NotImplementedError as exc:
        return CheckResult(law, subject, SKIPPED, message=f"not available: {exc}",
                           duration=time.perf_counter() - start)
    except (VerimonoError, ArithmeticError, ValueError) as exc:
        return CheckResult(law, subject, FAILED, message=f"{type(exc).__name__}: {exc}",
                           counterexample={"problem": problem.name, "x0": problem.x0,
                                           "grids": {g: t for g, t in grids.items()}},
                           duration=time.perf_counter() - start)
    gname = max(outcomes, key=lambda g: outcomes[g].worst)
    out = outcomes[gname]
    details = {"worst_by_grid": {g: o.worst for g, o in outcomes.items()}, **out.details, **(extra or {})}
    if not out.failed:
        return CheckResult(law, subject, PASSED, worst=out.worst, bound=1.0, message=message_ok,
                           details=details, duration=time.perf_counter() - start)
    grid = grids[gname]
    counter = {"problem": problem.name, "T": problem.T, "x0": problem.x0, "grid": grid, "grid_kind": gname,
               **out.counter, "shrunk": False}
    if shrink and out.k is not None and 1 <= out.k < len(grid) - 1:
        t_k = float(grid[out.k])
        try:
            small = problem.replace(T=t_k)
            prefix = grid[:out.k + 1].copy()
            again = evaluate(small, prefix)
        except (_Skip, NotImplementedError, VerimonoError, ArithmeticError, ValueError):
            again = None
        if again is not None and again.failed:
            counter = {"problem": problem.name, "T": t_k, "x0": problem.x0, "grid": prefix,
                       "grid_kind": f"{gname} prefix [0, t_{out.k}]", **again.counter, "shrunk": True}
    msg = counter.pop("message", "") or f"{law} violated"
    return CheckResult(law, subject, FAILED, worst=out.worst, bound=1.0, counterexample=counter,
                       message=msg, details=details, duration=time.perf_counter() - start)


# -- contraction ------------------------------------------------------------------------------------

def _lipschitz(problem: Problem) -> float:
    if problem.f is None:
        return 0.0
    if problem.lipschitz is None:
        raise _Skip("f is given without its Lipschitz constant (Problem(lipschitz=...)); the bound "
                    "e^{L t} needs L")
    return float(problem.lipschitz)


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
                z = np.asarray(op.project_domain(z, 0.0), dtype=float)
            except NotImplementedError:
                z = np.asarray(op.resolvent(z, 1e-3 * problem.T, 0.0), dtype=float)
        if np.linalg.norm(z - x0) > tolerance(x0, z) * 10:
            out.append(z)
    return out


def _step_growth(L: float, h: np.ndarray) -> np.ndarray:
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
            xs = np.asarray(stepper(problem.replace(x0=np.stack([problem.x0, *starts])), grid), dtype=float)
        except (VerimonoError, ArithmeticError, ValueError, TypeError, IndexError):
            xs = None
        if (xs is not None and xs.shape == (len(grid), len(starts) + 1) + problem.x0.shape
                and np.array_equal(xs[:, 0], x) and np.all(np.isfinite(xs))):
            return [xs[:, i + 1] for i in range(len(starts))]
    return [run_stepper(stepper, problem.replace(x0=z), grid) for z in starts]


@stepper_law("contraction", "uniqueness argument and the Lipschitz theorem (Section 6)", CONTRACTION_CLAIM,
             _holds(lambda p: _lipschitz(p)))
def check_contraction(stepper: Callable, problem: Problem, *, grids: Any = None, x0_primes: Any = None,
                      seed: int = 0) -> CheckResult:
    """Two discrete solutions never move apart faster than ``e^{L t}`` (uniqueness argument, Section 6).

    Checks ``|x_k - x'_k| ≤ g_k |x_{k-1} - x'_{k-1}|`` step by step; ``L = 0`` (nonexpansive resolvents)
    without ``f``.  The per-step factor ``g_k`` is ``e^{L h_k}`` for the paper's explicit treatment of ``f``
    (``x_{k+1} = J(x_k + h f(x_k))``: ``1 + hL ≤ e^{hL}``), or ``1/(1 - L h_k)`` when larger (``hL < 1``: a
    stepper treating ``f`` implicitly, ``x_{k+1} = J(x_k + h f(x_{k+1}))``); both give ``e^{L t_k}`` as
    ``h → 0``.

    Claim: ``contracts`` — the proximal scheme contracts (its resolvents are nonexpansive); a scheme
    claiming only convergence need not contract step by step, so it must say so (``contracts=True``).
    """
    grids = _as_grids(grids, problem, seed)

    def evaluate(p: Problem, t: np.ndarray) -> Outcome:
        L = _lipschitz(p)
        starts = perturbed_starts(p, seed) if x0_primes is None else [np.asarray(z, float) for z in x0_primes]
        if not starts:
            raise _Skip("no second initial point distinct from x0 in cl dom F(0)")
        x = run_stepper(stepper, p, t)
        growth = _step_growth(L, np.diff(t))
        worst, best = -np.inf, None
        glob = 0.0
        for z, y in zip(starts, run_starts(stepper, p, starts, t, x)):
            d = _norms(x - y)
            tol = tolerance(x, y)
            ratio = d[1:] / (growth * d[:-1] + tol)
            glob = max(glob, float(np.max(d / (np.concatenate([[1.0], np.cumprod(growth)]) * d[0] + tol))))
            bad = np.flatnonzero(ratio > 1.0)
            k = int(bad[0]) + 1 if bad.size else int(np.argmax(ratio)) + 1
            r = float(np.max(ratio))
            if r > worst:
                worst = r
                best = {"x0_prime": z, "k": k, "t_k": t[k], "x_k": x[k], "x_prime_k": y[k],
                        "x_k_minus_1": x[k - 1], "x_prime_k_minus_1": y[k - 1],
                        "lhs": d[k], "rhs": growth[k - 1] * d[k - 1], "L": L,
                        "message": f"|x_k - x'_k| = {d[k]:.6g} > g_k |x_(k-1) - x'_(k-1)| = "
                                   f"{growth[k - 1] * d[k - 1]:.6g} at k = {k}, t_k = {t[k]:.6g}"}
        return Outcome(worst, best["k"], best, {"global_ratio": glob, "pairs": len(starts), "L": L})

    return _drive("contraction", stepper, problem, grids, evaluate,
                  message_ok="|x_k - x'_k| <= g_k |x_{k-1} - x'_{k-1}| at every step (g_k = max(e^{L h}, 1/(1 - L h)))")


# -- uniqueness of the limit ------------------------------------------------------------------------

def _interp(t: np.ndarray, x: np.ndarray, tau: np.ndarray) -> np.ndarray:
    return np.stack([np.interp(tau, t, x[:, j]) for j in range(x.shape[1])], axis=-1)


def limit_grids(T: float, K: int, seed: int = 0) -> dict[str, np.ndarray]:
    """Uniform, random and graded (``t_k = T (k/K)²``) partitions with ``K`` cells."""
    return {"uniform": uniform_grid(T, steps=K), "random": random_grid(T, K, seed=seed, spread=RANDOM_SPREAD),
            "graded": graded_grid(T, K, 2.0)}


@stepper_law("unique_limit", "the limit of x_Δ is the unique solution (Section 5.4)")
def check_unique_limit(stepper: Callable, problem: Problem, *, levels: Sequence[int] = LIMIT_LEVELS,
                       seed: int = 0) -> CheckResult:
    """Solutions on different partitions approach one limit as ``|Δ| → 0`` (unique limit, Section 5.4).

    No rate is assumed (the paper gives none: ``x' ∈ −∂(c(t)|x|)`` with ``c = 0.1 t^{-0.9}``, σ in L¹ but
    unbounded, converges like ``h^{0.1}``, and its uniform and graded partitions even move *apart* until
    ``K ≈ 1000``).  For each kind ``k`` of partition (uniform, random, graded) the solutions ``x^k_m`` on
    ``K_m`` cells form a sequence; ``c_{k,m}`` is the sup distance between the piecewise-linear interpolants
    of ``x^k_m`` and ``x^k_{m+1}`` (from the end of both first cells on: the first cell holds the
    catching-up jump, or a transient faster than the mesh, that no interpolant resolves there).

    Criterion — Cauchy, against each sequence's own trend: when the last ratio ``r = c_{k,M-1}/c_{k,M-2}``
    is below 1, ``|x^k_M − x^k_∞| ≤ c_{k,M-1} r/(1 − r)`` (the a-posteriori bound of a geometrically
    convergent sequence — Banach's fixed-point estimate; Aitken's Δ² model; any rate ``h^p``, ``p > 0``,
    is geometric in ``m`` on 4-fold refinements, with ``r = 4^{-p}``), times ``LIMIT_TAIL_SAFETY`` = 4, with
    ``r`` raised to ``LIMIT_RATIO_FLOOR = 1/4`` (a fall faster than order 1 between the coarse levels is
    pre-asymptotic and does not extrapolate: the scheme is first order).
    The law fails when two kinds' limits are provably apart, ``D(K_M) > tail_a + tail_b + tol`` with
    ``D(K_M)`` the sup distance between their finest solutions (different limits, e.g. a stepper using
    the mean step), or when a kind's differences do not shrink (``r ≥ 1``: not a Cauchy sequence) after up
    to ``LIMIT_EXTRA_LEVELS`` further 4-fold refinements.  Those are granted while some kind's differences
    still grow (``x' ∈ −∂(2|x|)`` from ``x0 = 1/32`` dies out at ``t = 1/64``: meshes 0.1 and 0.025 all
    give 0 there, the differences are 0, then ``c h``).  Evidence, not proof: a sequence converging at
    rate ``p`` gives ``tail ≈ 4/(4^p − 1)`` times its last difference, so a slow one is judged leniently.

    Claim: any — every convergent scheme has a unique limit (Section 5.4: it is the unique solution).
    """
    subject = f"{_name(stepper)} on {problem.name}"
    start = time.perf_counter()
    levels = list(levels)
    while len(levels) < 3:               # two differences per kind: the least the own-trend tail needs
        levels.append(4 * levels[-1])
    try:
        p = _single(problem)
        scale = [float(np.max(np.abs(p.x0)))]

        def sup_dist(ga, xa, gb, xb, since=0.0):
            tau = np.union1d(ga, gb)
            tau = tau[tau >= max(ga[1], gb[1], since)]
            if tau.size == 0:
                return 0.0, float(ga[-1]), xa[-1], xb[-1]
            dist = _norms(_interp(ga, xa, tau) - _interp(gb, xb, tau))
            m = int(np.argmax(dist))
            return float(dist[m]), float(tau[m]), _interp(ga, xa, tau[m:m + 1])[0], _interp(gb, xb, tau[m:m + 1])[0]

        runs: list[tuple[dict, dict]] = []     # (grids, solutions) per level

        def add_level(K: int) -> None:
            gs = limit_grids(p.T, K, seed)
            K0 = levels[0]
            if K % K0 == 0:
                # the random kind as a refinement sequence: the first level's random partition with every
                # cell split in K/K0 equal parts (independent random partitions per level have errors C_m h_m
                # with a random C_m, which no own-trend tail can extrapolate)
                base = limit_grids(p.T, K0, seed)["random"]
                sub = np.linspace(0.0, 1.0, K // K0 + 1)[:-1]
                gs["random"] = np.append((base[:-1, None] + np.diff(base)[:, None] * sub[None, :]).ravel(), p.T)
            sols = {g: run_stepper(stepper, p, t) for g, t in gs.items()}
            scale[0] = max(scale[0], max(float(np.max(np.abs(x))) for x in sols.values()))
            runs.append((gs, sols))

        def cross(m: int, since: dict | None = None) -> tuple[float, dict | None]:
            gs, sols = runs[m]
            names, best, info = list(gs), 0.0, None
            for i in range(len(names)):
                for j in range(i + 1, len(names)):
                    a, b = names[i], names[j]
                    s0 = 0.0 if since is None else max(since[a], since[b])
                    d, tau, xa, xb = sup_dist(gs[a], sols[a], gs[b], sols[b], s0)
                    if d >= best:
                        best, info = d, {"pair": [a, b], "tau": tau, "x_a": xa, "x_b": xb}
            return best, info

        def judge():
            """Tails of each kind and the cross distance, both from the end of the first cells of the
            coarsest level the tails use on (where the differences are measured)."""
            tol = tolerance(scale[0])
            kinds, M = list(runs[0][0]), len(runs) - 1
            since = {k: float(runs[M - 2][0][k][1]) for k in kinds}
            diffs = {k: [sup_dist(runs[m][0][k], runs[m][1][k], runs[m + 1][0][k], runs[m + 1][1][k], since[k])[0]
                         for m in (M - 2, M - 1)] for k in kinds}
            tails, ratios = {}, {}
            for k, c in diffs.items():
                if c[-1] <= tol:
                    tails[k], ratios[k] = c[-1], 0.0
                    continue
                r = c[-1] / c[-2] if c[-2] > 0 else np.inf
                ratios[k] = r
                re = max(r, LIMIT_RATIO_FLOOR)      # a faster fall than order 1 is pre-asymptotic
                tails[k] = LIMIT_TAIL_SAFETY * c[-1] * re / (1.0 - re) if r < 1.0 else np.inf
            D, info = cross(M, since)
            a, b = info["pair"] if info else (kinds[0], kinds[1])
            gap = D - tails[a] - tails[b]
            # a distance before the tails' region (first cells of the coarser levels) is not judged, but
            # asks for a finer level; so do differences that do not shrink yet
            D_all, _ = cross(M)
            unresolved = any(r >= 1.0 for r in ratios.values()) or (
                D_all > D and D_all > min(tails[x] + tails[y] for x in kinds for y in kinds if x < y) + tol)
            return D, info, diffs, tails, ratios, gap, tol, unresolved

        for K in levels:
            add_level(K)
        D, info, diffs, tails, ratios, gap, tol, unresolved = judge()
        for _ in range(LIMIT_EXTRA_LEVELS):
            if not unresolved or (gap > tol and all(r < 1.0 for r in ratios.values())):
                break        # judged: no doubt left, or two settled kinds are provably apart
            levels.append(4 * levels[-1])
            add_level(levels[-1])
            D, info, diffs, tails, ratios, gap, tol, unresolved = judge()
    except NotImplementedError as exc:
        return CheckResult("unique_limit", subject, SKIPPED, message=f"not available: {exc}",
                           duration=time.perf_counter() - start)
    except (VerimonoError, ArithmeticError, ValueError) as exc:
        return CheckResult("unique_limit", subject, FAILED, message=f"{type(exc).__name__}: {exc}",
                           counterexample={"problem": problem.name, "levels": levels, "seed": seed},
                           duration=time.perf_counter() - start)
    distances = [cross(m)[0] for m in range(len(runs))]
    not_cauchy = [k for k, r in ratios.items() if r >= 1.0]
    details = {"levels": levels, "distances": distances, "mesh": [p.T / K for K in levels],
               "differences": diffs, "ratios": ratios, "tails": tails, "criterion": "Cauchy with own-trend tail"}
    pair = info["pair"] if info else list(tails)[:2]
    worst = D / (tails[pair[0]] + tails[pair[1]] + tol) if not not_cauchy else max(ratios.values())
    if gap <= tol and not not_cauchy:
        return CheckResult("unique_limit", subject, PASSED, worst=worst if gap > 0 else min(worst, 1.0),
                           bound=1.0, details=details, duration=time.perf_counter() - start,
                           message=f"distance between partitions {distances[0]:.3g} -> {D:.3g}, within the "
                                   f"estimated distances to their limits {tails[info['pair'][0]]:.3g} + "
                                   f"{tails[info['pair'][1]]:.3g} (last ratios "
                                   f"{', '.join(f'{k} {r:.3g}' for k, r in ratios.items())}; no rate assumed)"
                           if info else f"distance between partitions {D:.3g}")
    counter = {"problem": problem.name, "T": p.T, "x0": p.x0, "levels": levels, "seed": seed,
               "distances": distances, "grid_kinds": list(runs[0][0]), "tails": tails, **(info or {})}
    if not_cauchy:
        msg = (f"no limit: on {', '.join(not_cauchy)} partitions the differences between successive refinements "
               f"do not shrink ({'; '.join(f'{k}: ' + ', '.join(f'{c:.3g}' for c in diffs[k]) for k in not_cauchy)}"
               f" for K = {levels})")
    else:
        msg = (f"solutions on different partitions converge to different limits: {info['pair'][0]} and "
               f"{info['pair'][1]} are {D:.3g} apart at K = {levels[-1]} (t = {info['tau']:.4g}) while each is "
               f"within {tails[info['pair'][0]]:.3g} and {tails[info['pair'][1]]:.3g} of its own limit "
               f"(distances {', '.join(f'{d:.3g}' for d in distances)} for K = {levels})")
    return CheckResult("unique_limit", subject, FAILED, worst=max(worst, 1.0 + 1e-12) if np.isfinite(worst) else worst,
                       bound=1.0, counterexample=counter, details=details, duration=time.perf_counter() - start,
                       message=msg)


# -- domain -----------------------------------------------------------------------------------------

@stepper_law("in_domain", "e:x k+1 props.1", Member("project_domain"))
def check_in_domain(stepper: Callable, problem: Problem, *, grids: Any = None, seed: int = 0) -> CheckResult:
    """``x_k ∈ cl dom F(t_k,·)`` for every node (``e:x k+1 props.1``; from ``k = 1`` after a jump).

    That is a property of the proximal scheme's iterates (``x_k = J(...)`` lies in ``dom F(t_k)``).  A
    stepper claiming only ``scheme="any"`` with order ``p`` is held to what every convergent scheme
    obeys instead — ``dist(x_k, cl dom F(t_k)) ≤ |x_k - x(t_k)|`` vanishes at order ``p``
    (:func:`check_domain_vanishing`)."""
    claim = claim_of(stepper)
    if not claim.proximal and grids is None:
        return check_domain_vanishing(stepper, problem, claim.order, seed=seed)
    grids = _as_grids(grids, problem, seed)

    def evaluate(p: Problem, t: np.ndarray) -> Outcome:
        x = run_stepper(stepper, p, t)
        first = 1 if p.initial_jump else 0
        ratios = np.zeros(len(t))
        dists = np.zeros(len(t))
        for k in range(first, len(t)):
            q = np.asarray(p.operator.project_domain(x[k], float(t[k])), dtype=float)
            dists[k] = float(np.linalg.norm(q - x[k]))
            ratios[k] = dists[k] / tolerance(x[k], q)
        bad = np.flatnonzero(ratios > 1.0)
        k = int(bad[0]) if bad.size else int(np.argmax(ratios))
        counter = {"k": k, "t_k": t[k], "x_k": x[k], "distance": dists[k],
                   "projection": p.operator.project_domain(x[k], float(t[k])),
                   "message": f"x_k = {np.array2string(x[k], precision=6)} is at distance {dists[k]:.3g} "
                              f"from cl dom F(t_k) at k = {k}, t_k = {t[k]:.6g}"}
        return Outcome(float(np.max(ratios)), k, counter, {"max_distance": float(np.max(dists))})

    return _drive("in_domain", stepper, problem, grids, evaluate, message_ok="x_k in cl dom F(t_k) at every node")


def _domain_distances(stepper: Callable, p: Problem, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(x, dist(x_k, cl dom F(t_k)))`` along ``stepper``'s solution on ``t`` (0 at ``k = 0`` after a jump)."""
    x = run_stepper(stepper, p, t)
    d = np.zeros(len(t))
    for k in range(1 if p.initial_jump else 0, len(t)):
        d[k] = float(np.linalg.norm(np.asarray(p.operator.project_domain(x[k], float(t[k])), dtype=float) - x[k]))
    return x, d


def check_domain_vanishing(stepper: Callable, problem: Problem, order: float, *,
                           levels: Sequence[int] = LIMIT_LEVELS, seed: int = 0) -> CheckResult:
    """``D(K) = max_k dist(x_k, cl dom F(t_k))`` on uniform partitions with ``K`` cells vanishes at order
    ``p = min(order, the order the problem's regularity allows)``: every convergent scheme has
    ``dist(x_k, cl dom F(t_k)) ≤ |x_k - x(t_k)| = O(h^p)`` since ``x(t_k) ∈ cl dom F(t_k)``.

    Law: ``D(K_m) ≤ DOMAIN_ORDER_SLACK · max_{j<m} D(K_j) (K_j/K_m)^p + tol`` at the finest level
    (the constant of ``C h^p`` is not known; the slack absorbs its drift between levels).
    """
    p = _single(problem)
    target = p.order.for_claim(order).value if p.order is not None else float(order)
    D, where = [], []
    for K in levels:
        t = uniform_grid(p.T, steps=K)
        x, d = _domain_distances(stepper, p, t)
        k = int(np.argmax(d))
        D.append(float(d[k]))
        where.append({"K": K, "k": k, "t_k": t[k], "x_k": x[k]})
    scale = max(1.0, float(np.max(np.abs(p.x0))))
    rhs = DOMAIN_ORDER_SLACK * max(D[j] * (levels[j] / levels[-1]) ** target for j in range(len(levels) - 1))
    out = Outcome(D[-1] / (rhs + tolerance(scale)),
                  counter={"problem": p.name, "T": p.T, "x0": p.x0, "levels": list(levels), "distances": D,
                           "order": target, **where[-1],
                           "message": f"dist(x_k, cl dom F(t_k)) does not vanish at order {target:g}: "
                                      f"{', '.join(f'{d:.3g}' for d in D)} for K = {list(levels)}"},
                  details={"levels": list(levels), "distances": D, "order": target, "claim": "any"})
    return record("in_domain", f"{_name(stepper)} on {problem.name}", out,
                  passed=f"dist(x_k, cl dom F(t_k)) {D[0]:.3g} -> {D[-1]:.3g} as K = {levels[0]} -> {levels[-1]} "
                         f"(order {target:g} claimed; scheme='any')")


# -- a-priori bounds --------------------------------------------------------------------------------

_FULL_DOMAIN = (Linear, NormSubdifferential, L1Subdifferential)


def _phi_of(problem: Problem) -> tuple[Callable[[float], float], str]:
    """φ of (A3): the problem's, or ``φ ≡ 0`` when ``dom F(t,·)`` cannot move (static or all of R^n)."""
    if problem.phi is not None:
        return problem.phi, "stated"
    op = problem.operator
    if isinstance(op, _FULL_DOMAIN) or getattr(op, "static", False):
        return (lambda t: 0.0), "derived: dom F(t) does not move"
    raise _Skip("the problem states no φ of (A3) and the domain of F may move")


def _sigma_of(problem: Problem) -> tuple[Callable[[float], float], str]:
    """σ of (LG): the problem's, or derived from the catalog operator — ``N_S``: ``F^0 = 0``, ``σ ≡ 0``;
    ``Linear``: ``|M(t)x| ≤ ‖M(t)‖₂|x|``; ``∂(c|·|)``, ``∂(Σc_i|x_i|)``: ``|F^0(t,x)| ≤ |F^0(t, 1)|``."""
    if problem.sigma is not None:
        return problem.sigma, "stated"
    op = problem.operator
    if isinstance(op, NormalCone):
        return (lambda t: 0.0), "derived: F^0 = 0 for a normal cone"
    if isinstance(op, Linear):
        return (lambda t: float(np.linalg.norm(op.M(t), 2))), "derived: ||M(t)||_2"
    if isinstance(op, (NormSubdifferential, L1Subdifferential)):
        one = np.ones(op.dim)
        return (lambda t: float(np.linalg.norm(op.min_norm(one, t)))), "derived: |F^0(t, 1)| = |c(t)|"
    raise _Skip("the problem states no σ of (LG)")


def _theta_of(problem: Problem) -> tuple[Callable[[float], float], str]:
    """θ of (YB): the problem's, or ``θ ≡ 0`` for a static operator (Prop. ``prop:maxmon-resolvent-Yosida``
    vi: ``|Y_λ x| ≤ |F^0(x)|``; the paper's remark after Theorem ``thm:main``)."""
    if problem.theta is not None:
        return problem.theta, "stated"
    if getattr(problem.operator, "static", False):
        return (lambda t: 0.0), "derived: static operator, theta constant"
    raise _Skip("the problem states no θ of (YB)")


class LGBounds:
    """β, γ and ψ of lemma ``lem:bndSeq`` (``e:only beta``, ``eq:defPsi``, ``e:alpha and r alpha``,
    ``e:gamma and r gamma``) for ``|x0|``, ``φ`` and ``σ`` on ``[0, T]``.

    With an input (lemma ``l:extinput``) pass ``absu = |u|``: then ``φ̄ = φ + ∫_0^t |u|`` and
    ``σ̄ = σ (1 + ∫_0^T |u|)`` are used.
    """

    def __init__(self, x0_norm: float, phi: Callable, sigma: Callable, T: float,
                 absu: Callable | None = None, grid: np.ndarray | None = None) -> None:
        self.phi0, self.sigma0, self.T, self.absu = phi, sigma, T, absu
        self.grid = None if grid is None else np.asarray(grid, dtype=float)
        if self.grid is not None:
            # the proof uses (LG) only at the nodes, |F^0(t_k, ξ)| ≤ σ(t_k)(1 + |ξ|): on this partition ∫σ
            # becomes the right Riemann sum Σ h_k σ(t_k) (exact for σ piecewise constant on the cells; the
            # paper reaches ∫σ only along specially chosen partitions, via Lakshmikantham–Leela 3.3.1)
            h = np.diff(self.grid)
            self._sigma_nodes = np.concatenate([[0.0], np.cumsum(h * _vals(sigma, self.grid[1:]))])
        self.u_total = 0.0 if absu is None else integrate.quad(absu, 0.0, T, limit=200)[0]
        dphi = float(phi(T)) - float(phi(0.0))
        if dphi < -tolerance(phi(T), phi(0.0)):
            raise _Skip(f"φ must be nondecreasing; φ(T) - φ(0) = {dphi:.3g}")
        dphi += self.u_total
        int_sigma = (1.0 + self.u_total) * float(self._sigma_cumulative(np.array([0.0, T]))[-1])
        self.alpha = x0_norm + dphi
        self.beta = self.alpha + dphi + (1.0 + self.alpha) * int_sigma
        self.gamma = self.beta + dphi

    def _sigma_cumulative(self, pts: np.ndarray) -> np.ndarray:
        """``∫_0^s σ`` at the increasing ``pts`` (from 0), or its Riemann-sum version on the partition."""
        if self.grid is None:
            return _cumulative(self.sigma0, pts)
        return np.interp(pts, self.grid, self._sigma_nodes)

    def psi_nodes(self, t: np.ndarray) -> np.ndarray:
        """``ψ`` at the increasing points ``t`` (``t_0 = 0`` or not)."""
        t = np.asarray(t, dtype=float)
        pts = np.concatenate([[0.0], t]) if t[0] > 0 else t
        phi = _vals(self.phi0, pts)
        if self.absu is not None:
            phi = phi + _cumulative(self.absu, pts)
        out = pts + 2.0 * phi + (1.0 + self.gamma) * (1.0 + self.u_total) * self._sigma_cumulative(pts)
        return out[1:] if t[0] > 0 else out

    def psi_function(self, points: np.ndarray) -> Callable[[float], float]:
        """``ψ`` tabulated at ``points`` (exact there), for :meth:`Trajectory.interpolate`."""
        pts = np.unique(np.asarray(points, dtype=float))
        table = dict(zip(pts.tolist(), self.psi_nodes(pts).tolist()))
        return lambda s: table[float(s)] if float(s) in table else float(self.psi_nodes(np.array([s]))[-1])

    def constants(self) -> dict:
        return {"alpha": self.alpha, "beta": self.beta, "gamma": self.gamma}


class YBBounds:
    """β and ψ of lemma ``lem:bndSeqYB``: ``α = 2(θ(T) - θ(0)) + |F^0(0, x0)|``, ``β = |x0| + αT``,
    ``ψ(t) = αt`` (``eq:betaYB``, ``eq:defPsiYB``)."""

    def __init__(self, x0: np.ndarray, theta: Callable, op: Operator, T: float) -> None:
        try:
            f0 = float(np.linalg.norm(op.min_norm(x0, 0.0)))
        except OutsideDomain:
            raise _Skip("x0 is not in dom F(0,·) (lem:bndSeqYB needs |F^0(0, x0)|)") from None
        if not np.isfinite(f0):   # x0 within rounding of the boundary: F^0 overflows (c/x at x = 7e-304)
            raise _Skip(f"|F^0(0, x0)| = {f0} is not finite: x0 is at the edge of dom F(0,·), where "
                        "lem:bndSeqYB's α is infinite and its bounds say nothing")
        self.alpha = 2.0 * (float(theta(T)) - float(theta(0.0))) + f0
        self.beta = float(np.linalg.norm(x0)) + self.alpha * T
        self.f0 = f0

    def psi_nodes(self, t: np.ndarray) -> np.ndarray:
        return self.alpha * np.asarray(t, dtype=float)

    def psi_function(self, points: np.ndarray) -> Callable[[float], float]:
        return lambda s: self.alpha * float(s)

    def constants(self) -> dict:
        return {"alpha": self.alpha, "beta": self.beta, "F0_at_x0": self.f0}


def _lg_requirements(p: Problem) -> None:
    """What lem:bndSeq assumes of the problem (raises :class:`NotApplicable` with the reason)."""
    if p.initial_jump:
        raise _Skip("x0 is outside cl dom F(0,·) (catching-up jump): lem:bndSeq assumes x0 in the closure")
    if p.f is not None:
        raise _Skip("the bounds of the Lipschitz-perturbation theorem involve a constant C_1 that is not "
                    "explicit; lem:bndSeq covers f = 0")
    _phi_of(p), _sigma_of(p)
    if p.u is None and p.U is not None:
        raise _Skip("an input given only by its primitive U: ∫|u| is not available")


def _yb_requirements(p: Problem) -> None:
    """What lem:bndSeqYB assumes of the problem (raises :class:`NotApplicable` with the reason)."""
    if p.initial_jump:
        raise _Skip("x0 is outside dom F(0,·) (catching-up jump): lem:bndSeqYB assumes x0 in dom F(0,·)")
    if p.f is not None:
        raise _Skip("lem:bndSeqYB covers f = 0 (the Lipschitz theorem's constants are not explicit)")
    if p.u is not None or p.U is not None:
        raise _Skip("with an input, lem:bndSeqYB would apply to G(t, ξ) = F(t, ξ + Φ(t)) (l:extinput), but (YB) "
                    "does not pass from F to G: t:non-auto's θ̄ = M_u + θ has the increments of θ (the constant "
                    "cancels) while the defect |Φ(s+λ) − Φ(s)|/λ ≈ |u(s)| stays as λ → 0 (F = ∂|x|, u = 1: G "
                    "fails (YB) for every θ)")
    _theta_of(p)


def _lg_setup(p: Problem, t: np.ndarray):
    """Bounds of lem:bndSeq and the sequence they bound (``ξ_k = x_k - Φ(t_k)`` with an input)."""
    _lg_requirements(p)
    (phi, phi_src), (sigma, sigma_src) = _phi_of(p), _sigma_of(p)
    shift = np.zeros((len(t), p.dim))
    extra = {"phi": phi_src, "sigma": sigma_src}
    absu = None
    if p.u is not None or p.U is not None:
        # lemma l:extinput: ξ = x - Φ solves the scheme of G(t, ξ) = F(t, ξ + Φ(t)), which satisfies (A3)
        # with φ̄ = φ + ∫|u| and (LG) with σ (1 + |Φ|) ≤ σ (1 + ∫_0^T |u|)
        if p.u is None:
            raise _Skip("an input given only by its primitive U: ∫|u| is not available")
        shift = np.concatenate([np.zeros((1, p.dim)), np.cumsum(p.input_increments(t), axis=0)])
        absu = lambda s: float(np.linalg.norm(p.u(s)))  # noqa: E731
        extra["via"] = "l:extinput (xi_k = x_k - Phi(t_k))"
    return LGBounds(float(np.linalg.norm(p.x0)), phi, sigma, p.T, absu, grid=t), shift, extra


def _yb_setup(p: Problem, t: np.ndarray):
    _yb_requirements(p)
    theta, src = _theta_of(p)
    return YBBounds(p.x0, theta, p.operator, p.T), np.zeros((len(t), p.dim)), {"theta": src}


def _bounds_evaluate(stepper: Callable, setup: Callable, label: str):
    def evaluate(p: Problem, t: np.ndarray) -> Outcome:
        bounds, shift, extra = setup(p, t)
        x = run_stepper(stepper, p, t)
        xi = x - shift
        psi = bounds.psi_nodes(t)
        nx = _norms(xi)
        steps = _norms(np.diff(xi, axis=0))
        dpsi = np.diff(psi)
        r_beta = nx / (bounds.beta + tolerance(bounds.beta, nx))
        r_step = steps / (dpsi + tolerance(xi, psi))
        ratios = np.maximum(r_beta[1:], r_step)
        bad = np.flatnonzero(ratios > 1.0)
        k = int(bad[0]) + 1 if bad.size else int(np.argmax(ratios)) + 1
        which = "|x_k| <= beta" if r_beta[k] >= r_step[k - 1] else "|x_k - x_(k-1)| <= psi(t_k) - psi(t_(k-1))"
        counter = {"k": k, "t_k": t[k], "x_k": xi[k], "x_k_minus_1": xi[k - 1], "bound": which,
                   "norm_x_k": nx[k], "step": steps[k - 1], "psi_increment": dpsi[k - 1], **bounds.constants(),
                   **extra,
                   "message": f"{label}: {which} fails at k = {k}, t_k = {t[k]:.6g}: |x_k| = {nx[k]:.6g}, "
                              f"beta = {bounds.beta:.6g}, |x_k - x_(k-1)| = {steps[k - 1]:.6g}, "
                              f"psi increment = {dpsi[k - 1]:.6g}"}
        details = {**bounds.constants(), **extra, "max_ratio_beta": float(np.max(r_beta)),
                   "max_ratio_psi": float(np.max(r_step))}
        return Outcome(float(np.max(ratios)), k, counter, details)
    return evaluate


@stepper_law("bounds_lg", "lem:bndSeq", PROXIMAL_CLAIM, _holds(_lg_requirements))
def check_bounds_lg(stepper: Callable, problem: Problem, *, grids: Any = None, seed: int = 0) -> CheckResult:
    """Lemma ``lem:bndSeq`` (under (A3), (LG)): ``|x_k| ≤ β``, ``|x_k - x_{k-1}| ≤ ψ(t_k) - ψ(t_{k-1})``.

    ``β = α + φ(T) - φ(0) + (1 + α)∫_0^T σ``, ``ψ(t) = t + 2φ(t) + (1 + γ)∫_0^t σ``, ``α = |x0| + φ(T) -
    φ(0)``, ``γ = β + φ(T) - φ(0)``.  For non-constant σ the lemma holds on fine enough partitions (the
    proof's piecewise-constant approximation); the default partitions have 40 cells.

    Claim: ``proximal`` — the lemma bounds the iterates of the paper's scheme on the given partition.
    """
    return _drive("bounds_lg", stepper, problem, _as_grids(grids, problem, seed),
                  _bounds_evaluate(stepper, _lg_setup, "lem:bndSeq"),
                  message_ok="|x_k| <= beta and |x_k - x_(k-1)| <= psi(t_k) - psi(t_(k-1)) (lem:bndSeq)")


@stepper_law("bounds_yb", "lem:bndSeqYB", PROXIMAL_CLAIM, _holds(_yb_requirements))
def check_bounds_yb(stepper: Callable, problem: Problem, *, grids: Any = None, seed: int = 0) -> CheckResult:
    """Lemma ``lem:bndSeqYB`` (under (YB), ``|Δ| < Λ``): ``|x_k| ≤ |x0| + αT`` and
    ``|x_k - x_{k-1}| ≤ α h_k`` with ``α = 2(θ(T) - θ(0)) + |F^0(0, x0)|``.

    Claim: ``proximal`` — the lemma bounds the iterates of the paper's scheme on the given partition."""
    return _drive("bounds_yb", stepper, problem, _as_grids(grids, problem, seed),
                  _bounds_evaluate(stepper, _yb_setup, "lem:bndSeqYB"),
                  message_ok="|x_k| <= |x0| + alpha T and |x_k - x_(k-1)| <= alpha h_k (lem:bndSeqYB)")


# -- ψ-interpolation --------------------------------------------------------------------------------

@stepper_law("psi_interpolation", "lem:bndEquiCont", PROXIMAL_CLAIM, _either(_lg_requirements, _yb_requirements))
def check_psi_interpolation(stepper: Callable, problem: Problem, *, grids: Any = None, seed: int = 0,
                            samples: int = 40) -> CheckResult:
    """Lemma ``lem:bndEquiCont``: ``|x_Δ(τ̄) - x_Δ(τ)| ≤ ψ(τ̄) - ψ(τ)`` for the ψ-interpolant ``e:x delta``.

    ``ψ`` from lem:bndSeq and/or lem:bndSeqYB (whichever applies); ``x_Δ`` from
    :meth:`verimono.Trajectory.interpolate` with ``kind="psi"``; all pairs among the nodes, cell
    midpoints and ``samples`` random times.

    Claim: ``proximal`` — ``x_Δ`` interpolates the proximal iterates with the ψ of their lemmas.
    """
    grids = _as_grids(grids, problem, seed)

    def evaluate(p: Problem, t: np.ndarray) -> Outcome:
        setups = []
        reasons = []
        for label, setup in (("lem:bndSeq", _lg_setup), ("lem:bndSeqYB", _yb_setup)):
            try:
                setups.append((label,) + setup(p, t))
            except _Skip as exc:
                reasons.append(f"{label}: {exc}")
        setups = [s for s in setups if not (isinstance(s[1], YBBounds) and s[1].alpha <= 0.0)]
        if not setups:
            raise _Skip("no ψ available — " + "; ".join(reasons) if reasons else "ψ ≡ 0 (α = 0)")
        x = run_stepper(stepper, p, t)
        rng = np.random.default_rng(seed)
        tau = np.unique(np.concatenate([t, 0.5 * (t[:-1] + t[1:]), rng.uniform(0.0, p.T, samples)]))
        worst, best, det = -np.inf, None, {}
        for label, bounds, shift, extra in setups:
            traj = Trajectory(t, x - shift, None)
            psi = bounds.psi_function(np.union1d(t, tau))
            X = traj.interpolate(tau, kind="psi", psi=psi)
            P = np.array([psi(s) for s in tau])
            i, j = np.triu_indices(len(tau), 1)
            lhs = _norms(X[j] - X[i])
            rhs = P[j] - P[i]
            ratio = lhs / (rhs + tolerance(X, P))
            m = int(np.argmax(ratio))
            det[label] = float(ratio[m])
            if ratio[m] > worst:
                worst = float(ratio[m])
                k = int(np.searchsorted(t, tau[j[m]], side="left"))
                best = {"k": max(1, min(k, len(t) - 1)), "lemma": label, "tau_low": tau[i[m]],
                        "tau_high": tau[j[m]], "x_low": X[i[m]], "x_high": X[j[m]], "lhs": lhs[m], "rhs": rhs[m],
                        **bounds.constants(),
                        "message": f"{label}/lem:bndEquiCont: |x_D(tau') - x_D(tau)| = {lhs[m]:.6g} > "
                                   f"psi(tau') - psi(tau) = {rhs[m]:.6g} for tau = {tau[i[m]]:.6g}, "
                                   f"tau' = {tau[j[m]]:.6g}"}
        return Outcome(worst, best["k"], best, {"worst_by_lemma": det, "pairs": len(tau) * (len(tau) - 1) // 2})

    return _drive("psi_interpolation", stepper, problem, grids, evaluate,
                  message_ok="|x_D(tau') - x_D(tau)| <= psi(tau') - psi(tau) (lem:bndEquiCont)")


# -- selections -------------------------------------------------------------------------------------

@stepper_law("selections", "eq:iteration", PROXIMAL_CLAIM)
def check_selections(stepper: Callable, problem: Problem, *, grids: Any = None, seed: int = 0) -> CheckResult:
    """``y_{k+1} = (z_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})`` (``eq:iteration``), ``z_k = x_k + h f(x_k)
    + ∫u``: through ``operator.contains`` and through ``J_μ(x_{k+1} + μ y_{k+1}) = x_{k+1}`` at ``μ = h/2``.

    Tolerance: :func:`verimono.tolerances.quotient_tolerance` (a difference quotient divides the
    round-off of the states by ``h``).

    Claim: ``proximal`` — the discrete velocities of the paper's scheme are selections; another scheme's
    (the midpoint rule, the exact solution sampled) are not, and need not be.
    """
    grids = _as_grids(grids, problem, seed)
    has_contains = type(problem.operator).contains is not Operator.contains

    def evaluate(p: Problem, t: np.ndarray) -> Outcome:
        x = run_stepper(stepper, p, t)
        y = Trajectory(t, x, p).selections
        h = np.diff(t)
        op = p.operator
        ratios = np.zeros(len(h))
        member = np.ones(len(h), dtype=bool)
        contains_available = True
        for k in range(len(h)):
            xk1, yk, tk1 = x[k + 1], y[k], float(t[k + 1])
            mu = 0.5 * h[k]
            back = np.asarray(op.resolvent(xk1 + mu * yk, mu, tk1), dtype=float)
            ratios[k] = float(np.linalg.norm(back - xk1)) / tolerance(xk1, mu * yk, x[k])
            if contains_available:
                try:
                    member[k] = op.contains(xk1, yk, tk1, tol=quotient_tolerance(h[k], x[k], xk1, h[k] * yk))
                except NotImplementedError:
                    contains_available = False
        worst = float(np.max(ratios))
        if contains_available and not member.all():
            worst = max(worst, 1.0 + float(np.sum(~member)))   # membership is boolean: count the misses
        bad = np.flatnonzero((ratios > 1.0) | ~member)
        k = int(bad[0]) if bad.size else int(np.argmax(ratios))
        counter = {"k": k + 1, "t_k": t[k + 1], "x_k": x[k], "x_k_plus_1": x[k + 1], "h": h[k], "selection": y[k],
                   "contains": bool(member[k]), "resolvent_residual_ratio": ratios[k],
                   "message": f"y = (x_k - x_(k+1))/h = {np.array2string(y[k], precision=6)} is not in "
                              f"F(t_(k+1), x_(k+1)) at k+1 = {k + 1}, t = {t[k + 1]:.6g} "
                              f"(contains: {bool(member[k])}, |J(x + mu y) - x|/tol = {ratios[k]:.3g})"}
        return Outcome(worst, k + 1, counter, {"contains_used": contains_available,
                                                "misses": int(np.sum(~member))})

    return _drive("selections", stepper, problem, grids, evaluate,
                  message_ok="(x_k - x_(k+1))/h in F(t_(k+1), x_(k+1)) at every step"
                             + ("" if has_contains else " (resolvent characterisation only: no contains)"))


# -- registry ---------------------------------------------------------------------------------------

#: the trajectory laws' names, in the order they run
LAWS = tuple(CHECKS)


def reproduce(stepper: Callable, problem: Problem, record: CheckResult) -> CheckResult:
    """Re-run the law of ``record`` on exactly the inputs of its counterexample."""
    cx = record.counterexample or {}
    law = CHECKS[record.check]
    if record.check == "unique_limit":
        return law(stepper, problem, levels=cx["levels"], seed=cx["seed"])
    p = _single(problem).replace(T=float(cx["T"]))
    kw: dict[str, Any] = {"grids": [np.asarray(cx["grid"], dtype=float)]}
    if "x0_prime" in cx:
        kw["x0_primes"] = [np.asarray(cx["x0_prime"], dtype=float)]
    return law(stepper, p, **kw)


def law_checks(problems: Iterable[Problem], laws: Sequence[str] = LAWS, seed: int = 0
               ) -> Iterator[tuple[str, Callable[[Callable], CheckResult]]]:
    """``(name, check)`` pairs: ``name = "<law>[<problem>]"``, ``check(stepper) -> CheckResult``."""
    for p in problems:
        for law in laws:
            fn = CHECKS[law]
            yield f"{law}[{p.name}]", (lambda stepper, _fn=fn, _p=p: _fn(stepper, _p, seed=seed))


def stepper_checks(stepper: Callable | None = None, problems: Iterable[Problem] | None = None, *,
                   seed: int = 0, generated: int = 4, laws: Sequence[str] = LAWS, orders: bool = True,
                   executor: Any = None) -> Iterator[tuple[str, Callable[[Callable], CheckResult]]]:
    """The battery of a stepper, as ``(name, check)`` pairs — one source for
    :func:`verimono.check_stepper` and :func:`verimono.testing.parametrize_with_checks`.

    ``problems=None``: the reference catalog (convergence orders and laws) plus ``generated`` sampled
    problems (:func:`verimono.checks.sample_problems.sample_problems`, laws only).  ``stepper`` is unused
    (the battery does not depend on it); it is accepted for the protocol ``stepper_checks(stepper)``.
    """
    if problems is None:
        from verimono.reference import catalog

        from .sample_problems import sample_problems

        refs = catalog()
        extra = sample_problems(seed, generated)
    else:
        refs, extra = list(problems), []
    if orders:
        for p in refs:
            yield (f"convergence_order[{p.name}]",
                   lambda s, _p=p: check_convergence_order(s, _p, executor=executor))
    yield from law_checks(list(refs) + list(extra), laws, seed)


def check_stepper(stepper: Callable, problems: Iterable[Problem] | None = None, *, scheme: str | None = None,
                  order: float | None = None, seed: int | None = None, executor=None,
                  laws: bool | Iterable[str] = True, generated: int = 4, orders: bool = True) -> Report:
    """Result records for ``stepper``: convergence orders on the references, then the trajectory laws.

    ``scheme``/``order`` state what the stepper claims (:class:`verimono.Stepper`; a bare callable
    claims ``scheme="proximal"``, the paper's scheme): a law that needs more than the claim is skipped
    with that reason, and ``convergence_order``/``in_domain`` hold an ``"any"`` scheme to its order.

    ``problems=None`` means the whole catalog of :mod:`verimono.reference` (orders and laws) plus
    ``generated`` seeded sample problems (laws only).  The records come first per problem for the
    convergence orders (in the order of ``problems``), then one record per (problem, law) of
    :mod:`verimono.checks.trajectory_laws`; ``laws=False`` keeps the orders only, a list of law names
    selects laws, ``orders=False`` keeps the laws only.  The records are those of :func:`stepper_checks`, the
    same generator :func:`verimono.testing.parametrize_with_checks` turns into pytest cases.
    """
    if problems is not None:
        problems = list(problems)
        if not problems:
            raise InvalidCheckArgument("check_stepper was given an empty list of problems: it would verify "
                                       "nothing (pass problems=None for the whole catalog)")
    stepper = with_claim(stepper, scheme, order)
    seed = 0 if seed is None else int(seed)
    selected = () if laws is False else (LAWS if laws is True else tuple(laws))
    report = Report()
    for _name_, check in stepper_checks(stepper, problems, seed=seed, generated=generated, laws=selected,
                                        orders=orders, executor=executor):
        law, _, problem_name = _name_.partition("[")
        # a stepper that never returns: a failed record naming the unit, and the battery goes on
        rec = run_unit(lambda: check(stepper), check=law,
                       subject=f"{_stepper_name(stepper)} on {problem_name[:-1]}")
        report.add(rec)
        if rec.study is not None:
            report.studies.append(rec.study)
    if not len(report):
        raise InvalidCheckArgument("check_stepper selected no check (no law, no order): it would verify nothing")
    return report


def _stepper_name(stepper: Any) -> str:
    return _convergence_name(stepper)


__all__ = ["LAWS", "CHECKS", "check_contraction", "check_unique_limit", "check_in_domain", "check_domain_vanishing",
           "stepper_law", "check_bounds_lg", "check_bounds_yb", "check_psi_interpolation", "check_selections",
           "stepper_checks", "check_stepper", "law_checks", "reproduce", "run_stepper", "with_changes",
           "perturbed_starts", "default_grids", "limit_grids", "LGBounds", "YBBounds"]
