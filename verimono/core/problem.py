"""Evolution inclusions ``x'(t) ∈ -F(t, x) + f(x) + u(t)``, ``x(0) = x0``, on ``[0, T]``."""

from __future__ import annotations

import dataclasses
import math
import numbers
import weakref
from collections.abc import Iterable, Mapping
from typing import Any, Callable, Sequence

import numpy as np

from .errors import InvalidProblem, OutsideDomain
from .operator_protocol import stated_data_scale
from .arrays import as_float64, precision_of
from .tolerances import coarser, current_precision, judged_at_scale, judged_precision, rtol_for, tolerance


@dataclasses.dataclass(frozen=True)
class Order:
    """Expected convergence order of a scheme on a problem, with where the claim comes from.

    ``value`` is the exponent ``p`` in ``error ≈ C h^p``; ``exact=True`` means the scheme reproduces
    the solution at the grid points up to round-off.  ``constant`` is the leading error constant ``C``
    in the sup norm when it is known in closed form.
    """

    value: float | None
    source: str
    exact: bool = False
    constant: float | None = None
    #: the highest order the solution's regularity allows *any* convergent scheme (``inf``: smooth), with
    #: its source — what a stepper claiming only ``scheme="any"`` is held to (:mod:`verimono.core.claims`)
    regularity: float | None = None
    regularity_source: str = ""

    @classmethod
    def exact_at_nodes(cls, source: str, regularity: float | None = None, regularity_source: str = "") -> "Order":
        return cls(None, source, exact=True, regularity=regularity, regularity_source=regularity_source)

    def for_claim(self, claimed: float) -> "Order":
        """The order a scheme claiming convergence with order ``claimed`` must reach here:
        ``min(claimed, regularity)`` (the claim alone where the regularity is not stated)."""
        reg = math.inf if self.regularity is None else float(self.regularity)
        if claimed <= reg:
            why = (f"the claimed order {claimed:g}" + ("" if self.regularity is None else
                   f" (within the order {reg:g} the solution's regularity allows: {self.regularity_source})"))
            return Order(float(claimed), why)
        return Order(reg, f"the claimed order {claimed:g}, capped at {reg:g} by the solution's regularity: "
                          f"{self.regularity_source}")

    def __str__(self) -> str:
        return "exact" if self.exact else f"{self.value:g}"


def _as_order(order: Any) -> Order | None:
    if order is None or isinstance(order, Order):
        return order
    if order == "exact":
        return Order.exact_at_nodes("stated by the caller")
    try:
        return Order(float(order), "stated by the caller")
    except (TypeError, ValueError):
        raise InvalidProblem(f"order must be a number, 'exact' or an Order, got {order!r}") from None


def _finite_array(value: Any, what: str) -> np.ndarray:
    if np.iscomplexobj(value):   # np.array(z, dtype=float) would drop the imaginary part silently
        raise InvalidProblem(f"{what} must be real, got complex values {value!r:.80}")
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"{what} must be numeric: {exc}") from None
    if not np.all(np.isfinite(arr)):
        raise InvalidProblem(f"{what} must be finite, got {value!r}")
    return arr


