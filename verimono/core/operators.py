"""The catalog of maximal monotone operators ``F(t, ·)`` with closed-form resolvents, and the protocol they follow.

An :class:`Operator` is known through its resolvent ``J_λ = (I + λF(t,·))^{-1}``, which for a maximal
monotone ``F`` is single-valued, defined everywhere and firmly nonexpansive (the paper's Proposition
``prop:maxmon-resolvent-Yosida``, items i–ii), its Yosida approximation ``Y_λ = (I - J_λ)/λ``, its
minimal section ``F^0(t, x) = proj(0, F(t, x))``, the projection onto ``cl dom F(t,·)`` and a membership
test ``y ∈ F(t, x)``.  Members an operator cannot provide raise :class:`NotImplementedError`; checks that
need them are then counted as skipped, never silently passed.

Every catalog operator accepts points of shape ``(n,)`` or a batch of shape ``(B, n)`` and every
parameter may be a constant or a callable of ``t``.  Scalar and vector parameters may also carry a
leading batch axis — ``NormSubdifferential(c)`` with ``c`` of shape ``(B,)`` is a batch of ``B`` operators
applied row by row to points of shape ``(B, n)`` (likewise ``Ball`` and ``Box`` in :mod:`verimono.core.sets`).
A time per row: ``resolvent``, ``yosida``, ``min_norm`` and ``project_domain`` of the catalog take ``t`` of shape
``(B,)`` beside ``x`` of shape ``(B, n)`` — row ``i`` at ``t[i]``, bit-identical to ``B`` separate calls — as
:meth:`Operator._accepts_times` declares (:func:`verimono.core.operator_protocol.accepts_times`); the assumption
laws call such an operator once per block of times, any other once per time.

Performance: the per-step work of :func:`verimono.solve` is the resolvent.  Catalog operators compute it
without ``np.errstate``/``np.where`` (``x max(|x| - λc, 0)/max(|x|, tiny)`` has no ``0/0``), with sums of
squares by the BLAS ``dot`` of each row (``np.vecdot``) — the same summation for a point ``(n,)`` and for
every row of a batch ``(B, n)``, so batched and separate solves agree bit for bit — and offer
:meth:`Operator._kernel`, a private fast path for one point shape that prebinds constant parameters and
does its scalar arithmetic in Python floats (the same IEEE operations, hence the same bits).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ._params import as_param
from ._rows import _INF, _TINY, _mx, _norm, _sqrt, dot_rows, per_row, per_row_steps, steps_of, times_of
from ._validate import bad_lam, bad_param, batch_column, check_lam, real_array
from .errors import InvalidProblem, NotMonotone, OutsideDomain
from .tolerances import tolerance
from .operator_protocol import (Operator, accepts_steps, accepts_times, operator_from_resolvent, provides,
                                resolvent_kernel, resolvent_rows)


def _own(obj: Any, cls: type, member: str = "resolvent") -> bool:
    """Whether ``obj`` uses ``cls``'s own ``member`` (a subclass override disables the fast kernel)."""
    return getattr(type(obj), member) is getattr(cls, member)


def _own_written(obj: Any, cls: type, member: str) -> bool:
    """Whether ``obj``'s ``member`` is the one written in ``cls``'s body (kept as ``cls._<member>_written``): not
    overridden by a subclass, not replaced on the object nor on the class (a wrapper there is called per row, which
    :func:`_own_read`, comparing with the class's current attribute, would not see)."""
    return (getattr(type(obj), member) is cls.__dict__[f"_{member}_written"]
            and member not in getattr(obj, "__dict__", {}))


def _own_read(obj: Any, cls: type, member: str = "_c_at") -> bool:
    """Whether ``obj`` reads its parameter by ``cls``'s own ``member``: neither overridden in a subclass nor
    replaced on the object itself."""
    return _own(obj, cls, member) and member not in getattr(obj, "__dict__", {})


#: the members that take a time per row (:meth:`Operator._accepts_times`)
_TIMED = ("resolvent", "yosida", "min_norm", "project_domain")


def _own_times(obj: Any, cls: type) -> bool:
    """``obj`` uses ``cls``'s own members that take a time per row: no subclass override of any, none replaced on
    the object itself (a user's wrapper is not assumed to take an array of times)."""
    mine = getattr(obj, "__dict__", {})
    return all(_own(obj, cls, m) and m not in mine for m in _TIMED)


#: the members that take a step size per row (:meth:`Operator._accepts_steps`)
_STEPPED = ("resolvent", "yosida")


def _own_steps(obj: Any, cls: type) -> bool:
    """``obj`` uses ``cls``'s own ``resolvent`` and ``yosida`` (those that take a step size per row): neither
    overridden by a subclass nor replaced on the object itself (a user's wrapper is called with a float ``λ``)."""
    mine = getattr(obj, "__dict__", {})
    return all(_own(obj, cls, m) and m not in mine for m in _STEPPED)


def _steps(op: Operator, x: np.ndarray, lam, t):
    """``(λ, None)`` for one step size (checked), ``(λ column (B, 1), None)`` for a step size per row the operator
    computes at once, or ``(None, J)`` with ``J`` the rows' resolvents called one by one (a float ``λ_i`` and ``t_i``
    each) when it does not declare it, or the times per row with it (:meth:`Operator._accepts_steps`)."""
    ls = steps_of(lam, x, f"{op.name}.resolvent")
    if ls is None:
        return check_lam(lam, f"{op.name}.resolvent"), None
    if not op._accepts_steps() or (type(t) is np.ndarray and not op._accepts_times()):
        return None, per_row_steps(op.resolvent, x, ls, t)
    return ls[:, None], None


def _column(p: np.ndarray) -> np.ndarray:
    """A value per row ``(B,)`` as a column ``(B, 1)``; a scalar, or rows ``(B, n)``, as they are."""
    return p[:, None] if np.ndim(p) == 1 else p


def _weight_times(param, ts: np.ndarray, owner: str, what: str) -> np.ndarray:
    """:func:`_weight_at` at every time of ``ts`` (a constant as it is, checked at construction; a moving one a row
    per time, each time where it is not ``≥ 0`` going through :func:`_weight_at`: its error)."""
    if param.constant:
        return param(0.0)
    c = param.at_times(ts)
    if not (c >= 0).all():
        for t in ts.tolist():
            _weight_at(param, t, owner, what)
    return c


