"""Maximal monotone relations ``(−z, w) ∈ graph 𝓜`` closing the linear system of Section 7 (``e:lin+rel``).

* :class:`Complementarity` — the paper's ``𝓟``: ``w ∈ 𝓟(−z)`` iff ``0 ≤ z ⊥ w ≥ 0`` (Siconos' ``0 ≤ y ⊥ λ ≥ 0``).
* :class:`Relay` — ``−w ∈ N_[l,u](z)`` (Siconos' relay ``−y ∈ N_[−1,1](λ)``), i.e. ``𝓜 = N_[−u,−l]``.
* :class:`OperatorRelation` — any maximal monotone ``𝓜`` given as a :class:`verimono.Operator` on ``R^m``.

Each solves the one-step problem ``w = Mz + q``, ``(−z, w) ∈ graph 𝓜`` for a matrix ``M`` (the system's
``D + h C W^{-1} B``): :meth:`Relation.solve` from scratch (least-norm ``z`` for box relations with PSD
``M``) and :meth:`Relation.stepper` for a constant ``M``, which reuses the factorisation of ``M_II`` for the
last active pattern (``I`` the components strictly inside the box) and falls back to :meth:`solve` when the
pattern changes.  A pattern solution that is strictly complementary with ``M_II`` nonsingular is the unique
solution for PSD ``M`` (the solution set is convex, and moving inside it keeps the pattern), hence the
least-norm one.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import InvalidProblem, NotMonotone, UnverifiedSolution
from ..core.operators import Operator
from ..core.tolerances import QP_RTOL, RTOL, tolerance
from ..core._linalg import absmax, singular_values
from ._lu import _GETRS, lu_factor, lu_solve
from .lcp import LCPResult, is_psd, lcp_scale, solve_box, solve_lcp


class Relation:
    """Base class: a maximal monotone ``𝓜: R^m ⇉ R^m`` used as ``(−z, w) ∈ graph 𝓜``."""

    name = "relation"

    def solve(self, M: np.ndarray, q: np.ndarray, scale: float | None = None) -> LCPResult:
        """Solve ``w = Mz + q``, ``(−z, w) ∈ graph 𝓜`` from scratch; ``result.z``, ``result.w``.

        ``scale``: the size of the numbers ``q`` was computed from (see :func:`verimono.lcs.solve_lcp`)."""
        raise NotImplementedError

    def stepper(self, M: np.ndarray):
        """A callable ``(q, scale=None) ↦ (z, w)`` for a constant ``M`` (default: :meth:`solve` every time)."""
        def step(q, scale=None):
            r = self.solve(M, q, scale)
            return r.z, r.w
        return step

    def check_dim(self, m: int) -> None:
        pass

    def __repr__(self) -> str:
        return self.name


class BoxRelation(Relation):
    """``−w ∈ N_[l,u](z)`` componentwise, ``l`` finite, ``u ≤ ∞`` (complementarity is ``[0, ∞)``)."""

    def __init__(self, lower, upper, name: str) -> None:
        lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or not np.all(np.isfinite(lo)):
            raise InvalidProblem(f"{name}: lower bounds must be finite and upper bounds not NaN, got {lo}, {hi}")
        if np.any(lo > hi):
            raise NotMonotone(f"{name}: lower {lo} exceeds upper {hi}; the box is empty and the relation "
                              "would not be maximal monotone (its graph would be empty)")
        self.lower_, self.upper_, self.name = lo, hi, name

    def bounds(self, m: int) -> tuple[np.ndarray, np.ndarray]:
        # made once per (m, bounds) and copied: the one-step and multiplier problems ask at every call
        key = (m, self.lower_.tobytes(), self.upper_.tobytes(), self.lower_.shape, self.upper_.shape)
        cache = self.__dict__.setdefault("_bounds", {})
        hit = cache.get(key)
        if hit is None:
            hit = (np.broadcast_to(self.lower_, (m,)).astype(float), np.broadcast_to(self.upper_, (m,)).astype(float))
            if len(cache) >= 16:
                cache.clear()
            cache[key] = hit
        return hit[0].copy(), hit[1].copy()

    def check_dim(self, m: int) -> None:
        for b in (self.lower_, self.upper_):
            if b.ndim and b.shape != (m,):
                raise InvalidProblem(f"{self.name}: bounds must be scalars or have shape ({m},), got {b.shape}")

    @property
    def is_lcp(self) -> bool:
        key = (self.lower_.tobytes(), self.upper_.tobytes(), self.lower_.shape, self.upper_.shape)
        hit = self.__dict__.get("_is_lcp")
        if hit is None or hit[0] != key:    # once per bounds (asked at every multiplier problem)
            hit = self.__dict__["_is_lcp"] = (key, bool(np.all(self.lower_ == 0.0) and np.all(np.isinf(self.upper_))))
        return hit[1]

    def solve(self, M, q, scale=None):
        if self.is_lcp:
            return solve_lcp(M, q, info=True, scale=scale)
        lo, hi = self.bounds(q.shape[0])
        return solve_box(M, q, lo, hi, info=True, scale=scale)

    def stepper(self, M):
        return _BoxStepper(self, np.asarray(M, dtype=float))


class Complementarity(BoxRelation):
    """The paper's ``𝓟(ζ) = {η ≥ 0 : ζ ≤ 0, ⟨η, ζ⟩ = 0}``: ``(−z, w) ∈ graph 𝓟`` iff ``0 ≤ z ⊥ w ≥ 0``."""

    def __init__(self) -> None:
        super().__init__(0.0, np.inf, "Complementarity")


