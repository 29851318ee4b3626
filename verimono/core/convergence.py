"""Convergence studies: errors on a sequence of grids and least-squares order estimates.

For each grid the study records three errors against the exact solution (or, when the problem has
none, against a fine-grid solution of the same stepper, which the result says):

* ``sup``:   ``max_k |x_k - x(t_k)|`` (the norm of the paper's uniform convergence),
* ``l2``:    ``(Σ_k h_k |x_k - x(t_k)|²)^{1/2}`` (discrete L2 in time),
* ``final``: ``|x_K - x(T)|``.

The order in each norm is the slope of ``log e`` against ``log |Δ|`` (``|Δ| = max_k h_k``) by least
squares — valid for any step ratio — with a 95% Student-t confidence interval.  Errors at the floor of a
grid are dropped; if every error is there the scheme is exact on the grids.  The floor is round-off,
``ROUNDOFF_FACTOR · ε · scale`` (in the precision the stepper computes in, :func:`verimono.core.tolerances.roundoff_floor`), plus — for a stepper that states the accuracy ``τ`` of its inner solve
(``Stepper(..., solve_tol=τ)``) — what ``K`` inexact steps of a nonexpansive scheme can accumulate,
``K τ (1 + scale)`` (:func:`solve_floor`).

*Pre-asymptotic* and *stalled* are told apart by the local slopes (the slopes between successive grids,
coarse to fine):

* **pre-asymptotic** — the local slopes spread by more than ``ASYMPTOTIC_SPREAD``: the data have not
  reached the regime ``e ≈ C h^p`` yet; said in the verdict, which is still that of the fit's interval;
* **stalled** — the errors stop falling far above the floor: over the last two refinements they fall by
  less than a quarter of the expected order, ``e_K / e_{K-2} > (h_K / h_{K-2})^{p/4}``, while
  ``e_K > STALL_MARGIN`` times the floor.  A stall fails, whatever the fit's interval says (a stepper that
  answers the finest grids with a coarser solve has a wide interval that still reaches ``p``), and is never
  called pre-asymptotic.

Performance: the grids run as independent jobs, in parallel through any ``concurrent.futures.Executor``
(``executor=``; a ``dask.distributed`` client's ``get_executor()`` works the same), or a process pool
chosen automatically for large studies.  When the problem has an exact solution each job returns only
its three errors: with :func:`verimono.solve` as the stepper the states stream through an
:class:`ErrorAccumulator` block by block (:func:`verimono.core.stepping.stream`), so no job holds a
trajectory at all; any other stepper's trajectory is held by its job only while its errors are computed.
Without an exact solution the fine reference runs first and returns only its values at the studied
grids' nodes (streamed through a :class:`Sampler` for :func:`verimono.solve`); each grid's job then
accumulates its errors against its share of them, so neither the fine trajectory nor any grid's
trajectory reaches the caller.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import pickle
import sys
import time
from typing import Any, Callable, Sequence

import numpy as np

from ._jsonable import to_jsonable
from .display import render
from ._validate import real_array
from .errors import InvalidProblem
from .grids import uniform_grid, validate_grid
from .naming import subject_name
from .problem import Order, Problem
from .stepping import solve, stream
from .arrays import as_float64
from .tolerances import ROUNDOFF_STEPS, coarser, judged_precision, observe, roundoff_floor

NORMS = ("sup", "l2", "final")
#: errors below ROUNDOFF_FACTOR * eps * (1 + max|x|) are round-off (≈ 2e-12 for unit-size states):
#: a K-step scheme accumulates O(K eps) rounding, and K ≤ 1e4 in the catalog's studies.  A stepper computing
#: in a coarser precision (observed from its states) gets that precision's floor,
#: :func:`verimono.core.tolerances.roundoff_floor` (float32: 1.2e-5)
ROUNDOFF_FACTOR = ROUNDOFF_STEPS
#: local slopes that spread by more than this are not yet in the asymptotic regime
ASYMPTOTIC_SPREAD = 0.25
#: an order estimate "reaches" p when its interval's upper end is within this of p; the slack absorbs
#: the O(h) drift of the slope of C h^p (1 + O(h)) over the studied range
ORDER_SLACK = 0.1
#: a stall is judged only on errors this many times above their floor (closer to it, rounding and an
#: inner solve's tolerance flatten any scheme's errors)
STALL_MARGIN = 100.0
#: over the last two refinements the errors of an order-p scheme fall like (h_K/h_{K-2})^p; falling by less
#: than (h_K/h_{K-2})^{p·STALL_FRACTION} is a stall.  A quarter of the order leaves room for data still
#: pre-asymptotic: measured under verimono.solve, every catalog study falls within 1% of (h_K/h_{K-2})^p there
STALL_FRACTION = 0.25


def solve_floor(steps: int, solve_tol: float, scale: float) -> float:
    """What ``steps`` inner solves of accuracy ``solve_tol`` (relative to ``1 + scale``) can add to the error
    of a nonexpansive scheme: each step's error passes through later steps without growing (the
    resolvent is nonexpansive, Proposition ``prop:maxmon-resolvent-Yosida`` ii), so they add up."""
    return float(steps) * float(solve_tol) * (1.0 + float(scale))


@dataclasses.dataclass
class OrderFit:
    """Least-squares slope of ``log e`` vs ``log h`` with its 95% interval (``nan`` with < 3 points)."""

    slope: float
    low: float
    high: float
    used: list[int]
    dropped: list[int]
    local_slopes: list[float]
    pre_asymptotic: bool
    exact: bool = False
    #: indices of the grids whose error is not a finite number (a failed study, never "exact")
    nonfinite: list[int] = dataclasses.field(default_factory=list)

    def contains(self, p: float, slack: float = ORDER_SLACK) -> bool:
        return self.low - slack <= p <= self.high + slack

    def reaches(self, p: float, slack: float = ORDER_SLACK) -> bool:
        return self.high + slack >= p

    def __str__(self) -> str:
        if self.nonfinite:
            return "undefined (non-finite errors)"
        if self.exact:
            return "exact (round-off)"
        if math.isnan(self.low):
            return f"{self.slope:.3f}"
        return f"{self.slope:.3f} [{self.low:.3f}, {self.high:.3f}]"


def fit_order(h: Sequence[float], e: Sequence[float], floor: float | Sequence[float] = 0.0) -> OrderFit:
    """Fit ``e ≈ C h^p`` on the points above ``floor`` (one floor, or one per grid; see the module docstring).

    A non-finite error (``nan``/``inf``: a stepper that diverged or returned garbage) is never "below the
    floor": the fit is then ``nan`` with ``nonfinite`` listing the offending grids, and the study fails.
    """
    h, e = np.asarray(h, float), np.asarray(e, float)
    floor = np.broadcast_to(np.asarray(floor, float), e.shape)
    bad = np.flatnonzero(~np.isfinite(e)).tolist()
    if bad:
        return OrderFit(math.nan, math.nan, math.nan, [], list(range(len(e))), [], False, nonfinite=bad)
    keep = e > floor
    used, dropped = np.flatnonzero(keep).tolist(), np.flatnonzero(~keep).tolist()
    if len(used) == 0:
        return OrderFit(math.inf, math.inf, math.inf, used, dropped, [], False, exact=True)
    lh, le = np.log(h[keep]), np.log(e[keep])
    order = np.argsort(lh)
    lh, le = lh[order], le[order]
    local = (np.diff(le) / np.diff(lh)).tolist() if len(lh) > 1 else []
    if len(lh) < 2:
        return OrderFit(math.nan, math.nan, math.nan, used, dropped, local, True)
    from scipy.special import stdtrit   # the Student-t quantile (scipy.special: already loaded by scipy.linalg)

    slope, stderr = least_squares_slope(lh, le)
    half = float(stdtrit(len(lh) - 2, 0.975)) * stderr if len(lh) > 2 else math.nan
    spread = (max(local) - min(local)) if len(local) > 1 else 0.0
    return OrderFit(slope, slope - half, slope + half, used, dropped, local, spread > ASYMPTOTIC_SPREAD)


def least_squares_slope(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """The least-squares slope of ``y`` on ``x`` and its standard error, as ``scipy.stats.linregress`` computes
    them (its formulas, without importing ``scipy.stats``: 0.6 s, paid again by every worker process).
    ``x`` must not be constant (a study's meshes are distinct)."""
    ssxm, ssxym, _, ssym = np.cov(x, y, bias=True).flat
    r = 0.0 if ssxm == 0.0 or ssym == 0.0 else min(1.0, max(-1.0, ssxym / math.sqrt(ssxm * ssym)))
    slope = ssxym / ssxm
    df = len(x) - 2
    stderr = math.sqrt((1.0 - r * r) * ssym / ssxm / df) if df > 0 else math.nan
    return float(slope), float(stderr)


@dataclasses.dataclass
class ConvergenceStudy:
    """Errors of a stepper on a sequence of grids and the fitted orders (see the module docstring)."""

    problem: str
    stepper: str
    mesh: list[float]
    steps: list[int]
    errors: dict[str, list[float]]
    fits: dict[str, OrderFit]
    expected: Order | None
    reference: str
    floor: float
    timings: list[float]
    #: the floor of each grid (round-off plus what a stated inner-solve tolerance accumulates); ``None``:
    #: ``floor`` on every grid
    floors: list[float] | None = None
    #: the accuracy of its inner solve the stepper stated, if any
    solve_tol: float | None = None

    @property
    def order(self) -> OrderFit:
        """The sup-norm fit, the norm of the paper's convergence result."""
        return self.fits["sup"]

    @property
    def grid_floors(self) -> list[float]:
        """The floor of each grid."""
        return list(self.floors) if self.floors is not None else [self.floor] * len(self.mesh)

    def stall(self) -> str | None:
        """Why the errors stalled far above their floor (module docstring), or ``None``."""
        exp, e, h, fl = self.expected, self.errors["sup"], self.mesh, self.grid_floors
        if exp is None or exp.exact or len(e) < 3:
            return None
        order = sorted(range(len(h)), key=lambda i: -h[i])          # coarse to fine
        a, b = order[-3], order[-1]
        if not (e[b] > STALL_MARGIN * fl[b] and e[a] > 0 and h[b] < h[a]):
            return None
        limit = (h[b] / h[a]) ** (exp.value * STALL_FRACTION)
        if e[b] / e[a] <= limit:
            return None
        return (f"the errors stall far above their floor: {e[a]:.3g} -> {e[b]:.3g} over the last two refinements "
                f"(h {h[a]:.3g} -> {h[b]:.3g}) where order {exp.value:g} predicts {e[a] * (h[b] / h[a]) ** exp.value:.3g} "
                f"(a fall by less than (h_K/h_(K-2))^(p/4) = {limit:.3g}, {e[b] / fl[b]:.3g}x the floor: a stall, "
                "not a pre-asymptotic regime, whose local slopes rise toward p)")

    def verdict(self) -> tuple[bool, str]:
        """Whether the stepper reaches the expected order, with the reason."""
        fit, exp = self.order, self.expected
        bad = _nonfinite_errors(self.errors, self.mesh)
        if bad:
            return False, f"non-finite error: {bad} (the stepper diverged or returned non-finite values)"
        if exp is None:
            return True, "no expected order stated"
        at = "the stated solve tolerance" if self.solve_tol else "round-off"
        if exp.exact:
            worst = max(self.errors["sup"])
            ok = fit.exact
            return ok, (f"errors at {at} (max {worst:.2e} ≤ floor {max(self.grid_floors):.2e})" if ok else
                        f"expected exact at the nodes, max error {worst:.2e} > floor {max(self.grid_floors):.2e}")
        if fit.exact:
            if self.solve_tol:
                return True, (f"exact to the stated solve tolerance {self.solve_tol:g}: every error at its floor "
                              f"(max {max(self.errors['sup']):.2e} ≤ {max(self.grid_floors):.2e})")
            return True, "errors at round-off: exceeds every order"
        stall = self.stall()
        if stall:
            return False, f"measured {fit}, expected {exp.value:g}: {stall}"
        if math.isnan(fit.high):
            return False, f"too few points above {at} to estimate an order (slope {fit.slope:.3f})"
        ok = fit.reaches(exp.value)
        msg = f"measured {fit}, expected {exp.value:g}"
        if fit.pre_asymptotic:
            msg += " (pre-asymptotic: local slopes " + ", ".join(f"{s:.2f}" for s in fit.local_slopes) + ")"
        return ok, msg

    def __repr__(self) -> str:
        """The errors per grid, the fitted orders and the verdict, as a small table."""
        return study_text(self)

    def _repr_html_(self) -> str | None:
        """Jupyter: the report's log-log plot of this study next to its table of errors and orders."""
        return render("study_html", self)

    def plot(self, ax: Any = None) -> Any:
        """The report's log-log plot (errors per norm, fitted slope with its 95% interval, expected slope,
        round-off floor) as a matplotlib ``Figure`` on the Agg canvas, or drawn on ``ax``."""
        return render("study_figure", self, ax)

    def to_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["expected"] = None if self.expected is None else dataclasses.asdict(self.expected)
        d["verdict"] = self.verdict()[0]
        return to_jsonable(d)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "ConvergenceStudy":
        def num(v):
            return float(v) if isinstance(v, str) else v

        fits = {}
        for k, f in d["fits"].items():
            f = dict(f)
            for key in ("slope", "low", "high"):
                f[key] = num(f[key])
            f["local_slopes"] = [num(s) for s in f["local_slopes"]]
            fits[k] = OrderFit(**f)
        exp = None if d.get("expected") is None else Order(**d["expected"])
        floors = d.get("floors")
        return cls(d["problem"], d["stepper"], [num(m) for m in d["mesh"]], list(d["steps"]),
                   {k: [num(x) for x in v] for k, v in d["errors"].items()}, fits, exp, d["reference"],
                   num(d["floor"]), [num(x) for x in d["timings"]],
                   None if floors is None else [num(x) for x in floors], num(d.get("solve_tol")))


def study_text(study: Any) -> str:
    """The study as a small table: mesh, steps, each norm's error per grid, the fitted orders, the verdict."""
    norms = list(study.errors)
    head = f"ConvergenceStudy({study.stepper} on {study.problem}; expected order " + \
        ("none stated" if study.expected is None else str(study.expected)) + f"; reference: {study.reference})"
    cols = ["mesh |Δ|", "steps"] + [f"{n} error" for n in norms]
    rows = [[f"{h:.4g}", str(k)] + [f"{float(study.errors[n][i]):.3e}" for n in norms]
            for i, (h, k) in enumerate(zip(study.mesh, study.steps))]
    rows.append(["order", ""] + [str(study.fits[n]) for n in norms])
    widths = [max(len(r[j]) for r in rows + [cols]) for j in range(len(cols))]
    fmt = "  " + "  ".join(f"{{:>{w}}}" for w in widths)
    ok, msg = study.verdict()
    return "\n".join([head, fmt.format(*cols)] + [fmt.format(*r) for r in rows]
                     + [f"  verdict: {'reaches the expected order' if ok else 'MISSES the expected order'} — {msg}"])


def _nonfinite_errors(errors: dict[str, list[float]], mesh: list[float]) -> str:
    """``"sup error nan at h=0.1, ..."`` for every error that is not a finite number ('' when none)."""
    out = [f"{norm} error {e} at h={h:.3g}" for norm in NORMS for h, e in zip(mesh, errors.get(norm, []))
           if not math.isfinite(float(e))]
    return ", ".join(out[:4]) + (f" and {len(out) - 4} more" if len(out) > 4 else "")


def exact_on(problem: Problem, t: np.ndarray) -> np.ndarray:
    """Exact solution at the times ``t``, shape ``(len(t),) + x0.shape``."""
    if problem.exact is None:
        raise InvalidProblem(f"{problem.name} has no exact solution")
    return np.array([np.asarray(problem.exact(s), dtype=float) for s in t.tolist()])


def _pointwise(x: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``|x_k - ref_k|`` per grid point (the largest over a batch)."""
    diff = (np.asarray(x) - ref).reshape(ref.shape[0], -1, ref.shape[-1])
    return np.linalg.norm(diff, axis=-1).max(axis=1)


def grid_errors(t: np.ndarray, x: np.ndarray, ref: np.ndarray) -> dict[str, float]:
    """Sup, discrete-L2 and final errors of ``x`` against ``ref`` at the grid times ``t``.

    The L2 sum is exactly rounded (``math.fsum``), so :class:`ErrorAccumulator` fed the same data in
    blocks gives the same bits.
    """
    d = _pointwise(x, ref)
    h = np.diff(t)
    return {"sup": float(d.max()), "l2": math.sqrt(math.fsum((h * d[1:] ** 2).tolist())), "final": float(d[-1])}


class ErrorAccumulator:
    """Streaming :func:`grid_errors`: feed ``(t_block, x_block)`` pieces in order.

    Against ``problem.exact``, or against ``reference``: the reference values at every node of the grid,
    in order (the fine-grid reference of a study without exact solution).  Holds ``O(1)`` data besides the
    current block (and ``reference``).  ``errors()`` equals ``grid_errors`` on the whole trajectory:
    ``sup`` and ``final`` bit for bit, ``l2`` to within one rounding (its sum is carried as an exactly
    rounded double-double, error ≤ 2^-106 relative before the final rounding, so in practice bit for
    bit).  ``scale`` is ``max |x(t_k)|`` of the reference.
    """

    def __init__(self, problem: Problem, reference: np.ndarray | None = None) -> None:
        if problem.exact is None and reference is None:
            raise InvalidProblem(f"{problem.name} has no exact solution")
        self.problem = problem
        self.reference = reference
        self.sup = 0.0
        self.final = math.nan
        self.scale = 0.0
        self._l2 = [0.0, 0.0]      # running L2 sum as hi + lo (double-double, exactly rounded parts)
        self._t_last: float | None = None
        self._row = 0              # grid index of the next block's first row

    def update(self, t: np.ndarray, x: np.ndarray) -> None:
        if self.reference is None:
            ref = exact_on(self.problem, t)
        else:
            ref = self.reference[self._row:self._row + len(t)]
            if ref.shape[0] != len(t):
                raise InvalidProblem(f"the reference has {self.reference.shape[0]} values, fewer than the grid")
        self._row += len(t)
        d = _pointwise(x, ref)
        self.sup = _nanmax(self.sup, float(d.max()))      # d.max() is nan when any d is; keep it so
        self.final = float(d[-1])
        self.scale = _nanmax(self.scale, float(np.max(np.abs(ref))))
        if self._t_last is None:
            h, dd = np.diff(t), d[1:]
        else:
            h, dd = np.diff(t, prepend=self._t_last), d
        terms = self._l2 + (h * dd ** 2).tolist()
        hi = math.fsum(terms)
        terms.append(-hi)
        self._l2 = [hi, math.fsum(terms)]
        self._t_last = float(t[-1])

    def errors(self) -> dict[str, float]:
        return {"sup": self.sup, "l2": math.sqrt(math.fsum(self._l2)), "final": self.final}


def _nanmax(a: float, b: float) -> float:
    """``max`` that propagates ``nan`` (Python's ``max(0.0, nan)`` is ``0.0``: a diverged stepper would
    have looked exact)."""
    return a if (a != a or a >= b) else b


class Sampler:
    """Streaming linear interpolation of a trajectory at the increasing times ``times``.

    Feed ``(t_block, x_block)`` pieces in order; ``values`` then holds ``x`` at every time, computed as
    ``np.interp`` on the whole trajectory would (the bracketing cell and its formula do not depend on the
    blocking).  Holds the samples and one previous row.
    """

    def __init__(self, times: np.ndarray) -> None:
        self.times = np.asarray(times, dtype=float)
        self.values: np.ndarray | None = None
        self._next = 0                                   # first sample time not yet computed
        self._prev: tuple[np.ndarray, np.ndarray] | None = None

    def update(self, t: np.ndarray, x: np.ndarray) -> None:
        if self.values is None:
            self.values = np.empty((len(self.times),) + x.shape[1:])
        if self._prev is not None:                       # the cell joining the previous block to this one
            t = np.concatenate([self._prev[0], t])
            x = np.concatenate([self._prev[1], x])
        stop = int(np.searchsorted(self.times, t[-1], side="right"))
        if stop > self._next:
            tau = self.times[self._next:stop]
            flat = x.reshape(len(t), -1)
            vals = np.stack([np.interp(tau, t, flat[:, j]) for j in range(flat.shape[1])], axis=-1)
            self.values[self._next:stop] = vals.reshape((len(tau),) + x.shape[1:])
            self._next = stop
        self._prev = (t[-1:].copy(), x[-1:].copy())


def study_grids(T: float, steps: Sequence[Any]) -> list[np.ndarray]:
    """The grids of a study: a step size is the uniform grid of ``[0, T]``, an array an explicit grid."""
    return [validate_grid(s, T) if np.ndim(s) else uniform_grid(T, float(s)) for s in steps]


def convergence_study(stepper: Callable, problem: Problem, steps: Sequence[Any] | None = None, *,
                      reference_refinement: int = 8, executor: Any = None,
                      solve_tol: float | None = None) -> ConvergenceStudy:
    """Run ``stepper`` on a sequence of grids and estimate its convergence order.

    ``steps`` are step sizes (uniform grids of ``[0, T]``) or explicit grids; by default the problem's
    recommended ``steps``.  Without an exact solution the reference is the same stepper on a uniform
    grid ``reference_refinement`` times finer than the finest one, interpolated linearly where the grid
    points do not coincide.

    ``executor`` runs the grids (and the fine reference) as parallel jobs: any
    ``concurrent.futures.Executor`` — a process pool, a thread pool, ``dask.distributed``'s
    ``Client.get_executor()`` — or ``"process"`` (a process pool of ``os.cpu_count()`` workers) or
    ``"serial"``.  ``None`` picks ``"process"`` for studies of at least :data:`PARALLEL_MIN_STEPS`
    steps in all on a multi-core machine, else ``"serial"``.  Problems and steppers built from
    lambdas and closures (the reference catalog's) need no pickling with verimono's own process pool
    (forked workers inherit them); for other executors they travel by pickle, else by ``cloudpickle``
    (by value, with the parameters their closures captured).

    ``solve_tol``: the accuracy of the stepper's inner solve, relative to the state's size (default: the
    stepper's own claim, ``Stepper(..., solve_tol=τ)``); it raises each grid's floor by :func:`solve_floor`.
    """
    if solve_tol is None:
        solve_tol = getattr(getattr(stepper, "claim", None), "solve_tol", None)
    steps = problem.steps if steps is None else steps
    if not steps or len(steps) < 2:
        raise InvalidProblem("a convergence study needs at least two step sizes or grids")
    grids = study_grids(problem.T, steps)
    if problem.exact is not None:
        reference = "exact solution"
        executor = _choose_executor(executor, sum(len(g) for g in grids))
        results = _run_jobs(stepper, problem, [(g, "errors", None) for g in grids], executor)
    else:
        fine_t = uniform_grid(problem.T, steps=_cells_finer_than(grids, problem.T) * reference_refinement)
        executor = _choose_executor(executor, len(fine_t) + sum(len(g) for g in grids))
        nodes = functools.reduce(np.union1d, grids)       # the fine solution is needed only there
        at_nodes, _, _, at_precision = _run_jobs(stepper, problem, [(fine_t, "sample", nodes)], executor)[0]
        jobs = [(g, "errors", at_nodes[np.searchsorted(nodes, g)]) for g in grids]
        results = _run_jobs(stepper, problem, jobs, executor)
        reference = f"fine-grid solution of the same stepper (h = {problem.T / (len(fine_t) - 1):.3g})"
    errors = {n: [errs[n] for errs, _, _, _ in results] for n in NORMS}
    scale = max([1.0] + [sc for _, sc, _, _ in results if math.isfinite(sc)])
    precision = coarser(*[r[3] for r in results], *([at_precision] if problem.exact is None else []))
    observe(precision)          # jobs run in other processes report it here
    floor = roundoff_floor(scale, precision)
    mesh = [float(np.max(np.diff(g))) for g in grids]
    floors = None if not solve_tol else [floor + solve_floor(len(g) - 1, solve_tol, scale) for g in grids]
    fits = {n: fit_order(mesh, errors[n], floor if floors is None else floors) for n in NORMS}
    return ConvergenceStudy(problem.name, subject_name(stepper), mesh, [len(g) - 1 for g in grids], errors, fits,
                            problem.order, reference, floor, [r[2] for r in results[:len(grids)]], floors,
                            solve_tol or None)


#: a study of at least this many steps in all runs in a process pool when ``executor=None``
PARALLEL_MIN_STEPS = 200_000


def _job(stepper, problem, grid, want, ref=None):
    """One grid: ``(errors, scale, seconds, precision)`` when ``want == "errors"`` (against the exact
    solution, or against ``ref``, the reference values at the grid's nodes), ``(values at the times ref,
    None, seconds, precision)`` when ``want == "sample"``.

    ``seconds`` is the stepper's own time (streaming: the blocks' production, not the error sums);
    ``precision`` the one the stepper's states were computed in (:mod:`verimono.core.tolerances`).
    """
    with judged_precision() as precision:
        out = _job_values(stepper, problem, grid, want, ref)
    return (*out, precision.name)


def _job_values(stepper, problem, grid, want, ref=None):
    stepper, problem = _unwrap(stepper), _unwrap(problem)
    sink = ErrorAccumulator(problem, ref) if want == "errors" else Sampler(ref)
    if stepper is solve:
        spent = 0.0
        it = stream(problem, grid)
        while True:
            start = time.perf_counter()
            piece = next(it, None)
            spent += time.perf_counter() - start
            if piece is None:
                break
            sink.update(*piece)
    else:
        x, spent = _timed_run(stepper, problem, grid)
        for i in range(0, len(grid), 8192):     # in blocks, as the stream: one trajectory held, not two
            sink.update(grid[i:i + 8192], x[i:i + 8192])
    if want == "errors":
        return sink.errors(), sink.scale, spent
    return sink.values, None, spent


def _cells_finer_than(grids, T: float) -> int:
    """The fewest uniform cells of ``[0, T]`` no longer than any cell of ``grids``: ``T/h_min``, rounded
    when it is an integer up to rounding (the steps of ``uniform_grid(T, T/K)`` fall a few ulps short of
    ``T/K``: ``ceil`` would give ``K + 1`` and a reference grid that is not a refinement of the grids)."""
    k = T / min(float(np.min(np.diff(g))) for g in grids)
    return int(round(k)) if abs(k - round(k)) <= 1e-9 * k else int(math.ceil(k))


def _choose_executor(executor, total_steps):
    """``executor``, or for ``None`` a process pool above :data:`PARALLEL_MIN_STEPS` steps in all (on a
    multi-core machine), else ``"serial"``."""
    if executor is not None:
        return executor
    return "process" if total_steps >= PARALLEL_MIN_STEPS and (os.cpu_count() or 1) > 1 else "serial"


def _run_jobs(stepper, problem, jobs, executor):
    """Results of :func:`_job` for every ``(grid, want, ref)``, in order (largest jobs submitted first)."""
    if executor == "serial":
        return [_job(stepper, problem, *job) for job in jobs]
    order = sorted(range(len(jobs)), key=lambda i: -len(jobs[i][0]))
    if executor == "process":
        import multiprocessing  # with the process pool: only for a parallel study, not `import verimono`
        from concurrent.futures import ProcessPoolExecutor

        workers = max(1, min(len(jobs), os.cpu_count() or 1))
        if "fork" in multiprocessing.get_all_start_methods() and sys.platform.startswith("linux"):
            # forked workers inherit the registry: closures and lambdas need no pickling
            token = id(jobs)
            _REGISTRY[token] = (stepper, problem)
            try:
                with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork")) as pool:
                    futures = {i: pool.submit(_registered_job, token, *jobs[i]) for i in order}
                    return [futures[i].result() for i in range(len(jobs))]
            finally:
                _REGISTRY.pop(token, None)
        with ProcessPoolExecutor(workers) as pool:
            return _submit_all(pool, stepper, problem, jobs, order)
    if not hasattr(executor, "submit"):
        raise InvalidProblem(f"executor must be a concurrent.futures.Executor, 'process', 'serial' or None, "
                             f"got {executor!r}")
    return _submit_all(executor, stepper, problem, jobs, order)


def _submit_all(executor, stepper, problem, jobs, order):
    s, p = _Portable(stepper), _Portable(problem)
    futures = {i: executor.submit(_job, s, p, *jobs[i]) for i in order}
    return [futures[i].result() for i in range(len(jobs))]


_REGISTRY: dict[int, tuple[Any, Any]] = {}


def _registered_job(token, grid, want, ref=None):
    stepper, problem = _REGISTRY[token]
    return _job(stepper, problem, grid, want, ref)


class _Portable:
    """Wraps a stepper or problem for executors that pickle their tasks.

    Pickles as the object itself when it pickles, else through ``cloudpickle`` (the catalog's problems and
    most users' are built from lambdas and closures, which it serialises by value, captured parameters
    included).  Executors that do not pickle (threads) hand the wrapper over as is; :func:`_unwrap`.
    """

    __slots__ = ("obj",)

    def __init__(self, obj: Any) -> None:
        self.obj = obj

    def __reduce__(self):
        obj = self.obj
        try:
            pickle.dumps(obj)
            return (_identity, (obj,))
        except Exception:
            pass
        import cloudpickle

        try:
            return (pickle.loads, (cloudpickle.dumps(obj),))
        except Exception as exc:
            raise InvalidProblem(f"cannot send {subject_name(obj)} to the executor's workers: cloudpickle cannot "
                                 f"serialise it ({type(exc).__name__}: {exc}); use executor='process' (forked "
                                 "workers inherit it) or 'serial'") from None


def _identity(obj):
    return obj


def _unwrap(obj):
    return obj.obj if isinstance(obj, _Portable) else obj


def _timed_run(stepper, problem, grid):
    start = time.perf_counter()
    x = stepper(problem, grid)
    try:
        x = as_float64(x)                   # any array library; its precision observed
    except (TypeError, ValueError):
        x = real_array(x, f"the values of stepper {subject_name(stepper)}")   # complex: an error
    if x.shape != (len(grid),) + problem.x0.shape:
        raise InvalidProblem(f"stepper {subject_name(stepper)} returned shape {x.shape}, expected "
                             f"{(len(grid),) + problem.x0.shape}")
    return x, time.perf_counter() - start


__all__ = ["convergence_study", "study_grids", "ConvergenceStudy", "OrderFit", "fit_order", "grid_errors", "exact_on", "solve_floor",
           "ErrorAccumulator", "Sampler"]