def _scalar_fn(param) -> Callable[[float], float]:
    """``t -> float(param(t))`` with the least overhead (for parameters whose value is a scalar)."""
    if param.constant:
        v = float(param(0.0))
        return lambda t: v
    fn = param._fn

    def call(t):
        v = fn(t)
        if type(v) is float:
            return v
        return float(real_array(v, f"{param.name}({t!r})"))
    return call


def _weight_at(param, t: float, owner: str, what: str) -> np.ndarray:
    """A nonnegative weight ``param(t)`` of a convex function, checked at ``t`` when it moves (constants are
    checked once, at construction); :class:`NotMonotone` naming ``t`` otherwise (also for ``nan``)."""
    c = param(t)
    if not param.constant and not (float(c) >= 0.0 if c.ndim == 0 else (c >= 0).all()):
        raise bad_param(owner, what, c, t, "must be >= 0 (a negative weight makes the operator non-monotone)",
                        NotMonotone)
    return c


def _weight_value(param, t, owner: str, what: str):
    """:func:`_weight_at`'s ``c(t)`` as a Python float when it is a scalar ``≥ 0``, else what :func:`_weight_at`
    returns or raises (an array: a batch of weights; its error: a negative or NaN weight).

    The same number either way: a constant's 0-d float64 read once; a callable's ``float`` or ``np.float64``
    taken as it is (``Param`` would wrap it as a 0-d float64 array of the same value).  The callable is called
    once, as :func:`_weight_at` calls it: a value off the fast path is converted as ``Param`` converts it
    (:meth:`verimono.core._params.Param.of`) and checked as :func:`_weight_at` checks it."""
    fn = param._fn
    if fn is None:
        v = param._value
        return float(v) if v.ndim == 0 else v       # a constant was checked at construction
    v = fn(t)
    if (type(v) is float or type(v) is np.float64) and v >= 0.0:
        return float(v)
    c = param.of(v, t)
    if not (float(c) >= 0.0 if c.ndim == 0 else (c >= 0).all()):
        raise bad_param(owner, what, c, t, "must be >= 0 (a negative weight makes the operator non-monotone)",
                        NotMonotone)
    return c


def _frobenius(x: np.ndarray) -> float:
    """``float(np.linalg.norm(x))`` of a float array: NumPy's own default path (the flattened array's
    ``sqrt(x·x)``, the same dot and its warnings) without its dispatch."""
    x = x.ravel(order="K")
    return _sqrt(x.dot(x))


