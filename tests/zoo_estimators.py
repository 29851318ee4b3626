"""Deliberately broken estimators and constants, each the kind of mistake a real implementation makes, for
the checks of issue 13 that compare them with an exact value:

* pseudo-distance estimators for ``pseudo_distance_hausdorff`` (``def:dis``; :mod:`verimono.checks.pseudo_distance`);
* a wrong Lipschitz constant for ``picard_step`` (``e: bound x l plus one to x l``; :mod:`verimono.checks.picard`).
"""

from __future__ import annotations

import numpy as np

from verimono.core.pseudo_distance import graph_points, pseudo_distance_lower_bound


def twice_too_large(F1, F2, samples, *, lams=(1.0,), t1=0.0, t2=0.0):
    """The right supremum, doubled (a factor-2 slip, e.g. ``|y1| + |y2|`` halved in the denominator)."""
    return 2.0 * float(pseudo_distance_lower_bound(F1, F2, samples, lams=lams, t1=t1, t2=t2))


def sign_error(F1, F2, samples, *, lams=(1.0,), t1=0.0, t2=0.0):
    """``⟨y1 − y2, x1 − x2⟩`` instead of ``⟨y1 − y2, x2 − x1⟩`` in the numerator of ``def:dis``."""
    X1, Y1 = graph_points(F1, samples, lams, t1)
    X2, Y2 = graph_points(F2, samples, lams, t2)
    num = -(Y1 @ X2.T - np.sum(Y1 * X1, axis=1)[:, None] - np.sum(Y2 * X2, axis=1)[None, :] + X1 @ Y2.T)
    den = 1.0 + np.linalg.norm(Y1, axis=1)[:, None] + np.linalg.norm(Y2, axis=1)[None, :]
    return float(np.max(num / den))


def half_as_large(F1, F2, samples, *, lams=(1.0,), t1=0.0, t2=0.0):
    """A valid lower bound but a useless one (only half of the supremum)."""
    return 0.5 * float(pseudo_distance_lower_bound(F1, F2, samples, lams=lams, t1=t1, t2=t2))


#: estimator → the side of ``pseudo_distance_hausdorff`` it must be seen failing on
ESTIMATORS = {"twice_too_large": (twice_too_large, "above d_H: not a lower bound"),
              "sign_error": (sign_error, None),
              "half_as_large": (half_as_large, "below")}


def understated_lipschitz(problem, factor: float = 0.5):
    """The problem's Lipschitz constant of ``f`` understated by ``factor`` (a constant copied from a
    component, or from the wrong norm)."""
    return factor * problem.lipschitz


def alpha_min_max_slip(M):
    """``1/λ_max`` of the symmetric part instead of ``1/λ_min`` for the constant of Proposition p:lcp2 v."""
    lam = np.linalg.eigvalsh(0.5 * (np.asarray(M) + np.asarray(M).T))
    return 1.0 / float(lam[-1]) if lam[0] > 0 else None


def hoffman_sigma_max(Q, R=None):
    """``1/σ_max`` of the whole row stack instead of the max of ``1/σ_min`` over independent row sets (the
    angle between the rows ignored)."""
    A = np.atleast_2d(Q) if R is None else np.vstack([np.atleast_2d(R), np.atleast_2d(Q)])
    return 1.0 / float(np.linalg.svd(A, compute_uv=False)[0])


def hoffman_without_equalities(Q, R=None):
    """The Hoffman constant of the inequalities alone (the equality rows forgotten)."""
    from verimono.lcs.hoffman import hoffman_constant
    return hoffman_constant(Q)
