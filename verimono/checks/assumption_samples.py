"""What the assumption laws of :mod:`verimono.checks.assumptions` evaluate: points, times, step sizes, the
jumps of ``t ↦ J_λ(t) p``, and the outcome helpers they share.

The points ``p`` are where bugs live, not only where the solution goes: ``x0``; ``points`` draws around it
at the problem's scale ``r = 1 + |x0|`` and ``3r`` (today's design); **far points** ``x0 + 10^k r u``,
``k ∈`` :data:`FAR_DECADES` (a bound that holds near ``x0`` and breaks at ``|x| ≫ r``); and points near
the **kink** of every norm, ``0`` and ``10^{-k} r u``, ``k ∈`` :data:`KINK_DECADES`.  Points of ``dom F(t)``
on its boundary are ``J_λ(t) p`` of the far points.  Step sizes ``λ = T, T/10, T/100, T/1000`` reach points
ever closer to the boundary of the domain.  Times: ``times`` equally spaced ones, and (:meth:`_Samples.design`)
the times just after every jump of ``t ↦ J_λ(t) p`` found (:mod:`verimono.checks.jumps`), where a bound
that holds up to a jump is most likely to break: the law's own design, from which each "for all t" is
searched by count (:mod:`verimono.checks.engine.times`).

The far and kink points serve the laws whose bound grows with ``|x|`` or breaks near ``0`` ((A1), (LG),
(YB)); the domain's motion (A3) and the right limits (A2) are sampled at ``x0`` and the points around it
(``near``), whose projections already reach the boundary.  One :class:`_Samples` serves the five laws of one
battery (:func:`samples_for`): the jump search runs once.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..core.errors import OutsideDomain, UnverifiedSolution
from ..core.operator_protocol import accepts_times
from ..core.operators import dot_rows, resolvent_rows
from ..core.problem import Problem
from ..core.tolerances import GROWTH_FLAG
from ..execution.timeouts import note_progress
from ..records.results import PASSED, CheckResult
from .core import Outcome, run, subject_name
from .jumps import find_jumps
from .subjects import require_problem

EVIDENCE = "evidence from samples, not a proof"
#: step sizes λ (relative to T) used to reach points of dom F(t,·) ever closer to its boundary
LAMBDAS = (1.0, 1e-1, 1e-2, 1e-3)
#: far points x0 + 10^k r u (r = 1 + |x0|): a growth bound that holds near x0 and fails far from it
FAR_DECADES = (2, 4)
#: points 10^-k r u near the kink x = 0 of every norm (∂|x|, a norm ball's normal cone at its centre)
KINK_DECADES = (3, 6)
#: the times just after a jump t_j that the designs of the sup searches add: t_j + δ T
AFTER_JUMP = (1e-9, 1e-6, 1e-3)
#: (A2): the step size (relative to T) of the resolvents whose jumps are searched
A2_LAMBDAS = (1e-1,)


class _Samples:
    """The points, times and step sizes of one problem's assumption laws (module docstring)."""

    def __init__(self, problem: Problem, seed: int, points: int, times: int) -> None:
        rng = np.random.default_rng(seed)
        x0 = problem.x0[0] if problem.batched else problem.x0
        self.problem, self.op, self.T, self.seed = problem, problem.operator, problem.T, seed
        self.scale = r = 1.0 + float(np.linalg.norm(x0))
        base = rng.standard_normal((points, problem.dim))
        unit = base / np.linalg.norm(base, axis=1, keepdims=True)
        scales = np.where(np.arange(points) % 2 == 0, 1.0, 3.0)[:, None] * r
        extra = rng.standard_normal((len(FAR_DECADES) + len(KINK_DECADES), problem.dim))
        extra /= np.linalg.norm(extra, axis=1, keepdims=True)
        far = [x0 + 10.0 ** k * r * u for k, u in zip(FAR_DECADES, extra)]
        kink = [np.zeros(problem.dim)] + [10.0 ** -k * r * u for k, u in zip(KINK_DECADES, extra[len(FAR_DECADES):])]
        self.points = np.vstack([x0[None, :], x0 + scales * unit, *far, *kink])
        #: what each point is: "x0", "near", "far" or "kink"
        self.kinds = ["x0"] + ["near"] * points + ["far"] * len(far) + ["kink"] * len(kink)
        #: x0 and the points around it: what the domain's motion, the jumps and the right limits are
        #: sampled at (a far point's projection is a boundary point as the near ones' are)
        self.near = self.points[: 1 + points]
        self.times = np.linspace(0.0, problem.T, times)
        self.lambdas = [lam * problem.T for lam in LAMBDAS]
        self._jumps: tuple | None = None
        #: resolvents at sampled points that verimono's own solver could not verify (skipped)
        self.unverified = 0
        #: batches of the subject's resolvent calls made (stated to the unit's budget: :meth:`progress`)
        self.calls = 0

    def rows(self, P: np.ndarray, lam: float, t: float) -> np.ndarray:
        """``J_λ(t)`` of every row of ``P``; a row where verimono's own solver cannot verify the resolvent
        (a far point, one near a kink of an LCS operator) is NaN and counted in ``unverified``: no evidence
        either way there, and the law goes on at the others."""
        self.progress()
        try:
            return resolvent_rows(self.op, P, lam, t)
        except UnverifiedSolution:
            out = np.full(np.shape(P), np.nan)
            for i, p in enumerate(P):
                try:
                    out[i] = resolvent_rows(self.op, p[None, :], lam, t)[0]
                except UnverifiedSolution:
                    self.unverified += 1
            return out

    def rows_at_times(self, P: np.ndarray, lam: float, ts: np.ndarray) -> np.ndarray:
        """``J_λ(t) p`` of every row ``p`` of ``P`` at every time of ``ts``, ``(len(ts), len(P), n)``: one call
        when the operator takes a time per row (:func:`verimono.core.operator_protocol.accepts_times`: the
        catalog's, each row as a separate call gives it), else :meth:`rows` at each time."""
        if accepts_times(self.op):
            self.progress()
            return on_times(self.op, P, lam, ts)
        return np.stack([self.rows(P, lam, t) for t in ts.tolist()])

    def graph(self, t: float, lam: float, P: np.ndarray | None = None):
        """``(z, y, p)`` with ``z = J_λ p ∈ dom F(t)``, ``y = Y_λ p ∈ F(t, z)`` (rows of the points whose
        resolvent verimono could not verify dropped)."""
        P = self.points if P is None else P
        J = self.rows(P, lam, t)
        keep = np.all(np.isfinite(J), axis=1)
        J, P = J[keep], P[keep]
        return J, (P - J) / lam, P

    def jumps(self) -> tuple[list, dict]:
        """The jumps of ``t ↦ J_λ(t) p`` (``λ = A2_LAMBDAS[0]·T``, ``x0`` and the points around it), searched
        once."""
        if self._jumps is None:
            lam = A2_LAMBDAS[0] * self.T
            def at(t: float) -> np.ndarray:
                self.progress()
                return resolvent_rows(self.op, self.near, lam, t)
            def grid(times: np.ndarray) -> np.ndarray:     # every grid time in one call, the rows time-major
                for _ in range(len(times)):
                    self.progress()
                return on_times(self.op, self.near, lam, times)
            # ``at`` of each grid time, in their order (the same rows, the same calls of a stateful subject)
            self._jumps = find_jumps(at, self.T, values=grid if accepts_times(self.op) else None)
        return self._jumps

    def progress(self) -> None:
        """A call of the subject starts (:func:`verimono.execution.timeouts.note_progress`): a unit budget that
        stops the law between such calls of a subject slow at every one finds progress, not a call that never
        returns (a law that stated none counted as one call: failed)."""
        self.calls += 1
        note_progress(self.calls, True, "batches of resolvent calls")

    def design(self, lo: float = 0.0, hi: float | None = None) -> np.ndarray:
        """Times a sup search starts from: the sample times and the times just after every jump found."""
        hi = self.T if hi is None else hi
        jumps, _ = self.jumps()
        after = [j.b + d * self.T for j in jumps for d in AFTER_JUMP] + [j.b for j in jumps]
        ts = np.r_[self.times, after]
        return np.unique(ts[(ts >= lo) & (ts <= hi)])

    def x_range(self) -> list[float]:
        """The range of ``|p|`` over the sampled points."""
        n = np.linalg.norm(self.points, axis=1)
        return [float(n.min()), float(n.max())]


