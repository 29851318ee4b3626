"""Value laws: what ``prox_{λg}`` must satisfy *for the given* ``g`` (operators providing ``value``).

For a proper closed convex ``g``, ``p = J_λx = prox_{λg}(x)`` is the unique minimiser of the 1-strongly
convex ``Φ(z) = λg(z) + |z - x|²/2``, characterised by the prox inequality

    ⟨x - p, z - p⟩ ≤ λ (g(z) - g(p))   for every z          (⟺ Φ(p) + |z - p|²/2 ≤ Φ(z)),

equivalently ``(x - p)/λ ∈ ∂g(p)`` (the subgradient inequality, tested by the value-based ``contains`` of
:func:`verimono.core.prox.subgradient_contains`, through ``yosida_in_graph``).  The resolvent laws hold for the
prox of *any* convex function; these laws tie it to the stated ``g`` and catch the exact prox of a wrong
one (a wrong weight, another norm's formula, a degenerate functional).  The Moreau envelope
``e_λ(x) = g(p) + |x - p|²/(2λ)`` is convex and differentiable with the ``1/λ``-Lipschitz gradient
``Y_λx = (x - p)/λ``, hence two-sided bounds between any two points.

Each law is a decorated evaluator ``check_<law>(op, s) -> Outcome`` (``s`` a
:class:`verimono.checks.engine.samples.Sample`) whose ratio is the violation in units of its slack
(``(lhs - rhs)/slack``), so a negative or small ratio holds; it needs the operator's ``value`` (``g``), and
is skipped before it runs on an operator that does not state it.  Slacks: ``τ = tolerance(x, p, z)`` per point (the resolvent's accuracy,
:mod:`verimono.core.tolerances`), propagated through each side, plus ``tolerance`` of the function values.
"""

from __future__ import annotations

import functools
import math
import sys
import zlib

import numpy as np

from ..core.arrays import as_float64
from ..core._rows import dot_rows
from ..core._small import abs_max
from ..core.tolerances import current_data_scale, current_eps, current_precision, current_rtol, tolerance
from .core import Member, Outcome, ratio as _ratio
from ._powell import powell
from ..core.errors import NotApplicable
from .members import ROUNDOFF_ULPS, outside_by_roundoff_of_dom_g
from .members import listed, norm as _nrm
from .members import resolvent as _J
from .members import value as _g
from .engine.batches import rounding, row_dots, row_norms, row_ratios, row_resolvents, row_values, vectorised
from .engine.search import operator_law
from ..core.tolerances import row_tolerances
from ..execution.profiles import LARGE_N
from ..execution.timeouts import interrupted

#: the independent minimiser (scipy.optimize, derivative-free Powell) runs only on R^n with n ≤ this
MINIMISER_MAX_DIM = 4
#: relative perturbation sizes of the optimality law, times 1 + |p|_∞
PERTURBATIONS = (1e-4, 1e-2, 1.0)
#: above this many coordinates the optimality law reads ``|z - x|²`` of its perturbation ``z = p + c·d`` as
#: ``|x - p|² - 2c⟨x - p, d⟩ + c²|d|²`` (two dots per direction, none per perturbation: at n = 10^6 the
#: subtraction and dot were a third of the law's work).  Its rounding beyond the direct sum's, that of three
#: dots — at most ``~n·eps·(|x - p| + |c|)²``, in practice ``~√n·eps`` times that — is set against a slack of at
#: least ``0.8·RTOL·(|x - p| + |c|)²`` (``4·tolerance(Φ)``, ``Φ(p) ≥ |x - p|²/4`` or ``|λg(p)| ≥ |x - p|²/4``, and
#: ``4τ|δ| ≥ 4·RTOL·c²``): a ratio moved by ``~1e-5`` at n = 10^6 (``0.1`` in the worst case of rounding).  At or
#: below it the arithmetic is the direct one, and records there do not move.
EXPANDED_N = LARGE_N