def _check_dim(op: Operator, x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.shape[-1:] != (op.dim,):
        raise InvalidProblem(f"{op.name} acts on R^{op.dim}; got a point of shape {x.shape}")
    return x


class _EverywhereDefined(Operator):
    """An operator defined on all of ``R^n`` at every ``t`` (``dom F(t,·) = R^n``): (A3) holds with ``φ ≡ 0``,
    and the projection onto the domain is the identity."""

    full_domain = True

    def project_domain(self, x, t=0.0):
        return np.array(x, dtype=float)


class Linear(_EverywhereDefined):
    """``F(t, x) = M(t) x`` with ``M + Mᵀ ⪰ 0`` (``M`` need not be symmetric).

    Monotone because ``⟨M(x-y), x-y⟩ ≥ 0``; continuous and everywhere defined, hence maximal.
    ``J_λ = (I + λM)^{-1}``, well conditioned: ``xᵀ(I + λM)x ≥ |x|²`` gives singular values ≥ 1.
    For a constant ``M`` the inverse is computed once per step size and reused.
    """

    def __init__(self, M: Any, name: str | None = None) -> None:
        self._M = as_param(M, "M")
        M0 = self._M(0.0)
        if M0.ndim != 2 or M0.shape[0] != M0.shape[1]:
            raise InvalidProblem(f"M must be a square matrix, got shape {M0.shape}")
        super().__init__(M0.shape[0], name or "Linear")
        self.static = self._M.constant
        _require_monotone_matrix(M0, "M")
        self._cache_lam: float | None = None
        self._cache_inv: np.ndarray | None = None
        # a uniform grid's steps np.diff(linspace) take a handful of values differing in the last bits:
        # keep every factor seen (bounded), not only the last one
        self._inv_cache: dict[float, np.ndarray] = {}
        self._norm2: float | None = None

    def M(self, t: float = 0.0) -> np.ndarray:
        return self._M(t)

    def _inverse(self, lam: float, t: float) -> np.ndarray:
        if self.static:
            if lam != self._cache_lam:
                inv = self._inv_cache.get(lam)
                if inv is None:
                    if len(self._inv_cache) >= 256:
                        self._inv_cache.clear()
                    inv = np.linalg.inv(np.eye(self.dim) + lam * self._M(t)).T.copy()
                    self._inv_cache[lam] = inv
                self._cache_inv = inv
                self._cache_lam = lam
            return self._cache_inv
        return np.linalg.inv(np.eye(self.dim) + lam * self._M_at(t)).T

    def _inverses(self, lams: list) -> np.ndarray:
        """``[_inverse(λ, 0) for λ in lams]`` stacked (constant ``M``): the factors not cached are inverted in one
        call of the stacked ``I + λ_k M`` (NumPy's ``inv`` solves each matrix of a stack as it solves one alone: the
        same numbers), then cached in the order a call per row would cache them."""
        cache = self._inv_cache
        new = [lam for lam in dict.fromkeys(lams) if lam not in cache]
        if len(new) > 1:
            M = self._M(0.0)
            made = np.linalg.inv(np.eye(self.dim) + np.array(new)[:, None, None] * M).transpose(0, 2, 1).copy()
            fresh = dict(zip(new, made))
            out = []
            for lam in lams:
                inv = cache.get(lam)
                if inv is None:
                    if len(cache) >= 256:
                        cache.clear()
                    inv = cache[lam] = fresh[lam]
                out.append(inv)
            self._cache_lam, self._cache_inv = lams[-1], out[-1]
            return np.array(out)
        inverse = self._inverse
        return np.array([inverse(lam, 0.0) for lam in lams])

    def _M_at(self, t: float) -> np.ndarray:
        """``M(t)``, checked at this ``t``: square of the operator's size, finite, ``M + Mᵀ ⪰ 0`` (a moving
        ``M`` validated at ``t = 0`` only once gave ``x(1) = -11197`` for ``M(t) = 1 - 20t``)."""
        M = self._M(t)
        if M.shape != (self.dim, self.dim) or not np.isfinite(M).all():
            raise bad_param(self.name, "M(t)", M, t, f"must be a finite {self.dim}x{self.dim} matrix")
        _require_monotone_matrix(M, "M", t)
        return M

    def resolvent(self, x, lam, t=0.0):
        x = real_array(x)
        if type(lam) is np.ndarray:
            ls, J = _steps(self, x, lam, t)
            if J is not None:
                return J
            if not self.static:     # M(t) per row: its own inverse each
                return per_row_steps(self.resolvent, x, ls[:, 0], t)
            # each row's (I + λ_i M)^{-T} (the same cached factor a separate call uses), and a stack of
            # (1, n) @ (n, n) products: each row exactly as the single point's x @ W
            W = self._inverses(ls[:, 0].tolist())
            return (x[:, None, :] @ W)[:, 0, :]
        ts = times_of(t, x, self.name)
        if ts is not None:
            if not self.static or not self._accepts_times():     # M(t) per row: its own inverse each
                return per_row(lambda xi, ti: self.resolvent(xi, lam, ti), x, ts)
            t = 0.0
        W = self._inverse(check_lam(lam, f"{self.name}.resolvent"), t)
        if x.ndim == 1:
            return x @ W
        # a stack of (1, n) @ (n, n) products: each row is computed exactly as the single point x @ W
        # (one BLAS call per row); a plain (B, n) @ (n, n) product would sum in another order
        return (x[..., None, :] @ W)[..., 0, :]

    def _accepts_batches(self):
        return _own(self, Linear)

    def _accepts_times(self):
        return _own_times(self, Linear)

    def _accepts_steps(self):
        return _own_steps(self, Linear)

    def _kernel(self, x0):
        if not _own(self, Linear) or not self.static or x0.ndim != 1:
            return None
        inverse, name = self._inverse, self.name

        def step(x, lam, t):
            if not 0.0 < lam < _INF:
                raise bad_lam(lam, name)
            return x @ inverse(lam, t)
        return step

    def min_norm(self, x, t=0.0):
        ts = times_of(t, x, self.name)
        if ts is not None:
            x = real_array(x)
            if not self.static or not self._accepts_times():
                return per_row(lambda xi, ti: self.min_norm(xi, ti), x, ts)
            # a stack of (1, n) @ (n, n) products: each row exactly as the single point's x @ Mᵀ
            return (x[:, None, :] @ self._M(0.0).T)[:, 0, :]
        return real_array(x) @ (self._M(t) if self.static else self._M_at(t)).T

    def growth(self, t=0.0):
        """``|M(t)x| ≤ ‖M(t)‖₂ |x|`` (a constant ``M``'s norm, an SVD, computed once: the bounds ask it at
        every node of every partition)."""
        if not self.static:
            return float(np.linalg.norm(self._M_at(t), 2))
        if self._norm2 is None:
            self._norm2 = float(np.linalg.norm(self._M(t), 2))
        return self._norm2

    def contains(self, x, y, t=0.0, tol=None):
        Mx = self.min_norm(x, t)
        tol = tolerance(Mx, y) if tol is None else tol
        return bool(np.max(np.abs(np.asarray(y) - Mx)) <= tol)

    _contains_written = contains     # the contains _contains_rows answers for (_own_written)

    def _contains_rows(self, X, Y, ts, tols):
        """:meth:`contains` of every row ``(X_i, Y_i, t_i, tol_i)`` at once (``(B,)`` booleans), bit-identically to
        the calls per row — ``min_norm`` of the rows at their times (bit-identical to its calls per row, as the
        class declares) and the same elementwise test; ``None`` where the members are not this class's own."""
        if not (_own_written(self, Linear, "contains") and _own_read(self, Linear, "min_norm") and self._accepts_times()):
            return None
        return np.abs(Y - self.min_norm(X, ts)).max(axis=1, initial=0.0) <= tols


def _require_monotone_matrix(M: np.ndarray, what: str, t: float | None = None) -> None:
    sym = 0.5 * (M + M.T)
    lmin = float(np.linalg.eigvalsh(sym)[0]) if M.size else 0.0
    if lmin < -tolerance(M):
        at = "" if t is None else f" at t = {t!r}"
        raise NotMonotone(f"{what} + {what}ᵀ must be positive semidefinite for a monotone operator; "
                          f"its smallest eigenvalue{at} is {2 * lmin:.3g}")


def _nonnegative(value: np.ndarray, what: str) -> None:
    if np.any(np.asarray(value) < 0):
        raise NotMonotone(f"{what} must be nonnegative for a convex function (got {value}); "
                          "a negative weight makes the operator non-monotone")


#: NormSubdifferential's reads of its weight: replaced on an object, its fast paths step aside (``_fast_c``)
_WEIGHT_READS = ("_c_at", "_col")


class NormSubdifferential(_EverywhereDefined):
    """``F(t, ·) = ∂(c(t)‖·‖₂)``: ``F(t, x) = c x/|x|`` for ``x ≠ 0`` and the ball ``c B`` at 0.

    The paper's example ``g(t, x) = t|x|`` is ``c(t) = t``.  ``J_λ x = max(1 - λc/|x|, 0) x``
    (block soft thresholding), ``F^0(t, 0) = 0``.
    """

    static = False
    #: the one-point paths read c(t) by :func:`_weight_value` (the same number and checks as :meth:`_c_at`): only
    #: while :meth:`_c_at` and :meth:`_col` are this class's own (a subclass overriding either is called through them)
    _fast_c = True

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls._fast_c = cls._c_at is NormSubdifferential._c_at and cls._col is NormSubdifferential._col

    def __setattr__(self, name: str, value: Any) -> None:
        # an _c_at or _col replaced on the object itself (not in a subclass) is honoured as a subclass's is: the
        # object's _fast_c is then false (the one-point paths, the kernel and the blocks of times go through it);
        # a flag set here, not a dictionary look-up on every call (catfast's one-point paths stay as fast)
        super().__setattr__(name, value)
        if name in _WEIGHT_READS:
            super().__setattr__("_fast_c", False)

    def __delattr__(self, name: str) -> None:
        super().__delattr__(name)
        if name in _WEIGHT_READS and not any(m in self.__dict__ for m in _WEIGHT_READS):
            self.__dict__.pop("_fast_c", None)      # the class's own reads again: the class's flag

    def __init__(self, c: Any, dim: int = 1, name: str | None = None) -> None:
        super().__init__(dim, name or "NormSubdifferential")
        self._c = as_param(c, "c")
        self.static = self._c.constant
        c0 = self._c(0.0)
        if c0.ndim > 1:
            raise InvalidProblem(f"c must be a scalar or a batch of shape (B,), got shape {c0.shape}")
        _nonnegative(c0, "c(0)")

    def c(self, t: float = 0.0) -> float:
        return self._c(t)

    def _c_at(self, t):
        """``c(t)``, checked ``≥ 0`` at this ``t`` when it moves (a negative weight is not monotone)."""
        return _weight_at(self._c, t, self.name, "c(t)")

    def _col(self, t, x):
        """``c(t)`` shaped to broadcast against the norms ``(..., 1)`` of ``x`` (a batch ``(B,)`` per row; with
        ``t`` of shape ``(B,)``, ``c(t[i])`` for row ``i``)."""
        ts = times_of(t, x, self.name)
        if ts is not None:
            return _column(_weight_times(self._c, ts, self.name, "c(t)"))
        return batch_column(self._c_at(t), x, "c")

    def resolvent(self, x, lam, t=0.0):
        # J x = x max(|x| - λc, 0)/|x|, written so that x = 0 gives 0 without a 0/0
        x = real_array(x)
        if x.ndim == 1 and type(lam) is not np.ndarray and type(t) is not np.ndarray and self._fast_c:
            # one point, one λ, one t: the same checks in the same order, and the scalar arithmetic in Python
            # floats (the same IEEE operations on the same |x|², hence the same bits)
            lam = check_lam(lam, f"{self.name}.resolvent")
            s = dot_rows(x, x)      # before c(t), as below: an overflow warns before a bad weight raises
            c = _weight_value(self._c, t, self.name, "c(t)")
            if type(c) is float:
                nrm = _sqrt(s)
                lc = lam * c
                if nrm < _INF and lc < _INF:    # else NumPy's arithmetic below: its overflow warnings
                    return x * (max(nrm - lc, 0.0) / max(nrm, _TINY))
            nrm = np.sqrt(s)[..., None]         # _norm(x)
            return x * (_mx(nrm - lam * batch_column(np.asarray(c), x, "c"), 0.0) / _mx(nrm, _TINY))
        lam, J = _steps(self, x, lam, t)
        if J is not None:
            return J
        if type(t) is np.ndarray and not self._accepts_times():
            return per_row(lambda xi, ti: self.resolvent(xi, lam, ti), x, times_of(t, x, self.name))
        nrm = _norm(x)
        return x * (_mx(nrm - lam * self._col(t, x), 0.0) / _mx(nrm, _TINY))

    def _accepts_batches(self):
        return _own(self, NormSubdifferential)

    def _accepts_times(self):
        # a block of times reads c by _weight_times, not through a subclass's _c_at or _col (then: per row)
        return self._fast_c and _own_times(self, NormSubdifferential) and self._c(0.0).ndim == 0

    def _accepts_steps(self):
        return _own_steps(self, NormSubdifferential) and self._c(0.0).ndim == 0

    def _kernel(self, x0):
        if not _own(self, NormSubdifferential) or not self._fast_c or x0.ndim != 1 or self._c(0.0).ndim:
            return None
        c, name = _scalar_fn(self._c), self.name

        def step(x, lam, t):
            if not 0.0 < lam < _INF:
                raise bad_lam(lam, name)
            ct = c(t)
            if not ct >= 0.0:       # also catches nan
                raise bad_param(name, "c(t)", ct, t, "must be >= 0 (a negative weight is not monotone)",
                                NotMonotone)
            nrm = _sqrt(x.dot(x))
            return x * (max(nrm - lam * ct, 0.0) / max(nrm, _TINY))
        return step

    def value(self, x, t=0.0):
        """``g(t, x) = c(t)|x|`` (``F(t,·) = ∂g(t,·)``): the value laws check the resolvent is its prox."""
        c = _weight_value(self._c, t, self.name, "c(t)") if self._fast_c else self._c_at(t)
        if type(c) is not float:
            c = np.asarray(c, dtype=float)
            if c.ndim:
                raise NotImplementedError(f"{self.name}: a value needs one weight c(t), not a batch of them")
            c = float(c)
        return c * _frobenius(np.asarray(x, dtype=float))

    _value_written = value      # the value _value_rows answers for (_own_written)

    def _value_rows(self, Z, t=0.0):
        """:meth:`value` of every row of ``Z`` ``(B, n)`` at the one time ``t``, or at ``t_i`` for row ``i`` with ``t`` of
        shape ``(B,)`` (``(B,)`` floats), bit-identically to the calls per row: ``c(t)`` read once as :meth:`value`
        reads it (a block of times as :meth:`_accepts_times` declares), each norm the BLAS dot of its row
        (:func:`dot_rows`, :func:`_frobenius`'s number) and the same product; ``None`` where ``value``, ``_c_at`` or
        ``_col`` is not this class's own (then: the calls per row)."""
        if not (_own_written(self, NormSubdifferential, "value") and self._fast_c):
            return None
        if type(t) is np.ndarray:       # a time per row: c(t_i) as a block of times reads it (_accepts_times)
            if not self._accepts_times():
                return None
            c = np.broadcast_to(_weight_times(self._c, times_of(t, Z, self.name), self.name, "c(t)"), t.shape)
            return c * np.sqrt(dot_rows(Z, Z))
        c = self._one_weight(t)
        if c is None:
            raise NotImplementedError(f"{self.name}: a value needs one weight c(t), not a batch of them")
        return c * np.sqrt(dot_rows(Z, Z))

    def _one_weight(self, t):
        """``c(t)`` read as :meth:`value` reads it, as a float; ``None`` for a batch of weights (value declines it)."""
        c = _weight_value(self._c, t, self.name, "c(t)")
        if type(c) is not float:
            c = np.asarray(c, dtype=float)
            if c.ndim:
                return None
            c = float(c)
        return c

    def _value_at(self, t=0.0):
        """``z ↦`` :meth:`value` ``(z, t)`` for float64 points ``z`` of shape ``(n,)`` (a minimiser's many calls at one
        time), bit-identically: ``c(t)`` read once as :meth:`value` reads it, then ``c·sqrt(z·z)``, the dot
        :func:`_frobenius` takes; ``None`` where ``value``, ``_c_at`` or ``_col`` is not this class's own."""
        if not (_own_written(self, NormSubdifferential, "value") and self._fast_c):
            return None
        c = self._one_weight(t)
        if c is None:
            return None             # value's NotImplementedError: met by its own calls

        def g(z):
            return c * _sqrt(z.dot(z))
        return g

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if type(t) is np.ndarray and not self._accepts_times():
            return per_row(lambda xi, ti: self.min_norm(xi, ti), x, times_of(t, x, self.name))
        if x.ndim == 1 and type(t) is not np.ndarray and self._fast_c:
            # one point at one t: the same operations in the same order (|x|², then c(t), then the array's
            # c·x/|x|, computed whatever |x| as np.where computes it: its warnings), the norm a Python float
            s = dot_rows(x, x)
            c = _weight_value(self._c, t, self.name, "c(t)")
            if type(c) is float:
                nrm = _sqrt(s)
                v = c * x / max(nrm, _TINY)
                return v if nrm > 0.0 else np.zeros(x.shape)
            nrm = np.sqrt(s)[..., None]
            return np.where(nrm > 0.0, batch_column(c, x, "c") * x / _mx(nrm, _TINY), 0.0)
        nrm = _norm(x)
        # 0 where |x| is 0 or underflows (x·x < tiny): F^0(0) = 0; the max only avoids a 0/0 warning
        return np.where(nrm > 0.0, self._col(t, x) * x / _mx(nrm, _TINY), 0.0)

    def growth(self, t=0.0):
        """``|F^0(t, x)| ≤ c(t)`` for every ``x``."""
        return float(np.linalg.norm(self.min_norm(np.ones(self.dim), t)))

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        c = _weight_value(self._c, t, self.name, "c(t)") if self._fast_c else self._c_at(t)
        c = c if type(c) is float else float(c)
        tol = tolerance(c, y) if tol is None else tol
        nx = _frobenius(x)
        if nx <= tol and _frobenius(y) <= c + tol:  # x within tol of 0, where F = the ball cB
            return True
        return bool(nx > 0.0 and _frobenius(y - c * x / nx) <= tol)

    _contains_written = contains     # the contains _contains_rows answers for (_own_written)

    def _contains_rows(self, X, Y, ts, tols):
        """:meth:`contains` of every row ``(X_i, Y_i, t_i, tol_i)`` at once (``(B,)`` booleans), bit-identically to the
        calls per row: ``c(t_i)`` as a block of times reads it, each norm the BLAS dot of its row (:func:`dot_rows`,
        :func:`_frobenius`'s number) and the same elementwise arithmetic; ``None`` where a member is not this class's
        own."""
        if not (_own_written(self, NormSubdifferential, "contains") and self._accepts_times()):
            return None
        c = np.broadcast_to(_weight_times(self._c, ts, self.name, "c(t)"), ts.shape)
        nx, ny = np.sqrt(dot_rows(X, X)), np.sqrt(dot_rows(Y, Y))
        with np.errstate(divide="ignore", invalid="ignore"):
            Z = Y - c[:, None] * X / nx[:, None]
        return ((nx <= tols) & (ny <= c + tols)) | ((nx > 0.0) & (np.sqrt(dot_rows(Z, Z)) <= tols))


class L1Subdifferential(_EverywhereDefined):
    """``F(t, ·) = ∂(Σ_i c_i(t)|x_i|)`` (``c`` a scalar or a vector of weights).

    Componentwise: ``c_i sgn(x_i)`` for ``x_i ≠ 0`` and ``[-c_i, c_i]`` at 0;
    ``J_λ`` is soft thresholding ``sgn(x) max(|x| - λc, 0)``.
    """

    def __init__(self, c: Any, dim: int = 1, name: str | None = None) -> None:
        super().__init__(dim, name or "L1Subdifferential")
        self._c = as_param(c, "c")
        self.static = self._c.constant
        c0 = self._c(0.0)
        if c0.ndim and c0.shape != (dim,):
            raise InvalidProblem(f"c must be a scalar or have shape ({dim},), got {c0.shape}")
        _nonnegative(c0, "c(0)")

    def resolvent(self, x, lam, t=0.0):
        x = real_array(x)
        if type(lam) is not np.ndarray:     # one λ: _steps' own path (steps_of is None), without the call
            lam = check_lam(lam, f"{self.name}.resolvent")
        else:
            lam, J = _steps(self, x, lam, t)
            if J is not None:
                return J
        return np.sign(x) * _mx(np.abs(x) - lam * self._c_rows(t, x), 0.0)

    def _c_rows(self, t, x):
        """``c(t)``, or with ``t`` of shape ``(B,)`` ``c(t[i])`` for row ``i`` of ``x``."""
        if type(t) is not np.ndarray:       # times_of's None, without the call
            return _weight_at(self._c, t, self.name, "c(t)")
        ts = times_of(t, x, self.name)
        if ts is None:
            return _weight_at(self._c, t, self.name, "c(t)")
        c = _weight_times(self._c, ts, self.name, "c(t)")
        # a constant c, scalar or a weight per coordinate (n,), broadcasts as it is: as a column (n, 1) it was c_i for
        # row i (wrong values for B = n rows, a broadcast error otherwise); a moving one is a row per time
        return c if self._c.constant else _column(c)

    def _accepts_batches(self):
        return _own(self, L1Subdifferential)

    def _accepts_times(self):
        return _own_times(self, L1Subdifferential)

    def _accepts_steps(self):
        return _own_steps(self, L1Subdifferential)

    def _kernel(self, x0):
        if not _own(self, L1Subdifferential):
            return None
        sign, absolute, name = np.sign, np.abs, self.name
        if self._c.constant:
            c = self._c(0.0)

            def step(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                return sign(x) * _mx(absolute(x) - lam * c, 0.0)
        else:
            cfn = self._c

            def step(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                return sign(x) * _mx(absolute(x) - lam * _weight_at(cfn, t, name, "c(t)"), 0.0)
        return step

    def value(self, x, t=0.0):
        """``g(t, x) = Σ c_i(t)|x_i|`` (``F(t,·) = ∂g(t,·)``): the value laws check the resolvent is its prox."""
        c = self._weight_now(t)
        if type(x) is not np.ndarray or x.dtype != np.float64:
            x = np.asarray(x, dtype=float)
        return float(np.add.reduce(c * np.abs(x), axis=None))   # np.sum without its dispatch

    _value_written = value      # the value _value_rows answers for (_own_written)

    def _value_rows(self, Z, t=0.0):
        """:meth:`value` of every row of ``Z`` ``(B, n)`` at the one time ``t``, or at ``t_i`` for row ``i`` with ``t`` of
        shape ``(B,)`` (``(B,)`` floats), bit-identically to the calls per row: ``c(t)`` read once as :meth:`value`
        reads it (a block of times by :meth:`_c_rows`, as :meth:`_accepts_times` declares), the same products and each row's sum NumPy's
        pairwise sum of that row, as the one-point reduction is; ``None`` where ``value`` is not this class's own."""
        if not _own_written(self, L1Subdifferential, "value"):
            return None
        if type(t) is np.ndarray:       # a time per row: c(t_i) as a block of times reads it (_accepts_times)
            if not self._accepts_times():
                return None
            c = self._c_rows(t, Z)
        else:
            c = self._weight_now(t)
        Z = np.asarray(Z, dtype=float)
        return np.add.reduce(c * np.abs(Z), axis=1)

    def _weight_now(self, t):
        """``c(t)`` at one time as :meth:`value` reads it: a constant's read-only float64 array is what
        :func:`_weight_at` returns for it and ``np.asarray(·, float)`` keeps."""
        p = self._c
        return p._value if p._fn is None else np.asarray(_weight_at(p, t, self.name, "c(t)"), dtype=float)

    def _value_at(self, t=0.0):
        """``z ↦`` :meth:`value` ``(z, t)`` for float64 points ``z`` of shape ``(n,)`` (a minimiser's many calls at one
        time), bit-identically: ``c(t)`` read once as :meth:`value` reads it, then the same product and sum; ``None``
        where ``value`` is not this class's own."""
        if not _own_written(self, L1Subdifferential, "value"):
            return None
        c = self._weight_now(t)
        add, absolute = np.add.reduce, np.abs

        def g(z):
            return float(add(c * absolute(z), axis=None))
        return g

    def min_norm(self, x, t=0.0):
        x = real_array(x)
        return np.sign(x) * self._c_rows(t, x)

    def growth(self, t=0.0):
        """``|F^0(t, x)| ≤ |c(t)|`` (Euclidean norm of the weights) for every ``x``."""
        return float(np.linalg.norm(self.min_norm(np.ones(self.dim), t)))

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        c = np.broadcast_to(_weight_at(self._c, t, self.name, "c(t)"), x.shape)
        tol = tolerance(c, y) if tol is None else tol
        at_kink = (np.abs(x) <= tol) & (np.abs(y) <= c + tol)  # x_i within tol of 0: F_i = [-c_i, c_i]
        on_branch = (x != 0.0) & (np.abs(y - c * np.sign(x)) <= tol)
        return bool(np.all(at_kink | on_branch))

    _contains_written = contains     # the contains _contains_rows answers for (_own_written)

    def _contains_rows(self, X, Y, ts, tols):
        """:meth:`contains` of every row at once (``(B,)`` booleans), bit-identically to the calls per row: ``c(t_i)``
        as a block of times reads it and the same elementwise test; ``None`` where a member is not this class's own."""
        if not (_own_written(self, L1Subdifferential, "contains") and self._accepts_times()):
            return None
        c = np.broadcast_to(self._c_rows(ts, X), X.shape)
        tol = tols[:, None]
        at_kink = (np.abs(X) <= tol) & (np.abs(Y) <= c + tol)
        on_branch = (X != 0.0) & (np.abs(Y - c * np.sign(X)) <= tol)
        return (at_kink | on_branch).all(axis=1)


class NormalCone(Operator):
    """``F(t, ·) = N_{S(t)}``, the normal cone of a moving closed convex set (the sweeping process).

    ``J_λ = proj_{S(t)}`` for every ``λ`` (the catching-up algorithm), ``dom F(t,·) = S(t)`` and
    ``F^0(t, x) = 0`` on ``S(t)``; ``y ∈ N_S(x)`` iff ``x ∈ S`` and ``proj_S(x + y) = x``.
    """

    def __init__(self, S: Any, name: str | None = None) -> None:
        if not all(callable(getattr(S, m, None)) for m in ("project", "contains")) or not hasattr(S, "dim"):
            raise InvalidProblem(f"NormalCone needs a convex set (verimono.core.sets: Ball, Box, HalfSpace, Polyhedron, "
                                 f"...: dim, project(x, t), contains(x, t)), got {type(S).__name__} {S!r:.60}")
        super().__init__(S.dim, name or f"NormalCone({getattr(S, 'name', type(S).__name__)})")
        self.S = S
        self.static = getattr(S, "static", False)

    def growth(self, t=0.0):
        """``F^0 = 0`` on the domain of a normal cone."""
        return 0.0

    def resolvent(self, x, lam, t=0.0):
        if type(lam) is np.ndarray:     # J_λ = proj for every λ > 0, and only for those: each row's checked
            lam, J = _steps(self, np.asarray(x, dtype=float), lam, t)
            if J is not None:
                return J
        else:
            check_lam(lam, f"{self.name}.resolvent")  # J_λ = proj for every λ > 0, and only for those
        if type(t) is np.ndarray and not accepts_times(self.S):     # a set that takes one time per call
            return per_row(self.S.project, np.asarray(x, dtype=float), times_of(t, x, self.name))
        return self.S.project(x, t)

    def _accepts_batches(self):
        return _own(self, NormalCone) and getattr(self.S, "_accepts_batches", lambda: False)()

    def _accepts_times(self):
        return _own_times(self, NormalCone) and accepts_times(self.S)

    def _accepts_steps(self):
        return _own_steps(self, NormalCone) and self._accepts_batches()

    def _kernel(self, x0):
        if not _own(self, NormalCone):
            return None
        kern = getattr(self.S, "_kernel", None)
        step = kern(x0) if kern is not None else None
        if step is not None:
            return step  # a set's kernel is step(x, lam, t) = proj_{S(t)} x already
        project, name = self.S.project, self.name

        def step(x, lam, t):
            if not 0.0 < lam < _INF:
                raise bad_lam(lam, name)
            return project(x, t)
        return step

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        ts = times_of(t, x, self.name)
        if ts is not None:      # every row at its own time: outside at any, the first named
            inside = self.S.contains(x, ts) if accepts_times(self.S) else \
                np.array([self.S.contains(xi, ti) for xi, ti in zip(x, ts.tolist())], dtype=bool)
            if not np.all(inside):
                i = int(np.argmin(inside))
                raise OutsideDomain(f"x = {x[i]} is not in S(t={ts[i]!r}); N_S(x) is empty there")
            return np.zeros_like(x)
        if not self.S.contains(x, t):
            raise OutsideDomain(f"x = {x} is not in S(t={t}); N_S(x) is empty there")
        return np.zeros_like(x)

    def project_domain(self, x, t=0.0):
        if type(t) is np.ndarray and not accepts_times(self.S):
            return per_row(self.S.project, np.asarray(x, dtype=float), times_of(t, x, self.name))
        return self.S.project(x, t)

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        tol = tolerance(x, y) if tol is None else tol
        if not self.S.contains(x, t, tol):
            return False
        d = np.abs(self.S.project(x + y, t) - x)
        # the ndarray's own max (np.max's dispatch is most of a small point's cost): the same reduction
        return bool((d.max() if type(d) is np.ndarray else np.max(d)) <= tol)

    _contains_written = contains     # the contains _contains_rows answers for (_own_written)

    def _contains_rows(self, X, Y, ts, tols):
        """:meth:`contains` of every row ``(X_i, Y_i, t_i, tol_i)`` at once (``(B,)`` booleans), bit-identically to
        the calls per row: the set's ``contains`` and ``project`` of the rows at their times (bit-identical to its
        calls per row, as the catalog's sets declare) and the same exact maxima; ``None`` where the members are not
        the catalog's own.  ``proj(x + y)`` is computed for every row (a row outside ``S`` is then False as before;
        should it raise there, the caller asks row by row)."""
        if not (_own_written(self, NormalCone, "contains") and self._accepts_times()):
            return None
        inside = self.S.contains(X, ts, tols)
        d = np.abs(self.S.project(X + Y, ts) - X).max(axis=1, initial=0.0)
        return inside & (d <= tols)


class Shifted(Operator):
    """``G(t, x) = F(t, x + Φ(t))`` — the input-shift lemma of Section 6 (label ``l:extinput``).

    With ``Φ(t) = ∫_0^t u``, ``x' ∈ -F(t,x) + u`` has the solution ``x = ξ + Φ`` where
    ``ξ' ∈ -G(t, ξ)``.  ``J^G_λ(x) = J^F_λ(x + Φ) - Φ``, ``G^0(t,x) = F^0(t, x + Φ)``.
    """

    def __init__(self, F: Operator, Phi: Any, name: str | None = None) -> None:
        super().__init__(F.dim, name or f"Shifted({F.name})")
        self.F = F
        self._Phi = as_param(Phi, "Phi")
        self.static = F.static and self._Phi.constant

    def Phi(self, t: float = 0.0) -> np.ndarray:
        return self._Phi(t)

    def _shift(self, t, x):
        """``Φ(t)``, or with ``t`` of shape ``(B,)`` the rows ``Φ(t[i])``."""
        ts = times_of(t, x, self.name)
        if ts is None:
            return self._Phi(t)
        if not self._accepts_times():
            raise InvalidProblem(f"{self.name}: its operator does not take a time per row")
        return self._Phi(0.0) if self._Phi.constant else self._Phi.at_times(ts)

    def resolvent(self, x, lam, t=0.0):
        x = real_array(x)
        if type(lam) is np.ndarray:
            ls, J = _steps(self, x, lam, t)
            if J is not None:
                return J
            lam = ls[:, 0]      # the inner operator takes the steps as they were given
        else:
            lam = check_lam(lam, f"{self.name}.resolvent")
        if type(t) is np.ndarray and not self._accepts_times():
            return per_row(lambda xi, ti: self.resolvent(xi, lam, ti), x, times_of(t, x, self.name))
        p = self._shift(t, x)
        return self.F.resolvent(x + p, lam, t) - p

    def _accepts_batches(self):
        return _own(self, Shifted) and self.F._accepts_batches()

    def _accepts_times(self):
        return _own_times(self, Shifted) and accepts_times(self.F) and np.ndim(self._Phi(0.0)) <= 1

    def _accepts_steps(self):
        return _own_steps(self, Shifted) and accepts_steps(self.F) and np.ndim(self._Phi(0.0)) <= 1

    def _kernel(self, x0):
        if not _own(self, Shifted):
            return None
        inner = resolvent_kernel(self.F, x0 + self._Phi(0.0))
        if self._Phi.constant:
            p = self._Phi(0.0)

            def step(x, lam, t):
                return inner(x + p, lam, t) - p
        else:
            Phi = self._Phi

            def step(x, lam, t):
                p = Phi(t)
                return inner(x + p, lam, t) - p
        return step

    def provides(self, member):
        return Operator.provides(self, member) and provides(self.F, member)

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if type(t) is np.ndarray and not self._accepts_times():
            return per_row(lambda xi, ti: self.min_norm(xi, ti), x, times_of(t, x, self.name))
        return self.F.min_norm(x + self._shift(t, x), t)

    def project_domain(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if type(t) is np.ndarray and not self._accepts_times():
            return per_row(lambda xi, ti: self.project_domain(xi, ti), x, times_of(t, x, self.name))
        p = self._shift(t, x)
        return self.F.project_domain(x + p, t) - p

    def contains(self, x, y, t=0.0, tol=None):
        p = self._Phi(t)
        x = np.asarray(x, dtype=float)
        # x + Φ carries the rounding of the shift: the default tolerance is scaled to |Φ| too
        tol = tolerance(x, p, y) if tol is None else tol
        return self.F.contains(x + p, y, t, tol)

    _contains_written = contains     # the contains _contains_rows answers for (_own_written)

    def _contains_rows(self, X, Y, ts, tols):
        """:meth:`contains` of every row at once: the rows ``X_i + Φ(t_i)`` (the shift at each time, as
        :meth:`min_norm` takes it, bit-identical to ``Φ(t_i)``) handed to the inner operator's own block test; ``None``
        where a member is not this class's own or the inner operator has no block test."""
        inner = getattr(self.F, "_contains_rows", None)
        if inner is None or not (_own_written(self, Shifted, "contains") and self._accepts_times()):
            return None
        return inner(X + self._shift(ts, X), Y, ts, tols)


class LogBarrier(Operator):
    """``F(t, ·) = ∂(-c(t) Σ_i ln x_i)`` on the open orthant ``(0, ∞)^n``: ``F(x) = -c/x``.

    Its domain is open, ``cl dom F = [0, ∞)^n``, and ``|F^0|`` is unbounded near the boundary, so
    (LG) fails there: from ``x0 = 0`` the solution of ``x' = c/x`` is ``sqrt(2ct)`` and the proximal
    scheme converges with order exactly 1/2 (see ``verimono.reference``).
    ``J_λ x = (x + sqrt(x² + 4λc))/2`` componentwise, evaluated without cancellation.
    """

    def __init__(self, c: Any = 1.0, dim: int = 1, name: str | None = None) -> None:
        super().__init__(dim, name or "LogBarrier")
        self._c = as_param(c, "c")
        self.static = self._c.constant
        if np.any(self._c(0.0) <= 0):
            raise InvalidProblem("LogBarrier needs c > 0")

    def _c_at(self, t):
        c = self._c(t)
        if not self._c.constant and not np.all(c > 0):
            raise bad_param(self.name, "c(t)", c, t, "must be > 0")
        return c

    def _c_rows(self, t, x):
        """``c(t)``, or with ``t`` of shape ``(B,)`` ``c(t[i])`` for row ``i`` of ``x`` (each checked as
        :meth:`_c_at` checks it)."""
        ts = times_of(t, x, self.name)
        if ts is None:
            return self._c_at(t)
        if self._c.constant:
            return self._c(0.0)
        c = self._c.at_times(ts)
        if not np.all(c > 0):
            for tt in ts.tolist():
                self._c_at(tt)
        return _column(c)

    def resolvent(self, x, lam, t=0.0):
        x = real_array(x)
        lam, J = _steps(self, x, lam, t)
        if J is not None:
            return J
        if type(t) is np.ndarray and not self._accepts_times():
            return per_row(lambda xi, ti: self.resolvent(xi, lam, ti), x, times_of(t, x, self.name))
        return self._resolve(x, lam, self._c_rows(t, x))

    @staticmethod
    def _resolve(x, lam, c):
        # the root of y² − x y − λc = 0 that is positive, without cancellation: (x + r)/2 for x ≥ 0, and for
        # x < 0 its equal 2λc/(r − x) = 2λc/(r + |x|), whose denominator is ≥ r > 0 for every x (the entries
        # np.where discards never divide by a vanishing r − x)
        r = np.hypot(x, 2.0 * np.sqrt(lam * c))       # sqrt(x² + 4λc) without overflow for |x| > 1e154
        return np.where(x >= 0.0, 0.5 * (x + r), 2.0 * lam * c / (r + np.abs(x)))

    def _accepts_batches(self):
        return _own(self, LogBarrier)

    def _accepts_times(self):
        # a block of times reads c from the parameter, not through a subclass's or the object's _c_at (then: per row)
        return _own_read(self, LogBarrier) and _own_times(self, LogBarrier)

    def _accepts_steps(self):
        return _own_steps(self, LogBarrier) and np.shape(self._c(0.0)) in ((), (self.dim,))

    def _kernel(self, x0):
        if not _own(self, LogBarrier) or not _own_read(self, LogBarrier):     # a subclass's c(t): its resolvent
            return None
        resolve, name = self._resolve, self.name
        if self._c.constant:
            c = self._c(0.0)

            def step(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                return resolve(x, lam, c)
            return step
        c_at = self._c_at

        def moving(x, lam, t):
            if not 0.0 < lam < _INF:
                raise bad_lam(lam, name)
            return resolve(x, lam, c_at(t))
        return moving

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if (x <= 0.0).any():       # the ndarray's own any: np.any's dispatch is most of a small point's cost
            raise OutsideDomain(f"LogBarrier is defined on (0, ∞)^n; got x = {x}")
        if type(t) is np.ndarray and not self._accepts_times():     # a subclass's _c_at: per row, through it
            return per_row(lambda xi, ti: self.min_norm(xi, ti), x, times_of(t, x, self.name))
        # c(t) through _c_at (a subclass's own read of its weight, as the resolvent reads it; checked > 0 when it
        # moves), per row by _c_rows: the same numbers as the parameter's for the class itself
        return -self._c_rows(t, x) / x

    def project_domain(self, x, t=0.0):
        return np.maximum(np.asarray(x, dtype=float), 0.0)

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if (x <= 0.0).any():
            return False
        c = self._c_at(t)          # a subclass's own read of its weight, as min_norm and the resolvent
        expected = -c / x
        tol = tolerance(expected, y) if tol is None else tol
        # the contract: some x' within tol of x (coordinatewise) with |F(x') - y| ≤ tol.  F = -c/x' is
        # increasing, so F(x') sweeps [-c/(x - tol), -c/(x + tol)] (unbounded below when x - tol ≤ 0): near
        # the barrier a rounding of x far below tol moves F(x) far beyond tol (a float32 J_λx at distance
        # 5.6e-6 from it: F off by 1.6e-3 relative)
        with np.errstate(divide="ignore", over="ignore"):
            lo = np.where(x - tol > 0.0, -c / np.maximum(x - tol, _TINY), -np.inf)
        hi = -c / (x + tol)
        return bool(((y >= lo - tol) & (y <= hi + tol)).all())

    _contains_written = contains     # the contains _contains_rows answers for (_own_written)

    def _contains_rows(self, X, Y, ts, tols):
        """:meth:`contains` of every row at once (``(B,)`` booleans), bit-identically to the calls per row: ``c(t_i)`` as
        a block of times reads it and the same elementwise test (a row with a coordinate ``≤ 0`` False, as there);
        ``None`` where a member is not this class's own."""
        if not (_own_written(self, LogBarrier, "contains") and self._accepts_times()):
            return None
        c = self._c_rows(ts, X)
        c = c[:, None] if np.ndim(c) == 1 else c
        tol = tols[:, None]
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            lo = np.where(X - tol > 0.0, -c / np.maximum(X - tol, _TINY), -np.inf)
            hi = -c / (X + tol)
            inside = ((Y >= lo - tol) & (Y <= hi + tol)).all(axis=1)
        return (X > 0.0).all(axis=1) & inside


__all__ = [
    "Operator",
    "provides",
    "operator_from_resolvent",
    "Linear",
    "NormSubdifferential",
    "L1Subdifferential",
    "NormalCone",
    "Shifted",
    "LogBarrier",
    "resolvent_kernel",
    "dot_rows",
]


#: the protocol (re-exported: ``verimono.core.operators.Operator`` is where users find it) and the catalog
__all__ = ["Operator", "operator_from_resolvent", "provides", "resolvent_kernel", "resolvent_rows",
           "Linear", "NormSubdifferential", "L1Subdifferential", "NormalCone", "Shifted", "LogBarrier"]