class Relay(BoxRelation):
    """Relay ``−w ∈ N_[lower,upper](z)`` (``z ∈ −sgn(w)`` for ``[−1, 1]``); ``𝓜 = N_[−upper,−lower]``."""

    def __init__(self, lower=-1.0, upper=1.0) -> None:
        super().__init__(lower, upper, "Relay")
        if not np.all(np.isfinite(self.upper_)):
            raise InvalidProblem("Relay bounds must be finite (use Complementarity for [0, ∞))")


#: active patterns a stepper of a PSD ``M`` tries after its last one, before a full solve
RECENT_PATTERNS = 8


def _well_conditioned(A: np.ndarray) -> bool:
    """``np.linalg.cond(A) < 1e12`` for a square float64 ``A`` without its dispatch: the same ratio of the same
    singular values (:func:`verimono.core._linalg.singular_values`, ``np.linalg.svd``'s bit for bit), a NaN ratio
    (``cond`` makes it ``inf`` or keeps it NaN) as not below.  A 1×1 ``[[a]]``: its one singular value is ``|a|``,
    so the ratio is exactly 1 for a finite nonzero ``a`` and NaN for ``a = 0`` (a non-finite ``a`` goes the general
    way, raising where ``cond`` raises)."""
    if A.shape == (1, 1):
        a = abs(float(A[0, 0]))
        if a < _INF:
            return a > 0.0
    sv = singular_values(A)
    with np.errstate(all="ignore"):
        return bool(sv[0] / sv[-1] < 1e12)
_INF = float("inf")


#: :func:`_pattern_sets`' answers, by a pattern's bytes (emptied past :data:`_PATTERN_SETS_MAX` entries): a pattern
#: recurs over the step sizes of one system, each with its own ``M`` (an operator law sweeps hundreds of ``λ``)
_PATTERN_SETS: dict[bytes, tuple] = {}
_PATTERN_SETS_MAX = 1024


def _pattern_sets(pat: bytes) -> tuple:
    """What an active pattern's bytes (``int8``: 0 at the lower bound, 1 inner, 2 at the upper bound) say alone:
    ``(at the upper bound (bool mask), inner rows, rows at the lower bound, rows at the upper bound, whether each of
    the three is nonempty)`` — the index arrays :meth:`_BoxStepper._entry` made for each stepper, made once per
    pattern and shared read only (they only index)."""
    got = _PATTERN_SETS.get(pat)
    if got is None:
        s = np.frombuffer(pat, dtype=np.int8)
        two, I, at_lo, at_hi = s == 2, np.flatnonzero(s == 1), np.flatnonzero(s == 0), np.flatnonzero(s == 2)
        for a in (two, I, at_lo, at_hi):
            a.flags.writeable = False
        got = (two, I, at_lo, at_hi, bool(I.size), bool(at_lo.size), bool(at_hi.size))
        if len(_PATTERN_SETS) >= _PATTERN_SETS_MAX:
            _PATTERN_SETS.clear()
        _PATTERN_SETS[pat] = got
    return got