def _tolf(*values: float) -> float:
    """:func:`verimono.core.tolerances.tolerance` of scalars, in Python floats (called per perturbation), at the
    precision under judgement."""
    return current_rtol() * (1.0 + max(abs(v) for v in values))


_VALUE = Member("value")


def _amax(v: np.ndarray) -> float:
    """``max |v_i|`` (0 for an empty point), as :func:`verimono.core.tolerances.tolerance` reads each array: above
    4096 entries ``max(max v, -min v)`` (no ``|v|`` copy), the same number."""
    if not v.size:
        return 0.0
    if v.size > 4096 and v.dtype.kind == "f":
        return float(max(v.max(), -v.min()))
    return abs_max(v)


def _tol(rtol: float, *maxima: float) -> float:
    """:func:`verimono.core.tolerances.tolerance` of arrays whose maxima (:func:`_amax`) are known: the same loop
    (a NaN maximum is passed over there too), so the same number without reading the arrays again."""
    m = current_data_scale()            # the operator's own scale under judgement: one more magnitude, as there
    for a in maxima:
        if a > m:
            m = a
    return rtol * (1.0 + m)


def _owned_value(op, z: np.ndarray, t: float) -> float:
    """``g(t, z)`` as :func:`verimono.checks.members.value` reads it, for a float64 point ``z`` made for this one
    call and read by nothing after it (no protective copy: at n = 10^6 that copy was a quarter of the optimality
    law's time)."""
    v = op.value(z, t)
    if type(v) is not float:
        v = as_float64(v)
    return float(v)


class _Scratch:
    """One n-vector handed to ``g`` per perturbation, written whole before each call and reused while ``g`` keeps
    no reference to it.

    A fresh n-vector per perturbation was 42 allocations of 8 MB per sample at n = 10^6, each freed to the system
    and faulted in again page by page (a fifth of the battery's CPU was the kernel's).  A ``g`` that writes into
    its argument changes nothing: every entry is written again before the next call.  A ``g`` that keeps its
    argument (a memo of the last point, a view of it) raises its reference count: the buffer is then left to it and
    the next perturbation gets a fresh one, as before."""

    __slots__ = ("like", "buf", "refs")

    def __init__(self, like: np.ndarray) -> None:
        self.like, self.buf, self.refs = like, None, 0

    def take(self) -> np.ndarray:
        """The buffer to write the next point into (``empty_like`` the sample's ``p``: its layout, as a fresh result
        of ``np.add(p, ·)`` has)."""
        if self.buf is None:
            self.buf = np.empty_like(self.like)
        return self.buf

    def value(self, op, z: np.ndarray, t: float) -> float:
        """``g(t, z)`` for ``z`` the buffer (:func:`_owned_value`), the buffer given up if ``g`` kept it."""
        refs = sys.getrefcount(z)
        try:
            return _owned_value(op, z, t)
        finally:
            if sys.getrefcount(z) != refs:
                self.buf = None


def _outside(op, p, gp, what, x, t) -> Outcome:
    """The outcome of a law whose ``p = J_λx`` the user's value function puts outside ``dom g`` (``g(p) = ∞``):
    no sample (:class:`NotApplicable`: inconclusive) when ``g`` is finite within the round-off of ``J`` at that
    point (:func:`verimono.checks.members.outside_by_roundoff_of_dom_g`); otherwise
    a failure (the prox of ``g`` lies in ``dom g``) that says the value function said so, and gives the
    round-off of ``J`` at that point, ``eps·(1 + |x|)`` with ``eps`` the unit round-off of the precision under
    judgement — a float32 projection from ``|x| = 1e3`` may leave its set by up to about ``eps·|x| ≈ 1e-4``,
    which a strict indicator (``inf`` for any point outside) rejects although ``J`` is exact to its precision."""
    tau = current_eps() * (1.0 + max(_nrm(x), _nrm(p)))
    prec = current_precision().name
    if outside_by_roundoff_of_dom_g(op, p, t, max(_nrm(x), _nrm(p)), x - p):
        raise NotApplicable(f"{what}: g(p) = {gp} at p = J_λx only by round-off (g is finite within "
                            f"{ROUNDOFF_ULPS[-1]:g} x eps·|x| = {ROUNDOFF_ULPS[-1] * tau:.3g} of p, {prec})")
    return Outcome.compare(math.inf, 0.0, 1.0,
                           f"{what}: the value function says p = J_λx lies outside dom g (g(p) = {gp}); J's "
                           f"round-off at this point is about eps·|x| = {tau:.3g} ({prec}, |x| = {_nrm(x):.3g}): a value function "
                           "that rejects every point outside its set (a strict indicator) also rejects a J that "
                           "leaves it by round-off; give it that tolerance if J is exact to its precision",
                           {"p": listed(p), "g(p)": gp, "outside_dom_g": "the value function says so",
                            "resolvent_roundoff": tau, "precision": prec})


