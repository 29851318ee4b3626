"""Linear systems with maximal monotone relations (the paper's Section 7, ``e:lin+rel``):

    x' = Ax + Bz + u(t),   w = Cx + Dz + v(t),   (−z, w) ∈ graph 𝓜,

rewritten as ``x' ∈ −H(t, x) + u`` with ``H(t, x) = −Ax + B(𝓜 + D)^{-1}(Cx + v(t))`` (``e:defht``).

One step of size ``h`` of Siconos' ``EulerMoreauOSI(θ)`` (``../shared/siconos/CASES.md``), with
``W = I − hθA``:

    x_free = W^{-1}((I + h(1−θ)A) x_k + ∫_{t_k}^{t_{k+1}} u),
    q = C(γ x_free + (1−γ) x_k) + v(t_{k+1}),   M = D + hγ C W^{-1} B,   solve (z, w = Mz + q) ∈ relation,
    x_{k+1} = x_free + h W^{-1} B z,   w_{k+1} = C x_{k+1} + D z + v(t_{k+1}),

with ``γ = 1`` unless the θ-γ variant is asked for.  ``θ = 1`` is the paper's proximal scheme: then
``x_{k+1} = J_{hH(t_{k+1},·)}(x_k + ∫u)``, the resolvent of :meth:`LinearRelationSystem.operator`.
"""

from __future__ import annotations

import types
from typing import Any, Callable

import numpy as np
import scipy.linalg as sla

from .._params import as_param
from ..errors import InfeasibleStep, InvalidProblem, OutsideDomain
from ..grids import validate_grid
from ..operators import Operator
from ..problem import Problem
from ..qp import solve_qp
from ..stepping import Trajectory
from ..tolerances import tolerance
from .lcp import _box_lcp, _feasible, is_psd, select_over_sol, solve_lcp
from .relations import BoxRelation, as_relation


