"""Operator laws: the paper's Proposition ``prop:maxmon-resolvent-Yosida`` (items i–vi) as checks.

Every law is an inequality ``lhs ≤ rhs`` that holds exactly for a maximal monotone ``F(t,·)``; in
floating point it is accepted when ``lhs ≤ rhs + slack``, with ``slack`` built from
:func:`verimono.tolerances.tolerance` of the magnitudes involved (divided by ``λ`` where a Yosida value
``(x - J_λ x)/λ`` amplifies the resolvent's error).  The recorded ratio of a sample is
``lhs / (rhs + slack)`` and every check's bound is 1: ratios near 1 mean "tight" (e.g.
``|J_λx - J_λy|² / ⟨J_λx - J_λy, x - y⟩`` for firm nonexpansiveness), and for laws with ``rhs = 0``
(identities, membership) the ratio counts violations in units of the stated tolerance.

Samples ``(x1, x2, λ, μ, ν, t)``: ``examples`` NumPy draws from the distribution of :func:`law_samples`
(:func:`verimono.checks.sweep.law_draws`, seeded by the record's seed) first, then a hypothesis search
(:func:`law_samples`) that starts from the simplest samples, climbs toward violations through
:func:`hypothesis.target` on the ratio and shrinks a failing sample — with ``examples // HYPOTHESIS_SHARE``
examples when the draws found nothing, with all ``examples`` when one broke the law (a draw hypothesis
does not meet again is shrunk greedily), then the scale sweep.  Hypothesis's engine costs about 1.7 ms
per example here against about 0.02 ms per NumPy draw.  Points known to
lie in ``dom F(t,·)`` are produced as ``x = J_ν x1``, which comes with the graph element
``y0 = Y_ν x1 ∈ F(t, x)`` (item v) — so the minimal-section laws need no knowledge of the domain.

Each ``check_<law>(op, *, seed=None, examples=None, horizon=1.0, sample=None)`` returns one
:class:`verimono.CheckResult`; it never prints or asserts.  A member the operator does not provide
(``NotImplementedError``) makes the check *skipped*; an exception on a sample is a failure of that sample.
``sample=`` evaluates one given :class:`Sample` (or its dict from a counterexample) without hypothesis,
which is how a failure is replayed and how outer ``@given`` tests drive the laws.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import random
import time
from typing import Any, Callable, Iterator

import numpy as np
import hypothesis
import hypothesis.errors
from hypothesis import HealthCheck, Phase, Verbosity, given, settings
from hypothesis import strategies as st

from ..errors import VerimonoError
from ..operators import Operator
from ..profiles import UnknownProfile, active_profile, get_profile
from ..errors import InvalidCheckArgument, UnitTimeout, UnverifiedSolution
from ..results import FAILED, PASSED, SKIPPED, UNDECIDED, CheckResult, Report
from ..timeouts import current_budget, time_limit
from .core import Law, Member, Outcome, law as _declare, laws_of, run as _run_law
from ..strategies import points, step_sizes, times
from .._reproducible import no_local_constants
from .prox_laws import VALUE_LAWS
from .sweep import law_draws, shrink as _shrink, sweep_count, sweep_samples
from ..tolerances import EPS, LIMIT_FLOOR, STALL_RATIO, STALL_WINDOW, tolerance

#: hypothesis examples per law when ``examples`` is not given and the active profile is not one of
#: verimono's (a user's own hypothesis profile); otherwise the profile's ``law_examples`` governs
#: (:func:`default_examples`)
DEFAULT_EXAMPLES = 50
#: every law's ratio ``lhs / (rhs + slack)`` must not exceed this
BOUND = 1.0
#: ratios handed to hypothesis.target are clipped to this (observations must be finite)
_TARGET_CAP = 1e12
#: tolerance multiples tried when grading a failed membership test ``y ∈ F(t, x)``
_GRADES = tuple(10.0 ** k for k in range(0, 13, 2))


# -- samples ----------------------------------------------------------------------------------------

#: above this dimension the points of a sample are drawn by NumPy from a seed (and a kind) that hypothesis
#: draws and shrinks: hypothesis draws each coordinate through its byte buffer, which cannot hold vectors of
#: ~500 floats (``Unsatisfiable``) — image- and PDE-sized operators (10^4–10^6 unknowns) need NumPy
NUMPY_DIM = 64
#: kinds of NumPy-drawn points: dense uniform in ``[-scale, scale]^n``, sparse (90% exact zeros: the kinks
#: of norms and boxes), and the zero vector (the kink of every norm)
NUMPY_KINDS = ("uniform", "sparse", "zero")


def numpy_point(n: int, recipe: dict[str, Any]) -> np.ndarray:
    """The point of ``R^n`` a recipe ``{"seed", "kind", "scale"}`` stands for (deterministic)."""
    kind, scale = recipe["kind"], float(recipe["scale"])
    if kind == "zero":
        return np.zeros(n)
    rng = np.random.default_rng(int(recipe["seed"]))
    x = rng.uniform(-scale, scale, n)
    if kind == "sparse":
        x[rng.random(n) < 0.9] = 0.0
    return x


@dataclasses.dataclass(frozen=True)
class Sample:
    """Inputs of one evaluation: points ``x1, x2``, step sizes ``λ = lam, μ = mu, ν = nu`` and time ``t``.

    ``recipe`` (large dimensions only) says how NumPy drew the points, so that a sample of a million
    coordinates is recorded and replayed by a few numbers instead of its coordinates."""

    x1: np.ndarray
    x2: np.ndarray
    lam: float
    mu: float
    nu: float
    t: float
    recipe: dict[str, Any] | None = dataclasses.field(default=None, compare=False)

    def to_dict(self) -> dict[str, Any]:
        scalars = {"lam": self.lam, "mu": self.mu, "nu": self.nu, "t": self.t}
        if self.recipe is not None:
            return {"recipe": dict(self.recipe), **scalars}
        return {"x1": self.x1.tolist(), "x2": self.x2.tolist(), **scalars}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "Sample":
        if "recipe" in d:
            return _from_recipe(d["recipe"], float(d["lam"]), float(d["mu"]), float(d["nu"]), float(d["t"]))
        return cls(np.asarray(d["x1"], dtype=float), np.asarray(d["x2"], dtype=float), float(d["lam"]),
                   float(d["mu"]), float(d["nu"]), float(d["t"]))

    def __repr__(self) -> str:
        if self.recipe is not None:
            return (f"Sample.from_dict({{'recipe': {self.recipe!r}, 'lam': {self.lam!r}, 'mu': {self.mu!r}, "
                    f"'nu': {self.nu!r}, 't': {self.t!r}}})")
        f = lambda a: np.array2string(a, precision=17, separator=", ")  # noqa: E731 - exact replay
        return (f"Sample(x1={f(self.x1)}, x2={f(self.x2)}, lam={self.lam!r}, mu={self.mu!r}, "
                f"nu={self.nu!r}, t={self.t!r})")


def _from_recipe(recipe: dict[str, Any], lam: float, mu: float, nu: float, t: float) -> Sample:
    n = int(recipe["n"])
    x1 = numpy_point(n, recipe["x1"])
    if recipe.get("near"):
        x2 = x1 + numpy_point(n, recipe["x2"])
    else:
        x2 = numpy_point(n, recipe["x2"])
    return Sample(x1, x2, lam, mu, nu, t, recipe=recipe)


def _numpy_recipes(scale: float) -> st.SearchStrategy[dict[str, Any]]:
    return st.fixed_dictionaries({"seed": st.integers(0, 2 ** 32 - 1), "kind": st.sampled_from(NUMPY_KINDS),
                                  "scale": st.sampled_from([scale, scale / 10.0, scale * 1e-4])})


def law_samples(n: int, horizon: float = 1.0) -> st.SearchStrategy[Sample]:
    """Samples for the laws on ``R^n``: ``x1`` from :func:`verimono.strategies.points`, ``x2`` either
    independent or within ``10^-2`` of ``x1`` (local violations), ``λ, μ, ν ∈ [10^-3, 10]`` and
    ``t ∈ [0, horizon]``; everything shrinks toward 0, 1 and ``t = 0``.  The strategy is built once per
    ``(n, horizon)`` (building strategies inside every draw cost more than evaluating the law).

    For ``n > NUMPY_DIM`` the points come from :func:`numpy_point` (seed, kind and scale drawn and shrunk by
    hypothesis; shrinking goes toward the zero vector and seed 0), the step sizes and time as above."""
    return _law_samples(int(n), float(horizon))


@functools.lru_cache(maxsize=128)
def _law_samples(n: int, horizon: float) -> st.SearchStrategy[Sample]:
    steps, when, coin = step_sizes(), times(horizon), st.booleans()
    if n > NUMPY_DIM:
        @st.composite
        def _recipe(draw):
            near = draw(coin, label="x2 near x1")
            recipe = {"n": n, "near": near, "x1": draw(_numpy_recipes(10.0), label="x1"),
                      "x2": draw(_numpy_recipes(1e-2 if near else 10.0), label="x2")}
            lam, mu, nu = (draw(steps, label=k) for k in ("lam", "mu", "nu"))
            return _from_recipe(recipe, lam, mu, nu, draw(when, label="t"))
        return _recipe()
    pts, near = points(n), points(n, 1e-2)

    @st.composite
    def _draw(draw):
        x1 = draw(pts, label="x1")
        if draw(coin, label="x2 near x1"):
            x2 = x1 + draw(near, label="x2 - x1")
        else:
            x2 = draw(pts, label="x2")
        lam, mu, nu = (draw(steps, label=k) for k in ("lam", "mu", "nu"))
        return Sample(x1, x2, lam, mu, nu, draw(when, label="t"))
    return _draw()


# -- evaluation helpers -----------------------------------------------------------------------------

class _BadOutput(Exception):
    """An operator member returned something that is not a finite point of the right shape."""


def _point(value: Any, like: np.ndarray, member: str) -> np.ndarray:
    y = np.asarray(value, dtype=float)
    if y.shape != like.shape:
        raise _BadOutput(f"{member} returned shape {y.shape} for a point of shape {like.shape}")
    if not np.all(np.isfinite(y)):
        raise _BadOutput(f"{member} returned non-finite values {y}")
    return y


def _listed(a: np.ndarray) -> Any:
    """A point for a counterexample: its coordinates, or for ``n > NUMPY_DIM`` a summary (the sample's
    recipe replays it; a million coordinates per record would swamp the report)."""
    if a.size <= NUMPY_DIM:
        return a.tolist()
    return f"<{a.size} values, |.|_inf = {float(np.max(np.abs(a))):.6g}>"


def _J(op: Operator, x: np.ndarray, lam: float, t: float) -> np.ndarray:
    return _point(op.resolvent(x.copy(), lam, t), x, "resolvent")


def _F0(op: Operator, x: np.ndarray, t: float) -> np.ndarray:
    return _point(op.min_norm(x.copy(), t), x, "min_norm")


def _nrm(v: np.ndarray) -> float:
    """Euclidean norm without underflow: sampled points may differ by 1e-250, whose square is 0."""
    v = np.asarray(v, dtype=float)
    m = float(np.max(np.abs(v), initial=0.0))
    return 0.0 if m == 0.0 or not np.isfinite(m) else m * float(np.linalg.norm(v / m))


def _tol(*arrays: Any) -> float:
    return tolerance(*arrays)


def _graded_membership(op: Operator, x: np.ndarray, y: np.ndarray, t: float, tol: float) -> float:
    """Smallest tried multiple ``g`` of ``tol`` with ``y ∈ F(t, x)`` up to ``g·tol`` (``inf`` if none)."""
    for g in _GRADES:
        if op.contains(x.copy(), y.copy(), t, g * tol):
            return g
    return math.inf


def _domain_pair(op: Operator, s: Sample) -> tuple[np.ndarray, np.ndarray, float]:
    """``x = J_ν x1 ∈ dom F(t,·)`` with ``y0 = Y_ν x1 ∈ F(t, x)`` and the tolerance of ``x``."""
    x = _J(op, s.x1, s.nu, s.t)
    return x, (s.x1 - x) / s.nu, _tol(s.x1, x)


# -- the laws ---------------------------------------------------------------------------------------

def _resolvent_single_valued(op, s):
    x = s.x1.copy()
    a = _point(op.resolvent(x, s.lam, s.t), s.x1, "resolvent")
    moved = _nrm(x - s.x1)
    b = _J(op, s.x1, s.lam, s.t)
    tau = _tol(s.x1, a, b)
    return Outcome.compare(_nrm(a - b) + (math.inf if moved > 0 else 0.0), 0.0, tau,
                 "|J_λx - J_λx| over two calls" + (f" (the call modified its input by {moved:.3g})" if moved else ""),
                 {"J_first": _listed(a), "J_second": _listed(b), "input_modified_by": moved})


def _resolvent_nonexpansive(op, s):
    a, b = _J(op, s.x1, s.lam, s.t), _J(op, s.x2, s.lam, s.t)
    tau = _tol(s.x1, s.x2, a, b)
    return Outcome.compare(_nrm(a - b), _nrm(s.x1 - s.x2), 4 * tau, "|J_λx1 - J_λx2| ≤ |x1 - x2|",
                 {"J1": _listed(a), "J2": _listed(b)})


def _resolvent_firmly_nonexpansive(op, s):
    a, b = _J(op, s.x1, s.lam, s.t), _J(op, s.x2, s.lam, s.t)
    dJ, dx = a - b, s.x1 - s.x2
    tau = _tol(s.x1, s.x2, a, b)
    return Outcome.compare(float(dJ @ dJ), float(dJ @ dx), 4 * tau * (_nrm(dJ) + _nrm(dx) + tau),
                 "|J_λx1 - J_λx2|² ≤ ⟨J_λx1 - J_λx2, x1 - x2⟩", {"J1": _listed(a), "J2": _listed(b)})


def _resolvent_in_domain(op, s):
    a = _J(op, s.x1, s.lam, s.t)
    p = _point(op.project_domain(a.copy(), s.t), a, "project_domain")
    return Outcome.compare(_nrm(p - a), 0.0, 2 * _tol(s.x1, a), "dist(J_λx, cl dom F(t,·)) = 0",
                 {"J": _listed(a), "proj_dom_J": _listed(p)})


def _resolvent_identity(op, s):
    a = _J(op, s.x1, s.lam, s.t)
    r = s.mu / s.lam
    z = r * s.x1 + (1.0 - r) * a
    b = _J(op, z, s.mu, s.t)
    tau = _tol(s.x1, a, z)
    return Outcome.compare(_nrm(a - b), 0.0, tau * (4.0 + abs(1.0 - r)),
                 "J_λx = J_μ((μ/λ)x + (1 - μ/λ)J_λx)", {"J_lam": _listed(a), "J_mu_of_z": _listed(b), "z": _listed(z)})


def _resolvent_limit(op, s):
    x, y0, tau = _domain_pair(op, s)
    worst = None
    for k in range(6):
        lam = s.lam * 4.0 ** (-k)
        d = _nrm(_J(op, x, lam, s.t) - x)
        ev = Outcome.compare(d, lam * _nrm(y0), tau * (4.0 + lam / s.nu), "|J_λx - x| ≤ λ|y| for x = J_νx1, y = Y_νx1 ∈ F(x)",
                   {"x": _listed(x), "y": _listed(y0), "lam_at_worst": lam})
        if worst is None or not ev.ratio <= worst.ratio:
            worst = ev
    return worst


def _monotone(op, s):
    a, b = _J(op, s.x1, s.lam, s.t), _J(op, s.x2, s.mu, s.t)
    ya, yb = (s.x1 - a) / s.lam, (s.x2 - b) / s.mu
    dx, dy = a - b, ya - yb
    ex = 2 * _tol(s.x1, s.x2, a, b)
    ey = ex * (1.0 / s.lam + 1.0 / s.mu)
    return Outcome.compare(-float(dx @ dy), 0.0, 2 * (ex * _nrm(dy) + ey * _nrm(dx) + ex * ey),
                 "⟨x_a - x_b, y_a - y_b⟩ ≥ 0 for (x_a, y_a) = (J_λx1, Y_λx1), (x_b, y_b) = (J_μx2, Y_μx2)",
                 {"xa": _listed(a), "ya": _listed(ya), "xb": _listed(b), "yb": _listed(yb)})


def _yosida_lipschitz(op, s):
    a, b = _J(op, s.x1, s.lam, s.t), _J(op, s.x2, s.lam, s.t)
    dY = ((s.x1 - a) - (s.x2 - b)) / s.lam
    return Outcome.compare(s.lam * _nrm(dY), _nrm(s.x1 - s.x2), 4 * _tol(s.x1, s.x2, a, b),
                 "λ|Y_λx1 - Y_λx2| ≤ |x1 - x2|", {"J1": _listed(a), "J2": _listed(b)})


def _yosida_monotone(op, s):
    a, b = _J(op, s.x1, s.lam, s.t), _J(op, s.x2, s.lam, s.t)
    dx = s.x1 - s.x2
    dY = (dx - (a - b)) / s.lam
    return Outcome.compare(-float(dY @ dx), 0.0, 4 * _tol(s.x1, s.x2, a, b) * _nrm(dx) / s.lam,
                 "⟨Y_λx1 - Y_λx2, x1 - x2⟩ ≥ 0", {"J1": _listed(a), "J2": _listed(b)})


def _yosida_in_graph(op, s):
    a = _J(op, s.x1, s.lam, s.t)
    y = (s.x1 - a) / s.lam
    tol = _tol(s.x1, a, s.lam * y) * (2.0 + 2.0 / s.lam)
    g = _graded_membership(op, a, y, s.t, tol)
    return Outcome.compare(g, 0.0, 1.0, "Y_λx ∈ F(t, J_λx) (ratio: tolerance multiple needed)",
                 {"J": _listed(a), "Y": _listed(y), "tol": tol})


def _yosida_nonincreasing(op, s):
    lo, hi = sorted((s.lam, s.mu))
    if hi == lo:
        hi = 2.0 * lo
    a, b = _J(op, s.x1, lo, s.t), _J(op, s.x1, hi, s.t)
    ylo, yhi = (s.x1 - a) / lo, (s.x1 - b) / hi
    tau = _tol(s.x1, a, b)
    return Outcome.compare(_nrm(yhi), _nrm(ylo), 4 * tau * (1.0 / lo + 1.0 / hi),
                 "|Y_μx| ≤ |Y_λx| for λ ≤ μ", {"lam": lo, "mu": hi, "Y_lam": _listed(ylo), "Y_mu": _listed(yhi)})


def _yosida_bounded_by_min_norm(op, s):
    x, _, tau = _domain_pair(op, s)
    f0 = _F0(op, x, s.t)
    a = _J(op, x, s.lam, s.t)
    y = (x - a) / s.lam
    return Outcome.compare(_nrm(y), _nrm(f0), 4 * _tol(x, a) / s.lam + 2 * tau / s.lam + _tol(f0),
                 "|Y_λx| ≤ |F^0(t, x)| for x = J_νx1 ∈ dom F", {"x": _listed(x), "Y": _listed(y), "F0": _listed(f0)})


def _yosida_limit(op, s):
    x, _, tau = _domain_pair(op, s)
    f0 = _nrm(_F0(op, x, s.t))
    tx = _tol(x)
    floor = 2 * LIMIT_FLOOR * tx / (1.0 + f0)
    lam = max(s.lam, floor)
    gaps, lams = [], []
    while True:
        a = _J(op, x, lam, s.t)
        y = _nrm((x - a) / lam)
        gap, slack = abs(f0 - y), _tol(f0, y) + 2 * tx / lam
        gaps.append(gap)
        lams.append(lam)
        info = {"x": _listed(x), "|F0|": f0, "lams": lams, "gaps": gaps}
        if gap <= slack:
            return Outcome.compare(gap, 0.0, slack, "|Y_λx| → |F^0(t, x)| as λ → 0 (gap within tolerance)", info)
        if y <= 2 * tx / lam and _only_within_rounding(op, x, np.zeros_like(x), s.t, 2 * tx):
            return Outcome.compare(0.0, 0.0, slack, "|Y_λx| → 0: x is within rounding, not exactly at, a zero of F(t,·) "
                         "(F^0 is ill-conditioned there; sample inconclusive)", info, inconclusive=True)
        if lam / 2 < floor:
            break
        lam /= 2
    w = min(STALL_WINDOW, len(gaps) - 1)
    if w == 0:   # one λ above the rounding floor: the gap can be neither closed nor seen shrinking
        return Outcome.compare(gaps[-1], gaps[-1], slack, "|Y_λx| → |F^0(t, x)| (no room to halve λ; sample inconclusive)",
                     info, inconclusive=True)
    if _kink_within(op, x, s.t, KINK_PROBE * lams[-1] * (1.0 + f0)):
        return Outcome.compare(0.0, 0.0, slack, f"|Y_λx| → |F^0(t, x)|: F^0 jumps within {KINK_PROBE * lams[-1] * (1.0 + f0):.2g} "
                     "of x, where the gap closes only below the sweep's rounding floor λ = "
                     f"{lams[-1]:.3g} (sample inconclusive)", info, inconclusive=True)
    if _closing_below_floor(gaps, 8 * EPS * (1.0 + float(np.max(np.abs(x)))) / lams[-1]):
        return Outcome.compare(0.0, 0.0, slack, "|Y_λx| → |F^0(t, x)|: the gap is still closing, ever faster, at the rounding "
                     "floor (a kink of F closer to x than λ|F^0| resolves; sample inconclusive)", info,
                     inconclusive=True)
    # the gap exceeds the rounding floor: it must at least still be shrinking
    return Outcome.compare(gaps[-1], STALL_RATIO * gaps[-1 - w], _tol(gaps[-1], gaps[-1 - w]),
                 f"|Y_λx| → |F^0(t, x)|: gap ||F^0| - |Y_λx|| above tolerance {slack:.3g} must still shrink over "
                 f"the last {w} halvings down to λ = {lams[-1]:.3g}", info)


#: a stalled Yosida gap is inconclusive when F^0 jumps within KINK_PROBE·λ_floor·(1 + |F^0|) of x: at distance
#: d from a kink of F the gap closes once λ|F^0| ≲ d (soft thresholding: λc < d), so a kink nearer than
#: that is resolved only below the floor (a 2^-23 offset from a kink of a shifted ∂‖·‖₁, found by a
#: thorough run); the factor 4 covers the constant of that estimate
KINK_PROBE = 4.0


def _kink_within(op, x: np.ndarray, t: float, delta: float) -> bool:
    """Whether ``F^0(t, ·)`` jumps (changes by more than half its size) or leaves its domain within ``delta``
    of ``x``, probed along the coordinate axes and the direction of ``F^0(t, x)``."""
    f0 = _F0(op, x, t)
    n0 = _nrm(f0)
    dirs = list(np.eye(x.size))
    if n0 > 0:
        dirs.append(f0 / n0)
    for d in dirs:
        for sgn in (1.0, -1.0):
            try:
                g = _F0(op, x + sgn * delta * d, t)
            except (VerimonoError, ArithmeticError, ValueError):   # OutsideDomain among them
                return True
            if _nrm(g - f0) > 0.5 * max(n0, _nrm(g)):
                return True
    return False


def _closing_below_floor(gaps: list[float], noise: float) -> bool:
    """Whether the gaps ``|F^0| - |Y_λx|`` of the last halvings of ``λ`` close ever faster: the last three
    decrements each at least double (far above the rounding ``noise``) and, continued at that rate, close
    the gap within ``STALL_WINDOW`` more halvings.

    At ``x`` at distance ``d`` from a kink of ``F`` the gap only closes once ``λ ≲ d/|F^0|``: for
    ``∂|·|₁`` at ``x = (1, 1e-8)`` it is ``√2 - √(1 + (1e-8/λ)²)``, whose decrements grow 4-fold per halving
    down to ``λ = 1e-8``, below the rounding floor of the sweep.  A gap ``c + aλ^p`` (a wrong ``F^0`` or a
    wrong ``λ``, ``c > 0``) has decrements shrinking by ``2^-p`` per halving, and a constant gap none.  Near a
    kink the decrements are those of ``|Y_λx|`` alone, so such a sample is inconclusive for a wrong ``F^0``
    too: it fails at points away from kinks, which the search reaches first."""
    if len(gaps) < 4:
        return False
    d = [gaps[-4] - gaps[-3], gaps[-3] - gaps[-2], gaps[-2] - gaps[-1]]
    if not (d[0] > noise and d[1] >= 2 * d[0] and d[2] >= 2 * d[1]):
        return False
    r, step, closed = min(d[1] / d[0], d[2] / d[1]), d[2], 0.0
    for _ in range(STALL_WINDOW):
        step *= r
        closed += step
        if closed >= gaps[-1]:
            return True
    return False


def _min_norm_in_graph(op, s):
    x, _, _ = _domain_pair(op, s)
    f0 = _F0(op, x, s.t)
    tol = 2 * _tol(x, f0)
    g = _graded_membership(op, x, f0, s.t, tol)
    return Outcome.compare(g, 0.0, 1.0, "F^0(t, x) ∈ F(t, x) (ratio: tolerance multiple needed)",
                 {"x": _listed(x), "F0": _listed(f0), "tol": tol})


def _min_norm_least(op, s):
    x, y0, tau = _domain_pair(op, s)
    f0 = _F0(op, x, s.t)
    info = {"x": _listed(x), "y": _listed(y0), "F0": _listed(f0)}
    try:   # y0 must be certified in F(t, x) where that can be tested (else yosida_in_graph fails)
        if not op.contains(x.copy(), y0.copy(), s.t, _tol(x, y0) * (2.0 + 2.0 / s.nu)):
            return Outcome.compare(0.0, 0.0, 1.0, "uncertified y0 ∉ F(t, x) (contains rejects it): sample inconclusive", info,
                         inconclusive=True)
    except NotImplementedError:
        pass
    slack = 4 * tau / s.nu + _tol(f0)
    if _nrm(f0) > _nrm(y0) + slack and _only_within_rounding(op, x, y0, s.t, _tol(x, y0) * (2.0 + 2.0 / s.nu)):
        return Outcome.compare(0.0, 0.0, 1.0, "y0 ∈ F(t, x') only for x' within rounding of x, near a jump of F^0: "
                     "sample inconclusive", info, inconclusive=True)
    return Outcome.compare(_nrm(f0), _nrm(y0), slack, "|F^0(t, x)| ≤ |y| for x = J_νx1 and y = Y_νx1 ∈ F(t, x)", info)


def _only_within_rounding(op, x, y, t, tol) -> bool:
    """Whether ``y ∈ F(t, x)`` holds up to ``tol`` but not exactly: ``x`` is within rounding of a point
    where ``F`` jumps (a kink of ``|·|`` reached through rounded shifts, ``x + Φ = 1e-17``), where ``F^0`` is
    ill-conditioned and the λ → 0 limit and least-norm laws cannot be observed.  An exact kink (``x = 0``)
    is not such a point, so a wrong ``F^0`` there is still caught; without ``contains`` nothing is excused."""
    try:
        return bool(op.contains(x.copy(), y.copy(), t, tol)) and not op.contains(x.copy(), y.copy(), t, 0.0)
    except NotImplementedError:
        return False


_MIN_NORM, _CONTAINS, _PROJECT = Member("min_norm"), Member("contains"), Member("project_domain")

#: law name -> (evaluator, the paper's item, required operator members), in the order they run
_TABLE = [
    ("resolvent_single_valued", _resolvent_single_valued, "prop:maxmon-resolvent-Yosida i–ii", ()),
    ("resolvent_nonexpansive", _resolvent_nonexpansive, "prop:maxmon-resolvent-Yosida ii", ()),
    ("resolvent_firmly_nonexpansive", _resolvent_firmly_nonexpansive, "prop:maxmon-resolvent-Yosida ii (A1)", ()),
    ("resolvent_in_domain", _resolvent_in_domain, "range J_λ = dom F", (_PROJECT,)),
    ("resolvent_identity", _resolvent_identity, "resolvent identity", ()),
    ("resolvent_limit", _resolvent_limit, "prop:maxmon-resolvent-Yosida iii", ()),
    ("monotone", _monotone, "(A1)", ()),
    ("yosida_lipschitz", _yosida_lipschitz, "prop:maxmon-resolvent-Yosida iv", ()),
    ("yosida_monotone", _yosida_monotone, "prop:maxmon-resolvent-Yosida iv", ()),
    ("yosida_in_graph", _yosida_in_graph, "prop:maxmon-resolvent-Yosida v", (_CONTAINS,)),
    ("yosida_nonincreasing", _yosida_nonincreasing, "prop:maxmon-resolvent-Yosida vi", ()),
    ("yosida_bounded_by_min_norm", _yosida_bounded_by_min_norm, "prop:maxmon-resolvent-Yosida vi", (_MIN_NORM,)),
    ("yosida_limit", _yosida_limit, "prop:maxmon-resolvent-Yosida vi", (_MIN_NORM,)),
    ("min_norm_in_graph", _min_norm_in_graph, "minimal section F^0 = proj(0, F(x))", (_MIN_NORM, _CONTAINS)),
    ("min_norm_least", _min_norm_least, "minimal section F^0 = proj(0, F(x))", (_MIN_NORM,)),
]
_VALUE = Member("value")
#: the value laws (verimono.checks.prox_laws): they need g, given as ``value`` (operator_from_prox)
_TABLE += [(name, fn, label, (_VALUE,)) for name, fn, label in VALUE_LAWS]
for _name_, _fn, _item, _needs in _TABLE:
    _declare(_name_, _item, subject="operator", requires=_needs)(_fn)

#: the operator laws (:class:`verimono.checks.core.Law`, evaluator: one :class:`Sample` -> :class:`Outcome`)
LAWS: dict[str, Law] = laws_of("operator")


# -- the driver -------------------------------------------------------------------------------------

class _Violation(Exception):
    """Raised inside the hypothesis test when a sample breaks the law (so hypothesis shrinks it)."""


#: marks an evaluation that verimono's own numerical machinery could not decide (:class:`UnverifiedSolution`)
HARNESS_LIMIT = "harness_limit"


@dataclasses.dataclass
class _State:
    runs: int = 0
    worst: float = -math.inf
    worst_sample: Sample | None = None
    worst_eval: Outcome | None = None
    fail_sample: Sample | None = None
    fail_eval: Outcome | None = None
    unsupported: str | None = None
    found_by: str = ""
    inconclusive: int = 0
    inconclusive_what: str = ""
    harness_limited: int = 0


def _evaluate(law: Law, op: Operator, s: Sample) -> Outcome:
    try:
        return law.evaluate(op, s)
    except NotImplementedError:
        raise
    except UnverifiedSolution as exc:   # verimono's own solvers could not decide this sample: a harness limit
        return Outcome.compare(0.0, 0.0, 1.0, f"verimono's solver gave no verified answer ({exc})",
                               {HARNESS_LIMIT: str(exc)}, inconclusive=True)
    except Exception as exc:  # an operator that raises on a valid input fails that input
        return Outcome.compare(math.inf, 0.0, 1.0, f"raised {type(exc).__name__}: {exc}")


def fresh_seed() -> int:
    """A new 32-bit seed (recorded in every result so that a run can be repeated)."""
    return random.SystemRandom().getrandbits(32)


def _subject(op: Operator) -> str:
    return getattr(op, "name", None) or repr(op)


def default_examples() -> tuple[int, str]:
    """``(examples per law, profile)`` when ``examples`` is not given: the active profile's ``law_examples``
    (``dev``/``ci``/``thorough``, :func:`verimono.profiles.active_profile`), else ``DEFAULT_EXAMPLES``."""
    name = active_profile()
    try:
        return get_profile(name).law_examples, name
    except UnknownProfile:
        return DEFAULT_EXAMPLES, name


#: ``examples`` NumPy draws (:func:`verimono.checks.sweep.law_draws`) go first; hypothesis then searches with
#: ``examples // HYPOTHESIS_SHARE`` examples (at least ``HYPOTHESIS_MIN``), or with all ``examples`` when a draw
#: broke the law.  Hypothesis's engine costs about 1.7 ms per example here against about 0.02 ms per NumPy
#: draw, so a passing law costs a quarter of what 20 hypothesis examples did, with more samples evaluated
HYPOTHESIS_SHARE = 4
HYPOTHESIS_MIN = 3


def _draws(law: Law, op: Operator, seed: int, horizon: float, count: int, state: "_State",
           body: Callable) -> tuple[Sample, Outcome] | None:
    """Evaluate ``law`` on ``count`` NumPy draws; the first violation ``(sample, outcome)`` (taken out of
    ``state``, so that hypothesis searches afresh), or ``None``."""
    for s in law_draws(op.dim, seed, horizon, count, Sample):
        try:
            body(s, search=False)
        except _Violation:
            found = (state.fail_sample, state.fail_eval)
            state.fail_sample = state.fail_eval = None
            return found
        if state.unsupported is not None:
            break
    return None


def _shrunk_into(law: Law, op: Operator, failing: tuple[Sample, Outcome], state: "_State", how: str) -> None:
    """Record the violation at ``failing[0]``, shrunk greedily (:func:`verimono.checks.sweep.shrink`)."""
    def fails(c: Sample) -> bool:
        return not _evaluate(law, op, c).ratio <= BOUND
    small, _ = _shrink(failing[0], fails, dataclasses.replace)
    state.fail_sample, state.fail_eval = small, _evaluate(law, op, small)
    state.found_by = how


def _sweep(law: Law, op: Operator, seed: int, horizon: float, state: "_State", body: Callable) -> int:
    """Evaluate ``law`` on the scale sweep (:mod:`verimono.checks.sweep`) after a search found nothing; a
    violation is shrunk greedily and recorded in ``state``.  Returns the number of sweep samples."""
    samples = sweep_samples(op, seed, horizon, sweep_count(active_profile(), law.name), Sample)
    for s in samples:
        try:
            body(s, search=False)
        except _Violation:
            _shrunk_into(law, op, (s, state.fail_eval), state, "sweep (shrunk greedily)")
            break
        if state.unsupported is not None:
            break
    return len(samples)


def run_law(law: Law | str, op: Operator, *, seed: int | None = None, examples: int | None = None,
            horizon: float = 1.0, sample: Sample | dict | None = None) -> CheckResult:
    """Check one law on ``op``: NumPy draws, a hypothesis search and the scale sweep (or one given ``sample``).

    ``examples=None``: the active profile's effort (:func:`default_examples`).  Inconclusive samples (the
    law can neither hold nor fail there) are counted in ``details["inconclusive"]``; a record whose every
    evaluated sample was inconclusive is skipped with the reason, never passed."""
    law = LAWS[law] if isinstance(law, str) else law
    if examples is not None:
        examples = _positive_examples(examples)
    if sample is None:  # the search is seeded (a fresh recorded seed when none is given)
        seed = fresh_seed() if seed is None else int(seed)
    rec = _run_law(law, operator=op, call=lambda: _search(law, op, seed, examples, horizon, sample))
    if rec.status == SKIPPED and "examples" not in rec.details:   # skipped from the declaration: the effort
        n, profile = (examples, None) if examples is not None else default_examples()   # it would have had
        rec.details.update({"item": law.label, "examples": int(n), "evaluations": 0, "horizon": horizon})
        if profile is not None:
            rec.details["profile"] = profile
        rec.seed = seed
    return rec


#: the law that reports an operator whose resolvent raises on plain inputs (its statement: ``J_λ`` is
#: defined on all of ``R^n``); every other law is then not evaluated, so the cause is reported once
ROOT_LAW = "resolvent_single_valued"


def root_cause(op: Operator, horizon: float = 1.0) -> str | None:
    """Why ``op.resolvent`` cannot be evaluated at all — it raises (or returns no point of shape ``(n,)``)
    at ``x = 0`` or ``x = (1, ..., 1)`` with ``λ = 1``, ``t ∈ {0, horizon}`` — or ``None``.  verimono's own
    solvers giving up there (:class:`UnverifiedSolution`) is no cause of the operator's: the laws then meet it
    sample by sample."""
    for x in (np.zeros(op.dim), np.ones(op.dim)):
        for t in (0.0, float(horizon)):
            try:
                y = np.asarray(op.resolvent(x.copy(), 1.0, t))
            except UnverifiedSolution:
                continue
            except Exception as exc:   # noqa: BLE001 - any exception is the root cause we report
                return f"the resolvent raises {type(exc).__name__}: {exc} at x = {x[:3].tolist()}..., λ = 1, t = {t:g}"
            if y.shape != x.shape:
                return f"the resolvent returns shape {y.shape} for a point of shape {x.shape} (λ = 1, t = {t:g})"
    return None


def _search(law: Law, op: Operator, seed: int | None, examples: int | None, horizon: float,
            sample: Sample | dict | None) -> CheckResult:
    """The hypothesis search for a violation of ``law`` (or the evaluation of one given ``sample``)."""
    start = time.perf_counter()
    cause = root_cause(op, horizon) if sample is None else None
    if cause is not None:
        base = dict(check=law.name, subject=_subject(op), seed=seed, details={"item": law.label, "root_cause": cause})
        if law.name == ROOT_LAW:
            return CheckResult(status=FAILED, worst=math.inf, bound=BOUND, counterexample={"operator": repr(op)},
                               message=f"root cause: {cause}; the other laws are not evaluated", **base)
        return CheckResult(status=SKIPPED, message=f"not evaluated: {cause} (the root cause is recorded once, "
                                                   f"as {ROOT_LAW})", **base)
    profile = None
    if examples is None:
        examples, profile = default_examples()
    examples = _positive_examples(examples)
    state = _State()
    harness = ""

    def body(s: Sample, search: bool = True) -> None:
        try:
            ev = _evaluate(law, op, s)
        except NotImplementedError as exc:
            state.unsupported = str(exc) or type(exc).__name__
            return
        state.runs += 1
        if ev.inconclusive:
            state.inconclusive += 1
            state.inconclusive_what = ev.what
            state.harness_limited += HARNESS_LIMIT in ev.info
            return
        r = ev.ratio
        if state.worst_eval is None or not r <= state.worst:
            state.worst, state.worst_sample, state.worst_eval = r, s, ev
        if search:  # climb toward violations (only inside the search, never in an outer test)
            hypothesis.target(min(r, _TARGET_CAP) if r == r else _TARGET_CAP, label=law.name)
        if not r <= BOUND:
            state.fail_sample, state.fail_eval = s, ev
            raise _Violation(law.name)

    def searched(s: Sample) -> None:
        body(s, True)

    flaky, swept = "", 0
    timed_out = ""
    limit = current_budget()
    unit = f"{law.name} on {_subject(op)}"
    if sample is not None:
        s = Sample.from_dict(sample) if isinstance(sample, dict) else sample
        try:
            with time_limit(limit, unit):
                body(s, search=False)
        except _Violation:
            pass
        except UnitTimeout as exc:
            timed_out = str(exc)
    else:
        drawn_fail = None
        try:
            with no_local_constants(), time_limit(limit, unit):   # the same seed draws the same samples
                if op.dim <= NUMPY_DIM:
                    drawn_fail = _draws(law, op, seed, horizon, examples, state, body)
                # then hypothesis: its simplest examples and its climb toward large ratios (target), at the full
                # effort when the draws found a violation (its shrinking then reports the simplest one)
                full = drawn_fail is not None or op.dim > NUMPY_DIM
                budget = examples if full else max(HYPOTHESIS_MIN, examples // HYPOTHESIS_SHARE)
                test = settings(database=None, max_examples=max(1, budget), deadline=None, derandomize=False,
                                verbosity=Verbosity.quiet, print_blob=False,
                                suppress_health_check=list(HealthCheck),
                                phases=(Phase.generate, Phase.target, Phase.shrink))(
                    given(law_samples(op.dim, horizon))(searched))
                hypothesis.seed(seed)(test)()
        except _Violation:
            pass
        except UnitTimeout as exc:   # a resolvent that does not return: a failure of the operator, named
            timed_out = str(exc)
        except hypothesis.errors.Flaky as exc:  # a failure that did not reproduce on replay
            flaky = f" (not reproducible on replay: {type(exc).__name__}; the operator is not deterministic)"
        except (hypothesis.errors.HypothesisException, MemoryError, RecursionError) as exc:
            # the search engine itself gave up (inputs it cannot draw, memory): a limitation of the harness,
            # not of the operator — undecided, never failed and never passed
            harness = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
        if state.fail_eval is None and drawn_fail is not None:   # hypothesis did not meet it: the draw's
            if timed_out or harness:                              # violation, shrunk while time allows
                (state.fail_sample, state.fail_eval), state.found_by = drawn_fail, "NumPy draws"
            else:
                _shrunk_into(law, op, drawn_fail, state, "NumPy draws (shrunk greedily)")
        # the scale sweep spells out its points: for n > NUMPY_DIM the NumPy recipes cover the scales instead
        if (state.fail_eval is None and state.unsupported is None and not (timed_out or harness)
                and op.dim <= NUMPY_DIM):
            swept = _sweep(law, op, seed, horizon, state, body)
    duration = time.perf_counter() - start
    subject = _subject(op)
    base = dict(check=law.name, subject=subject, seed=seed, duration=duration)
    details = {"item": law.label, "examples": examples, "evaluations": state.runs, "horizon": horizon,
               "inconclusive": state.inconclusive, "harness_limited": state.harness_limited, "sweep": swept}
    if profile is not None:
        details["profile"] = profile

    if timed_out and state.fail_eval is None:
        details["timeout"], details["elapsed"] = limit, duration
        return CheckResult(status=FAILED, message=f"timed out: {timed_out} ({state.runs} samples evaluated "
                                                  "before)", details=details, **base)
    if state.fail_eval is None and harness:
        return CheckResult(status=UNDECIDED, message=f"the harness could not search this operator "
                                                     f"({harness}; {state.runs} samples evaluated before); "
                                                     "a limitation of verimono, not a failure of the operator",
                           details=details, **base)
    if state.fail_eval is None and state.unsupported is not None:
        return CheckResult(status=SKIPPED, message=f"needs a member the operator lacks: {state.unsupported} "
                                                   f"({state.runs} samples evaluated before)",
                           details=details, **base)
    if state.fail_eval is not None:
        ev, s = state.fail_eval, state.fail_sample
        cex = {**s.to_dict(), "seed": seed, "examples": examples, "horizon": horizon, "operator": repr(op),
               "ratio": ev.ratio, "lhs": ev.lhs, "rhs": ev.rhs, "slack": ev.slack, **ev.info}
        if state.found_by:
            cex["found_by"] = state.found_by
        msg = (f"{ev.what}: lhs {ev.lhs:.6g} > rhs {ev.rhs:.6g} + slack {ev.slack:.3g} "
               f"at {s!r}{flaky}")
        return CheckResult(status=FAILED, worst=max(state.worst, ev.ratio), bound=BOUND, counterexample=cex,
                           message=msg, details=details, **base)
    if state.runs == 0:        # nothing was evaluated: never a pass
        return CheckResult(status=UNDECIDED, message="no sample was evaluated", details=details, **base)
    if state.runs and state.harness_limited == state.runs:
        return CheckResult(status=UNDECIDED, message=f"verimono's own solvers decided none of the {state.runs} "
                                                     f"samples (e.g. {state.inconclusive_what}); a limitation of "
                                                     "verimono, not a failure of the operator",
                           details=details, **base)
    if state.runs and state.inconclusive == state.runs:
        return CheckResult(status=SKIPPED, message=f"all {state.runs} samples inconclusive (e.g. "
                                                   f"{state.inconclusive_what})", details=details, **base)
    if state.worst_sample is not None:
        details["worst_sample"] = state.worst_sample.to_dict()
        details["worst_info"] = {"what": state.worst_eval.what, "lhs": state.worst_eval.lhs,
                                 "rhs": state.worst_eval.rhs, "slack": state.worst_eval.slack}
    worst = state.worst if state.worst_eval is not None else None
    counted = f"{state.runs} samples" + (f" ({state.inconclusive} inconclusive)" if state.inconclusive else "")
    if state.harness_limited:
        counted += f", {state.harness_limited} of them undecided by verimono's own solvers"
    return CheckResult(status=PASSED, worst=worst, bound=BOUND,
                       message=counted + (f"; {flaky}" if flaky else ""), details=details, **base)


def _positive_examples(examples: Any) -> int:
    """``examples`` as a positive integer; :class:`InvalidCheckArgument` otherwise (0 examples verify
    nothing, and used to be searched once and reported as a pass)."""
    try:
        n = int(examples)
    except (TypeError, ValueError):
        raise InvalidCheckArgument(f"examples must be a positive integer, got {examples!r}") from None
    if isinstance(examples, bool) or n != examples or n < 1:
        raise InvalidCheckArgument(f"examples must be a positive integer, got {examples!r}")
    return n


def check_resolvent_single_valued(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida i–ii:
    ``J_λ`` is defined on all of ``R^n`` and single-valued — two calls on the same ``x``
    return the same finite point of shape ``(n,)`` and leave ``x`` unchanged (ratio: |difference|/tol)."""
    return run_law("resolvent_single_valued", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_resolvent_nonexpansive(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida ii:
    ``|J_λx1 - J_λx2| ≤ |x1 - x2|`` (ratio ``|ΔJ| / (|Δx| + slack)``)."""
    return run_law("resolvent_nonexpansive", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_resolvent_firmly_nonexpansive(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida ii (A1):
    item ii sharpened, equivalent to monotonicity of ``F``:
    ``|J_λx1 - J_λx2|² ≤ ⟨J_λx1 - J_λx2, x1 - x2⟩`` (ratio ``|ΔJ|² / (⟨ΔJ, Δx⟩ + slack)``)."""
    return run_law("resolvent_firmly_nonexpansive", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_resolvent_in_domain(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """range J_λ = dom F:
    ``J_λx ∈ dom F(t,·)`` (``x = J_λx + λy`` with ``y ∈ F(t, J_λx)``): the projection onto
    ``cl dom F(t,·)`` leaves ``J_λx`` in place (needs ``project_domain``; ratio: distance/tol)."""
    return run_law("resolvent_in_domain", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_resolvent_identity(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """The resolvent identity ``J_λx = J_μ((μ/λ)x + (1 - μ/λ)J_λx)`` for all ``λ, μ > 0`` (it holds because
    ``x - J_λx ∈ λF(J_λx)``); catches resolvents with a wrong or stale step size (ratio: |difference|/tol)."""
    return run_law("resolvent_identity", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_resolvent_limit(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida iii, quantitatively:
    for ``x ∈ dom F`` and ``y ∈ F(x)``, ``|J_λx - x| ≤ λ|y|`` (nonexpansiveness
    at ``J_λ(x + λy) = x``), hence ``J_λx → x`` as ``λ → 0``.  Tested at ``x = J_νx1``, ``y = Y_νx1`` over
    ``λ, λ/4, …, λ/4^5`` (ratio ``|J_λx - x| / (λ|y| + slack)``)."""
    return run_law("resolvent_limit", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_monotone(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Assumption (A1): the graph of ``F(t,·)`` is monotone, ``⟨x_a - x_b, y_a - y_b⟩ ≥ 0``, sampled through the
    resolvent: ``(J_λx1, Y_λx1)`` and ``(J_μx2, Y_μx2)`` are graph elements (item v) for different step
    sizes (ratio ``-⟨Δx, Δy⟩ / slack``)."""
    return run_law("monotone", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_yosida_lipschitz(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida iv:
    ``Y_λ`` is ``1/λ``-Lipschitz, ``λ|Y_λx1 - Y_λx2| ≤ |x1 - x2|``
    (ratio ``λ|ΔY| / (|Δx| + slack)``)."""
    return run_law("yosida_lipschitz", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_yosida_monotone(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida iv:
    ``Y_λ`` is (maximal) monotone, ``⟨Y_λx1 - Y_λx2, x1 - x2⟩ ≥ 0``
    (ratio ``-⟨ΔY, Δx⟩ / slack``)."""
    return run_law("yosida_monotone", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_yosida_in_graph(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida v:
    ``Y_λx ∈ F(t, J_λx)`` through ``contains`` (ratio: the smallest power-of-100 multiple of the
    tolerance at which membership is accepted; 1 when it is accepted at the tolerance)."""
    return run_law("yosida_in_graph", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_yosida_nonincreasing(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida vi:
    ``λ ↦ |Y_λx|`` is nonincreasing, ``|Y_μx| ≤ |Y_λx|`` for ``λ ≤ μ`` (stated in the paper for
    ``x ∈ dom F``; it holds for every ``x`` since ``Y_μ = (Y_λ)_{μ-λ}``) (ratio ``|Y_μx| / (|Y_λx| + slack)``)."""
    return run_law("yosida_nonincreasing", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_yosida_bounded_by_min_norm(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida vi:
    ``|Y_λx| ≤ |F^0(x)|`` for ``x ∈ dom F`` (at ``x = J_νx1``; needs ``min_norm``)
    (ratio ``|Y_λx| / (|F^0(x)| + slack)``)."""
    return run_law("yosida_bounded_by_min_norm", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_yosida_limit(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """Proposition prop:maxmon-resolvent-Yosida vi:
    ``|Y_λx| → |F^0(x)|`` as ``λ → 0`` for ``x ∈ dom F`` (needs ``min_norm``).  ``λ`` is halved
    until the gap ``||F^0(x)| - |Y_λx||`` is within tolerance, or down to the rounding floor where the gap must
    still be shrinking (``tolerances.STALL_RATIO`` over ``STALL_WINDOW`` halvings); a stalled positive gap
    means ``min_norm`` is not the least-norm element or ``J_λ`` has the wrong ``λ``."""
    return run_law("yosida_limit", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_min_norm_in_graph(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """The minimal section F^0 = proj(0, F(x)) lies in the graph:
    ``F^0(t, x) ∈ F(t, x)`` for ``x = J_νx1 ∈ dom F`` (needs
    ``min_norm`` and ``contains``; ratio as for :func:`check_yosida_in_graph`)."""
    return run_law("min_norm_in_graph", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_min_norm_least(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """The minimal section F^0 = proj(0, F(x)) has least norm,
    ``|F^0(t, x)| ≤ |y|`` for every ``y ∈ F(t, x)``: compared with
    ``y = Y_νx1`` at ``x = J_νx1`` (item v; certified by ``contains`` when available)
    (ratio ``|F^0(x)| / (|y| + slack)``)."""
    return run_law("min_norm_least", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_prox_inequality(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """The prox inequality:
    ``⟨x - p, z - p⟩ ≤ λ(g(z) - g(p))`` for ``p = J_λx`` and ``z`` among ``x2``,
    ``x1``, ``0`` and other resolvent values (needs ``value``; :mod:`verimono.checks.prox_laws`)."""
    return run_law("prox_inequality", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_prox_optimal(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """The prox optimality (perturbations):
    ``p = J_λx`` minimises ``Φ(z) = λg(z) + |z - x|²/2``, 1-strongly: ``Φ(p) + |δ|²/2 ≤ Φ(p + δ)`` for
    perturbations ``δ`` along coordinates, ``x - p``, ``p`` and seeded directions (needs ``value``)."""
    return run_law("prox_optimal", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_prox_minimiser(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """The prox optimality (independent minimiser):
    ``Φ(p) ≤ Φ(z*)`` for ``z*`` an independent minimiser of ``Φ`` (scipy's Powell from ``p``, ``x``, ``0``;
    ``n ≤ 4`` only, larger samples are inconclusive; needs ``value``)."""
    return run_law("prox_minimiser", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


def check_moreau_envelope(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult:
    """The Moreau envelope:
    ``e_λ(x) = g(J_λx) + |x - J_λx|²/(2λ)`` is convex with the ``1/λ``-Lipschitz
    gradient ``Y_λ``: ``e(x1) + ⟨Y_λx1, x2 - x1⟩ ≤ e(x2) ≤ e(x1) + ⟨Y_λx1, x2 - x1⟩ + |x2 - x1|²/(2λ)``
    (needs ``value``)."""
    return run_law("moreau_envelope", op, seed=seed, examples=examples, horizon=horizon, sample=sample)


#: the registry: stable law name → check function, in the order they run
OPERATOR_CHECKS: dict[str, Callable[..., CheckResult]] = {
    name: globals()[f"check_{name}"] for name in LAWS
}


def operator_checks(op: Operator | None = None, *, seed: int | None = None, examples: int | None = None,
                    horizon: float = 1.0) -> Iterator[tuple[str, Callable[[Operator], CheckResult]]]:
    """Yield ``(name, check)`` for every operator law, ``check(op) -> CheckResult`` with the given settings
    bound (like scikit-learn's ``_yield_all_checks``).  Names are stable and unique; the same generator
    feeds :func:`check_operator` and the pytest integration.  ``op`` is accepted for symmetry with other
    subjects' generators (all laws apply to every operator; unsupported members give skips)."""
    for name, fn in OPERATOR_CHECKS.items():
        check = functools.partial(fn, seed=seed, examples=examples, horizon=horizon)
        functools.update_wrapper(check, fn)
        yield name, check


def check_operator(op: Operator, *, seed: int | None = None, examples: int | None = None,
                   horizon: float = 1.0) -> Report:
    """Run every operator law on ``op`` and return the :class:`verimono.Report` of their records.

    ``seed`` makes the search reproducible (one fresh seed is drawn and recorded when ``None``);
    ``examples`` is the number of hypothesis examples per law (default: the active profile's
    ``law_examples``, :func:`default_examples`); times are sampled in ``[0, horizon]``.
    """
    seed = fresh_seed() if seed is None else int(seed)
    if examples is None:
        examples, profile = default_examples()
    else:
        examples, profile = _positive_examples(examples), None
    if not (isinstance(horizon, (int, float)) and math.isfinite(horizon) and horizon >= 0):
        raise InvalidCheckArgument(f"horizon must be a finite time >= 0, got {horizon!r}")
    report = Report(meta={"subject": _subject(op), "seed": seed, "examples": examples, "horizon": horizon,
                          **({"profile": profile} if profile else {})})
    for _, check in operator_checks(op, seed=seed, examples=examples, horizon=horizon):
        report.add(check(op))
    return report


__all__ = ["Sample", "law_samples", "Law", "LAWS", "run_law", "fresh_seed", "OPERATOR_CHECKS", "operator_checks",
           "check_operator", "DEFAULT_EXAMPLES", "default_examples", "BOUND"] + [f"check_{name}" for name in LAWS]