def _directions(x, p, n, seed_like, xp=None, nxp=None) -> list:
    """Unit directions: the coordinates, ``x - p``, ``p`` and seeded random ones (deterministic in the sample).
    A coordinate direction ``e_i`` is given as its index ``i`` (the optimality law perturbs one entry of ``p``;
    :func:`_unit` makes the vector when a counterexample needs it); ``xp = x - p`` and its norm when known."""
    dirs: list = list(range(min(n, 3)))    # e_i without the n x n identity (3.2 GB at n = 20000), nor n zeros each
    for v, nv in ((x - p if xp is None else xp, nxp), (p, None)):
        nv = _nrm(v) if nv is None else nv
        if nv > 0:
            dirs.append(v / nv)
    rng = np.random.default_rng(zlib.crc32(np.ascontiguousarray(seed_like, dtype=float)))   # its bytes, uncopied
    for _ in range(2):
        v = rng.standard_normal(n)
        dirs.append(v / _nrm(v))
    return dirs


#: the most coordinates (perturbations × n) of one sample's perturbations evaluated as a block (:func:`_perturbed_values`);
#: above it (n > ~1500) the loop of :func:`check_prox_optimal` evaluates them one by one, as before
BLOCK_CELLS = 1 << 16


def _perturbed_values(op, x, p, dirs, s0, t):
    """The optimality law's perturbations ``z = p ± h·s0·d`` (``d`` in ``dirs``, ``h`` in :data:`PERTURBATIONS`, ``+``
    then ``-``, in :func:`check_prox_optimal`'s order) as rows of one block: ``(g(t, z), |z - x|²)`` as two arrays
    ``(B,)``, when the operator's class states ``value`` of a block of rows (``_value_rows``, bit-identical to its
    calls per row, as the catalog's :class:`~verimono.core.operators.NormSubdifferential` and
    :class:`~verimono.core.operators.L1Subdifferential` declare; looked up on the class, so an input-form wrapper
    declines); else ``None`` (also when the block call raised or answered no ``(B,)`` array: the calls per row then
    meet it, one by one).

    The same numbers as the loop's: a coordinate perturbation is ``p + 0.0`` (``+``) or ``p`` (``-``) with entry ``i``
    set to ``p_i + c``, another ``p ± (d·h·s0)`` (one product for both signs), elementwise as there; ``|z - x|²`` the
    BLAS dot of each row (:func:`verimono.core.operators.dot_rows`), which is the loop's ``w @ w`` (for a coordinate
    it dots ``x - p`` with entry ``i`` patched: the same squares), taken before ``g`` sees the block."""
    rows = getattr(type(op), "_value_rows", None)
    if rows is None or x.ndim != 1 or p.dtype != np.float64:
        return None
    n, k = x.size, len(dirs)
    dzs = np.array([h * s0 for h in PERTURBATIONS])
    Z = np.empty((k, len(PERTURBATIONS), 2, n))
    nc = 0                  # the coordinate directions come first (:func:`_directions`): slices, not index lists
    while nc < k and type(dirs[nc]) is int:
        nc += 1
    if any(type(d) is int for d in dirs[nc:]):
        return None
    if nc:
        Z[:nc, :, 0, :] = p + 0.0
        Z[:nc, :, 1, :] = p
        C = np.array([(1.0 * h * s0, -1.0 * h * s0) for h in PERTURBATIONS])     # the loop's c = sgn·h·s0
        for i in range(nc):
            Z[i, :, :, dirs[i]] = p[dirs[i]] + C
    if nc < k:
        CD = np.array(dirs[nc:])[:, None, :] * dzs[None, :, None]
        np.add(p, CD, out=Z[nc:, :, 0, :])
        np.subtract(p, CD, out=Z[nc:, :, 1, :])
    Z = Z.reshape(k * 2 * len(PERTURBATIONS), n)
    W = Z - x
    Q = dot_rows(W, W)
    try:
        G = rows(op, Z, t)
    except Exception:   # noqa: BLE001 - the calls per row meet it, one by one
        if interrupted():
            raise
        return None
    if type(G) is not np.ndarray or G.dtype != np.float64 or G.shape != (Z.shape[0],):
        return None
    return G, Q