def _matrix(value, shape, what):
    try:
        a = np.array(value, dtype=float, ndmin=2)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"{what} must be a numeric matrix: {exc}") from None
    if a.shape != shape:
        raise InvalidProblem(f"{what} must have shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InvalidProblem(f"{what} must be finite")
    return a


class StepMatrices:
    """The constant matrices of one step size: ``W = I − hθA`` factorised once, ``E = W^{-1}(I + h(1−θ)A)``,
    ``G = hW^{-1}B``, ``M = D + hγ C W^{-1} B``."""

    def __init__(self, sys: "LinearRelationSystem", h: float, theta: float, gamma: float) -> None:
        n = sys.n
        self.h, self.theta, self.gamma = h, theta, gamma
        W = np.eye(n) - h * theta * sys.A
        try:
            self.lu = sla.lu_factor(W, check_finite=False)
        except (ValueError, np.linalg.LinAlgError):
            raise InvalidProblem(f"I − hθA is singular for h = {h:g}, θ = {theta:g}") from None
        if not np.all(np.isfinite(self.lu[0])) or np.min(np.abs(np.diag(self.lu[0]))) == 0.0:
            raise InvalidProblem(f"I − hθA is singular for h = {h:g}, θ = {theta:g}")
        self.E = sla.lu_solve(self.lu, np.eye(n) + h * (1.0 - theta) * sys.A)
        WiB = sla.lu_solve(self.lu, sys.B)
        self.G = h * WiB
        self.M = sys.D + h * gamma * sys.C @ WiB
        self.step = sys.relation.stepper(self.M)


class LinearRelationSystem:
    """``x' = Ax + Bz + u``, ``w = Cx + Dz + v``, ``(−z, w) ∈ graph 𝓜`` (``e:lin+rel``).

    ``A (n×n)``, ``B (n×m)``, ``C (m×n)``, ``D (m×m)``; ``relation`` a :class:`Complementarity`,
    :class:`Relay` or maximal monotone :class:`verimono.Operator` on ``R^m``; ``u(t) ∈ R^n`` a callable
    (or None); ``v`` a constant ``(m,)`` or a callable of ``t`` (or None for 0).
    """

    def __init__(self, A, B, C, D, relation, *, u: Callable | None = None, v: Any = None,
                 name: str | None = None) -> None:
        A = np.array(A, dtype=float, ndmin=2)
        n = A.shape[0]
        self.A = _matrix(A, (n, n), "A")
        B = np.array(B, dtype=float, ndmin=2)
        if B.shape[0] != n:
            raise InvalidProblem(f"B must have n = {n} rows (shape ({n}, m)), got {B.shape}")
        m = B.shape[1]
        self.B = _matrix(B, (n, m), "B")
        self.C = _matrix(C, (m, n), "C")
        self.D = _matrix(D, (m, m), "D")
        self.n, self.m = n, m
        self.relation = as_relation(relation, m)
        if u is not None:
            if not callable(u):
                raise InvalidProblem("u must be a callable of t returning an (n,) array")
            if np.shape(u(0.0)) != (n,):
                raise InvalidProblem(f"u(0) must have shape ({n},), got {np.shape(u(0.0))}")
        self.u = u
        self._v = as_param(np.zeros(m) if v is None else v, "v")
        if self._v(0.0).shape != (m,):
            raise InvalidProblem(f"v(t) must have shape ({m},), got {self._v(0.0).shape}")
        self.name = name or f"LinearRelationSystem({self.relation.name}, n={n}, m={m})"
        self._c_norm = float(np.abs(self.C).sum(axis=1).max(initial=0.0))

    def v(self, t: float) -> np.ndarray:
        return self._v(t)

    def q_scale(self, x: np.ndarray, v: np.ndarray) -> float:
        """``‖C‖∞|x|∞ + |v|∞``: the size of the terms the one-step data ``q = Cx + v`` is summed from, to
        which its rounding errors are relative (the ``scale`` of :func:`verimono.lcs.solve_lcp`)."""
        return self._c_norm * float(np.abs(x).max(initial=0.0)) + float(np.abs(v).max(initial=0.0))

    @property
    def v_constant(self) -> bool:
        return self._v.constant

    def step_matrices(self, h: float, theta: float = 1.0, gamma: float | None = None) -> StepMatrices:
        return StepMatrices(self, float(h), float(theta), 1.0 if gamma is None else float(gamma))

    def operator(self) -> "LCSOperator":
        """``H(t, x) = −Ax + B(𝓜 + D)^{-1}(Cx + v(t))`` as a :class:`verimono.Operator`."""
        return LCSOperator(self)

    def problem(self, x0, T: float, **kw) -> Problem:
        """``x' ∈ −H(t, x) + u(t)``, ``x(0) = x0`` on ``[0, T]`` as a :class:`verimono.Problem`."""
        kw.setdefault("name", self.name)
        return Problem(self.operator(), x0, T, u=self.u, **kw)

    def simulate(self, x0, t_grid, *, theta: float = 1.0, gamma: float | None = None) -> Trajectory:
        """Run ``EulerMoreauOSI(θ)`` (θ-γ variant when ``gamma`` is given) on ``t_grid``.

        Returns a :class:`verimono.Trajectory` with ``x`` of shape ``(K+1, n)`` and ``extras["z"]``,
        ``extras["w"]`` of shape ``(K, m)``: the multiplier and output of step ``k → k+1``.
        """
        x0 = np.array(x0, dtype=float).reshape(-1) if np.ndim(x0) <= 1 else None
        if x0 is None or x0.shape != (self.n,) or not np.all(np.isfinite(x0)):
            raise InvalidProblem(f"x0 must be a finite vector of shape ({self.n},)")
        if not (0.0 <= theta <= 1.0) or (gamma is not None and not 0.0 < gamma <= 1.0):
            raise InvalidProblem(f"need 0 ≤ θ ≤ 1 and 0 < γ ≤ 1, got θ = {theta}, γ = {gamma}")
        t = validate_grid(t_grid)
        hs = np.diff(t)
        K = hs.size
        uniform = np.ptp(hs) <= 1e-9 * hs.mean()
        cache: dict[float, StepMatrices] = {}

        def mats(k):
            h = (t[-1] / K) if uniform else float(hs[k])
            sm = cache.get(h)
            if sm is None:
                if len(cache) > 64:
                    cache.clear()
                sm = cache[h] = self.step_matrices(h, theta, gamma)
            return sm

        dU = None
        if self.u is not None:
            shim = types.SimpleNamespace(U=None, u=self.u, dim=self.n)
            dU = Problem.input_increments(shim, t)
        g = 1.0 if gamma is None else float(gamma)
        vconst = self.v(0.0) if self.v_constant else None
        X = np.empty((K + 1, self.n))
        Z = np.empty((K, self.m))
        Wout = np.empty((K, self.m))
        X[0] = x0
        C, D = self.C, self.D
        sm = mats(0)
        for k in range(K):
            if not uniform:
                sm = mats(k)
            xk = X[k]
            xfree = sm.E @ xk
            if dU is not None:
                xfree = xfree + sla.lu_solve(sm.lu, dU[k])
            v = vconst if vconst is not None else self.v(t[k + 1])
            xq = xfree if g == 1.0 else g * xfree + (1.0 - g) * xk
            z, _ = sm.step(C @ xq + v, self.q_scale(xq, v))
            X[k + 1] = xfree + sm.G @ z
            Z[k] = z
            Wout[k] = C @ X[k + 1] + D @ z + v
        return Trajectory(t, X, None, extras={"z": Z, "w": Wout})

    def __repr__(self) -> str:
        return self.name


class LCSOperator(Operator):
    """``H(t, x) = −Ax + B(𝓜 + D)^{-1}(Cx + v(t))`` (``e:defht``); its resolvent is the one-step problem

        J_{λH(t,·)}(x) = W^{-1}(x + λBz),  W = I − λA,  z the (least-norm) multiplier of
        w = C W^{-1} x + v(t) + (D + λ C W^{-1} B) z,  (−z, w) ∈ graph 𝓜.

    For box relations with PSD ``D`` also the minimal section ``H^0`` (the least-norm element
    ``−Ax − Bz`` over the multipliers ``z`` of ``(Cx + v, D)``), membership, and the projection onto
    ``dom H(t,·) = C^{-1}(im(𝓜 + D) − v(t))`` (``e:dom-ht``).
    """

    def __init__(self, system: LinearRelationSystem) -> None:
        super().__init__(system.n, f"H[{system.name}]")
        self.system = system
        self.static = system.v_constant
        self._mats: dict[float, StepMatrices] = {}

    def _sm(self, lam: float) -> StepMatrices:
        sm = self._mats.get(lam)
        if sm is None:
            if len(self._mats) > 16:
                self._mats.clear()
            sm = self._mats[lam] = self.system.step_matrices(lam, 1.0, None)
        return sm

    def _accepts_batches(self):
        return type(self).resolvent is LCSOperator.resolvent

    def resolvent(self, x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:
            return np.array([self.resolvent(xi, lam, t) for xi in x])
        if x.shape != (self.dim,):
            raise InvalidProblem(f"{self.name} acts on R^{self.dim}; got a point of shape {x.shape}")
        sm = self._sm(float(lam))
        s = self.system
        xE, v = sm.E @ x, s.v(t)
        z, _ = sm.step(s.C @ xE + v, s.q_scale(xE, v))
        return xE + sm.G @ z

    # -- the set-valued H(t, x) through the multipliers of (Cx + v, D) ----------------------------------
    def _box(self):
        rel = self.system.relation
        if not isinstance(rel, BoxRelation) or not is_psd(self.system.D):
            raise NotImplementedError(f"{self.name}: H(t, x) as a set is available for Complementarity/Relay "
                                      "relations with D + Dᵀ ⪰ 0")
        return rel

    def _select(self, x, t, P_lam, c_lam):
        """Minimise ``½λᵀP λ + cᵀλ`` over the multipliers ``λ`` of ``(η, D) = (Cx + v(t), D)``.

        ``x`` is in ``dom H(t)`` when the multipliers' LCP has a solution, or is feasible up to the linear
        program's tolerance (:func:`verimono.lcs.lcp._feasible`); otherwise :class:`OutsideDomain`.  Its data are solved
        relative to their own size (``scale`` of :func:`verimono.lcs.solve_lcp`), so a point at ``t = 1e-12``
        gets as accurate an answer as one at ``t = 1``.  A point that the program accepts but whose exact
        data are infeasible lies outside the domain by a rounding error of the computation that produced
        it (a resolvent of unit-size data returns ``-4e-16`` for the edge ``0`` of ``dom H = [0, ∞)``),
        whose size ``H`` cannot know: its data are then solved relative to a unit floor, i.e. as the
        nearest point of the domain."""
        rel, s = self._box(), self.system
        v = s.v(t)
        eta, scale = s.C @ x + v, s.q_scale(x, v)
        lo, hi = rel.bounds(s.m)
        big, qq, fin = _box_lcp(s.D, eta, lo, hi)
        try:   # a solution proves x ∈ dom H(t): the linear program is needed only when there is none
            zbar = solve_lcp(big, qq, least_norm=False, scale=scale)
        except InfeasibleStep:
            if not _feasible(big, qq):
                raise OutsideDomain(f"x = {x} is not in dom H(t={t}): Cx + v(t) ∉ im(𝓜 + D)") from None
            scale = 1.0 + scale
            zbar = solve_lcp(big, qq, least_norm=False, scale=scale)
        k = big.shape[0]
        P = np.zeros((k, k))
        P[:s.m, :s.m] = P_lam
        c = np.zeros(k)
        c[:s.m] = c_lam + P_lam @ lo
        zz = select_over_sol(big, qq, zbar, P, c, scale=scale)
        return lo + zz[:s.m]

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:
            return np.array([self.min_norm(xi, t) for xi in x])
        s = self.system
        Ax = s.A @ x
        lam = self._select(x, t, s.B.T @ s.B, s.B.T @ Ax)
        return -Ax - s.B @ lam

    def contains(self, x, y, t=0.0, tol=None):
        """Whether some ``(x', y') ∈ graph H(t,·)`` lies within ``tol`` of ``(x, y)`` in each coordinate (the
        :meth:`verimono.Operator.contains` contract): first at ``x' = x`` (the multiplier nearest to explaining
        ``y``), else through the graph point ``(p, x + y − p)``, ``p = J_1(x + y)``, which is ``|x − p|`` from
        ``(x, y)`` in both coordinates — a point within rounding of a kink of ``H`` (``x = 2e-16`` for the
        edge ``0`` of the Example's ``dom H``, where ``H(x) = {0}`` but ``H(0) = (−∞, 0]``) is a member there."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        s = self.system
        tol = tolerance(s.A @ x, y) if tol is None else tol
        try:
            lam = self._select(x, t, s.B.T @ s.B, s.B.T @ (s.A @ x + y))
            if np.max(np.abs(-s.A @ x - s.B @ lam - y)) <= tol:
                return True
        except OutsideDomain:
            pass
        p = self.resolvent(x + y, 1.0, t)
        return bool(np.max(np.abs(p - x)) <= tol)

    def project_domain(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:
            return np.array([self.project_domain(xi, t) for xi in x])
        rel, s = self._box(), self.system
        lo, hi = rel.bounds(s.m)
        if np.all(np.isfinite(hi)):
            return x.copy()  # bounded box: 𝓜 + D is surjective, dom H = R^n
        big, qq, fin = _box_lcp(s.D, s.C @ x + s.v(t), lo, hi)
        if _feasible(big, qq):
            return x.copy()
        # min ½|x' − x|² over {(x', z): z ≥ 0, D z + C x' + v ≥ 0} (complementarity: dom = C^{-1}(Q_D^+ − v))
        if not rel.is_lcp:
            raise NotImplementedError(f"{self.name}: projection onto dom H for mixed bounds")
        n, m = s.n, s.m
        P = np.zeros((n + m, n + m))
        P[:n, :n] = np.eye(n)
        G = np.block([[np.zeros((m, n)), -np.eye(m)], [-s.C, -s.D]])
        h = np.concatenate([np.zeros(m), s.v(t)])
        return solve_qp(P, np.concatenate([-x, np.zeros(m)]), G, h)[:n]


__all__ = ["LinearRelationSystem", "LCSOperator", "StepMatrices"]
