"""Convergence studies: errors on a sequence of grids and least-squares order estimates.

For each grid the study records three errors against the exact solution (or, when the problem has
none, against a fine-grid solution of the same stepper, which the result says):

* ``sup``:   ``max_k |x_k - x(t_k)|`` (the norm of the paper's uniform convergence),
* ``l2``:    ``(Σ_k h_k |x_k - x(t_k)|²)^{1/2}`` (discrete L2 in time),
* ``final``: ``|x_K - x(T)|``.

The order in each norm is the slope of ``log e`` against ``log |Δ|`` (``|Δ| = max_k h_k``) by least
squares — valid for any step ratio — with a 95% Student-t confidence interval.  Errors at the round-off
floor (``ROUNDOFF_FACTOR · ε · scale``) are dropped; if every error is there the scheme is exact on the
grid.  Data whose local slopes spread by more than ``ASYMPTOTIC_SPREAD`` are flagged pre-asymptotic.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any, Callable, Sequence

import numpy as np
from scipy import stats

from .errors import InvalidProblem
from .grids import uniform_grid, validate_grid
from .problem import Order, Problem
from .tolerances import EPS

NORMS = ("sup", "l2", "final")
#: errors below ROUNDOFF_FACTOR * eps * (1 + max|x|) are round-off (≈ 2e-12 for unit-size states):
#: a K-step scheme accumulates O(K eps) rounding, and K ≤ 1e4 in the catalog's studies
ROUNDOFF_FACTOR = 1e4
#: local slopes that spread by more than this are not yet in the asymptotic regime
ASYMPTOTIC_SPREAD = 0.25
#: an order estimate "reaches" p when its interval's upper end is within this of p; the slack absorbs
#: the O(h) drift of the slope of C h^p (1 + O(h)) over the studied range
ORDER_SLACK = 0.1


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

    def contains(self, p: float, slack: float = ORDER_SLACK) -> bool:
        return self.low - slack <= p <= self.high + slack

    def reaches(self, p: float, slack: float = ORDER_SLACK) -> bool:
        return self.high + slack >= p

    def __str__(self) -> str:
        if self.exact:
            return "exact (round-off)"
        if math.isnan(self.low):
            return f"{self.slope:.3f}"
        return f"{self.slope:.3f} [{self.low:.3f}, {self.high:.3f}]"


def fit_order(h: Sequence[float], e: Sequence[float], floor: float = 0.0) -> OrderFit:
    """Fit ``e ≈ C h^p`` on the points above ``floor`` (see the module docstring)."""
    h, e = np.asarray(h, float), np.asarray(e, float)
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
    res = stats.linregress(lh, le)
    if len(lh) > 2:
        half = stats.t.ppf(0.975, len(lh) - 2) * res.stderr
    else:
        half = math.nan
    spread = (max(local) - min(local)) if len(local) > 1 else 0.0
    return OrderFit(float(res.slope), float(res.slope - half), float(res.slope + half), used, dropped,
                    local, spread > ASYMPTOTIC_SPREAD)


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

    @property
    def order(self) -> OrderFit:
        """The sup-norm fit, the norm of the paper's convergence result."""
        return self.fits["sup"]

    def verdict(self) -> tuple[bool, str]:
        """Whether the stepper reaches the expected order, with the reason."""
        fit, exp = self.order, self.expected
        if exp is None:
            return True, "no expected order stated"
        if exp.exact:
            worst = max(self.errors["sup"])
            ok = fit.exact
            return ok, (f"errors at round-off (max {worst:.2e} ≤ floor {self.floor:.2e})" if ok else
                        f"expected exact at the nodes, max error {worst:.2e} > floor {self.floor:.2e}")
        if fit.exact:
            return True, "errors at round-off: exceeds every order"
        if math.isnan(fit.high):
            return False, f"too few points above round-off to estimate an order (slope {fit.slope:.3f})"
        ok = fit.reaches(exp.value)
        msg = f"measured {fit}, expected {exp.value:g}"
        if fit.pre_asymptotic:
            msg += " (pre-asymptotic: local slopes " + ", ".join(f"{s:.2f}" for s in fit.local_slopes) + ")"
        return ok, msg

    def to_dict(self) -> dict[str, Any]:
        from .results import to_jsonable

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
        return cls(d["problem"], d["stepper"], [num(m) for m in d["mesh"]], list(d["steps"]),
                   {k: [num(x) for x in v] for k, v in d["errors"].items()}, fits, exp, d["reference"],
                   num(d["floor"]), [num(x) for x in d["timings"]])