def _unit(i: int, n: int) -> np.ndarray:
    """The coordinate direction ``e_i`` of ``R^n``."""
    e = np.zeros(n)
    e[i] = 1.0
    return e


def _at_prox_point(what):
    """A value law evaluated at ``p = J_λ(x1)``: ``body(op, s, p, g(p))``, or the outcome recording
    ``p ∉ dom g`` (for ``what``) when ``g(p) = ∞``."""
    def decorate(body):
        @functools.wraps(body)
        def evaluate(op, s):
            p = _J(op, s.x1, s.lam, s.t)
            gp = _g(op, p, s.t)
            return body(op, s, p, gp) if math.isfinite(gp) else _outside(op, p, gp, what, s.x1, s.t)
        return evaluate
    return decorate


@operator_law("prox_inequality", "prox inequality", _VALUE)
@_at_prox_point("prox inequality")
def check_prox_inequality(op, s, p, gp):
    """The prox inequality ``⟨x - p, z - p⟩ ≤ λ(g(z) - g(p))`` for ``p = J_λx`` and ``z`` among ``x2``,
    ``x1``, ``0`` and other resolvent values."""
    x, lam, t = s.x1, s.lam, s.t
    cands = [("x2", s.x2), ("x1", x), ("0", np.zeros_like(x))]
    for k, (lab, v) in enumerate((("J_μ x2", s.x2), ("J_μ x1", x), ("J_ν x2", s.x2))):
        try:
            cands.append((lab, _J(op, v, s.mu if k < 2 else s.nu, t)))
        except Exception:   # noqa: BLE001 - other resolvent values are only extra test points
            pass
    # per sample, once: x - p, its norm, |x|_inf and |p|_inf; per candidate: z - p, one dot, one norm, one g(z),
    # the numbers of tolerance(x, p, z) and of the outcome exactly as before; the outcome (and its counterexample,
    # the points as listed(): a summary above NUMPY_DIM coordinates) is built for the worst candidate only
    rtol = current_rtol()
    xp = x - p
    nxp, ax, ap = _nrm(xp), _amax(x), _amax(p)
    worst = None
    for lab, z in cands:
        gz = _g(op, z, t)
        if gz == math.inf:
            continue
        tau = _tol(rtol, ax, ap, ax if z is x else _amax(z))
        zp, nzp = (xp, nxp) if z is x else (z - p, None)     # z = x: z - p is x - p, the same numbers
        lhs = float(xp @ zp)
        rhs = lam * (gz - gp)
        slack = 4 * tau * (nxp + (_nrm(zp) if nzp is None else nzp) + tau) + 4 * lam * tolerance(gp, gz)
        q = _ratio(lhs - rhs, 0.0, slack)
        if worst is None or not q <= worst[0]:
            worst = (q, lab, z, gz, lhs - rhs, slack)
    if worst is None:       # g(z) = +∞ at every candidate: the inequality holds there trivially, nothing was tested
        return Outcome.inconclusive_sample("no candidate z with g(z) < ∞ (x1, x2, 0 and the resolvent values other "
                                           "than p): the prox inequality tested nothing at this sample")
    _, lab, z, gz, lhs, slack = worst
    return Outcome.compare(lhs, 0.0, slack, "⟨x - p, z - p⟩ ≤ λ(g(z) - g(p)) for p = prox_{λg}(x), z = " + lab,
                           {"p": listed(p), "z": listed(z), "z_is": lab, "g(p)": gp, "g(z)": gz})


