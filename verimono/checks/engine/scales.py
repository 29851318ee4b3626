"""The scale of the points over every decade the input's precision represents: the search's ``|x|`` as a whole.

The draws, the edge samples and the sweep (:mod:`.sweep`) put ``|x|`` between ``10^-9`` and ``10^6`` and the edge
samples put subnormals and tiny numbers *beside* ordinary entries; no phase scales a whole point down into the
subnormal range or up toward overflow.  A subject wrong only there — an overflow-safe norm computed as
``x · (1/max|x_i|)``, whose reciprocal is ``+inf`` when *every* entry is below ``2^-1024`` (blind set 8,
``ball_reciprocal_scale_subnormal``: NaN out) — was met at some seeds only.  So, after the sweep, each law on an operator of at most
``NUMPY_DIM`` (64) coordinates is evaluated on :func:`scale_samples` (the search's ``_search`` runs the phase):

* **the worst sample scaled** — ``x1, x2`` multiplied together so that ``max(|x1|_∞, |x2|_∞)`` runs over every
  ``stride``-th decade of ``[2^-1074, hi]`` (float64's smallest subnormal to :func:`scale_top`), ``stride`` the
  smallest that ``SCALE_SHARE · points`` design points pay at the profile's coordinate budget (ci: every 16th
  decade), with its step sizes and time; the top is lowered by ``min(1, λ, μ, ν)/max(1, λ, μ, ν)`` so that the
  laws' own ``|x|/λ`` and ``(μ/λ)x`` stay representable;
* **whole points of one shape at the landmarks** (:func:`landmarks`: the smallest subnormal, every entry subnormal,
  just below ``1/largest`` — where a reciprocal overflows —, the smallest normal, just below ``sqrt(tiny)`` — where
  a square underflows — and the top), the precision's own landmarks too (a float32 subject's subnormals): ``x1``
  with every entry equal (``v·(1, …, 1)``) against ``x2`` zero but one (``v·e_k``), and ``x1`` zero but one against
  ``x2`` of alternating signs, at ``λ = μ = ν = 1``, ``t = 0``.

Every point is finite, so a non-finite value returned for one is the subject's failure (:class:`_BadOutput` of
:mod:`verimono.checks.members`: a non-finite output of a finite input), judged like any other sample.  The top
``hi``: ``10^-3 largest^(1/3)`` of the precision under judgement (float64 ``10^99``; float32 ``10^9``; never
below the sweep's ``min(10^6, largest/64)``): the laws' slacks are up to cubic in ``|x|`` (the Moreau envelope's
``tol·|Δx|/λ·(1 + |Δx|)``; at ``10^150`` it overflowed and a correct prox failed), so above it a violation could not be
told from the law's own overflow — and a sample of the phase whose law's own side (``rhs``, ``slack``) is not finite is
inconclusive, a limit of the harness (:func:`beyond_judgement`); and above the sweep's ``|x| = 10^6``
(:data:`JUDGED_TOP`) a sample is judged on ``J_λ`` finite there only (:func:`judged_by`): the laws' round-off
allowances are stated at the points they compute, not at the input's scale.  The record states what
was searched (``details["searched"]["scales"]``: range, stride, points, shapes).
"""

from __future__ import annotations

import functools
import math
from typing import Callable

import numpy as np

from ...core.tolerances import current_largest
from ..core import Outcome
from ..members import resolvent

#: float64's smallest subnormal, 2^-1074: the bottom of every scale design (the input points are float64)
SMALLEST = 5e-324
#: the design of the worst sample's decades gets ``SCALE_SHARE`` times the coordinate budget (at least one point a
#: ``MAX_STRIDE`` decades)
SCALE_SHARE = 1
MAX_STRIDE = 20
#: the shapes of the landmark samples, as the record states them
SHAPES = ("the worst sample scaled", "x1 every entry equal, x2 zero but one", "x1 zero but one, x2 alternating signs")
#: laws whose one evaluation is expensive (an independent minimiser): the landmark samples only, at most this many
SCALE_CAP = {"prox_minimiser": 8}


#: above this ``|x|`` (the sweep's top, :data:`verimono.checks.engine.sweep.SCALES`) a scale sample is judged on one
#: statement only, ``J_λ`` finite on finite points (:data:`FINITE_ONLY`; a row the law's vectorised form accepts is
#: counted as the law holding there): the laws' round-off allowances are stated at the points they compute (a
#: projection of ``x = 10^17 e_1`` onto a half-space a distance 0.4 away carries ``eps·10^17 ≈ 11`` of round-off, lands
#: outside it, and ``min_norm`` refuses it — a correct operator failed ``yosida_limit``), and ``yosida_limit`` halved
#: ``λ`` there for 47 ms a sample
JUDGED_TOP = 1e6