#: the samples of the batteries run last, ``(id(problem), settings) → (problem, samples)``: the laws of one
#: battery share them (the jump search runs once); at most :data:`MEMO_SIZE` are kept
_MEMO: dict[tuple, tuple[Any, "_Samples"]] = {}
MEMO_SIZE = 4


def samples_for(problem: Problem, seed: int, points: int, times: int) -> _Samples:
    """The :class:`_Samples` of ``problem`` for these settings (made once per problem and settings)."""
    key = (id(problem), seed, points, times)
    hit = _MEMO.get(key)
    if hit is not None and hit[0] is problem:
        return hit[1]
    samples = _Samples(problem, seed, points, times)
    _MEMO.pop(key, None)
    _MEMO[key] = (problem, samples)
    while len(_MEMO) > MEMO_SIZE:
        _MEMO.pop(next(iter(_MEMO)))
    return samples


def run_assumption(decl: Any, problem: Problem, *, seed: int = 0, points: int = 12, times: int = 7) -> CheckResult:
    """An assumption's law on ``problem``: its evaluator on the samples of ``seed`` (``points`` points around
    ``x0`` besides the far and kink points, ``times`` times in ``[0, T]``; shared by the laws of a battery)."""
    require_problem(problem)
    samples = samples_for(problem, seed, points, times)
    before = samples.unverified
    rec = run(decl, subject_name(problem), lambda: decl.evaluate(samples), problem=problem, seed=seed)
    if samples.unverified > before:      # points skipped: verimono's own solver could not verify them
        rec.details["unverified_points"] = samples.unverified - before
    return rec


