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


@dataclasses.dataclass(frozen=True)
class Claim:
    """What a stepper states about itself.

    ``scheme``: ``"proximal"`` or ``"any"``; ``order``: the convergence order claimed by an ``"any"``
    scheme (``None`` for the proximal scheme, whose order each reference states); ``contracts``: whether
    two of its solutions obey ``|x_k - x'_k| ≤ e^{L t_k}|x_0 - x'_0|`` (always for the proximal scheme);
    ``solve_tol``: the accuracy of the stepper's inner solve (Newton, fixed point, an iterative prox) per
    step, relative to ``1 + |x|`` — errors at what that accumulates pass as exact to it
    (:func:`verimono.core.convergence.solve_floor`).
    """

    scheme: str = PROXIMAL
    order: float | None = None
    contracts: bool = True
    solve_tol: float | None = None

    @property
    def proximal(self) -> bool:
        return self.scheme == PROXIMAL

    def describe(self) -> str:
        tol = f", solve_tol={self.solve_tol:g}" if self.solve_tol else ""
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
               solve_tol: Any = None) -> Claim:
    """Validate and normalise a claim (``order`` defaults to 1 for ``"any"``)."""
    if scheme not in SCHEMES:
        raise InvalidClaim(f"scheme must be one of {SCHEMES}, got {scheme!r}")
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
    solve_tol=None)``.

    Calling it calls ``fn(problem, t_grid)``.  ``scheme="any"`` claims only convergence with order
    ``order`` (default 1); ``contracts=True`` adds the contraction claim; ``solve_tol`` states the accuracy
    of its inner solve (:class:`Claim`).  ``batched`` is inherited from ``fn`` (a stepper accepting ``x0``
    of shape ``(B, n)``).
    """

    def __init__(self, fn: Callable, *, scheme: str = PROXIMAL, order: Any = None, name: str | None = None,
                 contracts: bool | None = None, solve_tol: Any = None) -> None:
        if not callable(fn):
            raise InvalidClaim(f"a stepper must be callable as stepper(problem, t_grid), got {fn!r}")
        if isinstance(fn, Stepper):
            fn = fn.fn
        self.fn = fn
        self.claim = make_claim(scheme, order, contracts, solve_tol)
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
               contracts: bool | None = None, solve_tol: Any = None) -> Callable:
    """``stepper`` with the claim given as keywords (unchanged when none is given); what is not given is kept
    from the stepper's own claim."""
    if scheme is None and order is None and contracts is None and solve_tol is None:
        return stepper
    own = claim_of(stepper)
    if scheme is None:
        scheme = ANY if order is not None else own.scheme
    if scheme == own.scheme == ANY:
        order = own.order if order is None else order
        contracts = own.contracts if contracts is None else contracts
    solve_tol = own.solve_tol if solve_tol is None else solve_tol
    return Stepper(stepper, scheme=scheme, order=order, name=subject_name(stepper), contracts=contracts,
                   solve_tol=solve_tol)


__all__ = ["Claim", "Stepper", "claim_of", "with_claim", "make_claim", "InvalidClaim", "PROXIMAL", "ANY",
           "SCHEMES"]
