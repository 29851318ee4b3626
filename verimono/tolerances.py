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