def exact_on(problem: Problem, t: np.ndarray) -> np.ndarray:
    """Exact solution at the times ``t``, shape ``(len(t),) + x0.shape``."""
    if problem.exact is None:
        raise InvalidProblem(f"{problem.name} has no exact solution")
    return np.array([np.asarray(problem.exact(s), dtype=float) for s in t.tolist()])


def grid_errors(t: np.ndarray, x: np.ndarray, ref: np.ndarray) -> dict[str, float]:
    """Sup, discrete-L2 and final errors of ``x`` against ``ref`` at the grid times ``t``."""
    d = np.linalg.norm((np.asarray(x) - ref).reshape(len(t), -1, ref.shape[-1]), axis=-1).max(axis=1)
    h = np.diff(t)
    return {"sup": float(d.max()), "l2": float(np.sqrt(np.sum(h * d[1:] ** 2))), "final": float(d[-1])}


def _name(obj: Any) -> str:
    return getattr(obj, "__name__", None) or getattr(obj, "name", None) or type(obj).__name__


def convergence_study(stepper: Callable, problem: Problem, steps: Sequence[Any] | None = None, *,
                      reference_refinement: int = 8, executor: Any = None) -> ConvergenceStudy:
    """Run ``stepper`` on a sequence of grids and estimate its convergence order.

    ``steps`` are step sizes (uniform grids of ``[0, T]``) or explicit grids; by default the problem's
    recommended ``steps``.  Without an exact solution the reference is the same stepper on a uniform
    grid ``reference_refinement`` times finer than the finest one, interpolated linearly where the grid
    points do not coincide.  ``executor`` (any ``concurrent.futures.Executor``) runs the grids in
    parallel.
    """
    steps = problem.steps if steps is None else steps
    if not steps or len(steps) < 2:
        raise InvalidProblem("a convergence study needs at least two step sizes or grids")
    grids = [validate_grid(s, problem.T) if np.ndim(s) else uniform_grid(problem.T, float(s)) for s in steps]
    mapper = executor.map if executor is not None else map
    runs = list(mapper(_timed_run, [stepper] * len(grids), [problem] * len(grids), grids))
    if problem.exact is not None:
        refs = [exact_on(problem, g) for g in grids]
        reference = "exact solution"
    else:
        hmin = min(float(np.min(np.diff(g))) for g in grids)
        fine_t = uniform_grid(problem.T, steps=int(math.ceil(problem.T / hmin)) * reference_refinement)
        fine_x = np.asarray(stepper(problem, fine_t), dtype=float)
        flat = fine_x.reshape(len(fine_t), -1)
        refs = [np.stack([np.interp(g, fine_t, flat[:, j]) for j in range(flat.shape[1])], axis=-1)
                .reshape((len(g),) + fine_x.shape[1:]) for g in grids]
        reference = f"fine-grid solution of the same stepper (h = {problem.T / (len(fine_t) - 1):.3g})"
    errors = {n: [] for n in NORMS}
    scale = 1.0
    for g, (x, _), ref in zip(grids, runs, refs):
        for n, v in grid_errors(g, x, ref).items():
            errors[n].append(v)
        scale = max(scale, float(np.max(np.abs(ref))))
    floor = ROUNDOFF_FACTOR * EPS * scale
    mesh = [float(np.max(np.diff(g))) for g in grids]
    fits = {n: fit_order(mesh, errors[n], floor) for n in NORMS}
    return ConvergenceStudy(problem.name, _name(stepper), mesh, [len(g) - 1 for g in grids], errors, fits,
                            problem.order, reference, floor, [dt for _, dt in runs])


def _timed_run(stepper, problem, grid):
    start = time.perf_counter()
    x = np.asarray(stepper(problem, grid), dtype=float)
    if x.shape != (len(grid),) + problem.x0.shape:
        raise InvalidProblem(f"stepper {_name(stepper)} returned shape {x.shape}, expected "
                             f"{(len(grid),) + problem.x0.shape}")
    return x, time.perf_counter() - start


__all__ = ["convergence_study", "ConvergenceStudy", "OrderFit", "fit_order", "grid_errors", "exact_on"]