@vectorised("prox_inequality")
def _rows_prox_inequality(op, r):
    """The prox inequality over rows (:mod:`verimono.checks.engine.batches`): the law's six candidates, every value
    one call per row; a row where a resolvent or a value failed or is not finite (``p`` or a candidate outside
    ``dom g``) goes to the law's evaluator, the others take the worst candidate's ratio, within the rounding bound
    of the dot product ``⟨x - p, z - p⟩`` (the values themselves are the same calls)."""
    x, lam, t = r.x1, r.lam, r.t
    p = row_resolvents(op, x, lam, t, r.ok)
    gp = row_values(op, p, t, r.ok)
    cands = [r.x2, x, np.zeros_like(x), row_resolvents(op, r.x2, r.mu, t, r.ok), row_resolvents(op, x, r.mu, t, r.ok),
             row_resolvents(op, r.x2, r.nu, t, r.ok)]
    worst, err = np.full(len(r.ok), -np.inf), np.zeros(len(r.ok))
    for z in cands:
        gz = row_values(op, z, t, r.ok)
        tau = row_tolerances(x, p, z)
        nxp, nzp = row_norms(x - p), row_norms(z - p)
        lhs = row_dots(x - p, z - p)
        rhs = lam * (gz - gp)
        slack = 4 * tau * (nxp + nzp + tau) + 4 * lam * row_tolerances(gp, gz)
        q = row_ratios(lhs - rhs, np.zeros_like(lhs), slack)
        err = np.maximum(err, rounding(r, q, slack, nxp * nzp))
        worst = np.where(np.isnan(q) | (q > worst), q, worst)
    r.err = err
    return worst


def _phi(op, z, x, lam, t):
    return lam * _g(op, z, t) + 0.5 * float((z - x) @ (z - x))