class _BoxStepper:
    """``q ↦ (z, w)`` for a constant ``M``: the last pattern's factorisation first, then (PSD ``M``) the
    :data:`RECENT_PATTERNS` patterns that solved before it, a full solve otherwise.

    A pattern's answer is taken only when strictly complementary with a nonsingular ``M_II`` (:meth:`_try`): an
    isolated solution, hence for PSD ``M`` (whose solution set is convex) *the* solution, which the full solve's
    least-norm answer equals up to rounding.  Points that alternate between a few patterns (an assumption law's
    sample points, some inside ``dom H``, some sent to its edge) so cost a factorised solve each, not a full one
    (the paper's Example, (YB) at ci: 6066 full solves of 7142 before, a few dozen after)."""

    def __init__(self, rel: BoxRelation, M: np.ndarray) -> None:
        self.rel, self.M = rel, M
        self.lo, self.hi = rel.bounds(M.shape[0])
        self.cache: dict[bytes, tuple] = {}
        self.last: bytes | None = None
        self.recent: list[bytes] = []
        self.psd = is_psd(M)
        self.full_solves = 0
        self.m_norm = float(np.abs(M).sum(axis=1).max(initial=0.0))

    def _remember(self, pat: bytes) -> None:
        self.last = pat
        if pat in self.recent:
            self.recent.remove(pat)
        self.recent.insert(0, pat)
        del self.recent[RECENT_PATTERNS:]

    def _entry(self, pat: bytes):
        e = self.cache.get(pat)
        if e is None:
            # the pattern's index sets, a function of its bytes alone (:func:`_pattern_sets`, shared read only)
            two, I, at_lo, at_hi, inner, lower_rows, upper_rows = _pattern_sets(pat)
            fixed = np.where(two, self.hi, self.lo)
            fixed[I] = 0.0
            lu = None
            if inner:
                MII = self.M[I[:, None], I]        # what np.ix_(I, I) indexes
                lu = lu_factor(MII) if _well_conditioned(MII) else False
            hiI = self.hi[I]
            # which checks of :meth:`_try` can fire: an upper bound +∞ is never within τ of a multiplier, an empty
            # set of rows at a bound has nothing to check (skipping them changes no answer)
            Mfixed = self.M @ fixed
            # ``(M·fixed)_I`` indexed once here, not at every try: the same numbers
            e = (I, fixed, lu, Mfixed[I], self.lo[I], hiI, at_lo, at_hi,
                 inner, not bool((hiI == np.inf).all()), lower_rows, upper_rows)
            self.cache[pat] = e
        return e

    def _try(self, pat: bytes, q: np.ndarray, qmax: float):
        """The pattern's solution for ``q`` if it is strictly complementary (margin ``RTOL`` of
        :func:`verimono.lcs.lcp.lcp_scale`), else ``None``; ``q`` finite, ``qmax = |q|∞``."""
        I, fixed, lu, MfixedI, loI, hiI, at_lo, at_hi, inner, upper, lower_rows, upper_rows = self._entry(pat)
        if lu is False:
            return None
        lam = fixed.copy()
        if inner:
            lam[I] = lu_solve(lu, -(q[I] + MfixedI))
        y = self.M @ lam + q
        # lcp_scale(M, q, lam), with ‖M‖∞ computed once
        tau = RTOL * (1.0 + max(qmax, self.m_norm * absmax(lam)))
        if inner:
            lamI = lam[I]
            if (lamI - loI <= tau).any() or (upper and (hiI - lamI <= tau).any()):
                return None
        if (lower_rows and (y[at_lo] <= tau).any()) or (upper_rows and (y[at_hi] >= -tau).any()):
            return None
        return lam, y

    def fresh(self) -> "_BoxStepper":
        """A new stepper of the same ``M``, as ``_BoxStepper(rel, M)`` makes it (no last or recent pattern, no
        full solve counted), without recomputing what is a function of ``M`` and the bounds alone: ``‖M‖∞``,
        whether ``M`` is PSD, and the patterns' factorisations (:meth:`_entry`), whose cache the two share."""
        new = object.__new__(_BoxStepper)
        new.rel, new.M, new.lo, new.hi, new.psd, new.m_norm = self.rel, self.M, self.lo, self.hi, self.psd, self.m_norm
        new.cache, new.last, new.recent, new.full_solves = self.cache, None, [], 0
        return new

    def warm_from(self, other: object) -> None:
        """Try ``other``'s last active pattern first (a nearby ``M``, e.g. the same system at another step
        size): a pattern is a guess that :meth:`_try` verifies for this ``M``, so a wrong one costs one
        factorisation and falls back to :meth:`BoxRelation.solve`."""
        if self.last is None and isinstance(other, _BoxStepper) and other.M.shape == self.M.shape:
            self.last = other.last

    def __call__(self, q, scale=None):
        # non-finite data: no pattern is tried, the full solve says what is wrong
        # |q|∞ is finite exactly when q is (absmax is NaN with a NaN entry, inf with an infinite one): one
        # reduction where np.isfinite(q).all() and absmax(q) were two
        if self.last is not None and (qmax := absmax(q)) < _INF:
            out = self._try(self.last, q, qmax)
            if out is not None:
                return out
            if self.psd:
                for pat in self.recent:
                    if pat != self.last:
                        out = self._try(pat, q, qmax)
                        if out is not None:
                            self._remember(pat)
                            return out
        return self._full(q, scale)

    def _full(self, q, scale):
        """The full solve of :meth:`__call__` (no pattern answered), remembering its pattern."""
        r = self.rel.solve(self.M, q, scale)
        self.full_solves += 1
        lam = r.z
        tau = RTOL * lcp_scale(self.M, q, lam)
        s = np.where(lam - self.lo <= tau, 0, np.where(self.hi - lam <= tau, 2, 1)).astype(np.int8)
        self._remember(s.tobytes())
        return r.z, r.w

    def _try_rows(self, pat: bytes, Q: np.ndarray, qmax: np.ndarray, fin: np.ndarray):
        """:meth:`_try` of every row of ``Q`` at once: ``(ok, lam)``, ``ok[i]`` whether the pattern answers row ``i``
        and ``lam[i]`` its answer then — each row's arithmetic :meth:`_try`'s for that row alone (the pattern's
        ``M_II`` solved per row by the same LAPACK call; ``M @ lam`` a stacked product, the same BLAS call per row as
        the 1-D one; ``abs``, ``max``, ``+`` and the comparisons round alike elementwise; Python's
        ``max(qmax, x)``, which keeps ``qmax`` when ``x`` is NaN, by ``where(x > qmax, x, qmax)``).  Rows not
        ``fin`` (non-finite data, which :meth:`__call__` never tries) are not answered."""
        I, fixed, lu, MfixedI, loI, hiI, at_lo, at_hi, inner, upper, lower_rows, upper_rows = self._entry(pat)
        B = Q.shape[0]
        if lu is False:
            return np.zeros(B, dtype=bool), None
        lam = np.repeat(fixed[None, :], B, axis=0)
        with np.errstate(all="ignore"):
            if inner:
                rhs = -(Q[:, I] + MfixedI)
                lu_, piv = lu
                sol = np.full((B, I.size), np.nan)
                for i in np.flatnonzero(fin).tolist():
                    sol[i] = _GETRS(lu_, piv, rhs[i])[0]
                lam[:, I] = sol
            y = (self.M @ lam[:, :, None])[:, :, 0] + Q
            a = self.m_norm * np.abs(lam).max(axis=1)
            tau = RTOL * (1.0 + np.where(a > qmax, a, qmax))
            bad = ~fin
            if inner:
                lamI = lam[:, I]
                bad |= (lamI - loI <= tau[:, None]).any(axis=1)
                if upper:
                    bad |= (hiI - lamI <= tau[:, None]).any(axis=1)
            if lower_rows:
                bad |= (y[:, at_lo] <= tau[:, None]).any(axis=1)
            if upper_rows:
                bad |= (y[:, at_hi] >= -tau[:, None]).any(axis=1)
        return ~bad, lam

    def rows(self, Q: np.ndarray, scales) -> np.ndarray:
        """``z`` of :meth:`__call__` for every row of ``Q`` (``scales[i]`` the ``scale`` of row ``i``), called in the
        rows' order: the same answers, the same last and recent patterns and full solves at the end.  Which
        pattern answers each row is decided as :meth:`__call__` decides it, row after row; a pattern's candidate
        answers are computed for the whole block (:meth:`_try_rows`) the first time a row tries it."""
        B = Q.shape[0]
        out = np.empty((B, self.M.shape[0]))
        fin = np.isfinite(Q).all(axis=1)
        qmax = np.abs(Q).max(axis=1)
        tried: dict[bytes, tuple] = {}
        # rows with q ≥ 0 that no pattern answers strictly (a zero component: a point on the domain's edge): the
        # full solve is solve_lcp's first branch, z = 0, whose pattern is every multiplier at its bound 0 (0 ≤ τ)
        trivial = np.zeros(B, dtype=bool)
        if type(self.rel).solve is BoxRelation.solve and self.rel.is_lcp and np.isfinite(self.M).all():
            trivial = fin & (Q >= 0.0).all(axis=1)
        zero = bytes(self.M.shape[0])
        for i in range(B):
            if self.last is not None and fin[i]:
                pats = [self.last]
                if self.psd:
                    pats += [p for p in self.recent if p != self.last]
                for k, pat in enumerate(pats):
                    hit = tried.get(pat)
                    if hit is None:
                        hit = tried[pat] = self._try_rows(pat, Q, qmax, fin)
                    if hit[0][i]:
                        if k:
                            self._remember(pat)
                        out[i] = hit[1][i]
                        break
                else:
                    out[i] = self._full(Q[i], scales[i])[0] if not trivial[i] else self._zero(zero)
                continue
            out[i] = self._full(Q[i], scales[i])[0] if not trivial[i] else self._zero(zero)
        return out

    def _zero(self, zero: bytes) -> float:
        """:meth:`_full` of finite data ``q ≥ 0`` of an LCP: ``z = 0`` (:func:`verimono.lcs.solve_lcp`'s trivial
        answer), its pattern remembered, the full solve counted."""
        self.full_solves += 1
        self._remember(zero)
        return 0.0


