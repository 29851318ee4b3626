"""Linear systems with maximal monotone relations (the paper's Section 7, ``e:lin+rel``):

    x' = Ax + Bz + u(t),   w = Cx + Dz + v(t),   (−z, w) ∈ graph 𝓜,

rewritten as ``x' ∈ −H(t, x) + u`` with ``H(t, x) = −Ax + B(𝓜 + D)^{-1}(Cx + v(t))`` (``e:defht``).

One step of size ``h`` of Siconos' ``EulerMoreauOSI(θ)`` (``verimono/data/siconos/CASES.md``), with
``W = I − hθA``:

    x_free = W^{-1}((I + h(1−θ)A) x_k + ∫_{t_k}^{t_{k+1}} u),
    q = C(γ x_free + (1−γ) x_k) + v(t_{k+1}),   M = D + hγ C W^{-1} B,   solve (z, w = Mz + q) ∈ relation,
    x_{k+1} = x_free + h W^{-1} B z,   w_{k+1} = C x_{k+1} + D z + v(t_{k+1}),

with ``γ = 1`` unless the θ-γ variant is asked for.  ``θ = 1`` is the paper's proximal scheme: then
``x_{k+1} = J_{hH(t_{k+1},·)}(x_k + ∫u)``, the resolvent of :meth:`LinearRelationSystem.operator`.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ..core._params import as_param
from ..core.errors import InfeasibleStep, InvalidProblem, OutsideDomain, SolverFailure, UnverifiedSolution
from ..core.grids import validate_grid
from ..core.operators import Operator
from ..core.problem import Problem
from ..core.stepping import Trajectory
from ..core.tolerances import RTOL, tolerance
from ..core._linalg import absmax
from ._lu import lu_factor, lu_solve
from .kernel import BatchStepError
from ._warm_qp import INFEASIBLE_MARGIN, row_infeasible, solve_qp_warm
from .lcp import (_box_lcp, _eye, _feasible, is_psd, proved_solvable, sol_polyhedron, solve_lcp,
                  unique_certificate)
from .relations import BoxRelation, as_relation
from ._select_rows import MAX_FACES_K, Faces, ProjectionFaces, project_rows, select_rows, solvable_rows


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
        # the identity made once per n (read only: every expression here makes a new array); the reductions
        # through the arrays' own methods (what np.all, np.min and np.diag call: the same values)
        eye = _eye(n)
        W = eye - h * theta * sys.A
        try:
            self.lu = lu_factor(W)
        except (ValueError, np.linalg.LinAlgError):
            raise InvalidProblem(f"I − hθA is singular for h = {h:g}, θ = {theta:g}") from None
        if not np.isfinite(self.lu[0]).all() or np.abs(self.lu[0].diagonal()).min() == 0.0:
            raise InvalidProblem(f"I − hθA is singular for h = {h:g}, θ = {theta:g}")
        self.E = lu_solve(self.lu, eye + h * (1.0 - theta) * sys.A)
        WiB = lu_solve(self.lu, sys.B)
        self.G = h * WiB
        self.M = sys.D + h * gamma * sys.C @ WiB
        self.step = sys.relation.stepper(self.M)
        self._relation = sys.relation

    def fresh(self) -> "StepMatrices":
        """What ``StepMatrices(sys, h, θ, γ)`` makes again — the same matrices (shared, never written) and a fresh
        one-step solver (:meth:`verimono.lcs.relations._BoxStepper.fresh`: its pattern factorisations shared) —
        without recomputing them."""
        new = object.__new__(type(self))       # copy.copy's shallow copy, without its reduce protocol
        new.__dict__.update(self.__dict__)
        fresh = getattr(self.step, "fresh", None)
        new.step = fresh() if fresh is not None else self._relation.stepper(self.M)
        return new

    def relation_step(self):
        """A fresh warm-started one-step solver ``(q, scale) ↦ (z, w)`` for ``M`` (:meth:`Relation.stepper`)."""
        return self._relation.stepper(self.M)


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
        return self._c_norm * absmax(x) + absmax(v)

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

    def simulate(self, x0, t_grid, *, theta: float = 1.0, gamma: float | None = None, u: Callable | None = None,
                 v: Any = None) -> Trajectory:
        """Run ``EulerMoreauOSI(θ)`` (θ-γ variant when ``gamma`` is given) on ``t_grid``.

        ``x0`` of shape ``(n,)``: a :class:`verimono.Trajectory` with ``x`` of shape ``(K+1, n)`` and
        ``extras["z"]``, ``extras["w"]`` of shape ``(K, m)``, the multiplier and output of step ``k → k+1``.
        ``x0`` of shape ``(B, n)``: ``B`` trajectories at once, ``x (K+1, B, n)``, ``z``, ``w`` ``(K, B, m)``,
        bit-identical to ``B`` separate runs (:mod:`verimono.lcs.kernel`).

        ``u`` / ``v`` replace the system's inputs for this run: ``u`` a callable of ``t`` returning ``(n,)``
        (every row) or ``(B, n)`` (one input per row); ``v`` a constant or a callable of ``t``, of shape
        ``(m,)`` or ``(B, m)``.

        Box relations on a uniform grid step through the cached active-set kernel (every step verified,
        least-norm kept); other relations and grids solve each step with the relation's verified solver.
        Raises :class:`InvalidProblem` on a malformed ``x0``/input (naming the rows), the step's error
        (e.g. :class:`InfeasibleStep`, naming the step) for a single run, and
        :class:`verimono.lcs.kernel.BatchStepError` (every row's results, the failed rows and steps) when
        rows of a batch fail.
        """
        X0, batched = self._initial(x0)
        if not (0.0 <= theta <= 1.0) or (gamma is not None and not 0.0 < gamma <= 1.0):
            raise InvalidProblem(f"need 0 ≤ θ ≤ 1 and 0 < γ ≤ 1, got θ = {theta}, γ = {gamma}")
        t = validate_grid(t_grid)
        B = X0.shape[0]
        hs = np.diff(t)
        K = hs.size
        uniform = np.ptp(hs) <= 1e-9 * hs.mean()
        u_fn = self.u if u is None else u
        vpar = self._v if v is None else as_param(v, "v")
        dU = _increments(u_fn, t, self.n, B if batched else None)
        V = None if vpar.constant else _values(vpar, t[1:], self.m, B if batched else None)
        vc = None
        if vpar.constant:
            vc = np.array(vpar(0.0), dtype=float)
            if vc.shape not in ((self.m,), (B, self.m)) or (vc.ndim == 2 and not batched):
                raise InvalidProblem(f"v must have shape ({self.m},)" + (f" or ({B}, {self.m})" if batched else "")
                                     + f", got {vc.shape}")
            if not np.all(np.isfinite(vc)):
                raise InvalidProblem(f"v is not finite (rows {_bad_rows(vc)})")
        if uniform and isinstance(self.relation, BoxRelation):
            x, z, w, failures = self._simulate_kernel(X0, t, theta, gamma, dU, V, vc, batched)
        else:
            x, z, w, failures = self._simulate_general(X0, t, theta, gamma, dU, V, vc, uniform)
        if not batched:
            if failures:
                raise failures[0].error
            return Trajectory(t, x[:, 0], None, extras={"z": z[:, 0], "w": w[:, 0]})
        tr = Trajectory(t, x, None, extras={"z": z, "w": w})
        if failures:
            valid = np.ones((K + 1, B), dtype=bool)
            for f in failures:
                valid[f.step + 1:, f.row] = False
            raise BatchStepError(failures, tr, valid)
        return tr

    def _initial(self, x0):
        try:
            X0 = np.array(x0, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InvalidProblem(f"x0 must be numeric: {exc}") from None
        batched = X0.ndim == 2
        if X0.ndim == 0 and self.n == 1:
            X0 = X0.reshape(1)
        if X0.ndim == 1 and X0.shape == (self.n,):
            X0 = X0[None]
        elif not (batched and X0.shape[1] == self.n and X0.shape[0] >= 1):
            raise InvalidProblem(f"x0 must be a finite vector of shape ({self.n},) or a batch of shape (B, {self.n}), "
                                 f"got shape {X0.shape}")
        if not np.all(np.isfinite(X0)):
            where = f" (rows {_bad_rows(X0)})" if batched else ""
            raise InvalidProblem(f"x0 must be a finite vector of shape ({self.n},): not finite{where}")
        return X0, batched

    def _simulate_kernel(self, X0, t, theta, gamma, dU, V, vc, batched):
        from .kernel import StepKernel

        K, B = t.size - 1, X0.shape[0]
        h = t[-1] / K
        # the step matrices and the kernel (its patterns' maps, built as steps meet them) depend on the system's
        # matrices, h, θ, γ and which exogenous terms vary: kept for the next run with the same ones, keyed by
        # the matrices' bytes (an attribute reassigned or edited in place makes a new key)
        exo_u, exo_v = dU is not None, V is not None or (vc is not None and bool(np.any(vc != 0.0)))
        key = (float(h), float(theta), gamma, exo_u, exo_v, id(self.relation),
               self.A.tobytes(), self.B.tobytes(), self.C.tobytes(), self.D.tobytes())
        cache = self.__dict__.setdefault("_kernels", {})
        kern = cache.get(key)
        if kern is None:
            if len(cache) >= 8:
                cache.clear()
            sm = self.step_matrices(h, theta, gamma)
            kern = cache[key] = StepKernel(self, sm, exo_u=exo_u, exo_v=exo_v, v_const=None)
            kern.relation = self.relation    # the key's id(relation) stays this object's while the kernel lives
        sm = kern.sm
        parts = []
        if dU is not None:
            flat = dU.reshape(-1, self.n)
            parts.append(lu_solve(sm.lu, flat.T).T.reshape(dU.shape))
        # a nonzero constant v enters as a column of the exogenous terms, like a per-row or varying v: a row of
        # a batch and its single run then do the same multiply-adds (a zero v is folded away: it adds nothing)
        vrow = vc is not None and bool(np.any(vc != 0.0))
        if V is not None:
            parts.append(V)
        elif vrow:
            parts.append(np.broadcast_to(vc, (K, B, self.m)) if vc.ndim == 2 else np.broadcast_to(vc, (K, self.m)))
        E = None
        if len(parts) == 1:
            E = parts[0]
        elif parts:   # W^{-1}∫u then v; shared (K, ·) parts repeated for every row when another part is per row
            if any(p.ndim == 3 for p in parts):
                parts = [np.broadcast_to(p[:, None, :], (K, B, p.shape[-1])) if p.ndim == 2 else p for p in parts]
            E = np.concatenate(parts, axis=-1)
        with np.errstate(over="ignore", invalid="ignore"):   # overflow becomes a typed error naming the step
            if not batched and (E is None or E.ndim == 2):
                x, z, w = kern.run(X0[0], E, t)
                return x[:, None], z[:, None], w[:, None], []
            return kern.run_batch(X0, E, t)

    def _simulate_general(self, X0, t, theta, gamma, dU, V, vc, uniform):
        """Every step solved by the relation's verified solver (non-box relations, non-uniform grids)."""
        from .kernel import RowFailure

        K, B = t.size - 1, X0.shape[0]
        hs = np.diff(t)
        cache: dict[float, StepMatrices] = {}

        def mats(k):
            h = (t[-1] / K) if uniform else float(hs[k])
            sm = cache.get(h)
            if sm is None:
                if len(cache) > 64:
                    cache.clear()
                sm = cache[h] = self.step_matrices(h, theta, gamma)
            return h, sm

        g = 1.0 if gamma is None else float(gamma)
        X = np.full((K + 1, B, self.n), np.nan)
        Z = np.full((K, B, self.m), np.nan)
        Wout = np.full((K, B, self.m), np.nan)
        X[0] = X0
        C, D = self.C, self.D
        failures = []
        steppers: dict[float, Callable] = {}   # by step size: each row starts from fresh warm starts
        for i in range(B):
            k = 0
            try:
                for k in range(K):
                    h, sm = mats(k)
                    step = steppers.get(h)
                    if step is None:
                        if len(steppers) > 64:
                            steppers.clear()
                        step = steppers[h] = sm.relation_step()
                    xk = X[k, i]
                    xfree = sm.E @ xk
                    if dU is not None:
                        xfree = xfree + lu_solve(sm.lu, dU[k] if dU.ndim == 2 else dU[k, i])
                    if V is not None:
                        v = V[k] if V.ndim == 2 else V[k, i]
                    else:
                        v = vc if vc.ndim == 1 else vc[i]
                    xq = xfree if g == 1.0 else g * xfree + (1.0 - g) * xk
                    z, _ = step(C @ xq + v, self.q_scale(xq, v))
                    X[k + 1, i] = xn = xfree + sm.G @ z
                    Z[k, i] = z
                    Wout[k, i] = wo = C @ xn + D @ z + v
                    if not (np.all(np.isfinite(xn)) and np.all(np.isfinite(wo))):
                        raise SolverFailure("the step produced non-finite values (overflow)")
            except (InfeasibleStep, SolverFailure, InvalidProblem) as exc:
                X[k + 1:, i] = np.nan
                Z[k:, i] = Wout[k:, i] = np.nan
                err = type(exc)(f"step {k} (t = {t[k]:.6g} → {t[k + 1]:.6g}): {exc}")
                err.__cause__ = exc
                failures.append(RowFailure(i, k, float(t[k]), err))
            steppers.clear()
        return X, Z, Wout, failures

    def __repr__(self) -> str:
        return self.name


def _bad_rows(a: np.ndarray) -> list[int]:
    bad = ~np.isfinite(a)
    return np.flatnonzero(bad.reshape(bad.shape[0], -1).any(axis=1) if a.ndim > 1 else bad).tolist()[:10]


def _values(vpar, ts: np.ndarray, m: int, B: int | None) -> np.ndarray:
    """``v(t)`` at every ``t`` of ``ts``: ``(K, m)``, or ``(K, B, m)`` when ``v`` returns a batch."""
    vals = [np.asarray(vpar(s), dtype=float) for s in ts.tolist()]
    shape = vals[0].shape
    ok = ((m,),) + (((B, m),) if B is not None else ())
    if shape not in ok or any(a.shape != shape for a in vals):
        raise InvalidProblem(f"v(t) must return shape {' or '.join(map(str, ok))}, got {shape}")
    V = np.array(vals)
    if not np.all(np.isfinite(V)):
        raise InvalidProblem("v(t) returned non-finite values on the grid" +
                             (f" (rows {_bad_rows(V.transpose(1, 0, 2))})" if V.ndim == 3 else ""))
    return V


def _increments(u, t: np.ndarray, n: int, B: int | None) -> np.ndarray | None:
    """``∫_{t_k}^{t_{k+1}} u`` per cell by 3-point Gauss–Legendre (as :meth:`Problem.input_increments`):
    ``(K, n)``, or ``(K, B, n)`` when ``u`` returns a batch."""
    if u is None:
        return None
    if not callable(u):
        raise InvalidProblem("u must be a callable of t returning an (n,) or (B, n) array")
    nodes, weights = np.polynomial.legendre.leggauss(3)
    h = np.diff(t)
    mid = 0.5 * (t[:-1] + t[1:])
    shape = np.shape(u(0.0))
    ok = ((n,),) + (((B, n),) if B is not None else ())
    if shape not in ok:
        raise InvalidProblem(f"u(t) must return shape {' or '.join(map(str, ok))}, got {shape}")
    total = np.zeros((h.size,) + shape)
    hb = h.reshape((-1,) + (1,) * len(shape))
    for xi, w in zip(nodes, weights):
        vals = np.array([np.asarray(u(s), dtype=float) for s in (mid + 0.5 * h * xi).tolist()])
        if vals.shape != total.shape:
            raise InvalidProblem(f"u(t) must return shape {shape} at every t, got {vals.shape[1:]}")
        total += (0.5 * w) * hb * vals
    if not np.all(np.isfinite(total)):
        raise InvalidProblem("u(t) returned non-finite values on the grid" +
                             (f" (rows {_bad_rows(total.transpose(1, 0, 2))})" if total.ndim == 3 else ""))
    return total


#: entries of an operator's memo of ``H^0(t, x)`` and ``proj_dom H(t,·)(x)`` (:meth:`LCSOperator._memoised`)
MEMO_SIZE = 8192
#: the margin, relative to the data, by which :meth:`LCSOperator._inside_rows` wants a multiplier positive and its
#: complement slack positive before it takes a row as inside ``dom H(t)`` (its own rounding: ``1e4·ε`` of the data)
INSIDE_MARGIN = 1e-9
#: step sizes whose matrices an operator keeps once made (:meth:`LCSOperator._sm`), forgotten all at once
STEP_TEMPLATES = 4096

#: the block projection onto dom H (:meth:`LCSOperator._projected_rows`) for at most this many multipliers (2^{2m}
#: active sets) and n + m at most PROJECT_MAX_SIZE (each active set's KKT pseudo-inverse is made once, dense)
PROJECT_MAX_M = 3
PROJECT_MAX_SIZE = 64


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
        self._templates: dict[str, StepMatrices] = {}
        self._proj_data: tuple | None = None
        self._recent: StepMatrices | None = None
        # the active sets of the last selection and projection QPs (:mod:`verimono.lcs._warm_qp`)
        self._warm_select: dict = {}
        self._warm_project: dict = {}
        self._memo: dict = {}
        self._patterns: list | None = None      # the multipliers' patterns of :meth:`_inside_rows`, made once
        self._faces = None                      # the faces of H^0's block selection (:meth:`_row_faces`), made once
        self._proj_faces = None                 # the active sets of the block projection (:meth:`_projected_rows`)
        self._v_block: tuple | None = None      # (times' bytes, v at each) of the last block (:meth:`_v_rows`)

    def _memoised(self, kind: str, x: np.ndarray, t, compute):
        """``compute()`` once per ``(kind, t, x)``: an assumption law asks ``H^0`` and ``proj_dom H`` at the same
        points and times again (about one call in five on the paper's Example at ci); what it returns depends on
        ``(t, x)`` alone (the system's matrices and ``v`` are fixed once built).  At most :data:`MEMO_SIZE`
        entries, forgotten all at once."""
        key = (kind, float(t), x.tobytes())
        out = self._memo.get(key)
        if out is None:
            out = compute()
            if len(self._memo) >= MEMO_SIZE:
                self._memo.clear()
            self._memo[key] = out
        return out.copy()

    def _v_of(self, ts: list) -> list:
        """``v(t_i)`` of every time of the list ``ts``, ``v`` called once per run of equal times (rows that share a
        time: the assumption laws' blocks are the points repeated at each time, time-major): what the calls per
        row return, ``v`` being a function of ``t`` (:meth:`_memoised` relies on it too).  Times are equal by their
        bits (``0.0`` and ``-0.0`` are two times, NaN is never equal)."""
        v = self.system.v
        out: list = []
        last_t, last_v = None, None
        for t in ts:
            if last_t is None or t != last_t or (t == 0.0 and math.copysign(1.0, t) != math.copysign(1.0, last_t)):
                last_t, last_v = t, v(t)
            out.append(last_v)
        return out

    def _v_rows(self, ts: np.ndarray) -> np.ndarray:
        """``v(t_i)`` of every time of ``ts`` ``(B,)`` stacked ``(B, m)`` (read only), for the block members: the last
        block's kept by the times' bytes (``project_domain`` of a block asks it of :meth:`_inside_rows`,
        :meth:`_solvable_rows` and :meth:`_projected_rows` in turn; a subset of rows indexes it)."""
        key = ts.tobytes()
        got = self._v_block
        if got is not None and got[0] == key:
            return got[1]
        V = np.array([np.asarray(v, dtype=float) for v in self._v_of(ts.tolist())]).reshape(len(ts), self.system.m)
        V.flags.writeable = False
        self._v_block = (key, V)
        return V

    def _sm(self, lam: float) -> StepMatrices:
        sm = self._mats.get(lam)
        if sm is None:
            if len(self._mats) > 16:
                self._mats.clear()
            # the matrices of a step size are a function of it alone: made once (an operator law asks ~20,000
            # resolvents over a few hundred λ, far more than the 16 live steppers), each live stepper made fresh
            # from them as a new StepMatrices would be — the same answers, bit for bit, at a copy's cost
            key = lam.hex()
            tpl = self._templates.get(key)
            if tpl is None:
                if len(self._templates) >= STEP_TEMPLATES:
                    self._templates.clear()
                tpl = self._templates[key] = self.system.step_matrices(lam, 1.0, None)
            sm = self._mats[lam] = tpl.fresh()
            warm = getattr(sm.step, "warm_from", None)
            if warm is not None and self._recent is not None:   # a new step size: the last one's pattern first
                warm(self._recent.step)
        self._recent = sm
        return sm

    def _accepts_batches(self):
        return type(self).resolvent is LCSOperator.resolvent

    def _accepts_times(self):
        """A time per row (:meth:`verimono.Operator._accepts_times`): ``resolvent``, ``yosida``, ``min_norm`` and
        ``project_domain`` of rows ``(B, n)`` at times ``(B,)`` take each row as its own call would, in the rows'
        order (the stateful stepper and the warm QPs see the same sequence of calls) — unless a subclass or the
        object itself replaces one of them.  One exception to "bit for bit": ``project_domain`` of rows outside the
        domain takes the block's own verified QP solution (:meth:`_projected_rows`, accepted at ``QP_RTOL``), which
        differs from the row's own call by up to 1.1e-12 (measured, perf10) — far below every tolerance judging it;
        a row's projection so given is remembered as its own call's would be (the memo of :meth:`_memoised`)."""
        mine = getattr(self, "__dict__", {})
        return all(getattr(type(self), m) is getattr(LCSOperator, m) and m not in mine
                   for m in ("resolvent", "yosida", "min_norm", "project_domain"))

    def _times(self, x: np.ndarray, t) -> np.ndarray | None:
        """``t`` as a time per row of ``x`` (:func:`verimono.core._rows.times_of`), else ``None``."""
        if type(t) is not np.ndarray or t.ndim != 1:
            return None
        if x.ndim != 2 or x.shape[0] != t.shape[0]:
            raise InvalidProblem(f"{self.name}: a time per row needs points of shape ({t.shape[0]}, n), "
                                 f"got {x.shape}")
        return t.astype(float, copy=False)

    def resolvent(self, x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        ts = self._times(x, t)
        if ts is not None:
            if x.shape[0] and x.shape[1] == self.dim and self._accepts_times():
                return self._rows(x, float(lam), ts.tolist())
            return np.array([self.resolvent(xi, lam, ti) for xi, ti in zip(x, ts.tolist())]).reshape(x.shape)
        if x.ndim == 2:
            if x.shape[0] and x.shape[1] == self.dim and type(self).resolvent is LCSOperator.resolvent:
                return self._rows(x, float(lam), t)
            return np.array([self.resolvent(xi, lam, t) for xi in x])
        if x.shape != (self.dim,):
            raise InvalidProblem(f"{self.name} acts on R^{self.dim}; got a point of shape {x.shape}")
        sm = self._sm(float(lam))
        s = self.system
        xE, v = sm.E @ x, s.v(t)
        z, _ = sm.step(s.C @ xE + v, s.q_scale(xE, v))
        return xE + sm.G @ z

    def _rows(self, X: np.ndarray, lam: float, t) -> np.ndarray:
        """The resolvent of every row of ``X``, each row's arithmetic exactly :meth:`resolvent`'s for one point
        (the same products, the same stepper called in the same order), with what the rows share looked up
        once: the step matrices of ``λ`` and ``v(t)``, a function of ``t`` (an assumption law's design asks
        ~20 rows at one ``(λ, t)``; the paper's Example's operator laws ~100).  ``t`` a list: row ``i`` at
        ``t[i]`` (``v`` looked up per row)."""
        sm = self._sm(lam)
        s = self.system
        E, G, C, step, q_scale = sm.E, sm.G, s.C, sm.step, s.q_scale
        out = []
        rows = getattr(step, "rows", None)
        own_scale = type(s).q_scale is LinearRelationSystem.q_scale
        if type(t) is list:
            vs = self._v_of(t)
        else:
            v = s.v(t)
            if own_scale and (rows is None or len(X) < 2):
                # one v for every row: q_scale's ‖C‖∞|xE|∞ + |v|∞ with |v|∞ read once (the same sum)
                cn, vmax = s._c_norm, absmax(v)
                for x in X:
                    xE = E @ x
                    z, _ = step(C @ xE + v, cn * absmax(xE) + vmax)
                    out.append(xE + G @ z)
                return np.array(out)
            vs = None if own_scale else [v] * len(X)
        if rows is not None and own_scale and len(X) > 1:
            # the same arithmetic for the whole block: each product a stacked matmul (the same BLAS call per row
            # as the 1-D one), ``q_scale``'s two |·|∞ and its sum elementwise, the stepper's rows in order; one
            # ``v`` for every row (a single time) broadcast over the block (the same sums)
            V = np.array(vs, dtype=float).reshape(len(X), -1) if vs is not None else \
                np.broadcast_to(np.asarray(v, dtype=float).reshape(1, -1), (len(X), np.size(v)))
            xE = (E @ X[:, :, None])[:, :, 0]
            Q = (C @ xE[:, :, None])[:, :, 0] + V
            scales = (s._c_norm * np.abs(xE).max(axis=1) + np.abs(V).max(axis=1)).tolist()
            Z = rows(Q, scales)
            return xE + (G @ Z[:, :, None])[:, :, 0]
        for x, v in zip(X, vs):
            xE = E @ x
            z, _ = step(C @ xE + v, q_scale(xE, v))
            out.append(xE + G @ z)
        return np.array(out)

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
        nearest point of the domain.  When the multipliers are provably unique (the rank certificate of
        :func:`verimono.lcs.lcp.unique_certificate`) there is nothing to select: the selection QP is skipped, as it
        must be where that unique point is the apex of a thin wedge (the Example at ``t = 2⁻²³``, whose
        ``SOL`` is cut out by rows ``t`` apart in angle, no back-end verifies to ``QP_RTOL``)."""
        rel, s = self._box(), self.system
        v = s.v(t)
        eta, scale = s.C @ x + v, s.q_scale(x, v)
        lo, hi = rel.bounds(s.m)
        big, qq, fin = _box_lcp(s.D, eta, lo, hi)
        if row_infeasible(big, qq):     # a row of the multipliers' constraints no z ≥ 0 meets, by a margin
            raise OutsideDomain(f"x = {x} is not in dom H(t={t}): Cx + v(t) ∉ im(𝓜 + D)")
        try:   # a solution proves x ∈ dom H(t): the linear program is needed only when there is none
            r = solve_lcp(big, qq, least_norm=False, scale=scale, info=True)
        except InfeasibleStep:
            if not _feasible(big, qq):
                raise OutsideDomain(f"x = {x} is not in dom H(t={t}): Cx + v(t) ∉ im(𝓜 + D)") from None
            scale = 1.0 + scale
            r = solve_lcp(big, qq, least_norm=False, scale=scale, info=True)
        zbar = r.z
        if r.unique is True:
            return lo + zbar[:s.m]
        k = big.shape[0]
        P = np.zeros((k, k))
        P[:s.m, :s.m] = P_lam
        c = np.zeros(k)
        c[:s.m] = c_lam + P_lam @ lo
        G, h, A, b = sol_polyhedron(big, qq, zbar, scale)     # select_over_sol, warm-started
        try:
            zz = solve_qp_warm(self._warm_select, P, c, G, h, A if len(A) else None, b if len(A) else None,
                               scale=scale)
        except (InfeasibleStep, UnverifiedSolution):
            # the QP's numerical limit, not the problem's: SOL holds the verified z̄.  Where a multiplier is
            # positive below RTOL·scale but above z̄'s own residual (the Example's z = (x, t) at t/x < RTOL, a
            # wedge t/x wide that no back-end verifies), the certificate at that residual proves SOL = {z̄}:
            # nothing to select.  Otherwise the failure stands (the selection does choose H⁰ there)
            tau = max(r.residual, 8 * np.finfo(float).eps * r.scale)
            if not unique_certificate(big, qq, zbar, big @ zbar + qq, tau / RTOL):
                raise
            zz = zbar
        return lo + zz[:s.m]

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        ts = self._times(x, t)
        if ts is not None:      # row by row in order: OutsideDomain when any row is outside at its time
            if x.shape[0] and x.shape[1] == self.dim and self._selects_rows():
                return self._min_norm_rows(x, ts.tolist())
            return np.array([self.min_norm(xi, ti) for xi, ti in zip(x, ts.tolist())]).reshape(x.shape)
        if x.ndim == 2:
            if x.shape[0] and x.shape[1] == self.dim and self._selects_rows():
                return self._min_norm_rows(x, [t] * x.shape[0])
            return np.array([self.min_norm(xi, t) for xi in x])
        return self._memoised("min_norm", x, t, lambda: self._min_norm(x, t))

    def _selects_rows(self) -> bool:
        """Whether ``min_norm`` of a block may select the rows' multipliers together (:meth:`_min_norm_rows`):
        none of the members it stands for replaced by a subclass or the instance."""
        mine = getattr(self, "__dict__", {})
        return self._accepts_times() and all(getattr(type(self), m) is getattr(LCSOperator, m) and m not in mine
                                             for m in ("_min_norm", "_select"))

    def _row_faces(self):
        """:class:`verimono.lcs._select_rows.Faces` of the multipliers' box LCP and ``H^0``'s selection, made once;
        ``False`` where the block selection does not apply (not a box relation with PSD ``D``, or more than
        :data:`~verimono.lcs._select_rows.MAX_FACES_K` multipliers)."""
        F = self._faces
        if F is None:
            F = False
            try:
                rel, s = self._box(), self.system
                lo, hi = rel.bounds(s.m)
                big, _, _ = _box_lcp(s.D, np.zeros(s.m), lo, hi)
                if big.shape[0] <= MAX_FACES_K and np.isfinite(s.A).all() and np.isfinite(s.B).all():
                    k = big.shape[0]
                    P = np.zeros((k, k))
                    P[:s.m, :s.m] = s.B.T @ s.B
                    F = Faces(big, P)
            except NotImplementedError:
                F = False
            self._faces = F
        return F

    def _min_norm_rows(self, X: np.ndarray, ts: list) -> np.ndarray:
        """``min_norm`` of every row ``x_i`` at ``t_i``: the rows not remembered selected together
        (:func:`verimono.lcs._select_rows.select_rows`: every row's candidate accepted only by the per-row path's
        own LCP residual and KKT checks), each row it does not accept taken as its own call, in the rows' order
        (``OutsideDomain`` when a row is outside at its time, as row by row).  The answers agree with the
        per-row path's to the selection QP's verification tolerance: ``H^0 = −Ax − Bλ*`` is unique even where
        the multipliers ``λ*`` are not (the edge of ``dom H(t)``)."""
        out = np.empty(X.shape)
        keys = [("min_norm", float(ti), xi.tobytes()) for xi, ti in zip(X, ts)]
        memo = self._memo
        miss = []
        for i, key in enumerate(keys):
            hit = memo.get(key)
            if hit is None:
                miss.append(i)
            else:
                out[i] = hit
        ok = np.zeros(len(miss), dtype=bool)
        F = self._row_faces() if miss else False
        if F:
            s = self.system
            try:
                rel = self.system.relation
                lo, hi = rel.bounds(s.m)
                fin = np.flatnonzero(np.isfinite(hi))
                Xm = X[miss]
                with np.errstate(all="ignore"):
                    V = np.array([np.asarray(v, dtype=float) for v in self._v_of([ts[i] for i in miss])]
                                 ).reshape(len(miss), s.m)
                    Q = Xm @ s.C.T + V
                    scales = s._c_norm * np.abs(Xm).max(axis=1) + np.abs(V).max(axis=1)
                    QQ = np.concatenate([Q + s.D @ lo, np.broadcast_to((hi - lo)[fin], (len(miss), fin.size))],
                                        axis=1)
                    AX = Xm @ s.A.T
                    Cc = np.zeros((len(miss), F.k))
                    Cc[:, :s.m] = AX @ s.B + (s.B.T @ s.B) @ lo
                    Z, ok = select_rows(F, QQ, Cc, scales)
                    H0 = -AX - (lo + Z[:, :s.m]) @ s.B.T
                ok &= np.isfinite(H0).all(axis=1)
            except Exception:   # noqa: BLE001 - whatever the block raises, each row's own call raises it in its turn
                ok = np.zeros(len(miss), dtype=bool)
        for j, i in enumerate(miss):
            if ok[j]:
                out[i] = H0[j]
                if len(memo) >= MEMO_SIZE:
                    memo.clear()
                memo[keys[i]] = H0[j].copy()
            else:
                out[i] = self.min_norm(X[i], ts[i])
        return out

    def _min_norm(self, x, t):
        s = self.system
        Ax = s.A @ x
        lam = self._select(x, t, s.B.T @ s.B, s.B.T @ Ax)
        return -Ax - s.B @ lam

    def contains(self, x, y, t=0.0, tol=None):
        """Whether some ``(x', y') ∈ graph H(t,·)`` lies within ``tol`` of ``(x, y)`` in each coordinate (the
        :meth:`verimono.Operator.contains` contract), through either witness: the graph point ``(p, x + y − p)``,
        ``p = J_1(x + y)``, which is ``|x − p|`` from ``(x, y)`` in both coordinates — so a point within rounding
        of a kink of ``H`` (``x = 2e-16`` for the edge ``0`` of the Example's ``dom H``, where ``H(x) = {0}`` but
        ``H(0) = (−∞, 0]``) is a member there — tried first, being the cheaper (the resolvent's warm-started
        kernel); else at ``x' = x``, the multiplier nearest to explaining ``y``."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        s = self.system
        tol = tolerance(s.A @ x, y) if tol is None else tol
        self._box()         # H(t, x) as a set needs a box relation: NotImplementedError otherwise, as always
        # either witness proves membership; the graph point through the (warm-started) resolvent is the cheaper
        # one, so it is tried first, and the multipliers' selection (an LCP and often a QP) only when it fails
        try:
            p, failure = self.resolvent(x + y, 1.0, t), None
            if np.max(np.abs(p - x)) <= tol:
                return True
        except Exception as exc:  # noqa: BLE001 - raised again below unless the multipliers decide
            failure = exc
        try:
            lam = self._select(x, t, s.B.T @ s.B, s.B.T @ (s.A @ x + y))
            if np.max(np.abs(-s.A @ x - s.B @ lam - y)) <= tol:
                return True
        except OutsideDomain:
            pass
        if failure is not None:     # neither witness: the resolvent's failure is the answer
            raise failure
        return False

    def project_domain(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        ts = self._times(x, t)
        if ts is not None:
            inside = self._inside_rows(x, ts) if self._accepts_times() else None
            if inside is None:
                return np.array([self.project_domain(xi, ti) for xi, ti in zip(x, ts.tolist())]).reshape(x.shape)
            projected = {}
            if not inside.all() and self._selects_rows():
                inside = inside | self._solvable_rows(x, ts, ~inside)
                if not inside.all():
                    projected = self._projected_rows(x, ts, ~inside)
            out = []
            for i, (xi, ti, ok) in enumerate(zip(x, ts.tolist(), inside.tolist())):
                # a row proved inside dom H(t_i) is its own projection, what _project_domain returns for it (its
                # proof skipped, the memo kept as that call keeps it); a row the block projected, its verified
                # projection (remembered as its own call would be); the others as their own call
                if ok:
                    out.append(self._memoised("project_domain", xi, ti, xi.copy))
                elif i in projected:
                    out.append(self._memoised("project_domain", xi, ti, projected[i].copy))
                else:
                    out.append(self.project_domain(xi, ti))
            return np.array(out).reshape(x.shape)
        if x.ndim == 2:
            return np.array([self.project_domain(xi, t) for xi in x])
        return self._memoised("project_domain", x, t, lambda: self._project_domain(x, t))

    def _solvable_rows(self, X: np.ndarray, ts: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Which of ``rows`` (a mask) are proved inside ``dom H(t_i)`` by a face's solution of the multipliers'
        LCP that passes the residual check Lemke's point passes in :meth:`_project_domain`
        (:func:`verimono.lcs._select_rows.solvable_rows`): the rows on the domain's edge, which
        :meth:`_inside_rows`' margin leaves to their own call.  A row not proved is its own call."""
        proved = np.zeros(len(X), dtype=bool)
        F = self._row_faces()
        idx = np.flatnonzero(rows)
        if not F or not idx.size:
            return proved
        s = self.system
        try:
            lo, hi = s.relation.bounds(s.m)
            fin = np.flatnonzero(np.isfinite(hi))
            Xm = X[idx]
            with np.errstate(all="ignore"):
                V = self._v_rows(ts)[idx]
                scales = s._c_norm * np.abs(Xm).max(axis=1) + np.abs(V).max(axis=1)
                QQ = np.concatenate([Xm @ s.C.T + V + s.D @ lo,
                                     np.broadcast_to((hi - lo)[fin], (len(idx), fin.size))], axis=1)
                proved[idx] = solvable_rows(F, QQ, scales) & np.isfinite(Xm).all(axis=1)
        except Exception:   # noqa: BLE001 - whatever the block raises, each row's own call raises it in its turn
            proved[:] = False
        return proved

    def _projected_rows(self, X: np.ndarray, ts: np.ndarray, rows: np.ndarray) -> dict:
        """The projections onto ``dom H(t_i)`` of ``rows`` (a mask) that the block verifies
        (:func:`verimono.lcs._select_rows.project_rows`: :meth:`_project_domain`'s QP for the rows together, each
        row's candidate accepted by ``kkt_residual`` at ``QP_RTOL`` in ``solve_qp``'s units), by row index;
        complementarity only (a bounded box is the whole space, mixed bounds are the rows' own call's error)."""
        s = self.system
        idx = np.flatnonzero(rows)
        if not idx.size or not self._row_faces():
            return {}
        try:
            rel = self._box()
            # 2^{2m} active sets of KKT systems of size n + m + |active|: kept small (the Section 7 systems, n ≤ 2)
            if not rel.is_lcp or s.m > PROJECT_MAX_M or s.n + s.m > PROJECT_MAX_SIZE:
                return {}
            F = self._proj_faces
            if F is None:
                n, m = s.n, s.m
                P = np.zeros((n + m, n + m))
                P[:n, :n] = np.eye(n)
                G = np.block([[np.zeros((m, n)), -np.eye(m)], [-s.C, -s.D]])
                F = self._proj_faces = ProjectionFaces(P, G)
            with np.errstate(all="ignore"):
                V = self._v_rows(ts)[idx]
                # only rows row_infeasible proves outside (what _project_domain takes to its QP with no linear
                # program: a row within the program's tolerance of the domain is its own projection there)
                Q = X[idx] @ s.C.T + V
                tol = INFEASIBLE_MARGIN * (1.0 + np.abs(Q).max(axis=1) + self._row_faces().m_max)
                far_out = (self._row_faces().nonpos[None, :] & (Q < -tol[:, None])).any(axis=1)
                idx, V = idx[far_out], V[far_out]
                if not idx.size:
                    return {}
                Xm = X[idx]
                c = np.concatenate([-Xm, np.zeros((len(idx), s.m))], axis=1)
                h = np.concatenate([np.zeros((len(idx), s.m)), V], axis=1)
                Y, ok = project_rows(F, c, h)
                ok &= np.isfinite(Y).all(axis=1)
        except Exception:   # noqa: BLE001 - whatever the block raises, each row's own call raises it in its turn
            return {}
        return {int(i): Y[j, :s.n] for j, i in enumerate(idx.tolist()) if ok[j]}

    def _inside_rows(self, X: np.ndarray, ts: np.ndarray) -> np.ndarray | None:
        """Which rows ``x_i`` are proved inside ``dom H(t_i)`` (complementarity, PSD ``D``) by a strictly complementary
        solution of the multipliers' ``LCP(Cx_i + v(t_i), D)``, for the whole block at once: on a pattern ``I`` whose
        ``D_II`` is well conditioned (``cond ≤ 1e4``), ``z_I = −D_II^{-1} q_I > τ`` and ``w_J = (Dz + q)_J > τ`` off it,
        ``τ = INSIDE_MARGIN·(1 + |q|∞ + ‖C‖∞|x|∞ + |v|∞ + ‖D‖∞|z|∞)`` — far above the rounding of this computation
        (``cond·ε`` of the data), so the exact solution of the pattern is a solution too and ``x_i ∈ dom H(t_i)``:
        what the row's own call proves with Lemke or the linear program (:meth:`_project_domain`), which is then
        spared.  A row not proved (on the domain's edge, outside it, a tie) is left to its own call.  ``None``:
        not applicable here (another relation, or ``H`` as a set unavailable), every row its own call."""
        s = self.system
        try:
            rel = self._box()
            if not rel.is_lcp or not len(X):
                return None
            pats = self._patterns
            if pats is None:
                D, m = s.D, s.m
                pats = []
                for mask in range(1 << m):
                    I = np.array([i for i in range(m) if mask >> i & 1], dtype=int)
                    J = np.array([i for i in range(m) if not mask >> i & 1], dtype=int)
                    inv = None
                    if I.size:
                        DII = D[np.ix_(I, I)]
                        if not np.linalg.cond(DII) <= 1e4:
                            continue
                        inv = np.linalg.inv(DII)
                    pats.append((I, J, inv))
                self._patterns = pats
            with np.errstate(all="ignore"):
                V = self._v_rows(ts)
                Q = X @ s.C.T + V
                size = 1.0 + np.abs(Q).max(axis=1) + s._c_norm * np.abs(X).max(axis=1) + np.abs(V).max(axis=1)
                d_norm = float(np.abs(s.D).sum(axis=1).max(initial=0.0))
                inside = np.zeros(len(X), dtype=bool)
                for I, J, inv in pats:
                    Z = np.zeros_like(Q)
                    if inv is not None:
                        Z[:, I] = -(Q[:, I] @ inv.T)
                    W = Z @ s.D.T + Q
                    tau = INSIDE_MARGIN * (size + d_norm * np.abs(Z).max(axis=1))
                    inside |= (Z[:, I] > tau[:, None]).all(axis=1) & (W[:, J] > tau[:, None]).all(axis=1)
            return inside & np.isfinite(size)
        except Exception:   # noqa: BLE001 - whatever the block raises, each row's own call raises it in its turn
            return None

    def _project_domain(self, x, t):
        rel, s = self._box(), self.system
        lo, hi = rel.bounds(s.m)
        if np.isfinite(hi).all():
            return x.copy()  # bounded box: 𝓜 + D is surjective, dom H = R^n
        v = s.v(t)
        big, qq, fin = _box_lcp(s.D, s.C @ x + v, lo, hi)
        # a verified multiplier proves x ∈ dom H(t) at a fraction of the linear program's cost, and a row no
        # z ≥ 0 meets proves x ∉ dom H(t) at a fraction of it too
        if not row_infeasible(big, qq) and (proved_solvable(big, qq, s.q_scale(x, v)) or _feasible(big, qq)):
            return x.copy()
        # min ½|x' − x|² over {(x', z): z ≥ 0, D z + C x' + v ≥ 0} (complementarity: dom = C^{-1}(Q_D^+ − v))
        if not rel.is_lcp:
            raise NotImplementedError(f"{self.name}: projection onto dom H for mixed bounds")
        n, m = s.n, s.m
        if self._proj_data is None:     # P and G are the system's: made once (read only), as np.block made them
            P = np.zeros((n + m, n + m))
            P[:n, :n] = np.eye(n)
            G = np.block([[np.zeros((m, n)), -np.eye(m)], [-s.C, -s.D]])
            P.flags.writeable = G.flags.writeable = False
            self._proj_data = (P, G)
        P, G = self._proj_data
        h = np.concatenate([np.zeros(m), v])        # v = v(t), looked up above
        return solve_qp_warm(self._warm_project, P, np.concatenate([-x, np.zeros(m)]), G, h)[:n]


__all__ = ["LinearRelationSystem", "LCSOperator", "StepMatrices", "BatchStepError"]
