"""The small-LCP kernel of :meth:`LinearRelationSystem.simulate` on a uniform grid.

With the constant step matrices of a uniform grid (:class:`StepMatrices`), one ``EulerMoreauOSI(θ, γ)`` step
is, for a fixed *pattern* ``s ∈ {0, 1, 2}^m`` of the box relation ``−w ∈ N_[l,u](z)`` (``s_i = 0``: ``z_i = l_i``,
``w_i ≥ 0``; ``1``: ``l_i < z_i < u_i``, ``w_i = 0``; ``2``: ``z_i = u_i``, ``w_i ≤ 0``), an **affine map** of
``ξ = (x_k, e_k, 1)`` with ``e_k = (W^{-1}∫u, v(t_{k+1}))`` the exogenous terms (only those that vary):

    z_I = −M_II^{-1}(q_I + (M z_fix)_I),  q = C(γ x_free + (1−γ)x_k) + v,  x_free = E x_k + W^{-1}∫u,
    x_{k+1} = x_free + G z,  w = Mz + q,  w_out = C x_{k+1} + D z + v.

The map of a pattern is built once (one LU of ``M_II``, accepted only when ``cond M_II ≤ ACTIVE_SET_COND``, and
its identity ``w_I ≡ 0`` verified to ``QP_RTOL`` coefficient by coefficient), cached by pattern, and a step
evaluates one map: a handful of multiply-adds.  Each step's candidate is **verified**: every sign condition
of its pattern (``w_i > τ`` at ``l``, ``−w_i > τ`` at ``u``, ``z_i − l_i > τ`` and ``u_i − z_i > τ`` inside)
must hold with the margin ``τ = RTOL·S_k``, ``S_k`` the size of the terms the checked entries are summed from
(``‖T_P‖ |ξ_k|``), and every output must be finite.  A candidate that passes is *strictly* complementary
with ``M_II`` nonsingular, hence (``M`` PSD) the **unique** solution of the step — so it is the least-norm
solution of Proposition ``p:lcp2`` (the solution set is convex; a second solution would give a segment of
solutions near the candidate keeping its pattern, where ``z_I`` is fixed by ``M_II``).  The pattern whose
``z`` is 0 needs only ``w ≥ 0``, not strictly: no solution has a smaller norm (``solve_lcp``'s ``q ≥ 0``).
When no candidate is strictly complementary, a *degenerate* one (``z_i ≈ 0 ≈ w_i`` in some components, e.g.
a diode with zero current and voltage) is accepted for a complementarity relation only with a certificate
that it is the least-norm solution (:meth:`StepKernel._least_norm_degenerate`: ``z_cᵀd ≥ 0`` on the tangent
cone of every piece of ``SOL`` through it) — the DiodeBridgeCapFilter's non-unique steps.  Otherwise the kernel
tries the pattern the violated signs point to, then (for ``≤ ENUM_PATTERNS`` patterns) every pattern, and
only then the verified least-norm solver (``Relation.solve``, i.e. :func:`verimono.lcs.solve_lcp` /
``solve_box``) with today's arithmetic; its solution's pattern is the next step's guess.

**Batches.** ``x0`` of shape ``(B, n)``: every row carries its own pattern; rows with the same pattern are
stepped together with the same elementwise operations, in the same order, as a single run (a single run
evaluates the map in Python floats, a batch in NumPy columns: IEEE multiply-add by multiply-add, so the
results are **bit-identical** to ``B`` separate runs).  A row whose step is infeasible or fails stops there;
the others run to the end, then :class:`BatchStepError` carries every row's results (``valid`` masks the
steps after a row's failure, which hold NaN) and names each failed row and step.

Pure Python/NumPy, with an optional compiled batch kernel (:mod:`verimono.lcs._batch_numba`, numba,
``pip install verimono[fast]``; ``BATCH_KERNEL``): it makes the same multiply-adds, tests and pattern changes per
row and leaves to Python what needs a new pattern's map, a degenerate step or the solver, so batches keep the
same bits with either kernel.  Single runs stay in Python: a compiled kernel would cost more in import and JIT
per process than a whole Section 7 run takes with the generated loops.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import os
import threading
from array import array

import numpy as np

from ..core.errors import BatchStepError, InfeasibleStep, InvalidProblem, SolverFailure, VerimonoError
from ..core.tolerances import ACTIVE_SET_COND, QP_RTOL, RTOL
from ._lu import lu_factor, lu_solve
from .lcp import lcp_scale
from .relations import BoxRelation

#: largest number of patterns (``∏ states``) that a failed guess is followed by trying all of
ENUM_PATTERNS = 64

#: which batch kernel :meth:`StepKernel.run_batch` uses: ``"auto"`` (the compiled one of
#: :mod:`verimono.lcs._batch_numba` when numba is installed — ``pip install verimono[fast]`` — the relation has
#: at most ``NUMBA_MAX_M`` components and the batch makes at least ``NUMBA_MIN_WORK`` trajectory-steps; the
#: NumPy one otherwise), ``"numba"`` (the compiled one whenever numba is installed) or ``"numpy"``.  Both give
#: the same bits (``tests/lcs/test_lcs_batch_kernel.py``); ``StepKernel.last_backend`` says which ran.  Set from
#: the environment variable ``VERIMONO_BATCH_KERNEL`` at import; assign to change it.
BATCH_KERNEL = os.environ.get("VERIMONO_BATCH_KERNEL", "auto")
#: the compiled kernel looks patterns up in a table of ``3^m`` ids
NUMBA_MAX_M = 10
#: below this many trajectory-steps a batch takes the NumPy kernel under ``"auto"``: importing numba and loading
#: a compiled shape from the disk cache cost about 0.5–1 s per process (compiling a new shape ~10 s, once per
#: machine), which the NumPy kernel (~0.13 µs per trajectory-step) spends on about 10^7 trajectory-steps
NUMBA_MIN_WORK = 100_000

_NUMBA: list = []


def _numba_advance():
    """:func:`verimono.lcs._batch_numba.load`, or None when numba cannot be imported (tried once)."""
    if not _NUMBA:
        try:
            import numba  # noqa: F401

            from ._batch_numba import load
        except ImportError:
            load = None
        _NUMBA.append(load)
    return _NUMBA[0]


def batch_backend(m: int = 1, work: float = math.inf) -> str:
    """The batch kernel a batch with ``m`` components and ``work`` trajectory-steps would use now: ``"numba"``
    or ``"numpy"``."""
    if BATCH_KERNEL == "numpy" or m > NUMBA_MAX_M or (BATCH_KERNEL == "auto" and work < NUMBA_MIN_WORK):
        return "numpy"
    return "numba" if _numba_advance() is not None else "numpy"


_ROW_FNS: dict[int, object] = {}


def _row_fn(ncols: int):
    """``f(rows, v_0, …, v_{c−1}) = [r_0 + r_1 v_0 + … + r_c v_{c−1} for r in rows]`` (left to right)."""
    fn = _ROW_FNS.get(ncols)
    if fn is None:
        names = [f"v{j}" for j in range(ncols)]
        coefs = [f"a{j}" for j in range(ncols)]
        expr = " + ".join(["c"] + [f"{a}*{v}" for a, v in zip(coefs, names)])
        src = f"lambda rows, {', '.join(names)}: [{expr} for c, {', '.join(coefs)} in rows]" if ncols else \
            "lambda rows: [c for (c,) in rows]"
        fn = _ROW_FNS[ncols] = eval(src)  # noqa: S307  (generated from integers only)
    return fn


def _loop_fn(p, n: int, ne: int, nrows: int):
    """A single run's steps through pattern ``p`` while its candidate passes: a loop of straight-line Python
    with ``p``'s coefficients as literals (``repr`` of a float reads back the same double), doing
    :meth:`StepKernel.try_row`'s multiply-adds in the same order and its test (every sign row ``> τ``,
    every row finite: ``−1e999 < y < 1e999``, ``1e999`` being ``inf``; the padding's repeated rows left out).

    ``loop(x, k, K, El, emax, xs, pid) -> (k, x)``: appends ``x_{k+1}`` to ``xs`` (an ``array("d")``) for every step it
    makes from ``k``, and returns the first step it could not make (``K`` when none) and the state there."""
    xs_ = [f"x{j}" for j in range(n)]
    es_ = [f"e{j}" for j in range(ne)]
    lines = ["def loop(x, k, K, El, emax, xs, pid):",
             f"    {', '.join(xs_)}, = x",
             "    app = xs.append",
             "    while k < K:"]
    if ne:
        lines.append(f"        {', '.join(es_)}, = El[k]")
        lines.append("        em = emax[k]")
    seen: dict = {}
    names = []
    for i in range(nrows):
        row = tuple(p.rows[i])
        if i >= n:
            if row in seen:           # a repeated (padding) sign row: the same value, tested once
                continue
            seen[row] = i
        terms = [repr(row[0])] + [f"({row[1 + j]!r})*{v}" for j, v in enumerate(xs_ + es_)]
        lines.append(f"        y{i} = {' + '.join(terms)}")
        names.append(i)
    # max(map(abs, x)) without calls: the same value (x is finite here; a zero's sign cannot change τ, whose
    # other term ``rb`` is ≥ 0 or −5e-324)
    for j, v in enumerate(xs_):
        lines.append(f"        a{j} = {v} if {v} >= 0.0 else -{v}")
        if j:
            lines.append(f"        a0 = a0 if a0 >= a{j} else a{j}")
    tau = "({!r})*a0 + ({!r})*em + ({!r})".format(p.ra, p.re, p.rb) if ne else "({!r})*a0 + ({!r})".format(p.ra, p.rb)
    lines.append(f"        tau = {tau}")
    tests = [f"tau < y{i} < 1e999" for i in names if i >= n] + [f"-1e999 < y{i} < 1e999" for i in names if i < n]
    lines.append(f"        if not ({' and '.join(tests)}):")
    lines.append(f"            return k, [{', '.join(xs_)}]")
    lines.append(f"        {', '.join(xs_)}, = {', '.join(f'y{j}' for j in range(n))},")
    lines.extend(f"        app({v})" for v in xs_)
    lines.append("        k += 1")
    lines.append(f"    return k, [{', '.join(xs_)}]")
    ns: dict = {}
    exec("\n".join(lines), {}, ns)  # noqa: S102  (generated from floats' reprs only)
    return ns["loop"]


@dataclasses.dataclass
class RowFailure:
    """Why row ``row`` of a batch stopped: at step ``step`` (``t_step → t_{step+1}``) with ``error``."""

    row: int
    step: int
    t: float
    error: VerimonoError

    def __str__(self) -> str:
        return f"row {self.row}, step {self.step} (t = {self.t:.6g}): {type(self.error).__name__}: {self.error}"


class _Pattern:
    __slots__ = ("key", "s", "rows", "const", "cols", "oconst", "ocols", "coef", "ra", "re", "rb", "pcomp", "pnew",
                 "loop")


#: steps post-processed at a time when the outputs ``z``, ``w`` are evaluated after the loop (bounds memory)
_OUT_BLOCK = 256


class StepKernel:
    """The per-pattern affine maps of one step for ``sm`` (see the module docstring).

    A pattern's map has *step rows* ``(x_{k+1}, sign rows)`` — evaluated every step, in the loop — and
    *output rows* ``(z_k, w_k)``, evaluated after the loop for all steps at once (the same multiply-adds).
    ``exo_u``/``exo_v``: whether ``W^{-1}∫u`` / ``v`` vary (columns of ``e_k``); otherwise ``v_const`` is
    folded into the constant column."""

    def __init__(self, system, sm, *, exo_u: bool, exo_v: bool, v_const: np.ndarray | None) -> None:
        rel = system.relation
        if not isinstance(rel, BoxRelation):
            raise TypeError("StepKernel needs a box relation (Complementarity, Relay)")
        n, m = system.n, system.m
        self.sys, self.sm, self.n, self.m = system, sm, n, m
        self.M = sm.M
        self.lo, self.hi = rel.bounds(m)
        self.nstates = np.where(np.isfinite(self.hi), 3, 2)
        self.exo_u, self.exo_v = exo_u, exo_v
        self.v_const = v_const
        self.F = n
        self.L = n + int(self.nstates.sum() - m)   # x_{k+1} and the most sign rows a pattern has
        g = sm.gamma
        self.g = g
        N = 2 * n + m + 1
        I = np.eye(n)
        X = np.zeros((n, N)); X[:, :n] = I
        R = np.zeros((n, N)); R[:, n:2 * n] = I
        V = np.zeros((m, N)); V[:, 2 * n:2 * n + m] = np.eye(m)
        self._xfree = sm.E @ X + R
        xq = self._xfree if g == 1.0 else g * self._xfree + (1.0 - g) * X
        self._q = system.C @ xq + V
        self._V = V
        keep = list(range(n)) + (list(range(n, 2 * n)) if exo_u else []) + \
            (list(range(2 * n, 2 * n + m)) if exo_v else [])
        self._keep = keep
        self.ne = len(keep) - n
        self.fn = _row_fn(len(keep))
        self.cache: dict[bytes, _Pattern | None] = {}
        self.by_id: list[_Pattern] = []
        self.enum = int(np.prod(self.nstates.astype(float))) <= ENUM_PATTERNS
        self.is_lcp = bool(rel.is_lcp)
        self._deg: dict = {}
        self._lock = threading.Lock()
        self.last_backend: str | None = None   # the kernel of the last batch: "numba" or "numpy"

    # -- patterns --------------------------------------------------------------------------------------
    def pattern(self, s: np.ndarray) -> _Pattern | None:
        """The map of pattern ``s`` (cached), or None when ``M_II`` is too ill-conditioned or the map's
        identity ``w_I ≡ 0`` fails its check."""
        key = np.asarray(s).astype(np.int8).tobytes()
        if key in self.cache:
            return self.cache[key]
        with self._lock:   # a kernel is shared by the runs of its system (threads too): ids stay by_id's indices
            if key in self.cache:
                return self.cache[key]
            p = self._build(np.frombuffer(key, dtype=np.int8))
            if p is not None:
                p.key = len(self.by_id)
                self.by_id.append(p)
            self.cache[key] = p
        return p

    def _build(self, s: np.ndarray) -> _Pattern | None:
        n, m, M, lo, hi = self.n, self.m, self.M, self.lo, self.hi
        q = self._q
        N = q.shape[1]
        I = np.flatnonzero(s == 1)
        fixed = np.where(s == 2, hi, lo)
        fixed[I] = 0.0
        Mfixed = M @ fixed
        z = np.zeros((m, N))
        z[:, -1] = fixed
        if I.size:
            MII = M[np.ix_(I, I)]
            cond = np.linalg.cond(MII)
            if not cond <= ACTIVE_SET_COND:
                return None
            rhs = q[I].copy()
            rhs[:, -1] += Mfixed[I]
            z[I] = -lu_solve(lu_factor(MII), rhs)
        xn = self._xfree + self.sm.G @ z
        wl = M @ z + q
        wo = self.sys.C @ xn + self.sys.D @ z + self._V
        if I.size:   # the identity w_I ≡ 0, coefficient by coefficient, against the terms it sums
            size = np.abs(M[I]) @ np.abs(z) + np.abs(q[I])
            if np.any(np.abs(wl[I]) > QP_RTOL * size):
                return None
        prow, pcomp, pnew = [], [], []
        one = np.zeros(N); one[-1] = 1.0
        for i in range(m):
            if s[i] == 0:
                prow.append(wl[i]); pcomp.append(i); pnew.append(1)
            elif s[i] == 2:
                prow.append(-wl[i]); pcomp.append(i); pnew.append(1)
            else:
                prow.append(z[i] - lo[i] * one); pcomp.append(i); pnew.append(0)
                if np.isfinite(hi[i]):
                    prow.append(hi[i] * one - z[i]); pcomp.append(i); pnew.append(2)
        while len(prow) < self.L - n:   # pad with a repeated sign row: one row length for every pattern
            prow.append(prow[0]); pcomp.append(pcomp[0]); pnew.append(pnew[0])
        T = np.vstack([xn, np.array(prow), z, wo])
        const = T[:, -1].copy()
        if not self.exo_v and self.v_const is not None:
            const = const + T[:, 2 * n:2 * n + m] @ self.v_const
        cols = T[:, self._keep]
        if not (np.all(np.isfinite(cols)) and np.all(np.isfinite(const))):
            return None
        L = self.L
        P = slice(n, L)
        p = _Pattern()
        p.s = s.copy()
        p.const, p.oconst = const[:L].copy(), const[L:].copy()
        p.cols = [cols[:L, j].copy() for j in range(cols.shape[1])]
        p.ocols = [cols[L:, j].copy() for j in range(cols.shape[1])]
        p.rows = np.column_stack([const[:L], cols[:L]]).tolist()
        p.coef = np.vstack([const[None], cols.T])          # (1 + ncols, L + 2m): every row, for batches
        p.ra = RTOL * float(np.abs(cols[P, :n]).sum(axis=1).max())
        p.re = RTOL * float(np.abs(cols[P, n:]).sum(axis=1).max(initial=0.0)) if self.ne else 0.0
        p.rb = RTOL * float(np.abs(const[P]).max())
        p.pcomp, p.pnew = np.array(pcomp), np.array(pnew)
        p.loop = None
        if not I.size and not np.any(fixed):
            # z = 0: no solution has a smaller norm, so w ≥ 0 (not strict, as in solve_lcp's q ≥ 0) suffices;
            # ``min > −5e-324`` is ``min ≥ 0`` in doubles
            p.ra = p.re = 0.0
            p.rb = -5e-324
        return p

    # -- one row ---------------------------------------------------------------------------------------
    def try_row(self, p: _Pattern, x: list, e: list, emax: float):
        """The step rows of pattern ``p`` at ``(x, e)`` and whether its sign checks pass: ``(y, accepted)``."""
        y = self.fn(p.rows, *x, *e)
        if self.ne:
            tau = p.ra * max(map(abs, x)) + p.re * emax + p.rb
        else:
            tau = p.ra * max(map(abs, x)) + p.rb
        return y, min(y[self.F:]) > tau and all(map(math.isfinite, y))

    def flipped(self, p: _Pattern, y) -> np.ndarray:
        """The pattern the violated signs of ``p``'s candidate ``y`` point to."""
        s = p.s.copy()
        viol = np.asarray(y[self.F:]) <= 0.0
        s[p.pcomp[viol]] = p.pnew[viol]
        return s

    def all_patterns(self):
        for states in itertools.product(*[range(k) for k in self.nstates]):
            yield np.array(states, dtype=np.int8)

    def enumerated(self) -> list:
        """The maps of every pattern in :meth:`all_patterns`' order (``None`` for one whose map fails), each
        looked up by :meth:`pattern` as a loop over :meth:`all_patterns` does — built on first sight, in the
        same order — with the patterns' keys made once per kernel instead of once per pattern and step (1442
        slow steps of DiodeBridgeCapFilter.ref looked up 46,794 patterns: a third of its unit)."""
        keys = self.__dict__.get("_enum_keys")
        if keys is None:
            keys = self._enum_keys = [(s.tobytes(), s) for s in self.all_patterns()]
        cache = self.cache
        for key, s in keys:
            yield cache[key] if key in cache else self.pattern(s)

    def slow_row(self, pid: int, x: list, e: list, emax: float):
        """A step whose guess ``pid`` failed (``pid < 0``: no guess, start from ``z = 0``): the patterns the
        violated signs point to (at most ``m`` in turn), every pattern when there are few, then the verified
        least-norm solver.

        Returns ``(x_{k+1}, pattern of this step, guess for the next, (z, w) or None)``: ``(z, w)`` only when
        the solver, not a pattern's map, made the step (the pattern is then −1)."""
        if pid >= 0:
            p = self.by_id[pid]
            y, ok = self.try_row(p, x, e, emax)
            s = self.flipped(p, y)
        else:
            s = np.zeros(self.m, dtype=np.int8)
        for _ in range(self.m):   # follow the violated signs (principal pivoting), at most m times
            q2 = self.pattern(s)
            if q2 is None:
                break
            y, ok = self.try_row(q2, x, e, emax)
            if ok:
                return y[:self.F], q2.key, q2.key, None
            s = self.flipped(q2, y)
        if self.enum:
            for p in self.enumerated():
                if p is not None:
                    y, ok = self.try_row(p, x, e, emax)
                    if ok:
                        return y[:self.F], p.key, p.key, None
        # no strictly complementary candidate: a degenerate one that is provably the least-norm solution
        for p in (list(self.enumerated()) if self.enum else
                  [self.by_id[pid]] if pid >= 0 else []):
            if p is not None:
                y, _ = self.try_row(p, x, e, emax)
                if self._least_norm_degenerate(p, y, x, emax):
                    return y[:self.F], p.key, p.key, None
        return self.solve_row(x, e)

    def _least_norm_degenerate(self, p: _Pattern, y: list, x: list, emax: float) -> bool:
        """Whether ``p``'s candidate, a solution whose sign rows are ``≥ −(QP_RTOL/RTOL)τ`` but some ``≤ τ`` (the
        *degenerate* components ``Dg``: ``z_i ≈ 0 ≈ w_i``), is the least-norm solution (complementarity only).

        ``SOL(q, M)`` is convex and, near the candidate ``z_c``, the union of the pieces
        ``P_γ = {z_γ̄ = 0, z_γ ≥ 0, w_γ = 0, w_γ̄ ≥ 0}`` with ``Z ⊆ γ ⊆ Z ∪ Dg`` (``Z``: ``z_i > τ``), so ``z_c`` is
        least-norm iff ``z_cᵀd ≥ 0`` on each piece's tangent cone: ``{0}`` when ``M_γγ`` is nonsingular; for a
        one-dimensional ``ker M_γγ = span(ν)`` the directions ``±ν`` that keep ``d_i ≥ 0`` (``i ∈ γ ∩ Dg``) and
        ``(Md)_i ≥ 0`` (``i ∈ Dg`` outside ``γ``).  Larger kernels are left to the solver."""
        if not self.is_lcp or not all(map(math.isfinite, y)):
            return False
        n, m = self.n, self.m
        tau = (p.ra * max(map(abs, x)) + p.re * emax + p.rb) if self.ne else (p.ra * max(map(abs, x)) + p.rb)
        tol = (QP_RTOL / RTOL) * tau
        P = np.array(y[n:n + m])
        if tau <= 0.0 or P.min() <= -tol:
            return False
        deg = P <= tau
        if not deg.any():
            return False
        key = (p.key, deg.tobytes())
        cert = self._deg.get(key, False)
        if cert is False:
            cert = self._deg[key] = self._degenerate_certificate(p.s, deg)
        if cert is None:
            return False
        z = np.where(p.s == 1, P, 0.0)
        return all(sg * float(nu @ z) >= -tol * float(np.abs(nu).sum()) for sg, nu in cert)

    def _degenerate_certificate(self, s: np.ndarray, deg: np.ndarray):
        """The directions ``(σ, ν)`` of :meth:`_least_norm_degenerate` for pattern ``s`` and degenerate set
        ``deg``, or None when some piece's ``M_γγ`` has a kernel of dimension ≥ 2 or an undecided rank."""
        M = self.M
        Zs = np.flatnonzero((s == 1) & ~deg)
        Dg = np.flatnonzero(deg)
        out = []
        big = float(np.abs(M).max()) or 1.0
        for r in range(Dg.size + 1):
            for S in itertools.combinations(Dg.tolist(), r):
                g = np.sort(np.concatenate([Zs, np.array(S, dtype=int)])).astype(int)
                if not g.size:
                    continue
                U, sv, Vt = np.linalg.svd(M[np.ix_(g, g)])
                zero = sv <= RTOL * big
                if np.any(~zero & (sv < sv[0] / ACTIVE_SET_COND)):
                    return None   # an undecided rank
                if zero.sum() == 0:
                    continue
                if zero.sum() > 1:
                    return None
                nu = np.zeros(self.m)
                nu[g] = Vt[-1] / np.abs(Vt[-1]).max()
                Mnu = M @ nu
                inside = [i for i in Dg.tolist() if i in set(g.tolist())]
                outside = [i for i in Dg.tolist() if i not in set(g.tolist())]
                small = RTOL * (1.0 + float(np.abs(Mnu).max()))
                for sg in (1.0, -1.0):
                    if all(sg * nu[i] >= -small for i in inside) and all(sg * Mnu[i] >= -small for i in outside):
                        out.append((sg, nu))
        return out

    def solve_row(self, x: list, e: list):
        """Today's arithmetic: ``x_free``, ``q``, the relation's verified least-norm solve, the update."""
        n, m, sm, sysm = self.n, self.m, self.sm, self.sys
        xk = np.array(x)
        ev = np.array(e)
        xfree = sm.E @ xk
        if self.exo_u:
            xfree = xfree + ev[:n]
        v = ev[self.ne - m:] if self.exo_v else (self.v_const if self.v_const is not None else np.zeros(m))
        xq = xfree if self.g == 1.0 else self.g * xfree + (1.0 - self.g) * xk
        q = sysm.C @ xq + v
        if not (np.all(np.isfinite(xk)) and np.all(np.isfinite(q))):
            raise SolverFailure("the state or the one-step data are not finite (overflow)")
        r = sysm.relation.solve(self.M, q, sysm.q_scale(xq, v))
        z = r.z
        xn = xfree + sm.G @ z
        wo = sysm.C @ xn + sysm.D @ z + v
        if not (np.all(np.isfinite(xn)) and np.all(np.isfinite(z)) and np.all(np.isfinite(wo))):
            raise SolverFailure("the step produced non-finite values (overflow)")
        tau = RTOL * lcp_scale(self.M, q, z)
        s = np.where(z - self.lo <= tau, 0, np.where(self.hi - z <= tau, 2, 1)).astype(np.int8)
        p = self.pattern(s)
        return xn.tolist(), -1, (p.key if p is not None else -1), (z, wo)

    # -- runs ------------------------------------------------------------------------------------------
    def run(self, x0: np.ndarray, E: np.ndarray | None, t: np.ndarray):
        """One trajectory: ``x (K+1, n)``, ``z``, ``w`` ``(K, m)``; errors name the step.  The steps of one
        pattern run in that pattern's generated loop (:func:`_loop_fn`), the others in :meth:`slow_row`."""
        K = t.size - 1
        n = self.n
        x = x0.tolist()
        El = E.tolist() if E is not None else None
        emax = np.abs(E).max(axis=1).tolist() if E is not None and self.ne else None
        empty: list = []
        pid = -1
        xs = array("d", x)
        segs = []          # (first step, pattern) of every run of steps with one pattern
        explicit = {}
        by_id, ne, L = self.by_id, self.ne, self.L
        k = 0
        while k < K:
            if pid >= 0:
                p = by_id[pid]
                if p.loop is None:
                    p.loop = _loop_fn(p, n, ne, L)
                k1, x = p.loop(x, k, K, El, emax, xs, pid)
                if k1 > k:
                    segs.append((k, pid))
                    k = k1
                    if k >= K:
                        break
            e = El[k] if El is not None else empty
            em = emax[k] if emax is not None else 0.0
            try:
                x, this, pid, zw = self.slow_row(pid, x, e, em)
            except (InfeasibleStep, SolverFailure, InvalidProblem) as exc:
                raise type(exc)(f"step {k} (t = {t[k]:.6g} → {t[k + 1]:.6g}): {exc}") from exc
            if zw is not None:
                explicit[k] = zw
            xs.extend(x)
            segs.append((k, this))
            k += 1
        X = np.frombuffer(xs, dtype=float).reshape(K + 1, n).copy()
        starts = [a for a, _ in segs] + [K]
        PID = np.repeat(np.array([b for _, b in segs], dtype=np.int64), np.diff(starts)) if segs else \
            np.empty(0, dtype=np.int64)
        Z, W = self.outputs(X, PID, E, explicit)
        return X, Z, W

    # -- batches ---------------------------------------------------------------------------------------
    def _stacked(self):
        """Every pattern's coefficients ``(npat + 1, 1 + ncols, L + 2m)`` and margins ``(npat + 1, 3)``; the
        last entry (index −1, "no pattern") is NaN, so its candidates never pass."""
        if getattr(self, "_stack_n", -1) != len(self.by_id):
            nc, Lf = len(self._keep) + 1, self.L + 2 * self.m
            st = np.full((len(self.by_id) + 1, nc, Lf), np.nan)
            mg = np.full((len(self.by_id) + 1, 3), np.nan)
            for p in self.by_id:
                st[p.key] = p.coef
                mg[p.key] = (p.ra, p.re, p.rb)
            self._stack, self._margins, self._stack_n = st, mg, len(self.by_id)
        return self._stack, self._margins

    def _eval_rows(self, pids: np.ndarray, XT: np.ndarray, ET, em):
        """Candidates ``(L + 2m, b)`` (step rows, then output rows) of the patterns ``pids`` at the states ``XT (n, b)`` (exogenous ``ET``:
        ``(ne,)`` shared or ``(ne, b)``) and whether they pass: the multiply-adds of :meth:`try_row`, in the same
        order, elementwise, and its test."""
        st, mg = self._stacked()
        CT = np.ascontiguousarray(st[pids].transpose(1, 2, 0))
        Y = np.empty(CT.shape[1:])
        return Y, self._eval_T(CT, mg[pids].T, XT, ET, em, Y, np.empty_like(Y), np.empty(Y.shape[1]))

    def _eval_T(self, CT, MG, XT, ET, em, Y, T, ax):
        """Into the buffers ``Y``, ``T`` ``(L + 2m, b)`` and ``ax`` ``(b,)``: ``Y = c + a_0 x_0 + … + a_{n−1} x_{n−1}
        + b_0 e_0 + …`` (summed left to right: ``Y = a_0 x_0; Y += c`` is ``c + a_0 x_0``, addition commuting
        exactly), ``τ = ra·max_j |x_j| + re·|e|_∞ + rb``, and the mask of the columns whose sign rows are all
        ``> τ`` and whose rows are all finite (``NaN`` fails every comparison and propagates through min/max)."""
        n, L = self.n, self.L
        np.multiply(CT[1], XT[0], out=Y)
        Y += CT[0]
        for j in range(1, n):
            np.multiply(CT[1 + j], XT[j], out=T)
            Y += T
        for j in range(self.ne):
            np.multiply(CT[1 + n + j], ET[j], out=T)
            Y += T
        np.abs(XT[0], out=ax)
        for j in range(1, n):
            np.maximum(ax, np.abs(XT[j]), out=ax)
        ax *= MG[0]
        if self.ne:
            ax += MG[1] * em
        ax += MG[2]
        ok = Y[n:L].min(axis=0) > ax
        ok &= Y[:L].max(axis=0) < math.inf
        ok &= (Y[:n].min(axis=0) if n > 1 else Y[0]) > -math.inf
        return ok

    def _flip_rows(self, pid: np.ndarray, YP: np.ndarray) -> np.ndarray:
        """:meth:`flipped` for many rows (``YP``: their sign rows, ``(P, b)``): the pattern ids the violated
        signs point to (−1 where that pattern is unusable; the zero pattern for rows without a guess).  Rows
        are grouped by their new pattern (a base-3 code), so :meth:`pattern` runs once per distinct one."""
        out = np.full(pid.size, -1, dtype=np.int64)
        w3 = 3 ** np.arange(self.m, dtype=np.int64)
        for p_id in np.unique(pid).tolist():
            sel = np.flatnonzero(pid == p_id)
            if p_id < 0:
                z = self.pattern(np.zeros(self.m, dtype=np.int8))
                out[sel] = -1 if z is None else z.key
                continue
            p = self.by_id[p_id]
            S = np.broadcast_to(p.s, (sel.size, self.m)).copy()
            viol = YP[:, sel] <= 0.0
            for r in np.flatnonzero(viol.any(axis=1)).tolist():
                S[viol[r], p.pcomp[r]] = p.pnew[r]
            codes, first, inv = np.unique(S.astype(np.int64) @ w3, return_index=True, return_inverse=True)
            ids = np.array([-1 if q is None else q.key for q in (self.pattern(S[i]) for i in first.tolist())],
                           dtype=np.int64)
            out[sel] = ids[inv.reshape(-1)]
        return out

    def run_batch(self, X0: np.ndarray, E: np.ndarray | None, t: np.ndarray):
        """``B`` trajectories: ``(x (K+1, B, n), z, w (K, B, m), failures)``, the arrays transposed views of
        row-major buffers (``x[k]`` is ``XT[k].T``); ``E`` is ``(K, ne)`` shared or ``(K, B, ne)``.  A failed row
        is NaN from its failure on; ``failures`` is the :class:`RowFailure` list.

        Every row keeps its pattern's coefficients in columns of ``CT (1 + ncols, L + 2m, B)``, so a step is a
        few elementwise operations on rows of length ``B`` into preallocated buffers (the output rows ``z``, ``w``
        too: evaluated after the loop, gathering each (step, row)'s coefficients cost more than twice as much).
        A failed guess is followed, for all failed rows at once, by the patterns :meth:`slow_row`
        tries (the flipped one, then every pattern when there are few), then by :meth:`slow_row` row by row: a
        candidate that passes is the unique solution, so the rows get the same bits as single runs."""
        K = t.size - 1
        B = X0.shape[0]
        n, m, L, ne = self.n, self.m, self.L, self.ne
        backend = batch_backend(m, B * K)
        XA = np.empty((K + 1, n, B))
        ZW = np.empty((K, 2 * m, B))
        X = XA.transpose(0, 2, 1)
        Z, W = ZW[:, :m].transpose(0, 2, 1), ZW[:, m:].transpose(0, 2, 1)
        X[0] = X0
        XT = XA[0]
        pid = np.full(B, -1, dtype=np.int64)
        st, mg = self._stacked()
        CT = np.ascontiguousarray(st[pid].transpose(1, 2, 0))
        MG = np.ascontiguousarray(mg[pid].T)
        Yb, Tb, axb = np.empty((L + 2 * m, B)), np.empty((L + 2 * m, B)), np.empty(B)
        alive = np.ones(B, dtype=bool)
        failures: list[RowFailure] = []
        shared = E is not None and E.ndim == 2
        emax = np.abs(E).max(axis=-1) if E is not None and ne else None   # (K,) or (K, B)

        def exo(k, rows):
            if not ne:
                return None, None
            if shared:
                return E[k], emax[k]
            return (E[k].T, emax[k]) if rows is None else (E[k, rows].T, emax[k, rows])

        stepped = np.zeros(B, dtype=bool)   # rows a pattern's map has made this step (after a failed guess)

        def accept(k, rows, Y, ok, newp):
            r = rows[ok]
            if r.size:
                stepped[r] = True
                XA[k + 1][:, r] = Y[:n, ok]
                ZW[k][:, r] = Y[L:, ok]
                newp = newp[ok] if np.ndim(newp) else np.full(r.size, newp)
                pid[r] = newp
                st, mg = self._stacked()
                CT[:, :, r] = st[newp].transpose(1, 2, 0)
                MG[:, r] = mg[newp].T
            return ~ok

        def resolve(k, rows, YP):
            """Rows ``rows`` (live) whose guess failed at step ``k`` (``YP``: their guesses' sign rows): the
            patterns :meth:`slow_row` tries, for all of them at once, then :meth:`slow_row` row by row."""
            stepped[rows] = False
            old = pid[rows].copy()
            XT_old = XA[k]
            XTr = XT_old[:, rows]
            guess = self._flip_rows(old, YP)
            cur, Xc = rows, XTr                  # the rows still following their violated signs
            for _ in range(m):
                live = guess >= 0
                cur, guess, Xc = cur[live], guess[live], Xc[:, live]
                if not cur.size:
                    break
                Er, em = exo(k, cur)
                Y2, ok2 = self._eval_rows(guess, Xc, Er, em)
                keep = accept(k, cur, Y2, ok2, guess)
                cur, Xc = cur[keep], Xc[:, keep]
                guess = self._flip_rows(guess[keep], Y2[n:L][:, keep])
            left = ~stepped[rows]
            rows, old, XTr = rows[left], old[left], XTr[:, left]
            if self.enum and rows.size:
                for s in self.all_patterns():
                    if not rows.size:
                        break
                    p = self.pattern(s)
                    if p is None:
                        continue
                    Er, em = exo(k, rows)
                    Y3, ok3 = self._eval_rows(np.full(rows.size, p.key), XTr, Er, em)
                    keep = accept(k, rows, Y3, ok3, p.key)
                    rows, old, XTr = rows[keep], old[keep], XTr[:, keep]
            for i, o in zip(rows.tolist(), old.tolist()):
                x = XT_old[:, i].tolist()
                if ne:
                    e = (E[k] if shared else E[k, i]).tolist()
                    emi = float(emax[k] if shared else emax[k, i])
                else:
                    e, emi = [], 0.0
                try:
                    xn, this, nxt, zw = self.slow_row(o, x, e, emi)
                except (InfeasibleStep, SolverFailure, InvalidProblem) as exc:
                    err = type(exc)(f"step {k} (t = {t[k]:.6g} → {t[k + 1]:.6g}): {exc}")
                    err.__cause__ = exc
                    failures.append(RowFailure(i, k, float(t[k]), err))
                    alive[i] = False
                    nxt = -1
                    XA[k + 1:, :, i] = np.nan
                    ZW[k:, :, i] = np.nan
                else:
                    XA[k + 1, :, i] = xn
                    if zw is None:   # a pattern's map made the step: its output rows, as a single run has them
                        Er, em = exo(k, np.array([i]))
                        Y4, _ = self._eval_rows(np.array([this]), XT_old[:, i:i + 1], Er, em)
                        ZW[k, :, i] = Y4[L:, 0]
                    else:
                        ZW[k, :m, i], ZW[k, m:, i] = zw
                pid[i] = nxt
                st, mg = self._stacked()
                CT[:, :, i] = st[nxt]
                MG[:, i] = mg[nxt]

        nb = _numba_advance() if backend == "numba" else None
        if nb is not None:
            nb = nb(n, L, L + 2 * m, ne)
        self.last_backend = "numba" if nb is not None else "numpy"
        firstbad = None
        if nb is not None:
            firstbad = self._run_numba(nb, K, B, XA, ZW, pid, alive, E, emax, shared, resolve, exo)
        else:
            for k in range(K):
                ok = self._eval_T(CT, MG, XT, *exo(k, None), Yb, Tb, axb)
                XA[k + 1] = Yb[:n]
                ZW[k] = Yb[L:]
                XT = XA[k + 1]
                if ok.all():
                    continue
                rows = np.flatnonzero(~ok & alive)
                if not rows.size:
                    continue
                resolve(k, rows, Yb[n:L][:, rows])
                if not alive.any():
                    break
        # a finite state with a non-finite multiplier or output (overflow in the output rows only): the first such
        # step of each live row (the compiled kernel tracks it as it writes them: this pass cost 12-21 ns per
        # trajectory-step)
        if firstbad is None:
            bad = ~np.isfinite(ZW).all(axis=1)
            bad[:, ~alive] = False
            badrows = [(i, int(np.flatnonzero(bad[:, i])[0])) for i in np.flatnonzero(bad.any(axis=0)).tolist()]
        else:
            badrows = [(i, int(firstbad[i])) for i in np.flatnonzero((firstbad < K) & alive).tolist()]
        for i, k in badrows:
            failures.append(RowFailure(i, k, float(t[k]), SolverFailure(
                f"step {k} (t = {t[k]:.6g} → {t[k + 1]:.6g}): the multiplier or output is not finite (overflow)")))
            XA[k + 1:, :, i] = np.nan
            ZW[k:, :, i] = np.nan
        failures.sort(key=lambda f: f.row)
        return X, Z, W, failures

    def _nb_tables(self):
        """The compiled kernel's view of the patterns built so far: ``(stack, margins, table, pstate, pcomp,
        pnew)`` (see :mod:`verimono.lcs._batch_numba`), rebuilt when a pattern was added."""
        key = (len(self.by_id), len(self.cache))
        if getattr(self, "_nb_key", None) != key:
            st, mg = self._stacked()
            m, P = self.m, self.L - self.n
            w3 = 3 ** np.arange(m, dtype=np.int64)
            table = np.full(3 ** m, -2, dtype=np.int64)
            for k, p in list(self.cache.items()):
                table[int(np.frombuffer(k, dtype=np.int8).astype(np.int64) @ w3)] = -1 if p is None else p.key
            npat = max(len(self.by_id), 1)
            pstate = np.zeros((npat, m), dtype=np.int64)
            pcomp = np.zeros((npat, P), dtype=np.int64)
            pnew = np.zeros((npat, P), dtype=np.int64)
            for p in self.by_id:
                pstate[p.key], pcomp[p.key], pnew[p.key] = p.s, p.pcomp, p.pnew
            self._nb = (np.ascontiguousarray(st), np.ascontiguousarray(mg), table, pstate, pcomp, pnew)
            self._nb_key = key
        return self._nb

    def _run_numba(self, advance, K, B, XA, ZW, pid, alive, E, emax, shared, resolve, exo):
        """:meth:`run_batch`'s loop through the compiled kernel: it makes every step it can, and returns the
        step where rows need Python's :meth:`slow_row` path (``resolve``), which runs before it resumes.
        Returns each row's first step with a non-finite multiplier or output (``K`` when none)."""
        n, m, L, ne = self.n, self.m, self.L, self.ne
        w3 = 3 ** np.arange(m, dtype=np.int64)
        if not hasattr(self, "_enum_codes"):
            self._enum_codes = np.array([int(s.astype(np.int64) @ w3) for s in self.all_patterns()] if self.enum
                                        else [], dtype=np.int64)
        if ne:
            E3 = np.ascontiguousarray(E[:, None, :] if shared else E, dtype=float)
            EM = np.ascontiguousarray(emax[:, None] if shared else emax, dtype=float)
        else:
            E3, EM = np.zeros((1, 1, 1)), np.zeros((1, 1))
        need = np.zeros(B, dtype=np.bool_)
        y = np.empty(L + 2 * m)
        badk = np.full(B, K, dtype=np.int64)
        k = 0
        while k < K:
            st, mg, table, pstate, pcomp, pnew = self._nb_tables()
            k = advance(st, mg, table, self._enum_codes, pstate, pcomp, pnew, w3, pid, alive, XA, ZW, E3, EM,
                        bool(shared), k, K, n, L, ne, m, need, y, badk)
            if k >= K:
                break
            rows = np.flatnonzero(need)
            need[rows] = False
            Er, em = exo(k, rows)
            Y0, _ = self._eval_rows(pid[rows], XA[k][:, rows], Er, em)
            resolve(k, rows, Y0[n:L])
            bad = rows[~np.isfinite(ZW[k][:, rows]).all(axis=0)]      # the steps Python made
            badk[bad] = np.minimum(badk[bad], k)
            if not alive.any():
                break
            k += 1
        return badk

    def _out_rows(self, p: _Pattern, Xk: np.ndarray, Ek: np.ndarray | None) -> np.ndarray:
        """``(z, w)`` rows ``(N, 2m)`` of pattern ``p`` at the states ``Xk (N, n)`` and exogenous terms ``Ek``
        ``(N, ne)``: elementwise, so a step's outputs do not depend on which other steps are evaluated with it
        (a batch and a single run agree bit for bit)."""
        Y = p.oconst + p.ocols[0] * Xk[:, 0:1]
        for j in range(1, self.n):
            Y = Y + p.ocols[j] * Xk[:, j:j + 1]
        for j in range(self.ne):
            Y = Y + p.ocols[self.n + j] * Ek[:, j:j + 1]
        return Y

    def outputs(self, X: np.ndarray, PID: np.ndarray, E: np.ndarray | None, explicit: dict):
        """``z``, ``w`` ``(K, m)`` of a single run: each run of steps with one pattern through its output rows
        (the multiply-adds of the batch, elementwise), the solver's where it made the step."""
        K = PID.size
        m, ne = self.m, self.ne
        Z = np.empty((K, m))
        W = np.empty((K, m))
        cuts = np.concatenate([[0], np.flatnonzero(PID[1:] != PID[:-1]) + 1, [K]]).tolist()
        for a, b in zip(cuts[:-1], cuts[1:]):
            p_id = int(PID[a])
            if p_id < 0:
                continue
            Y = self._out_rows(self.by_id[p_id], X[a:b], None if not ne else E[a:b])
            Z[a:b], W[a:b] = Y[:, :m], Y[:, m:]
        for k, (z, w) in explicit.items():
            Z[k], W[k] = z, w
        if not (np.all(np.isfinite(Z)) and np.all(np.isfinite(W))):
            k = int(np.flatnonzero(~(np.isfinite(Z).all(axis=1) & np.isfinite(W).all(axis=1)))[0])
            raise SolverFailure(f"step {k}: the multiplier or output is not finite (overflow)")
        return Z, W


__all__ = ["StepKernel", "BatchStepError", "RowFailure", "ENUM_PATTERNS", "BATCH_KERNEL", "NUMBA_MAX_M", "NUMBA_MIN_WORK",
           "batch_backend"]