class OperatorRelation(Relation):
    """A maximal monotone ``𝓜`` given as a :class:`verimono.Operator` on ``R^m`` (static in ``t``).

    The one-step problem ``q − Mζ ∈ 𝓜(ζ)``, ``ζ = −z`` (``0 ∈ 𝓜(ζ) + Mζ − q``, both monotone for PSD ``M``)
    is solved by Douglas–Rachford splitting with the exact resolvents ``J_{γ𝓜}`` and ``(I + γM)^{-1}``,
    stopped on the natural residual ``|ζ − J_γ𝓜(ζ − γ(Mζ − q))|`` at ``QP_RTOL`` relative.  It returns *a*
    solution (not necessarily the least-norm one); the system's state update ``Bz`` is the same for all of
    them when ``H`` is maximal monotone.  A sampled firm-nonexpansiveness test of the resolvent at
    construction rejects operators that are visibly not monotone (:class:`verimono.NotMonotone`).
    """

    MAX_ITER = 20_000

    def __init__(self, op: Operator, *, samples: int = 32, seed: int = 0) -> None:
        if not isinstance(op, Operator):
            raise InvalidProblem(f"relation must be Complementarity(), Relay(...) or a verimono.Operator, got {op!r}")
        self.op, self.name = op, f"OperatorRelation({op.name})"
        rng = np.random.default_rng(seed)
        X, Y = rng.normal(size=(2, samples, op.dim)) * 2.0
        for x, y in zip(X, Y):
            jx, jy = op.resolvent(x, 1.0), op.resolvent(y, 1.0)
            d = jx - jy
            if d @ d > d @ (x - y) + tolerance(x, y, jx, jy):
                raise NotMonotone(f"{op.name} is not monotone: its resolvent is not firmly nonexpansive at "
                                  f"x = {x}, y = {y} (|Jx − Jy|² = {d @ d:.4g} > ⟨Jx − Jy, x − y⟩ = {d @ (x - y):.4g})")

    def check_dim(self, m: int) -> None:
        if self.op.dim != m:
            raise InvalidProblem(f"{self.name} acts on R^{self.op.dim}; the system has m = {m}")

    def solve(self, M, q, scale=None):
        # ``scale`` is not needed: the splitting's stopping test is already relative to the data
        M, q = np.asarray(M, float), np.asarray(q, float)
        if not (np.isfinite(M).all() and np.isfinite(q).all()):   # the splitting would iterate on NaN to its limit
            raise InvalidProblem(f"{self.name}: the one-step problem's data are not finite (M or q)")
        m = q.shape[0]
        gamma = 1.0 / max(np.linalg.norm(M, 2), 1e-12)
        lu = lu_factor(np.eye(m) + gamma * M)
        s = np.zeros(m)
        scale = 1.0 + np.abs(q).max(initial=0.0)
        for _ in range(self.MAX_ITER):
            zeta = lu_solve(lu, s + gamma * q)
            s = s + self.op.resolvent(2 * zeta - s, gamma) - zeta
            nat = zeta - self.op.resolvent(zeta - gamma * (M @ zeta - q), gamma)
            if np.abs(nat).max() <= QP_RTOL * gamma * scale:
                break
        else:
            raise UnverifiedSolution(f"Douglas–Rachford for {self.name} did not reach residual {QP_RTOL:g} "
                                f"in {self.MAX_ITER} iterations (last {np.abs(nat).max():.3g})")
        z = -zeta
        return LCPResult(z, M @ z + q, float(np.abs(nat).max()), scale, "douglas-rachford", True, None, False)


def as_relation(rel, m: int) -> Relation:
    """A :class:`Relation` from a Relation or a :class:`verimono.Operator`, checked against ``m``."""
    if isinstance(rel, Relation):
        out = rel
    elif isinstance(rel, Operator):
        out = OperatorRelation(rel)
    else:
        raise InvalidProblem(f"relation must be Complementarity(), Relay(...) or a verimono.Operator, got {rel!r}")
    out.check_dim(m)
    return out


__all__ = ["Relation", "BoxRelation", "Complementarity", "Relay", "OperatorRelation", "as_relation"]
