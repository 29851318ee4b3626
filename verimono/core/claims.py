"""What a stepper claims to be, and therefore which laws it must obey.

A *stepper* is any callable ``stepper(problem, t_grid) -> array (len(t_grid), n)``.  The laws of the
paper bind different schemes differently:

* ``scheme="proximal"`` — the stepper *is* the paper's scheme (``eq:iteration``)
  ``x_{k+1} = J_{h_{k+1} F(t_{k+1},·)}(x_k + h_{k+1} f(x_k) + ∫_{t_k}^{t_{k+1}} u)`` on the given grid.
  Every law applies: the discrete velocities are selections of ``F(t_{k+1}, x_{k+1})``, the iterates lie
  exactly in ``cl dom F(t_k)`` (``e:x k+1 props.1``), they obey the bounds of ``lem:bndSeq`` /
  ``lem:bndSeqYB`` / ``lem:bndEquiCont``, two solutions contract (uniqueness argument, Section 6) and the
  scheme reaches the order each reference states for it (exact at the nodes where it is).
* ``scheme="any"`` — the stepper only claims to converge to the solution with order ``order``
  (default 1).  It gets the laws every convergent scheme obeys: convergence to the exact (or reference)
  solution at order ``≥ min(order, the order the reference's regularity allows)``, a unique limit as the
  mesh shrinks (Section 5.4: the limit is the unique solution), and a distance to ``cl dom F(t_k)``
  vanishing at the claimed order (the solution lies in the domain).  Contraction only where claimed
  (``contracts=True``).

Whatever a stepper claims, its trajectory starts at ``x0`` (``x(0) = x0``: the law ``initial_value``) and is its
caller's: it never changes when the stepper runs again, and the stepper writes into neither the grid nor
``problem.x0`` it was given (``trajectory_immutable``).

A bare callable claims ``"proximal"``; :func:`verimono.solve` is declared proximal.  Wrap any other
scheme with :class:`Stepper` to state what it is::

    midpoint = verimono.Stepper(my_midpoint_scheme, scheme="any", order=1)

Two more statements bind how the laws are judged, not which apply:

* ``grids="uniform"`` — the stepper runs on uniform partitions ``t_n = n T/K`` only (``"any"``, the default:
  every increasing partition).  Every law is then judged on uniform partitions only — each partition the
  battery would build is replaced by the uniform one of as many cells, each convergence study's grid is uniform
  (``np.linspace(0, T, K + 1)``: ``t_K = T`` exactly) — and never failed or skipped because the stepper refused
  another kind; the records say so (``details["grids"]``, the message).
* ``inexact=(C, q)`` (or a callable ``ε(h)``) — the proximal scheme with an inexact resolvent: each step's result
  lies within ``ε(h_{k+1}) = C h_{k+1}^q`` of the exact one, ``|x_{k+1} − J_{h F(t_{k+1})}(z_k)| ≤ ε(h_{k+1})``
  (Rockafellar's criterion (A) for the proximal point algorithm, per step: SIAM J. Control Optim. 14, 1976; the
  inexact catching-up algorithm of Garrido–Lioi–Vilches, arXiv 2501.04781).  The laws follow from it (each
  states its slack, :class:`Inexact`), and so does the order: ``K = T/h`` steps of a nonexpansive scheme
  accumulate at most ``Σ ε_k = C T h^{q−1}`` (times ``e^{LT}`` with a Lipschitz ``f``, the Gronwall factor of
  the uniqueness argument), so a scheme of order ``p`` with exact resolvents reaches ``min(p, q − 1)``, and a
  tolerance with ``q ≤ 1`` gives no convergence at all — ``convergence_order`` fails on such a claim.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

from .errors import InvalidClaim
from .naming import subject_name

PROXIMAL, ANY = "proximal", "any"
SCHEMES = (PROXIMAL, ANY)
UNIFORM = "uniform"
#: the partitions a stepper may claim to run on: every increasing one, or uniform ones only
GRID_KINDS = (ANY, UNIFORM)


@dataclasses.dataclass(frozen=True)
class Inexact:
    """The tolerance of an inexact resolvent as a function of the step: ``ε(h) = C h^q``, or ``fn(h)``.

    Per step ``|x_{k+1} − J_{h_{k+1} F(t_{k+1})}(z_k)| ≤ ε(h_{k+1})`` (``z_k`` the scheme's argument).  What it
    costs each law, derived once (the resolvents are nonexpansive, Proposition
    ``prop:maxmon-resolvent-Yosida`` ii, so a perturbation of one step is never amplified by the later ones):

    * the step's result: ``ε(h)`` from the exact resolvent, hence from ``cl dom F(t_{k+1})`` (``in_domain``);
    * the discrete velocity ``y = (z_k − x_{k+1})/h``: ``ε/h`` from the exact one, and the witness
      ``|J_μ(x_{k+1} + μ y) − x_{k+1}| ≤ 2ε`` for ``μ ≤ h`` (``selections``);
    * two runs: ``|x_k − x'_k| ≤ g_k |x_{k−1} − x'_{k−1}| + 2ε(h_k)`` (``contraction``);
    * the whole sequence: within ``E_k = Σ_{j≤k} ε(h_j)`` of the exact scheme's from the same ``x0``
      (``bounds_lg``, ``bounds_yb``, ``psi_interpolation``), and ``E_K = C T h^{q−1}`` on a uniform grid — the
      order ``min(p, q − 1)`` (Rockafellar's criterion (A) accumulated over ``K = T/h`` steps;
      /work/shared/literature.md, "Inexact resolvents").

    For a callable, ``q`` is the least slope of ``log ε`` against ``log h`` over ``h ∈ [T·10⁻⁴, T/4]``
    (:meth:`exponent`): the order the claim guarantees where the studies run.
    """

    C: float | None = None
    q: float | None = None
    fn: Callable | None = None

    def __call__(self, h: Any) -> np.ndarray:
        h = np.asarray(h, dtype=float)
        if self.fn is None:
            return self.C * h ** self.q
        return np.vectorize(lambda s: float(self.fn(float(s))), otypes=[float])(h)

    def exponent(self, T: float = 1.0) -> float:
        """``q`` (measured for a callable: the class docstring)."""
        if self.fn is None:
            return float(self.q)
        h = float(T) * np.logspace(-4, np.log10(0.25), 17)
        e = self(h)
        if np.any(~np.isfinite(e)) or np.any(e <= 0):
            return 0.0
        return float(np.min(np.diff(np.log(e)) / np.diff(np.log(h))))

    def describe(self) -> str:
        return (f"{self.C:g}·h^{self.q:g}" if self.fn is None
                else getattr(self.fn, "__name__", "a callable ε(h)"))


def steps_tolerance(claim: "Claim", h: Any) -> np.ndarray:
    """``ε(h_k)`` for each step ``h_k`` of ``h`` under ``claim`` (zeros for an exact resolvent)."""
    h = np.asarray(h, dtype=float)
    return np.zeros_like(h) if claim.inexact is None else claim.inexact(h)


def _inexact(value: Any) -> Inexact | None:
    if value is None or isinstance(value, Inexact):
        return value
    if callable(value):
        return Inexact(fn=value)
    try:
        C, q = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InvalidClaim(f"inexact must be (C, q) for ε(h) = C·h^q, or a callable ε(h); got {value!r}") from None
    if not (math.isfinite(C) and C > 0 and math.isfinite(q) and q > 0):
        raise InvalidClaim(f"inexact = (C, q) needs C > 0 and q > 0 finite (ε(h) = C·h^q), got {value!r}")
    return Inexact(C, q)


def _grids(value: Any) -> str:
    if value is None:
        return ANY
    if value not in GRID_KINDS:
        raise InvalidClaim(f"grids must be one of {GRID_KINDS}, got {value!r}")
    return value


@dataclasses.dataclass(frozen=True)
class Claim:
    """What a stepper states about itself.

    ``scheme``: ``"proximal"`` or ``"any"``; ``order``: the convergence order claimed by an ``"any"``
    scheme (``None`` for the proximal scheme, whose order each reference states); ``contracts``: whether
    two of its solutions obey ``|x_k - x'_k| ≤ e^{L t_k}|x_0 - x'_0|`` (always for the proximal scheme);
    ``solve_tol``: the accuracy of the stepper's inner solve (Newton, fixed point, an iterative prox) per
    step, relative to ``1 + |x|`` — errors at what that accumulates pass as exact to it
    (:func:`verimono.core.convergence.solve_floor`); ``grids``: ``"any"`` or ``"uniform"``, the partitions it
    runs on; ``inexact``: the tolerance ``ε(h)`` of its resolvent (:class:`Inexact`; proximal scheme only).
    """

    scheme: str = PROXIMAL
    order: float | None = None
    contracts: bool = True
    solve_tol: float | None = None
    grids: str = ANY
    inexact: Inexact | None = None

    @property
    def uniform(self) -> bool:
        """Whether the stepper runs on uniform partitions only."""
        return self.grids == UNIFORM

    @property
    def proximal(self) -> bool:
        return self.scheme == PROXIMAL

    def describe(self) -> str:
        tol = f", solve_tol={self.solve_tol:g}" if self.solve_tol else ""
        tol += ", grids='uniform'" if self.uniform else ""
        tol += f", inexact ε(h) = {self.inexact.describe()}" if self.inexact is not None else ""
        if self.proximal:
            return "scheme='proximal'" + tol
        return f"scheme='any', order={self.order:g}" + (", contracts" if self.contracts else "") + tol


def _solve_tol(value: Any) -> float | None:
    if value is None:
        return None
    try:
        tol = float(value)
    except (TypeError, ValueError):
        raise InvalidClaim(f"solve_tol must be a number in (0, 1), got {value!r}") from None
    if isinstance(value, bool) or not (0.0 < tol < 1.0):
        raise InvalidClaim(f"solve_tol must be a number in (0, 1) (a relative accuracy per step), got {value!r}")
    return tol


def make_claim(scheme: str = PROXIMAL, order: Any = None, contracts: bool | None = None,
               solve_tol: Any = None, grids: Any = None, inexact: Any = None) -> Claim:
    """Validate and normalise a claim (``order`` defaults to 1 for ``"any"``)."""
    if scheme not in SCHEMES:
        raise InvalidClaim(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    kinds, eps = _grids(grids), _inexact(inexact)
    if eps is not None and scheme != PROXIMAL:
        raise InvalidClaim("inexact= states the tolerance of the proximal scheme's resolvent: it needs "
                           "scheme='proximal' (a scheme='any' stepper states its order instead)")
    return dataclasses.replace(_make_claim(scheme, order, contracts, solve_tol), grids=kinds, inexact=eps)


def _make_claim(scheme: str, order: Any, contracts: bool | None, solve_tol: Any) -> Claim:
    tol = _solve_tol(solve_tol)
    if scheme == PROXIMAL:
        if order is not None:
            raise InvalidClaim("the proximal scheme's order is stated per reference; order= is for scheme='any'")
        if contracts is False:
            raise InvalidClaim("the proximal scheme contracts (uniqueness argument, Section 6): "
                               "contracts=False needs scheme='any'")
        return Claim(PROXIMAL, None, True, tol)
    order = 1.0 if order is None else order
    try:
        order = float(order)
    except (TypeError, ValueError):
        raise InvalidClaim(f"order must be a positive number, got {order!r}") from None
    if not (math.isfinite(order) and order > 0.0):
        raise InvalidClaim(f"order must be a positive finite number, got {order!r}")
    return Claim(ANY, order, bool(contracts), tol)


class Stepper:
    """A stepper with its claim: ``Stepper(fn, *, scheme="proximal", order=None, name=None, contracts=None,
    solve_tol=None, grids="any", inexact=None)``.

    Calling it calls ``fn(problem, t_grid)``.  ``scheme="any"`` claims only convergence with order
    ``order`` (default 1); ``contracts=True`` adds the contraction claim; ``solve_tol`` states the accuracy
    of its inner solve (:class:`Claim`); ``grids="uniform"``: it runs on uniform partitions only;
    ``inexact=(C, q)`` or a callable: its resolvent is within ``ε(h) = C h^q`` of the exact one
    (:class:`Inexact`).  ``batched`` is inherited from ``fn`` (a stepper accepting ``x0`` of shape ``(B, n)``).
    """

    def __init__(self, fn: Callable, *, scheme: str = PROXIMAL, order: Any = None, name: str | None = None,
                 contracts: bool | None = None, solve_tol: Any = None, grids: Any = None,
                 inexact: Any = None) -> None:
        if not callable(fn):
            raise InvalidClaim(f"a stepper must be callable as stepper(problem, t_grid), got {fn!r}")
        if isinstance(fn, Stepper):
            fn = fn.fn
        self.fn = fn
        self.claim = make_claim(scheme, order, contracts, solve_tol, grids, inexact)
        self.__name__ = name or getattr(fn, "__name__", None) or type(fn).__name__
        self.name = self.__name__
        self.__doc__ = getattr(fn, "__doc__", None)
        self.batched = bool(getattr(fn, "batched", False))

    @property
    def scheme(self) -> str:
        return self.claim.scheme

    @property
    def order(self) -> float | None:
        return self.claim.order

    def __call__(self, problem: Any, t_grid: Any) -> np.ndarray:
        return self.fn(problem, t_grid)

    def __repr__(self) -> str:
        return f"Stepper({self.__name__}, {self.claim.describe()})"

    def __reduce__(self):   # picklable by reference to fn (process pools, dask)
        return (_rebuild, (self.fn, self.claim, self.__name__))


def _rebuild(fn: Callable, claim: Claim, name: str) -> Stepper:
    s = Stepper(fn, name=name)
    s.claim = claim
    return s


def claim_of(stepper: Any) -> Claim:
    """The claim a stepper makes: its own ``claim`` attribute (:class:`Stepper`, :func:`verimono.solve`),
    else ``"proximal"`` — a bare callable is taken to be the paper's scheme."""
    claim = getattr(stepper, "claim", None)
    return claim if isinstance(claim, Claim) else Claim()


def with_claim(stepper: Callable, scheme: str | None = None, order: Any = None,
               contracts: bool | None = None, solve_tol: Any = None, grids: Any = None,
               inexact: Any = None) -> Callable:
    """``stepper`` with the claim given as keywords (unchanged when none is given); what is not given is kept
    from the stepper's own claim."""
    if scheme is None and order is None and contracts is None and solve_tol is None and grids is None \
            and inexact is None:
        return stepper
    own = claim_of(stepper)
    if scheme is None:
        scheme = ANY if order is not None else own.scheme
    if scheme == own.scheme == ANY:
        order = own.order if order is None else order
        contracts = own.contracts if contracts is None else contracts
    solve_tol = own.solve_tol if solve_tol is None else solve_tol
    grids = own.grids if grids is None else grids
    if inexact is None and scheme == PROXIMAL:
        inexact = own.inexact
    return Stepper(stepper, scheme=scheme, order=order, name=subject_name(stepper), contracts=contracts,
                   solve_tol=solve_tol, grids=grids, inexact=inexact)


__all__ = ["Claim", "Stepper", "claim_of", "with_claim", "make_claim", "InvalidClaim", "PROXIMAL", "ANY",
           "SCHEMES", "UNIFORM", "GRID_KINDS", "Inexact", "steps_tolerance"]