@operator_law("prox_optimal", "prox optimality (perturbations)", _VALUE)
@_at_prox_point("optimality")
def check_prox_optimal(op, s, p, gp):
    """The prox optimality (perturbations): ``p = J_λx`` minimises ``Φ(z) = λg(z) + |z - x|²/2``, 1-strongly:
    ``Φ(p) + |δ|²/2 ≤ Φ(p + δ)`` for perturbations ``δ`` along coordinates, ``x - p``, ``p`` and seeded
    directions."""
    x, lam, t = s.x1, s.lam, s.t
    # x - p once: (p - x) @ (p - x) is the same number (p - x = -(x - p) exactly, and the same squares)
    xp = x - p
    a2 = float(xp @ xp)
    fp = lam * gp + 0.5 * a2
    ap = _amax(p)
    s0 = 1.0 + ap
    rtol = current_rtol()
    tau, dxp = _tol(rtol, _amax(x), ap), _nrm(xp)      # tolerance(x, p), |p|_inf read once
    # _tolf(fp, fz, λg(p)) per perturbation with rtol and the two fixed magnitudes read once: the same max of
    # the same three numbers, the same products
    afp, algp = abs(fp), abs(lam * gp)
    # per perturbation: z = p + c·d made once and handed to g uncopied (it is made for that call: the
    # counterexample's z is made again from c and d, the same numbers).  For n <= EXPANDED_N, z - x into one
    # buffer and one dot — the same elementwise operations and BLAS dot as λg(z) + |z - x|²/2 was, without four
    # n-sized temporaries; a coordinate direction e_i changes one entry: z is p (p + 0.0 for the + sign:
    # p + (+0.0)·e_j, signed zeros included) with entry i set, and z - x is x - p negated (the same squares) with
    # entry i set, in a buffer of ours patched and restored — the same numbers, two passes over n where there
    # were eight.  Above EXPANDED_N, |z - x|² = |x - p|² - 2c⟨x - p, d⟩ + c²|d|² from two dots per direction
    # (:data:`EXPANDED_N`: the rounding this moves is far inside the slack)
    dirs = _directions(x, p, x.size, x, xp, dxp)
    block = _perturbed_values(op, x, p, dirs, s0, t) if x.size * len(dirs) * 6 <= BLOCK_CELLS else None
    if block is not None:
        return _optimal_outcome(x, p, fp, _worst_perturbation(block, dirs, lam, s0, fp, afp, algp, rtol, tau, dxp))
    expanded = x.size > EXPANDED_N
    w, cd, wi = np.empty_like(x), np.empty_like(x), None
    scratch = _Scratch(p)                # z, one buffer for the 42 perturbations while g keeps none
    worst, at = -math.inf, None
    for d in dirs:
        coordinate = type(d) is int
        if expanded:
            b, dd = (float(xp[d]), 1.0) if coordinate else (float(xp @ d), float(d @ d))
        elif coordinate and wi is None:
            wi = xp.copy()
        for h in PERTURBATIONS:
            dz = h * s0
            if not coordinate:
                np.multiply(d, dz, out=cd)      # (-c)·d = -(c·d) and p + (-(c·d)) = p - c·d exactly: one product for both signs
            for sgn in (1.0, -1.0):
                c = sgn * h * s0
                z = scratch.take()
                if coordinate:
                    if sgn > 0:
                        np.add(p, 0.0, out=z)
                    else:
                        np.copyto(z, p)
                    z[d] = p[d] + c
                else:
                    (np.add if sgn > 0 else np.subtract)(p, cd, out=z)
                if expanded:
                    q = max(a2 - 2.0 * c * b + c * c * dd, 0.0)
                elif coordinate:
                    wi[d] = z[d] - x[d]
                    q = float(wi @ wi)
                    wi[d] = xp[d]
                else:
                    np.subtract(z, x, out=w)
                    q = float(w @ w)
                fz = lam * scratch.value(op, z, t) + 0.5 * q
                if fz == math.inf:
                    continue
                slack = 4 * (rtol * (1.0 + max(afp, abs(fz), algp))) + 4 * tau * (dxp + dz + tau)
                r = (fp + 0.5 * dz * dz - fz) / slack
                if not r <= worst:
                    worst, at = r, (d, c, fz, slack)
    return _optimal_outcome(x, p, fp, at)