class _FiniteOnly:
    """The statement a scale sample above :data:`JUDGED_TOP` is judged on: ``J_λx1`` and ``J_λx2`` are finite points
    of ``R^n`` (prop:maxmon-resolvent-Yosida i, ``dom J_λ = R^n``); a non-finite value is raised by
    :func:`verimono.checks.members.resolvent` (``_BadOutput``) and failed by the core's policy like any sample's.
    Finite, the sample is inconclusive for the law (counted, never a pass of it: a law whose every other sample was
    inconclusive stays skipped)."""

    name = "J_λ finite on finite points"

    @staticmethod
    def evaluate(op, s) -> Outcome:
        resolvent(op, s.x1, s.lam, s.t)
        resolvent(op, s.x2, s.lam, s.t)
        big = max(float(np.max(np.abs(s.x1), initial=0.0)), float(np.max(np.abs(s.x2), initial=0.0)))
        return Outcome.compare(0.0, 0.0, 1.0, f"J_λx1, J_λx2 finite at |x| = {big:.3g}, the law not judged there (above "
                                              f"{JUDGED_TOP:g} the scale phase judges finiteness only)", inconclusive=True)


FINITE_ONLY = _FiniteOnly()


def judged_by(decl, s):
    """What the scale sample ``s`` is judged on: the law ``decl``, or above :data:`JUDGED_TOP` :data:`FINITE_ONLY`."""
    big = max(float(np.max(np.abs(s.x1), initial=0.0)), float(np.max(np.abs(s.x2), initial=0.0)))
    return FINITE_ONLY if big > JUDGED_TOP else decl


def beyond_judgement(out, s) -> str | None:
    """Why the violation ``out`` at the scale sample ``s`` is no verdict on the subject (inconclusive), or ``None``
    (judged): the law's own side (``rhs``, ``slack``) not finite — its overflow at that scale."""
    rhs, slack = out.rhs, out.slack
    if rhs is not None and not (math.isfinite(rhs) and math.isfinite(0.0 if slack is None else slack)):
        return f"the law's own arithmetic is not finite at this scale ({out.what}: rhs {rhs:.3g}, slack {slack:.3g})"
    return None


def scale_top(largest: float | None = None) -> float:
    """The top of the scale designs at the precision whose largest number is ``largest`` (module docstring)."""
    big = current_largest() if largest is None else float(largest)
    top = 10.0 ** (math.floor(math.log10(big) / 3.0) - 3)
    return max(top, min(1e6, big / 64.0))


def landmarks(largest: float | None = None) -> list[float]:
    """The scales where a whole point's arithmetic changes: float64's smallest subnormal, a deep subnormal, just
    below ``1/largest`` (``1/max|x_i|`` overflows there), the smallest normal, just below ``sqrt(tiny)`` (``|x|²``
    underflows), ``10^-9`` (the sweep's bottom) and the top (:func:`scale_top`); with a narrower precision under
    judgement (float32: ``largest`` = 3.4e38) its own smallest subnormal, smallest normal and ``1/largest``."""
    big = current_largest() if largest is None else float(largest)
    f64 = np.finfo(np.float64)
    out = [SMALLEST, 1e-320, 0.99 / float(f64.max), float(f64.tiny), 0.5 * math.sqrt(float(f64.tiny)), 1e-9,
           scale_top(big)]
    if big < float(f64.max):
        narrow = next((np.finfo(d) for d in (np.float32, np.float16) if float(np.finfo(d).max) >= big * (1 - 1e-6)),
                      np.finfo(np.float32))
        out += [float(narrow.smallest_subnormal), float(narrow.tiny), 0.99 / float(narrow.max)]
    return sorted(set(out))


def decade_design(points: int, top: float) -> tuple[list[float], int]:
    """Every ``stride``-th decade of ``[SMALLEST, top]`` and both ends, ``stride`` the smallest that ``SCALE_SHARE ·
    points`` design points pay (at most :data:`MAX_STRIDE`)."""
    lo, hi = math.ceil(math.log10(SMALLEST)), math.floor(math.log10(top))
    stride = min(MAX_STRIDE, max(1, math.ceil((hi - lo) / max(1, SCALE_SHARE * int(points)))))
    return sorted({SMALLEST, float(top), *(10.0 ** k for k in range(hi, lo - 1, -stride))}), stride