def _lipschitz(value: Any) -> float | None:
    """``lipschitz`` as a finite number ``>= 0`` (or ``None``: not stated).  A negative or NaN constant would
    make the laws' bounds (``contraction``'s ``e^{Lh}``, the Gronwall factors) wrong, and a correct stepper
    fail them for the caller's mistake."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) \
            or not (math.isfinite(value) and value >= 0):
        raise InvalidProblem(f"lipschitz (the Lipschitz constant of f) must be a finite number >= 0, got {value!r}")
    return float(value)


def _steps(steps: Any) -> list[float] | None:
    """``steps`` as a list of finite positive step sizes (or ``None``)."""
    if steps is None:
        return None
    if isinstance(steps, (str, bytes)) or not isinstance(steps, Iterable):
        raise InvalidProblem(f"steps must be a list of step sizes, got {steps!r}")
    out = []
    for h in steps:
        if isinstance(h, (bool, np.bool_)) or not isinstance(h, numbers.Real) or not (math.isfinite(h) and h > 0):
            raise InvalidProblem(f"steps must be finite step sizes > 0, got {h!r} in {steps!r}")
        out.append(float(h))
    return out


def _data(data: Any) -> dict[str, Any]:
    """``data`` (the user's own parameters) as a new dict with string keys; ``None`` is ``{}``.  A copy: the
    caller's mapping changed later does not change the problem (a shallow copy: the values are the caller's)."""
    if data is None:
        return {}
    if not isinstance(data, Mapping):
        raise InvalidProblem(f"data must be a mapping of the problem's own parameters (a dict), got "
                             f"{type(data).__name__}")
    bad = [k for k in data if not isinstance(k, str)]
    if bad:
        raise InvalidProblem(f"data's keys must be strings (parameter names), got {bad[0]!r}")
    return dict(data)


@dataclasses.dataclass(frozen=True, init=False, repr=False, eq=False)
class Problem:
    """``x' ∈ -F(t, x) + f(x) + u(t)`` on ``[0, T]`` with ``x(0) = x0``.

    Parameters
    ----------
    operator : Operator
        ``F``, maximal monotone for each ``t`` (assumption (A1)).
    x0 : array (n,) or (B, n)
        Initial point in ``cl dom F(0,·)``; a batch ``(B, n)`` solves ``B`` initial conditions at once.
    T : float
        Final time, ``T > 0``.
    f : callable, optional
        Lipschitz vector field ``f(x)`` (Section 6); treated explicitly by the scheme.
    u : callable, optional
        Integrable input ``u(t)`` (Section 6); enters through ``∫_{t_k}^{t_{k+1}} u``.
    exact : callable, optional
        The exact solution ``t ↦ x(t)`` when known.
    order : float, "exact" or Order, optional
        Expected convergence order of the proximal scheme, with its source.
    name : str, optional

    Keyword-only extras used by checks and references: ``U`` (primitive ``∫_0^t u``, used instead of
    quadrature when given), ``lipschitz`` (the Lipschitz constant of ``f``), ``phi``/``sigma``/``theta``
    (the functions of assumptions (A3), (LG), (YB) when known), ``steps`` (step sizes for which the
    expected order is asymptotic), ``initial_jump`` (allow ``x0 ∉ cl dom F(0)``: the catching-up
    scheme then jumps to the projection in its first step), ``notes``, and ``data``: the user's own parameters
    (a mapping with string keys, e.g. ``data={"radius": 0.5, "delay": 0.1}``), carried unchanged to every
    copy of the problem (:meth:`replace`, the shrinking of a failure, worker processes) so that a
    problem-specific stepper reads ``problem.data["radius"]`` instead of looking its parameters up by
    ``problem.name``; verimono never reads it and never writes it into a record or a report.

    A frozen dataclass: fields cannot be reassigned; :meth:`replace` (or :func:`dataclasses.replace`)
    builds a changed copy through the same validation.  Equality is identity (the fields hold arrays and
    functions).
    """

    operator: Any
    x0: np.ndarray
    T: float
    f: Callable | None = None
    u: Callable | None = None
    exact: Callable | None = None
    order: Order | None = None
    name: str = ""
    U: Callable | None = None
    lipschitz: float | None = None
    phi: Callable | None = None
    sigma: Callable | None = None
    theta: Callable | None = None
    steps: list[float] | None = None
    initial_jump: bool = False
    notes: str = ""
    data: Mapping[str, Any] = dataclasses.field(default_factory=dict)

    def __init__(self, operator: Any, x0: Any, T: float, *, f: Callable | None = None,
                 u: Callable | None = None, exact: Callable | None = None, order: Any = None,
                 name: str | None = None, U: Callable | None = None, lipschitz: float | None = None,
                 phi: Callable | None = None, sigma: Callable | None = None, theta: Callable | None = None,
                 steps: Sequence[float] | None = None, initial_jump: bool = False, notes: str = "",
                 data: Mapping[str, Any] | None = None) -> None:
        if not hasattr(operator, "resolvent") or not hasattr(operator, "dim"):
            raise InvalidProblem(f"operator must be a verimono.Operator (with .dim and .resolvent), got {operator!r}")
        x0 = _finite_array(x0, "x0")
        n = operator.dim
        if x0.ndim not in (1, 2) or x0.shape[-1] != n:
            raise InvalidProblem(f"x0 must have shape ({n},) or (B, {n}) for an operator on R^{n}, got {x0.shape}")
        try:
            T = float(T)
        except (TypeError, ValueError):
            raise InvalidProblem(f"T must be a number, got {T!r}") from None
        if not np.isfinite(T) or T <= 0:
            raise InvalidProblem(f"T must be positive and finite, got T = {T!r}")
        for what, fn in (("f", f), ("u", u), ("exact", exact), ("U", U), ("phi", phi), ("sigma", sigma),
                         ("theta", theta)):
            if fn is not None and not callable(fn):
                raise InvalidProblem(f"{what} must be callable, got {fn!r}")
        if name is not None and not isinstance(name, str):
            raise InvalidProblem(f"name must be a string, got {name!r}")
        if not isinstance(notes, str):
            raise InvalidProblem(f"notes must be a string, got {notes!r}")
        if not isinstance(initial_jump, (bool, np.bool_)):
            raise InvalidProblem(f"initial_jump must be True or False, got {initial_jump!r}")
        # the problem's own copy, read-only: a problem is shared by every stepper checked on it (the generated
        # problems by a whole process), so a stepper writing into problem.x0 (a bug: the problem is the caller's)
        # fails there, with the error NumPy raises, instead of moving x0 under the steppers checked after it
        x0.flags.writeable = False
        fields = dict(operator=operator, x0=x0, T=T, f=f, u=u, exact=exact, order=_as_order(order),
                      name=name or f"{getattr(operator, 'name', 'F')} problem", U=U,
                      lipschitz=_lipschitz(lipschitz), phi=phi, sigma=sigma, theta=theta, steps=_steps(steps),
                      initial_jump=bool(initial_jump), notes=notes, data=_data(data))
        for key, value in fields.items():
            object.__setattr__(self, key, value)  # frozen: the one place the fields are set
        if f is not None:
            fx = _finite_array(f(x0), "f(x0)")
            if fx.shape != x0.shape:
                raise InvalidProblem(f"f(x0) must have the shape of x0 {x0.shape}, got {fx.shape}")
        for what, fn in (("u(0)", u), ("U(0)", U)):
            if fn is not None:
                val = _finite_array(fn(0.0), what)
                if val.shape != (n,):
                    raise InvalidProblem(f"{what} must have shape ({n},), got {val.shape}")
        if not initial_jump:
            self._check_initial_point()

    def replace(self, **changes: Any) -> "Problem":
        """A copy with some constructor arguments replaced (``x0``, ``T``, ``name``, ``phi``, ...), validated
        as a new problem; an unknown name is an :class:`InvalidProblem`."""
        kw = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        unknown = sorted(set(changes) - kw.keys())
        if unknown:
            raise InvalidProblem(f"Problem has no field {', '.join(unknown)}; fields: {', '.join(kw)}")
        kw.update(changes)
        return Problem(kw.pop("operator"), kw.pop("x0"), kw.pop("T"), **kw)

    @property
    def dim(self) -> int:
        return self.operator.dim

    @property
    def batched(self) -> bool:
        return self.x0.ndim == 2

    def _check_initial_point(self) -> None:
        # at the precision the operator computes in (a float32 projection of x0 ∈ dom F moves it by its
        # rounding), the coarser of the one under judgement and the projection's own deciding — observed while
        # it runs: a wrapped operator (operator_from_resolvent) hands back float64, its float32 seen only by the
        # judgement in progress, and outside any (a user's Problem(...)) a float32 box's own rounding of x0,
        # 3e-8, refused it as outside its domain (probe8)
        try:
            with judged_precision(current_precision().name) as seen:
                raw = self.operator.project_domain(self.x0, 0.0)
        except NotImplementedError:
            return  # cannot be checked; the operator laws report the missing member
        precision = coarser(seen.name, precision_of(raw))
        p = as_float64(raw)
        dist = float(np.max(np.abs(p - self.x0)))
        # and at the operator's own scale when it states one (tolerances.py): a float32 projection onto a ball of
        # radius 10^6 moves a point of its domain near the origin by its rounding there, eps·10^6
        stated = stated_data_scale(self.operator)
        with judged_at_scale(stated):
            tol = tolerance(self.x0, rtol=rtol_for(precision))
        if dist > tol:
            hint = ("" if stated is not None else "; if the operator computes with data far larger than x0 and this "
                    "distance is its rounding, state its data_scale (operator_from_resolvent(..., data_scale=...))")
            raise OutsideDomain(f"x0 = {self.x0} lies outside cl dom F(0,·) (distance {dist:.3g} to its "
                                f"projection); pass initial_jump=True to start with the catching-up jump{hint}")

    def input_increments(self, t: np.ndarray) -> np.ndarray | None:
        """``∫_{t_k}^{t_{k+1}} u`` for every cell: exact from ``U`` or 3-point Gauss–Legendre (order 6)."""
        if self.U is not None:
            Ut = np.array([np.asarray(self.U(s), dtype=float) for s in t])
            return np.diff(Ut, axis=0)
        if self.u is None:
            return None
        nodes, weights = _GAUSS3
        h = np.diff(t)
        mid = 0.5 * (t[:-1] + t[1:])
        total = np.zeros((h.size, self.dim))
        for xi, w in zip(nodes, weights):
            vals = np.array([np.asarray(self.u(s), dtype=float) for s in (mid + 0.5 * h * xi).tolist()])
            total += (0.5 * w) * h[:, None] * vals
        if not np.all(np.isfinite(total)):
            raise InvalidProblem("u(t) returned non-finite values on the grid")
        return total

    def __repr__(self) -> str:
        return f"Problem({self.name!r}, n={self.dim}, T={self.T:g}, order={self.order})"



#: 3-point Gauss–Legendre nodes and weights on [-1, 1], computed once (``leggauss`` solves an eigenproblem per call:
#: ``input_increments`` called row by row by the trajectory laws spent 60% of their time there; the same arrays)
_GAUSS3 = tuple(a.copy() for a in np.polynomial.legendre.leggauss(3))
for _a in _GAUSS3:
    _a.flags.writeable = False
del _a

#: where a problem was loaded from (``MODULE:OBJECT``), for reproduction lines; weak: it dies with the problem
_ORIGINS: "weakref.WeakKeyDictionary[Problem, str]" = weakref.WeakKeyDictionary()


def with_origin(problem: "Problem", spec: str) -> "Problem":
    """Remember that ``problem`` was loaded from ``spec`` (``MODULE:OBJECT``); returns ``problem``."""
    _ORIGINS[problem] = str(spec)
    return problem


def origin_of(problem: Any) -> str | None:
    """The ``MODULE:OBJECT`` ``problem`` was loaded from (:func:`with_origin`), if any."""
    try:
        return _ORIGINS.get(problem)
    except TypeError:
        return None


__all__ = ["with_origin", "origin_of", "Problem", "Order"]