def _worst_perturbation(block, dirs, lam, s0, fp, afp, algp, rtol, tau, dxp):
    """The loop of :func:`check_prox_optimal` over a block's perturbations (:func:`_perturbed_values`):
    ``(d, c, Φ(z), slack)`` of the worst one, or ``None`` when none passed ``not r <= worst`` (every ``Φ(z)`` is
    ``+inf``).  The same IEEE operations in the same order in Python floats (a loop of 42 is cheaper so than NumPy's
    calls on arrays of 42), the parts that depend on ``h`` only (``4τ(|x - p| + dz + τ)`` and ``Φ(p) + dz²/2``) made
    once per ``h``, Python's ``max(a, b, c)`` as its own comparisons (``b > a``, then ``c`` against that)."""
    G, Q = block
    nh = len(PERTURBATIONS)
    dzs = [h * s0 for h in PERTURBATIONS]
    side = [4 * tau * (dxp + dz + tau) for dz in dzs]
    top = [fp + 0.5 * dz * dz for dz in dzs]
    inf = math.inf
    worst, k_at, f_at, s_at = -inf, None, None, None
    k = 0
    for g, q in zip(G.tolist(), Q.tolist()):
        fz = lam * g + 0.5 * q
        if fz != inf:
            m = (k >> 1) % nh
            a = abs(fz)
            mx = a if a > afp else afp
            if algp > mx:
                mx = algp
            slack = 4 * (rtol * (1.0 + mx)) + side[m]
            r = (top[m] - fz) / slack
            if not r <= worst:
                worst, k_at, f_at, s_at = r, k, fz, slack
        k += 1
    if k_at is None:
        return None
    h = PERTURBATIONS[(k_at >> 1) % nh]
    return dirs[k_at // (2 * nh)], (1.0 if k_at % 2 == 0 else -1.0) * h * s0, f_at, s_at


def _optimal_outcome(x, p, fp, at) -> Outcome:
    """The optimality law's outcome at its worst perturbation ``at = (d, c, Φ(z), slack)`` (``None``: every
    perturbation left ``dom g``)."""
    if at is None:
        return Outcome.compare(0.0, 0.0, 1.0, "optimality: every perturbation left dom g (sample inconclusive)", {},
                               inconclusive=True)
    d, c, fz, slack = at
    z = np.multiply(_unit(d, x.size) if type(d) is int else d, c)
    z += p
    dz2 = float((z - p) @ (z - p))
    return Outcome.compare(fp + 0.5 * dz2 - fz, 0.0, slack,
                           "Φ(p) + |z - p|²/2 ≤ Φ(z), Φ(z) = λg(z) + |z - x|²/2, at z = p + δ (perturbation)",
                           {"p": listed(p), "z": listed(z), "Phi(p)": fp, "Phi(z)": fz})


@operator_law("prox_minimiser", "prox optimality (independent minimiser)", _VALUE)
def check_prox_minimiser(op, s):
    """The prox optimality (independent minimiser): ``Φ(p) ≤ Φ(z*)`` for ``z*`` a minimiser of
    ``Φ`` found by scipy's Powell (its arithmetic without its wrappers: :mod:`verimono.checks._powell`) from ``p``
    and ``x`` (from ``p`` alone on ``R^1``: :func:`_starts`; ``n ≤ 4`` only: larger samples are inconclusive)."""
    if s.x1.size > MINIMISER_MAX_DIM:
        return Outcome.compare(0.0, 0.0, 1.0, f"independent minimiser runs only for n ≤ {MINIMISER_MAX_DIM} "
                               "(sample inconclusive)", {}, inconclusive=True)
    return _minimised(op, s)


def _starts(p, x):
    """Powell's start points: ``p`` and ``x``; on ``R^1`` ``p`` alone.  There Powell is a Brent line search along
    the one direction, its bracket grown without bound from the start, and ``Φ`` is strongly convex: from ``p``
    and from ``x`` it minimises the same function of one variable over the whole line, and the two results differ
    by the line search's tolerance only (from ``x`` it cost 1.5–2× the evaluations of the start at ``p``).  On
    ``R^n``, n ≥ 2, a start can stall at a kink of ``g`` (the coordinate directions none of them descending
    while another is), and the start at ``x`` reaches the minimiser by another path: both stay."""
    return (p,) if p.size == 1 else (p, x)


@_at_prox_point("independent minimiser")
def _minimised(op, s, p, gp):

    x, lam, t = s.x1, s.lam, s.t
    n = x.size
    fp = lam * gp + 0.5 * float((p - x) @ (p - x))
    big = 1e300

    def phi(z):
        # λg(z) + |z - x|²/2 as _phi makes it, g read by _owned_value: Powell hands each call a point of its own
        # (scipy's wrapper copies it) and |z - x|² is taken before g sees z, so members.value's protective copy
        # is not needed: the same numbers
        z = np.asarray(z, dtype=float)
        w = z - x
        q = 0.5 * float(w @ w)
        v = lam * _owned_value(op, z, t) + q
        return v if v < big else big
    at = getattr(type(op), "_value_at", None)       # looked up on the class: an input-form wrapper declines
    g_at = at(op, t) if at is not None and x.dtype == np.float64 else None
    if g_at is not None:
        def phi(z):     # noqa: F811 - the catalog's value at t (_value_at: the same numbers as op.value), one call less
            if type(z) is not np.ndarray or z.dtype != np.float64:
                z = np.asarray(z, dtype=float)
            w = z - x
            q = 0.5 * float(w @ w)
            v = lam * g_at(z) + q
            return v if v < big else big
    best, zbest = math.inf, None
    scale = 1.0 + float(np.max(np.abs(x), initial=0.0))
    for z0 in _starts(p, x):
        if phi(z0.copy()) >= big:     # a copy: p and x are read after it
            continue
        # scipy's minimize(phi, z0, method="Powell", options={"xtol": 1e-10·scale, "ftol": 1e-14, "maxfev": 200n})
        # without its wrappers (verimono.checks._powell): the same points evaluated, the same result
        fun, zmin = powell(phi, z0, 1e-10 * scale, 1e-14, 200 * n)
        if fun < best:
            best, zbest = float(fun), np.asarray(zmin, dtype=float)
    if zbest is None:
        return Outcome.compare(0.0, 0.0, 1.0, "independent minimiser: no start point in dom g (sample inconclusive)",
                               {}, inconclusive=True)
    tau = tolerance(x, p)
    slack = 4 * tolerance(fp, best, lam * gp) + 4 * tau * (_nrm(x - p) + tau)
    return Outcome.compare(fp - best, 0.0, slack,
                           "Φ(p) ≤ Φ(z*) for z* an independent minimiser (Powell) of Φ(z) = λg(z) + |z - x|²/2",
                           {"p": p.tolist(), "z_star": zbest.tolist(), "Phi(p)": fp, "Phi(z_star)": best})


@operator_law("moreau_envelope", "Moreau envelope", _VALUE)
def check_moreau_envelope(op, s):
    """The Moreau envelope ``e_λ(x) = g(J_λx) + |x - J_λx|²/(2λ)`` is convex with the ``1/λ``-Lipschitz
    gradient ``Y_λ``: ``e(x1) + ⟨Y_λx1, x2 - x1⟩ ≤ e(x2) ≤ e(x1) + ⟨Y_λx1, x2 - x1⟩ + |x2 - x1|²/(2λ)``."""
    lam, t = s.lam, s.t
    x1, x2 = s.x1, s.x2
    p1, p2 = _J(op, x1, lam, t), _J(op, x2, lam, t)
    g1, g2 = _g(op, p1, t), _g(op, p2, t)
    for x, p, gv in ((x1, p1, g1), (x2, p2, g2)):
        if not math.isfinite(gv):
            return _outside(op, p, gv, "Moreau envelope", x, t)
    d1, d2 = x1 - p1, x2 - p2           # each once (x1 - p1 was made three times)
    e1 = g1 + float(d1 @ d1) / (2 * lam)
    e2 = g2 + float(d2 @ d2) / (2 * lam)
    y1 = d1 / lam
    dx = x2 - x1
    lin = e1 + float(y1 @ dx)
    quad = float(dx @ dx) / (2 * lam)
    tau = tolerance(x1, x2, p1, p2)
    slack = 4 * tolerance(e1, e2, lin, g1, g2) + 4 * tau * (_nrm(y1) + _nrm(dx) / lam + tau / lam) * (1.0 + _nrm(dx))
    info = {"p1": listed(p1), "p2": listed(p2), "e1": e1, "e2": e2, "grad1": listed(y1)}
    low = Outcome.compare(lin - e2, 0.0, slack, "e_λ(x1) + ⟨Y_λx1, x2 - x1⟩ ≤ e_λ(x2) (the envelope "
                          "e_λ(x) = g(J_λx) + |x - J_λx|²/(2λ) is convex with gradient Y_λx)", info)
    high = Outcome.compare(e2 - lin - quad, 0.0, slack, "e_λ(x2) ≤ e_λ(x1) + ⟨Y_λx1, x2 - x1⟩ + |x2 - x1|²/(2λ) "
                           "(the gradient Y_λ of the envelope is 1/λ-Lipschitz)", info)
    return low if not low.ratio <= high.ratio else high


__all__ = ["check_prox_inequality", "check_prox_optimal", "check_prox_minimiser", "check_moreau_envelope",
           "MINIMISER_MAX_DIM", "PERTURBATIONS"]
