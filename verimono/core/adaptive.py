"""Steppers that choose their own steps: the protocol, one validated run, and the tolerance study.

A stepper of :class:`verimono.Stepper` is called on a partition it is given.  Most integrators for stiff
and nonsmooth dynamics choose their partition themselves: a step-size controller (diffrax's
``PIDController``, SciPy's ``solve_ivp``), an event-driven scheme that puts nodes at the switching times
it locates, verimono's own proximal scheme with a step controller (:func:`verimono.solve_adaptive`).
:class:`Adaptive` says how such a stepper is called and what it claims::

    stepper = verimono.Adaptive(fn, rate=1.0, order=5)      # fn(problem, T, tol) -> (t, x)

* ``control="tolerance"`` (default): ``fn(problem, T, tol)`` returns ``(t, x)`` — its own partition
  ``0 = t_0 < ... < t_N = T`` and the states there, shape ``(N+1, n)`` — or ``(t, x, events)`` with the
  switching times it located (an event-driven scheme).  ``dense=True``: it also takes ``t_out=`` (an array
  of output times) and then returns the states at those times (dense output), which the study measures
  beside the nodes.
* ``control="step"``: ``fn(problem, t_grid)`` returns ``(t, x)``: it steps on the given grid but may put
  nodes of its own in it (an event-driven scheme on a fixed grid); the study sweeps the grid's step.

The claims: ``rate`` — the error falls like ``tol^rate`` (tolerance proportionality is ``rate = 1``; a
controller of the error per step of an order-``p`` pair gives ``p/(p+1)``); ``order`` — the error falls like
``N^-order`` with the number ``N`` of steps it took (the method's order; ``None``: not claimed);
``scheme`` — ``"proximal"`` when every step is the paper's scheme (``eq:iteration``) on the stepper's own
partition, so that the laws local to steps (``selections``, ``in_domain``, the bounds of ``lem:bndSeq``)
apply there (the paper's results hold for any partition), ``"any"`` otherwise.

**The study** (:func:`tolerance_study`): the stepper at each control (tolerances, tight to loose, or step
sizes), the errors against the exact solution at its own nodes — ``sup`` ``max_k |x_k - x(t_k)|``, ``l2``
``(Σ_k h_k |x_k - x(t_k)|²)^{1/2}`` with its own steps, ``final`` — and at :data:`DENSE_POINTS` uniform
output times with dense output (``dense``), and two least-squares fits with their 95% intervals
(:func:`verimono.core.convergence.fit_order`): ``log e`` against ``log tol`` (the rate) and against
``log(T/N)`` (the order).  Errors at the round-off floor are not fitted.  The verdict fails a stepper

* whose number of steps does not respond to the control while its errors stay above the floor (a
  controller that ignores its error estimate, or the tolerance);
* whose errors stall far above the floor over the tightest controls (they fall by less than a quarter of the
  claimed rate: the stall of :mod:`verimono.core.convergence`);
* whose rate interval cannot reach the claimed rate (its upper end plus :data:`RATE_SLACK`), or whose order
  interval cannot reach the claimed order (plus :data:`OWN_ORDER_SLACK`).
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import time
from typing import Any, Callable, Sequence

import numpy as np

from ._jsonable import to_jsonable
from .arrays import as_float64, precision_of
from .claims import ANY, PROXIMAL, Claim, make_claim
from .convergence import OrderFit, exact_on, fit_order
from .display import render
from .errors import InvalidClaim, InvalidGrid, InvalidProblem
from .grids import uniform_grid
from .naming import subject_name
from .problem import Problem
from .tolerances import coarser, judged_precision, observe, roundoff_floor

CONTROLS = ("tolerance", "step")
#: the tolerances a study sweeps when neither it nor the stepper names any: two decades either side of 1e-6
DEFAULT_TOLERANCES = (1e-4, 10 ** -4.5, 1e-5, 10 ** -5.5, 1e-6, 10 ** -6.5, 1e-7, 10 ** -7.5, 1e-8)
#: uniform output times at which a dense stepper's error is measured (``dense`` norm)
DENSE_POINTS = 201
#: a claimed rate is reached when the fit's upper end plus this is at least the claim.  A step-size
#: controller's error is a staircase in the tolerance (steps are integers, rejections come and go), wider
#: than the O(h) drift of a fixed-step study: measured on the ODE references, diffrax's Tsit5 and Kvaerno5
#: with PIDController and solve_ivp's Radau and BDF give rate fits whose intervals reach within 0.2 of their
#: slope's long-run value over two decades
RATE_SLACK = 0.2
#: the same for the order against the number of steps (fits of e against T/N of adaptive runs)
OWN_ORDER_SLACK = 0.35
#: a stall is judged only on errors this many times above their floor (as in a fixed-step study)
STALL_MARGIN = 100.0
NORMS = ("sup", "l2", "final")


class Adaptive:
    """A stepper that chooses its own steps, with its claim (module docstring):
    ``Adaptive(fn, *, rate=1.0, order=None, control="tolerance", tolerances=None, dense=False,
    scheme="any", name=None, solve_tol=None)``.

    ``tolerances``: the controls its study sweeps by default (tolerances, or step sizes for
    ``control="step"``).  Calling it calls ``fn``.
    """

    def __init__(self, fn: Callable, *, rate: Any = 1.0, order: Any = None, control: str = "tolerance",
                 tolerances: Sequence[float] | None = None, dense: bool = False, scheme: str = ANY,
                 name: str | None = None, solve_tol: Any = None) -> None:
        if not callable(fn):
            raise InvalidClaim(f"an adaptive stepper must be callable as fn(problem, T, tol), got {fn!r}")
        if isinstance(fn, Adaptive):
            fn = fn.fn
        if control not in CONTROLS:
            raise InvalidClaim(f"control must be one of {CONTROLS}, got {control!r}")
        self.fn = fn
        self.control = control
        self.rate = _positive(rate, "rate") if control == "tolerance" else None
        self.claim: Claim = (make_claim(PROXIMAL, None, None, solve_tol) if scheme == PROXIMAL else
                             make_claim(ANY, 1.0 if order is None else order, False, solve_tol))
        #: the order claimed against the number of steps (``None``: not claimed)
        self.order = None if order is None else _positive(order, "order")
        self.tolerances = None if tolerances is None else _controls(tolerances, control)
        self.dense = bool(dense)
        if self.dense and control != "tolerance":
            raise InvalidClaim("dense output is for control='tolerance' (fn(problem, T, tol, t_out=...))")
        self.__name__ = self.name = name or getattr(fn, "__name__", None) or type(fn).__name__
        self.__doc__ = getattr(fn, "__doc__", None)

    @property
    def scheme(self) -> str:
        return self.claim.scheme

    def __call__(self, *args: Any, **kw: Any) -> Any:
        return self.fn(*args, **kw)

    def describe(self) -> str:
        parts = [f"control={self.control!r}"]
        if self.rate is not None:
            parts.append(f"rate={self.rate:g}")
        if self.order is not None:
            parts.append(f"order={self.order:g}")
        parts.append(f"scheme={self.scheme!r}")
        if self.dense:
            parts.append("dense")
        return ", ".join(parts)

    def __repr__(self) -> str:
        return f"Adaptive({self.name}, {self.describe()})"

    def __reduce__(self):   # picklable by reference to fn (process pools)
        return (_rebuild, (self.fn, dict(rate=self.rate or 1.0, order=self.order, control=self.control,
                                         tolerances=self.tolerances, dense=self.dense, scheme=self.scheme,
                                         name=self.name, solve_tol=self.claim.solve_tol)))


def _rebuild(fn: Callable, kw: dict) -> Adaptive:
    return Adaptive(fn, **kw)


def _positive(value: Any, what: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidClaim(f"{what} must be a positive number, got {value!r}") from None
    if isinstance(value, bool) or not (math.isfinite(v) and v > 0):
        raise InvalidClaim(f"{what} must be a positive finite number, got {value!r}")
    return v


def _controls(values: Any, control: str) -> tuple[float, ...]:
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise InvalidClaim(f"the {control}s must be numbers, got {values!r}") from None
    if len(out) < 2 or not all(math.isfinite(v) and v > 0 for v in out) or len(set(out)) != len(out):
        raise InvalidClaim(f"a study needs at least two distinct positive {control}s, got {values!r}")
    return out


def is_adaptive(obj: Any) -> bool:
    return isinstance(obj, Adaptive)


# -- one run ----------------------------------------------------------------------------------------


@dataclasses.dataclass
class OwnRun:
    """One run of an adaptive stepper: its partition ``t``, states ``x``, located ``events`` (or ``None``),
    the states at the dense output times (``dense``, or ``None``), its seconds and its precision."""

    t: np.ndarray
    x: np.ndarray
    events: np.ndarray | None
    dense: np.ndarray | None
    seconds: float
    precision: str

    @property
    def steps(self) -> int:
        return len(self.t) - 1


def _wants_t_out(fn: Callable) -> bool:
    try:
        return "t_out" in inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return False


def own_run(stepper: Adaptive, problem: Problem, control: float, *, t_out: np.ndarray | None = None) -> OwnRun:
    """``stepper`` at ``control`` (a tolerance, or a step size of a uniform grid), validated: its partition
    must be strictly increasing from 0 to ``T`` (:class:`verimono.InvalidGrid` otherwise) and its states
    finite, of shape ``(N+1,) + x0.shape`` (:class:`verimono.InvalidProblem`)."""
    name = subject_name(stepper)
    with judged_precision() as precision:
        start = time.perf_counter()
        if stepper.control == "step":
            out = stepper.fn(problem, uniform_grid(problem.T, float(control)))
        else:
            out = stepper.fn(problem, problem.T, float(control))
        seconds = time.perf_counter() - start
        t, x, events = _unpack(out, name)
        x_dense = None
        if t_out is not None and stepper.dense:
            x_dense = _states(stepper.fn(problem, problem.T, float(control), t_out=t_out), len(t_out), problem,
                              f"the dense output of {name}")
    t = _own_partition(t, problem.T, name)
    x = _states(x, len(t), problem, f"the states of {name}")
    if events is not None:
        events = np.sort(np.atleast_1d(np.asarray(events, dtype=float)))
        if not np.all(np.isfinite(events)) or np.any(events < 0) or np.any(events > problem.T):
            raise InvalidProblem(f"{name} located events outside [0, T]: {events[:5]}")
    return OwnRun(t, x, events, x_dense, seconds, precision.name)


def _unpack(out: Any, name: str) -> tuple[Any, Any, Any]:
    if hasattr(out, "t") and hasattr(out, "x"):              # a Trajectory (or any object with t and x)
        extras = getattr(out, "extras", None) or {}
        return out.t, out.x, getattr(out, "events", None) if extras.get("events") is None else extras["events"]
    if isinstance(out, tuple) and len(out) in (2, 3):
        return out[0], out[1], (out[2] if len(out) == 3 else None)
    raise InvalidProblem(f"adaptive stepper {name} must return (t, x) or (t, x, events): its own partition and "
                         f"the states there, got {type(out).__name__}")


def _own_partition(t: Any, T: float, name: str) -> np.ndarray:
    try:
        t = np.asarray(as_float64(t), dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidGrid(f"the partition returned by {name} is not an array of times: {exc}") from None
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)):
        raise InvalidGrid(f"the partition returned by {name} must be a finite 1-D array of at least 2 times, got "
                          f"shape {t.shape}")
    if t[0] != 0.0 or abs(t[-1] - T) > 1e-9 * max(1.0, abs(T)):
        raise InvalidGrid(f"the partition returned by {name} must run from 0 to T = {T:g}, got [{t[0]!r}, {t[-1]!r}]")
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise InvalidGrid(f"the partition returned by {name} must be strictly increasing: t[{k}] = {t[k]!r}, "
                          f"t[{k + 1}] = {t[k + 1]!r}")
    return t


def _states(x: Any, rows: int, problem: Problem, what: str) -> np.ndarray:
    precision = precision_of(x)
    x = np.asarray(as_float64(x), dtype=float)
    if precision:
        observe(precision)
    if x.shape != (rows,) + problem.x0.shape:
        raise InvalidProblem(f"{what} have shape {x.shape}, expected {(rows,) + problem.x0.shape}")
    return x


# -- errors on a partition of the stepper's own ------------------------------------------------------------


def own_errors(run: OwnRun, problem: Problem, t_out: np.ndarray | None = None) -> tuple[dict[str, float], float]:
    """The errors of ``run`` against the exact solution (module docstring) and the reference's scale
    ``max |x(t_k)|``."""
    ref = exact_on(problem, run.t)
    d = np.linalg.norm((run.x - ref).reshape(len(run.t), -1, ref.shape[-1]), axis=-1).max(axis=1)
    h = np.diff(run.t)
    errors = {"sup": float(np.max(d)), "l2": math.sqrt(math.fsum((h * d[1:] ** 2).tolist())), "final": float(d[-1])}
    scale = float(np.max(np.abs(ref)))
    if run.dense is not None and t_out is not None:
        ref_out = exact_on(problem, t_out)
        errors["dense"] = float(np.max(np.linalg.norm((run.dense - ref_out).reshape(len(t_out), -1,
                                                                                      ref.shape[-1]), axis=-1)))
        scale = max(scale, float(np.max(np.abs(ref_out))))
    return errors, scale


# -- the study --------------------------------------------------------------------------------------------


@dataclasses.dataclass
class ToleranceStudy:
    """Errors of an adaptive stepper over its controls, with the fits against the control and against the
    number of steps (module docstring)."""

    problem: str
    stepper: str
    control: str
    controls: list[float]
    steps: list[int]
    errors: dict[str, list[float]]
    fits: dict[str, OrderFit]
    step_fits: dict[str, OrderFit]
    rate: float | None
    order: float | None
    floor: float
    timings: list[float]
    events: list[list[float]] | None = None
    #: the horizon (the mean step of a run is ``T/N``)
    T: float = 1.0

    @property
    def mesh(self) -> list[float]:
        """The mean step ``T/N`` of each run (what the order is fitted against)."""
        return [self.T / n for n in self.steps]

    def diagnosis(self) -> str | None:
        """Why the stepper fails its claim independently of the fits, or ``None``."""
        e, fl = self.errors["sup"], self.floor
        above = [i for i, v in enumerate(e) if v > fl]
        if len(above) >= 2 and len({self.steps[i] for i in above}) == 1:
            what = "tolerance" if self.control == "tolerance" else "step"
            return (f"its number of steps does not respond to the {what}: {self.steps[above[0]]} steps at every "
                    f"{what} from {max(self.controls):.3g} to {min(self.controls):.3g} while its errors stay above "
                    f"the floor ({min(e[i] for i in above):.3g}-{max(e[i] for i in above):.3g}): a controller that "
                    "ignores its error estimate or the tolerance")
        claim = self.rate if self.control == "tolerance" else self.order
        if claim is None:
            return None
        order = sorted(range(len(self.controls)), key=lambda i: -self.controls[i])     # loose to tight
        if len(order) < 3:
            return None
        a, b = order[-3], order[-1]
        ca, cb = self.controls[a], self.controls[b]
        if not (e[b] > STALL_MARGIN * fl and e[a] > 0 and cb < ca):
            return None
        limit = (cb / ca) ** (claim / 4.0)
        if e[b] / e[a] <= limit:
            return None
        return (f"its errors stall far above the floor: {e[a]:.3g} -> {e[b]:.3g} as the {self.control} goes "
                f"{ca:.3g} -> {cb:.3g}, where rate {claim:g} predicts {e[a] * (cb / ca) ** claim:.3g}")

    def verdict(self) -> tuple[bool | None, str]:
        """Whether the stepper reaches its claimed rate (and order against the number of steps), with why;
        ``None``: undecided (too few errors above the round-off floor to fit a rate)."""
        e = self.errors["sup"]
        bad = [f"{c:.3g}" for c, v in zip(self.controls, e) if not math.isfinite(float(v))]
        if bad:
            return False, f"non-finite error at the {self.control}s {', '.join(bad)}"
        fit, sfit = self.fits["sup"], self.step_fits["sup"]
        what = "tolerance" if self.control == "tolerance" else "step"
        if fit.exact:
            return True, f"errors at round-off at every {what} (max {max(e):.2e} ≤ floor {self.floor:.2e})"
        why = self.diagnosis()
        if why:
            return False, why
        msgs, ok = [], True
        claim = self.rate if self.control == "tolerance" else self.order
        if claim is not None:
            if math.isnan(fit.high):
                # two errors or fewer above the floor (a stepper more accurate than its claim): no rate can be
                # fitted, so none is refuted; tighter tolerances would not help, looser ones would
                return None, (f"undecided: too few errors above the round-off floor to estimate a rate (slope "
                              f"{fit.slope:.3f} from {sum(1 for v in e if v > self.floor)} of them; looser "
                              f"{self.control}s would decide)")
            slack = RATE_SLACK if self.control == "tolerance" else OWN_ORDER_SLACK
            reached = fit.reaches(claim, slack)
            ok &= reached
            msgs.append(f"error ~ {what}^{fit} (claimed {claim:g})")
        if self.order is not None and self.control == "tolerance":
            if math.isnan(sfit.high):
                msgs.append("too few distinct step counts to fit the order")
            else:
                ok &= sfit.reaches(self.order, OWN_ORDER_SLACK)
                msgs.append(f"error ~ (T/N)^{sfit} (claimed order {self.order:g})")
        elif math.isfinite(sfit.slope):
            msgs.append(f"error ~ (T/N)^{sfit}")
        return ok, "; ".join(msgs) or "no rate or order claimed"

    def __repr__(self) -> str:
        ok, msg = self.verdict()
        head = f"ToleranceStudy({self.stepper} on {self.problem}; {self.control}s swept)"
        rows = [f"  {self.control:>10}  {'steps':>6}  " + "  ".join(f"{n + ' error':>12}" for n in self.errors)]
        for i, c in enumerate(self.controls):
            rows.append(f"  {c:>10.3g}  {self.steps[i]:>6d}  " +
                        "  ".join(f"{float(self.errors[n][i]):>12.3e}" for n in self.errors))
        said = "undecided" if ok is None else ("holds" if ok else "FAILS")
        return "\n".join([head, *rows, f"  verdict: {said} — {msg}"])

    def _repr_html_(self) -> str | None:
        return render("tolerance_study_html", self)

    def to_dict(self) -> dict[str, Any]:
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        d["fits"] = {k: dataclasses.asdict(v) for k, v in self.fits.items()}
        d["step_fits"] = {k: dataclasses.asdict(v) for k, v in self.step_fits.items()}
        d["verdict"] = self.verdict()[0]
        return to_jsonable(d)


def tolerance_study(stepper: Adaptive, problem: Problem, controls: Sequence[float] | None = None, *,
                    on_run: Callable[[int], None] | None = None) -> ToleranceStudy:
    """Run ``stepper`` at every control (default: its own ``tolerances``, else :data:`DEFAULT_TOLERANCES`, or
    the problem's ``steps`` for ``control="step"``) and fit its errors (module docstring).  The problem must
    have an exact solution (:class:`verimono.InvalidProblem` otherwise).  ``on_run(k)`` is called after the
    ``k``-th run returned (the checks state their progress to the unit budget with it)."""
    if not isinstance(stepper, Adaptive):
        raise InvalidClaim(f"a tolerance study needs a verimono.Adaptive stepper, got {subject_name(stepper)}")
    if problem.exact is None:
        raise InvalidProblem(f"{problem.name} has no exact solution: a tolerance study measures errors against it")
    if controls is None:
        controls = stepper.tolerances or (DEFAULT_TOLERANCES if stepper.control == "tolerance" else problem.steps)
    controls = list(_controls(controls, stepper.control))
    t_out = np.linspace(0.0, problem.T, DENSE_POINTS) if stepper.dense else None
    runs, errs, scales = [], [], [1.0]
    for c in controls:
        run = own_run(stepper, problem, c, t_out=t_out)
        e, sc = own_errors(run, problem, t_out)
        runs.append(run)
        errs.append(e)
        scales.append(sc)
        if on_run is not None:
            on_run(len(runs))
    norms = list(errs[0])
    errors = {n: [e[n] for e in errs] for n in norms}
    precision = coarser(*[r.precision for r in runs])
    floor = roundoff_floor(max(s for s in scales if math.isfinite(s)), precision)
    if stepper.claim.solve_tol:
        floor += max(r.steps for r in runs) * stepper.claim.solve_tol * (1.0 + max(scales))
    steps = [r.steps for r in runs]
    mean_step = [problem.T / n for n in steps]
    fits = {n: fit_order(controls, errors[n], floor) for n in norms}
    step_fits = {n: _fit_distinct(mean_step, errors[n], floor) for n in norms}
    events = [r.events.tolist() for r in runs] if all(r.events is not None for r in runs) else None
    study = ToleranceStudy(problem.name, subject_name(stepper), stepper.control, controls, steps, errors, fits,
                           step_fits, stepper.rate, stepper.order, floor, [r.seconds for r in runs], events,
                           problem.T)
    return study


def _fit_distinct(h: list[float], e: list[float], floor: float) -> OrderFit:
    """:func:`fit_order` on the distinct step counts (a fit needs distinct abscissae: repeated counts are
    averaged in log), ``nan`` when fewer than two remain."""
    groups: dict[float, list[float]] = {}
    for hi, ei in zip(h, e):
        groups.setdefault(hi, []).append(ei)
    if len(groups) < 2:
        return OrderFit(math.nan, math.nan, math.nan, [], list(range(len(e))), [], False)
    hs = sorted(groups)
    es = [float(np.exp(np.mean(np.log(np.maximum(groups[k], 1e-300))))) for k in hs]
    return fit_order(hs, es, floor)


__all__ = ["Adaptive", "OwnRun", "ToleranceStudy", "tolerance_study", "own_run", "own_errors", "is_adaptive",
           "CONTROLS", "DEFAULT_TOLERANCES", "DENSE_POINTS", "RATE_SLACK", "OWN_ORDER_SLACK"]