@functools.lru_cache(maxsize=64)
def _shapes(n: int, largest: float) -> tuple[tuple[float, ...], np.ndarray, np.ndarray]:
    """The landmarks at ``largest`` and their shaped points as rows of ``(X1, X2)`` (read-only; each sample gets
    copies): per landmark ``v``, ``(v·1, v·e_1)`` and ``(−v·e_n, v·(1, −1, 1, …))``."""
    marks = tuple(landmarks(largest))
    X1, X2 = np.zeros((2 * len(marks), n)), np.zeros((2 * len(marks), n))
    alt = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    for i, v in enumerate(marks):
        X1[2 * i] = v
        X2[2 * i, 0] = v
        X1[2 * i + 1, -1] = -v
        X2[2 * i + 1] = v * alt
    X1.flags.writeable = X2.flags.writeable = False
    return marks, X1, X2


def scale_samples(start, points: int, n: int, make: Callable, cap: int | None = None) -> tuple[list, dict]:
    """The samples of the module docstring and what they cover: ``start`` the worst sample so far (``None``: the
    landmarks only), ``points`` the coordinate budget, ``n`` the dimension, ``make(x1, x2, lam, mu, nu, t)`` a new
    sample (each owns its points); ``cap``: at most this many (the landmarks first, the smallest scales first).  A
    ``make`` with a ``block`` (:func:`verimono.checks.engine.blocks.make_sample`) gets the rows as one block (not when
    ``start``'s numbers are not Python floats: a block's rows are)."""
    X1, X2, steps, covered = scale_rows(start, points, n, cap)
    block = getattr(make, "block", None)      # a maker of blocks (blocks.make_sample): the rows as one block, when
    if block is not None and steps and all(type(v) is float for v in steps[-1]):     # every number is a float
        return block(X1, X2, np.array([st[:3] for st in steps], dtype=float),
                     np.array([st[3] for st in steps], dtype=float)), covered
    return [make(a.copy(), b.copy(), *st) for a, b, st in zip(X1, X2, steps)], covered


def scale_rows(start, points: int, n: int, cap: int | None = None) -> tuple[np.ndarray, np.ndarray, list, dict]:
    """:func:`scale_samples` as rows: the points ``X1, X2`` ``(B, n)`` (read-only when they are the landmarks' only:
    a sample made from a row gets copies), each row's ``(λ, μ, ν, t)`` (the landmarks' ``(1, 1, 1, 0)``, then
    ``start``'s own numbers) and what they cover."""
    marks, X1, X2 = _shapes(int(n), float(current_largest()))
    steps = [(1.0, 1.0, 1.0, 0.0)] * len(X1)
    covered = {"range": [marks[0], marks[-1]], "landmarks": list(marks), "shapes": list(SHAPES[1:])}
    if start is not None and cap is None:
        r = max(float(np.max(np.abs(start.x1), initial=0.0)), float(np.max(np.abs(start.x2), initial=0.0)))
        lams = (float(start.lam), float(start.mu), float(start.nu))
        if 0.0 < r < math.inf and all(s > 0.0 for s in lams):
            top = scale_top() * min(1.0, *lams) / max(1.0, *lams)
            design, stride = decade_design(points, top)
            V = np.array(design)[:, None]
            # row i: (x/r)·v_i — not x·(v_i/r), which underflows to 0 for a subnormal v_i: the entry of largest
            # magnitude r becomes ±v_i exactly
            S1, S2 = (start.x1 / r)[None, :] * V, (start.x2 / r)[None, :] * V
            X1, X2 = np.concatenate([X1, S1]), np.concatenate([X2, S2])
            steps = steps + [(start.lam, start.mu, start.nu, start.t)] * len(design)
            covered = {"range": [SMALLEST, max(marks[-1], design[-1])], "stride": stride, "decades": len(design),
                       "landmarks": list(marks), "shapes": list(SHAPES)}
    if cap is not None:
        X1, X2, steps = X1[:cap], X2[:cap], steps[:cap]
    covered["points"] = len(steps)
    return X1, X2, steps, covered


__all__ = ["scale_samples", "scale_rows", "scale_top", "beyond_judgement", "judged_by", "FINITE_ONLY", "JUDGED_TOP", "landmarks", "decade_design", "SMALLEST", "SHAPES", "SCALE_CAP"]
