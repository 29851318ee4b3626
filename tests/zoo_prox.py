"""A zoo of *lawful* prox bugs: each member is the exact prox of a convex function — so every resolvent law
holds — but of the WRONG one; only the value laws (given the intended ``g``) can catch it.  ``LAWFUL[name]``
is ``(buggy, correct)``: the buggy operator and its correct counterpart with the same ``value``; ``CAUGHT_BY``
lists the laws each bug must be seen failing.  ``THIN`` holds bugs confined to ``|x| < 1e-6`` (not lawful:
a crash, a skipped branch) that the default effort must catch at every seed.
"""

from __future__ import annotations

import numpy as np

from verimono import operator_from_prox


def soft(x, tau):
    """Soft thresholding, the prox of ``tau·|·|_1``."""
    return np.sign(x) * np.maximum(np.abs(x) - tau, 0.0)


def block_soft(x, tau):
    """Block soft thresholding, the prox of ``tau·|·|_2`` (Frobenius on matrices)."""
    n = float(np.linalg.norm(x))
    return x * (max(n - tau, 0.0) / n) if n > 0 else x * 0.0


# -- group lasso with weights (1, 3) on the groups {0, 1}, {2, 3} ----------------------------------------
_W = (1.0, 3.0)


def _group_prox(weights):
    def prox(x, lam):
        return np.concatenate([block_soft(x[:2], lam * weights[0]), block_soft(x[2:], lam * weights[1])])
    return prox


def group_value(x):
    return _W[0] * np.linalg.norm(x[:2]) + _W[1] * np.linalg.norm(x[2:])


def group_weights():
    """The weights applied to the wrong groups: the exact prox of ``3|x_{01}| + |x_{23}|``."""
    return (operator_from_prox(_group_prox(_W[::-1]), value=group_value, shape=4, name="group_weights_swapped"),
            operator_from_prox(_group_prox(_W), value=group_value, shape=4, name="group_lasso"))


# -- nuclear norm on R^{2x3} --------------------------------------------------------------------------
def nuclear_value(X):
    return float(np.linalg.svd(X, compute_uv=False).sum())


def svt(X, lam):
    U, s, Vt = np.linalg.svd(X, full_matrices=False)
    return (U * np.maximum(s - lam, 0.0)) @ Vt


def frobenius_for_nuclear():
    """Block soft thresholding of the whole matrix — the prox of the Frobenius norm — for the nuclear norm."""
    return (operator_from_prox(block_soft, value=nuclear_value, shape=(2, 3), name="frobenius_prox_for_nuclear"),
            operator_from_prox(svt, value=nuclear_value, shape=(2, 3), name="nuclear_svt"))


# -- l2 norm given, l1 formula used ---------------------------------------------------------------------
def l1_formula_for_l2():
    """Soft thresholding (ℓ1) for ``g = |·|_2``."""
    val = lambda x: float(np.linalg.norm(x))   # noqa: E731
    return (operator_from_prox(soft, value=val, shape=3, name="l1_prox_for_l2"),
            operator_from_prox(block_soft, value=val, shape=3, name="l2_block_soft"))


# -- a linear functional whose prox degenerated into the identity ----------------------------------------
_A = np.array([1.0, -2.0, 0.5])


def linear_identity():
    """``g(x) = ⟨a, x⟩`` has ``prox = x - λa``; the identity is the prox of ``g = 0``."""
    val = lambda x: float(_A @ x)   # noqa: E731
    return (operator_from_prox(lambda x, lam: x.copy(), value=val, shape=3, name="linear_as_identity"),
            operator_from_prox(lambda x, lam: x - lam * _A, value=val, shape=3, name="linear_shift"))


# -- a weight forgotten -----------------------------------------------------------------------------------
def l1_weight():
    """``g = 2|·|_1`` thresholded at ``λ`` instead of ``2λ``: the prox of ``|·|_1``."""
    val = lambda x: 2.0 * float(np.abs(x).sum())   # noqa: E731
    return (operator_from_prox(soft, value=val, shape=2, name="l1_weight_forgotten"),
            operator_from_prox(lambda x, lam: soft(x, 2.0 * lam), value=val, shape=2, name="l1_weighted"))


# -- a box with the wrong bounds ----------------------------------------------------------------------------
def box_value(x):
    return 0.0 if np.all((x >= 0.0) & (x <= 1.0)) else np.inf


def box_bounds():
    """The indicator of ``[0, 1]^2`` whose prox clips to ``[-1, 1]^2`` (the projection onto another box)."""
    return (operator_from_prox(lambda x, lam: np.clip(x, -1.0, 1.0), value=box_value, shape=2, name="box_wrong_bounds"),
            operator_from_prox(lambda x, lam: np.clip(x, 0.0, 1.0), value=box_value, shape=2, name="box_unit"))


LAWFUL = {
    "group_weights": group_weights,
    "frobenius_for_nuclear": frobenius_for_nuclear,
    "l1_formula_for_l2": l1_formula_for_l2,
    "linear_identity": linear_identity,
    "l1_weight": l1_weight,
    "box_bounds": box_bounds,
}


# -- thin-region bugs --------------------------------------------------------------------------------------
def _l1_value(x):
    return float(np.abs(x).sum())


def crash_tiny():
    """Soft thresholding that raises for ``0 < |x|_∞ < 1e-6`` (a guard against a 'too small' input)."""
    def prox(x, lam):
        m = float(np.max(np.abs(x)))
        if 0.0 < m < 1e-6:
            raise FloatingPointError("input below 1e-6")
        return soft(x, lam)
    return operator_from_prox(prox, value=_l1_value, shape=2, name="crash_tiny")


def wrong_tiny():
    """Soft thresholding that returns ``x`` unchanged for ``0 < |x|_∞ < 1e-6`` (a skipped branch)."""
    def prox(x, lam):
        m = float(np.max(np.abs(x)))
        return x.copy() if 0.0 < m < 1e-6 else soft(x, lam)
    return operator_from_prox(prox, value=_l1_value, shape=2, name="wrong_tiny")


def soft_l1():
    """The correct counterpart of the thin-region bugs (the closed-form prox timed by the tests)."""
    return operator_from_prox(soft, value=_l1_value, shape=2, name="soft_l1")


THIN = {"crash_tiny": crash_tiny, "wrong_tiny": wrong_tiny}
