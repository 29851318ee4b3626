"""The computations behind the hypotheses of Theorems ``thm: linear case`` and ``e: linear case-comp``
(Section 7): the relative-interior margin of item iii by linear programming, unit vectors of ``Q_D^+`` and
the search for a solution of an LCP shorter than a given one (Proposition ``p:lcp2`` iv).  The laws built
on them are in :mod:`verimono.checks.section7`.
"""

from __future__ import annotations

import numpy as np

from ..core.tolerances import tolerance
from ..core._highs import linprog_highs
from .lcp import is_psd, lcp_residual, sol_polyhedron
from .relations import BoxRelation


def rel_int_margin(system, t: float) -> float | None:
    """``max τ`` of the LP above (``> 0`` iff ``im C ∩ ri(im(𝓜 + D) − v(t)) ≠ ∅``), or None if undecidable."""
    rel = system.relation
    if not isinstance(rel, BoxRelation):
        return None
    lp = _margin_lp(system, rel)
    if lp is None:
        return None
    c, A_ub, head, tail, A_eq, b_eq, lb, ub = lp
    # linprog(method="highs")'s model, options and answer, without its wrapper (:mod:`verimono.core._highs`)
    status, fun, _ = linprog_highs(c, A_ub, np.concatenate([head + system.v(t), tail]), A_eq, b_eq, lb, ub)
    return float(-fun) if status == 0 else float("-inf")


#: the margin LPs made, by their system's data (:func:`_margin_lp`); emptied past :data:`_MARGIN_LPS` entries
_margin_lps: dict = {}
_MARGIN_LPS = 64


def _margin_lp(system, rel) -> tuple | None:
    """Everything of :func:`rel_int_margin`'s LP but ``v(t)``: ``(c, A_ub, D l, the other rows' right-hand sides,
    A_eq, b_eq, lb, ub)`` — the same arrays, made once per system's ``C``, ``D`` and bounds (a search over ``t``
    asks ~500 margins of one system: the rows, ``D ⪰ 0``'s eigenvalues and the loops were half of each
    call's Python) — or ``None`` when ``D`` is not positive semidefinite (undecidable)."""
    n, m = system.n, system.m
    lo, hi = rel.bounds(m)
    C, D = np.asarray(system.C, dtype=float), np.asarray(system.D, dtype=float)
    key = (n, m, C.shape, C.tobytes(), D.shape, D.tobytes(), np.asarray(lo, float).tobytes(),
           np.asarray(hi, float).tobytes())
    got = _margin_lps.get(key)
    if got is not None:
        return got[0]
    if not is_psd(system.D):
        lp = None
    else:
        fin = np.flatnonzero(np.isfinite(hi))
        f = fin.size
        E = np.eye(m)[:, fin]
        # variables y = (x, z, s, τ); rows "expr ≥ τ" written as −expr + τ ≤ 0
        nv = n + m + f + 1
        rows, rhs, eq_rows, eq_rhs = [], [], [], []
        # D z + E s + D l + C x + v ≥ τ
        G = np.hstack([-system.C, -system.D, -E, np.ones((m, 1))])
        rows.append(G)
        head = system.D @ lo          # + v(t), per call
        degenerate = np.zeros(m, bool)
        degenerate[fin] = (hi - lo)[fin] <= 0
        for i in range(m):  # z_i ≥ τ, unless the bound is degenerate (then z_i = 0 is an implicit equality)
            r = np.zeros(nv)
            if degenerate[i]:
                r[n + i] = 1.0; eq_rows.append(r); eq_rhs.append(0.0)
            else:
                r[n + i] = -1.0; r[-1] = 1.0; rows.append(r[None]); rhs.append(np.zeros(1))
        for j, i in enumerate(fin):  # (u − l)_i − z_i ≥ τ and s_j ≥ τ
            if degenerate[i]:
                continue
            r = np.zeros(nv); r[n + i] = 1.0; r[-1] = 1.0
            rows.append(r[None]); rhs.append(np.array([(hi - lo)[i]]))
            r = np.zeros(nv); r[n + m + j] = -1.0; r[-1] = 1.0
            rows.append(r[None]); rhs.append(np.zeros(1))
        c = np.zeros(nv); c[-1] = -1.0
        ub = np.full(nv, np.inf); ub[-1] = 1.0
        lp = (c, np.vstack(rows), head, np.concatenate(rhs) if rhs else np.zeros(0),
              np.vstack(eq_rows) if eq_rows else None, np.array(eq_rhs) if eq_rows else None, np.full(nv, -np.inf), ub)
    if len(_margin_lps) >= _MARGIN_LPS:
        _margin_lps.clear()
    _margin_lps[key] = (lp,)
    return lp


def sample_unit_q(D: np.ndarray, rng) -> np.ndarray:
    """A unit ``q ∈ Q_D^+``: ``q = w₀ − D z₀`` with ``z₀, w₀ ≥ 0`` of random supports, so ``z₀`` is feasible
    (Proposition ``p:lcp2``: feasible ⟺ ``q ∈ Q_D^+``); sparse supports put ``q`` on the boundary of the
    cone with positive probability, where ``SOL(q, D)`` is not a singleton and the selection matters."""
    m = D.shape[0]
    while True:
        z0 = np.abs(rng.normal(size=m)) * (rng.random(m) < 0.5)
        w0 = np.abs(rng.normal(size=m)) * (rng.random(m) < 0.5)
        q = w0 - D @ z0
        nq = float(np.linalg.norm(q))
        if nq > 0:
            return q / nq


def shorter_solution(D, q, z):
    """A solution of ``LCP(q, D)`` shorter than ``z`` by more than ``tolerance(z)``, or None.

    ``z`` is the least-norm point of the convex ``SOL(q, D)`` iff ``zᵀ(y − z) ≥ 0`` for every ``y ∈ SOL``;
    the LP ``min zᵀy`` over ``SOL`` (:func:`verimono.lcs.lcp.sol_polyhedron`) finds a violating ``y``, and
    the segment ``z + τ(y − z)`` its shortest point."""
    G, h, Aeq, beq = sol_polyhedron(D, q, z)
    status, _, y = linprog_highs(z, G, h, Aeq if len(Aeq) else None, beq if len(Aeq) else None,
                                 np.full(q.size, -np.inf), np.full(q.size, np.inf))
    if status != 0:
        return None
    d = y - z
    dd = float(d @ d)
    if dd == 0.0 or z @ d >= 0:
        return None
    p = z + min(1.0, -float(z @ d) / dd) * d
    # y comes from HiGHS, feasible to its ~1e-9 tolerances, not to QP_RTOL: p is accepted as a solution at
    # RTOL, and only a norm drop far beyond what such a perturbation could explain counts
    ok = lcp_residual(D, q, p) <= tolerance(q, D @ p)
    return p if ok and np.linalg.norm(p) < np.linalg.norm(z) - tolerance(z) else None


__all__ = ["rel_int_margin", "sample_unit_q", "shorter_solution"]