def min_norm_or_none(op, z, t):
    """``F^0(t, z)``, or ``None`` where ``z`` is outside the domain or verimono's own solver cannot verify
    it there (a limit of the harness at one point — a far point, one near a kink — is no evidence either way,
    and does not stop the law at the others)."""
    try:
        return np.asarray(op.min_norm(z, t), dtype=float)
    except (OutsideDomain, UnverifiedSolution):
        return None


def on_times(op, P: np.ndarray, lam: float, ts: np.ndarray) -> np.ndarray:
    """``J_λ(t) p`` for every time of ``ts`` and row of ``P``, ``(len(ts), len(P), n)``, in one call of an
    operator that takes a time per row (the rows time-major: ``P`` repeated at each time)."""
    m = len(P)
    X = np.tile(np.asarray(P, dtype=float), (len(ts), 1))
    return resolvent_rows(op, X, lam, np.repeat(np.asarray(ts, dtype=float), m)).reshape(len(ts), m, -1)


def norms(V: np.ndarray) -> np.ndarray:
    """``|v|`` of every row: ``sqrt(v·v)`` with the BLAS dot of each row, the bits of ``float(np.linalg.norm(v))``
    of the row alone."""
    return np.sqrt(dot_rows(V, V))


def f0_norms(op, Z: np.ndarray, ts: np.ndarray, mu: float, how: bool = False):
    """:func:`f0_norm` of every row ``z_i`` at ``t_i`` of an operator that takes a time per row, NaN where it is
    ``None`` (a row outside the domain: the rows then one by one, as :func:`f0_norm` takes them); ``how``: with
    what it was computed too, as :func:`f0_norm` says it."""
    try:
        out, by = norms(np.asarray(op.min_norm(Z, ts), dtype=float)), "min_norm"
    except (OutsideDomain, UnverifiedSolution):
        vals = [f0_norm(op, z, t, mu)[0] for z, t in zip(Z, ts.tolist())]
        out, by = np.array([np.nan if v is None else v for v in vals], dtype=float), "min_norm"
    except NotImplementedError:
        out, by = norms(np.asarray(op.yosida(Z, mu, ts), dtype=float)), "yosida lower estimate"
    return (out, by) if how else out


def min_norms(op, Z: np.ndarray, t: float) -> list:
    """:func:`min_norm_or_none` of every row of ``Z`` at ``t``: one call with the time on every row when the
    operator takes a time per row (each row as its own call gives it; a row outside the domain: the rows one by
    one), else one call per row."""
    if accepts_times(op) and len(Z):
        try:
            return list(np.asarray(op.min_norm(Z, np.full(len(Z), t)), dtype=float))
        except (OutsideDomain, UnverifiedSolution):
            pass
    return [min_norm_or_none(op, zi, t) for zi in Z]


def f0_norm(op, z, t, mu):
    """``|F^0(t, z)|``, or the lower estimate ``|Y_μ z|`` when the operator has no ``min_norm``."""
    try:
        v = min_norm_or_none(op, z, t)
        return None if v is None else float(np.linalg.norm(v)), "min_norm"
    except NotImplementedError:
        return float(np.linalg.norm(op.yosida(z, mu, t))), "yosida lower estimate"


def sampled(name: str, worst: float, counter: dict | None, details: dict, failed: Callable[[dict], str],
            passed: str) -> Outcome:
    """The outcome of a sampled ratio ``worst`` against the bound 1: ``failed(counter)`` is the message when
    a sample exceeds it (or the ratio is not a number), ``passed`` otherwise."""
    out = Outcome(float(worst), counter=dict(counter or {}), details=details, message=passed)
    if out.failed:
        out.counter["message"] = failed(counter) if counter else f"{name}: the sampled ratio is {worst}"
    return out


def growth(value: float, evidence: dict, details: dict, failed: str, passed: str) -> Outcome:
    """The evidence-from-growth outcome of (LG) and (YB) without a stated function: a sampled ratio growing
    more than ``GROWTH_FLAG``-fold as ``λ`` shrinks 1000-fold is evidence the bound fails."""
    if value > GROWTH_FLAG:
        return Outcome(value, bound=GROWTH_FLAG, counter={**evidence, "message": failed}, details=details)
    return Outcome(None, status=PASSED, details=details, message=passed)


__all__ = ["on_times", "norms", "f0_norms", "min_norms", "samples_for", "run_assumption", "EVIDENCE", "LAMBDAS", "FAR_DECADES", "KINK_DECADES", "AFTER_JUMP", "A2_LAMBDAS",
           "min_norm_or_none", "f0_norm", "sampled", "growth"]
