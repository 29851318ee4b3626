"""The one place where verimono's numerical tolerances are stated, with their reasons.

Every identity the checks test (nonexpansiveness, the resolvent identity, ``Y_λ x ∈ F(J_λ x)``, ...)
holds exactly in exact arithmetic.  Computed in float64 by closed forms, by factorised linear solves or
by QP solves whose KKT residual verimono verifies to ``QP_RTOL``, each side carries a relative error of a
few ulps up to ``QP_RTOL`` times the magnitude of the data.  ``RTOL = 1e-8`` leaves about two orders of
magnitude of headroom over the verified QP accuracy, and is still 10^4 times smaller than any
violation a genuinely wrong resolvent produces on inputs of unit size.

A comparison ``a <= b`` is accepted when ``a <= b + tolerance(scale)``, where ``scale`` is the size of
the inputs involved (``max |x|``, ``|λ| |y|``, ...): absolute tolerances would be wrong for inputs of
size 1e6 and meaningless for inputs of size 1e-6.
"""

from __future__ import annotations

import numpy as np

#: relative tolerance of exact identities computed in floating point (see module docstring)
RTOL = 1e-8
#: relative KKT residual below which a QP/LCP solution from a back-end is accepted
QP_RTOL = 1e-10
#: machine epsilon of float64
EPS = float(np.finfo(float).eps)


def tolerance(*scales: float, rtol: float = RTOL) -> float:
    """Tolerance for a comparison between quantities of size ``max(scales)``: ``rtol * (1 + max)``."""
    m = 0.0
    for s in scales:
        a = float(np.max(np.abs(s))) if np.size(s) else 0.0
        if a > m:
            m = a
    return rtol * (1.0 + m)

#: relative LCP residual below which a back-end's candidate is refined by one active-set (principal
#: pivot) solve.  The refinement turns a nearly right answer into a round-off-exact one; it is not a
#: solver, so a candidate further off than this (a back-end reporting "solved" on garbage) is never
#: rescued by it and is rejected by the residual check instead.
POLISH_RTOL = 1e-6

# -- trajectory laws and assumption evidence (verimono.checks.trajectory_laws / .assumptions) ----------


def quotient_tolerance(h: float, *scales: float, rtol: float = RTOL) -> float:
    """Tolerance for a difference quotient ``(a - b)/h`` of quantities of size ``max(scales)``.

    Each of ``a``, ``b`` carries a relative error ``rtol``; dividing by the step ``h`` divides nothing
    away, so the quotient carries ``rtol (1 + max scale) / h``.  Used for the scheme's selections
    ``(x_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})`` and for Yosida values ``(x - J_λ x)/λ``.
    """
    return tolerance(*scales, rtol=rtol) / float(h)


#: the distance between discrete solutions on two partitions of mesh ``|Δ|`` must shrink at least by
#: this factor when ``|Δ|`` shrinks 16-fold (i.e. observed order ≥ 1/4, half the worst known rate 1/2 of
#: the proximal scheme for ``x0 ∈ cl dom F``; a scheme converging to *different* limits on different
#: partitions keeps an O(1) distance and fails by a factor ~2)
LIMIT_SHRINK = 0.5
#: further 4-fold refinements (up to 64 times the finest of the default levels) granted to a problem whose
#: own time scale is finer than the default meshes before the unique-limit law is judged: a generated
#: sweeping process in a ball of radius 0.002 driven by a unit input is pre-asymptotic until |Δ| < 0.002
LIMIT_EXTRA_LEVELS = 3
#: a sampled ratio (``|F^0(t,x)|/(1+|x|)``, a Yosida increment per unit time) that grows by more than
#: this factor while the sampling parameter ``λ`` shrinks 1000-fold is reported as evidence that the
#: bound (LG) / (YB) fails; bounded quantities change by O(1) over that range
GROWTH_FLAG = 10.0

# -- the λ → 0 limits of prop:maxmon-resolvent-Yosida (items iii and vi) --------------------------------
# A limit cannot be observed in finitely many evaluations.  The operator-law checks halve λ from the
# sampled step down to the floor where the resolvent's own error bound 2·tolerance(x)/λ reaches
# (1 + |F^0(x)|)/LIMIT_FLOOR: below it Y_λ x = (x - J_λ x)/λ is dominated by rounding.  The gap
# |F^0(x)| - |Y_λ x| must fall within tolerance on the way, or still be shrinking at the floor: a gap that
# stays above STALL_RATIO times its value STALL_WINDOW halvings (a factor 2^8 in λ) earlier has stalled.
# A correct operator whose gap behaves like λ^p drops below that ratio for any p > 0.006.
#: the sweep stops where the rounding bound on |Y_λ x| is (1 + |F^0(x)|)/LIMIT_FLOOR
LIMIT_FLOOR = 16.0
#: a gap still above this fraction of its value STALL_WINDOW halvings earlier has stalled
STALL_RATIO = 0.99
#: number of halvings of λ over which stalling is judged
STALL_WINDOW = 8

#: relative accuracy of an interior-point SDP solution (KYP search in :mod:`verimono.lcs.passivity`).  Such
#: solvers stop at about 1e-8 relative duality gap; the LMI is then re-checked by an eigenvalue computation
#: against this looser tolerance, scaled to the size of the KYP matrix.
SDP_RTOL = 1e-6

#: a scheme claiming order p (``scheme="any"``) passes ``in_domain`` when the largest distance of its
#: iterates to ``cl dom F(t_k)`` at the finest level is at most this factor times the prediction
#: ``max_j D(K_j) (K_j/K_m)^p`` from the coarser levels: the constant of ``C h^p`` is unknown and drifts
#: by O(h) between levels; a distance that does not vanish (a constant offset) exceeds any fixed factor
DOMAIN_ORDER_SLACK = 2.0
