"""A zoo of deliberately broken operators: each one is wrong in a way a real implementation can be, and
``BREAKS[name]`` lists the operator laws (:data:`verimono.checks.LAWS`) it must be seen failing.

Every member is built from correct catalog pieces plus one bug, so a law failing on it is evidence that
the law detects that bug (a property test must be seen failing before it is trusted).
"""

from __future__ import annotations

import numpy as np

from verimono import L1Subdifferential, Linear, NormalCone, NormSubdifferential, operator_from_resolvent, sets
from verimono.core.operators import Operator

#: a monotone, non-symmetric matrix with ‖M‖ = √10: large λ make an explicit step expand
_M = np.array([[3.0, 1.0], [-1.0, 1.0]])


def explicit_step() -> Operator:
    """``x - λMx`` (forward Euler) passed off as ``(I + λM)^{-1}x``: not firmly nonexpansive, expansive for
    ``λ|M| > 2``, its "Yosida" ``Mx`` is not in ``F(J_λx) = {M(x - λMx)}``, the resolvent identity fails,
    and ``(J_λx, Mx)`` are not monotone pairs of the graph."""
    L = Linear(_M)
    return operator_from_resolvent(lambda x, lam, t: x - lam * (x @ _M.T), 2, min_norm=L.min_norm,
                                   project_domain=L.project_domain, contains=L.contains, name="explicit_step")


def wrong_lambda() -> Operator:
    """The resolvent of ``2λ`` returned for ``λ`` (a factor-2 bug): its Yosida value ``2Y_{2λ}`` is not in
    ``F(J)`` and exceeds ``|F^0|`` in the limit.  Every λ-free law (nonexpansive, identity, …) holds."""
    F = NormSubdifferential(1.0, 2)
    return operator_from_resolvent(lambda x, lam, t: F.resolvent(x, 2 * lam, t), 2, min_norm=F.min_norm,
                                   project_domain=F.project_domain, contains=F.contains, name="wrong_lambda")


def shifted_projection() -> Operator:
    """``N_S`` for ``S`` the unit ball whose "resolvent" projects onto ``S + (1/2, 0)``: ``J_λx`` leaves
    ``dom F = S`` and ``Y_λx`` is not normal to ``S`` at ``J_λx``."""
    S, e = sets.Ball([0.0, 0.0], 1.0), np.array([0.5, 0.0])
    N = NormalCone(S)
    return operator_from_resolvent(lambda x, lam, t: S.project(np.asarray(x) - e, t) + e, 2, min_norm=N.min_norm,
                                   project_domain=N.project_domain, contains=N.contains, name="shifted_projection")


def non_monotone_linear() -> Operator:
    """``(I + λM)^{-1}`` for ``M = [[-1/2, 1/2], [-1/2, -1/2]]`` (``M + Mᵀ = -I``; eigenvalues
    ``-1/2 ± i/2`` so ``I + λM`` is invertible for every λ): a correct resolvent of a non-monotone map.
    With ``|1 + λm|² = 1 - λ + λ²/2``: expansive for ``λ < 2``, ``λ|Y_λ| > 1`` for ``λ > 1``, ``|Y_λx|``
    increasing on ``λ < 1``; monotonicity of the graph and of ``Y_λ`` fail everywhere."""
    M = np.array([[-0.5, 0.5], [-0.5, -0.5]])
    return operator_from_resolvent(lambda x, lam, t: np.linalg.solve(np.eye(2) + lam * M, np.asarray(x)), 2,
                                   min_norm=lambda x, t: M @ np.asarray(x),
                                   project_domain=lambda x, t: np.array(x, dtype=float),
                                   name="non_monotone_linear")


def min_norm_not_least() -> Operator:
    """``∂|·|`` on R² whose ``min_norm(0)`` returns ``(1, 0) ∈ F(0) = B`` instead of ``0``: an element of
    the graph, but not the least-norm one."""
    F = NormSubdifferential(1.0, 2)

    def min_norm(x, t):
        x = np.asarray(x, dtype=float)
        return F.min_norm(x, t) if np.any(x) else np.array([1.0, 0.0])
    return operator_from_resolvent(F.resolvent, 2, min_norm=min_norm, project_domain=F.project_domain,
                                   contains=F.contains, name="min_norm_not_least")


def min_norm_outside_graph() -> Operator:
    """``∂‖·‖₁`` whose ``min_norm`` returns ``c·sgn(x)/2`` (a halved weight): outside ``F(x)`` wherever
    ``x ≠ 0``, and smaller than ``|Y_λx| → c``."""
    F = L1Subdifferential(1.0, 2)
    return operator_from_resolvent(F.resolvent, 2, min_norm=lambda x, t: 0.5 * np.sign(np.asarray(x, dtype=float)),
                                   project_domain=F.project_domain, contains=F.contains,
                                   name="min_norm_outside_graph")


def nondeterministic() -> Operator:
    """A linear resolvent with random perturbations of size 1e-6 (e.g. an iterative solver with a random
    start and a loose stopping rule): two calls at the same point disagree."""
    L, rng = Linear(_M), np.random.default_rng(0)
    return operator_from_resolvent(lambda x, lam, t: L.resolvent(x, lam, t) + 1e-6 * rng.standard_normal(2), 2,
                                   min_norm=L.min_norm, project_domain=L.project_domain, contains=L.contains,
                                   name="nondeterministic")


def mutates_input() -> Operator:
    """A soft-thresholding resolvent computed in place: correct value, but it overwrites the caller's ``x``."""
    F = L1Subdifferential(1.0, 2)

    def resolvent(x, lam, t):
        x[...] = F.resolvent(x, lam, t)
        return x
    return operator_from_resolvent(resolvent, 2, min_norm=F.min_norm, project_domain=F.project_domain,
                                   contains=F.contains, name="mutates_input")


def ignores_time() -> Operator:
    """The sweeping process of a ball moving along ``(2t, 0)`` whose resolvent always projects onto the
    ball at ``t = 0`` (the set evaluated at the wrong time): wrong for every ``t > 0``."""
    S = sets.Ball(lambda t: np.array([2.0 * t, 0.0]), 1.0)
    N = NormalCone(S)
    return operator_from_resolvent(lambda x, lam, t: S.project(x, 0.0), 2, min_norm=N.min_norm,
                                   project_domain=N.project_domain, contains=N.contains, name="ignores_time")


def stale_cache() -> Operator:
    """A linear resolvent caching ``(I + λM)^{-1}`` for the first λ it sees and reusing it for every λ (a
    cache keyed on nothing): the resolvent identity between two step sizes fails."""
    L = Linear(_M)
    cache: dict[str, np.ndarray] = {}

    def resolvent(x, lam, t):
        if "inv" not in cache:
            cache["inv"] = np.linalg.inv(np.eye(2) + lam * _M)
        return np.asarray(x, dtype=float) @ cache["inv"].T
    return operator_from_resolvent(resolvent, 2, min_norm=L.min_norm, project_domain=L.project_domain,
                                   contains=L.contains, name="stale_cache")


def ignores_lambda() -> Operator:
    """``(I + M)^{-1}`` returned whatever λ is (λ hard-coded to 1): it does not tend to the identity as
    ``λ → 0`` on ``dom F`` (item iii)."""
    L = Linear(_M)
    return operator_from_resolvent(lambda x, lam, t: L.resolvent(x, 1.0, t), 2, min_norm=L.min_norm,
                                   project_domain=L.project_domain, contains=L.contains, name="ignores_lambda")


class _L1WithYosida(L1Subdifferential):
    """``∂(c|·|₁)`` whose own ``yosida`` member is ``factor·(x - J_λx)/λ`` (an override, as a subclass writes it)."""

    factor = 1.0

    def yosida(self, x, lam, t=0.0):
        return self.factor * super().yosida(x, lam, t)


def yosida_member_halved(factor: float = 0.5) -> Operator:
    """``∂|·|₁`` whose resolvent, ``min_norm`` and ``contains`` are right and whose own ``yosida`` member returns half
    of ``(x - J_λx)/λ`` (a ``1/(2λ)`` written for ``1/λ``): the laws that compute ``Y_λ`` from the resolvent pass."""
    op = _L1WithYosida(1.0, 2, name="yosida_member_halved")
    op.factor = factor
    return op


def contains_accepts_everything() -> Operator:
    """``∂|·|₁`` with a right resolvent and ``min_norm`` and a membership test that says True to every pair: the
    graph it declares is not monotone, and every law certifying a membership through it is vacuous."""
    F = L1Subdifferential(1.0, 2)
    return operator_from_resolvent(F.resolvent, 2, min_norm=F.min_norm, project_domain=F.project_domain,
                                   contains=lambda x, y, t=0.0, tol=None: True, name="contains_accepts_everything")


_BOX = sets.Box([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0])
_BOX_CONE = NormalCone(_BOX)


def project_domain_radial(exact: bool = False) -> Operator:
    """``N_B`` of the box ``[-1, 1]³`` (resolvent: the coordinatewise clip, right) whose ``project_domain`` retracts
    radially, ``x/max(1, |x|_∞)``: a point of the box, not the nearest one (``(2, 1/2, 0) ↦ (1, 1/4, 0)``, the clip
    ``(1, 1/2, 0)`` is nearer).  ``exact=True``: the clip itself, the lawful twin."""
    def radial(x, t=0.0):
        x = np.asarray(x, dtype=float)
        return _BOX.project(x, t) if exact else x / max(1.0, float(np.abs(x).max()))
    return operator_from_resolvent(_BOX_CONE.resolvent, 3, min_norm=_BOX_CONE.min_norm, project_domain=radial,
                                   contains=_BOX_CONE.contains,
                                   name="project_domain_clip" if exact else "project_domain_radial")


#: member name → (constructor, laws it must break)
ZOO = {
    "explicit_step": (explicit_step, ["resolvent_nonexpansive", "resolvent_firmly_nonexpansive", "resolvent_identity",
                                      "monotone", "yosida_lipschitz", "yosida_in_graph"]),
    "wrong_lambda": (wrong_lambda, ["yosida_in_graph", "yosida_bounded_by_min_norm", "yosida_limit"]),
    "shifted_projection": (shifted_projection, ["resolvent_in_domain", "yosida_in_graph"]),
    "non_monotone_linear": (non_monotone_linear, ["monotone", "resolvent_nonexpansive",
                                                  "resolvent_firmly_nonexpansive", "yosida_lipschitz",
                                                  "yosida_monotone", "yosida_nonincreasing"]),
    # its only wrong value is at the kink 0 of ∂|·|, where yosida_limit calls a stalled gap inconclusive (F^0
    # jumps there: a correct operator's gap may close only below the rounding floor); min_norm_least decides
    "min_norm_not_least": (min_norm_not_least, ["min_norm_least"]),
    "min_norm_outside_graph": (min_norm_outside_graph, ["min_norm_in_graph", "yosida_bounded_by_min_norm"]),
    "nondeterministic": (nondeterministic, ["resolvent_single_valued"]),
    "mutates_input": (mutates_input, ["resolvent_single_valued"]),
    "ignores_time": (ignores_time, ["resolvent_in_domain", "yosida_in_graph"]),
    "stale_cache": (stale_cache, ["resolvent_identity"]),
    "ignores_lambda": (ignores_lambda, ["resolvent_limit", "resolvent_identity"]),
    "yosida_member_halved": (yosida_member_halved, ["yosida_member"]),
    "contains_accepts_everything": (contains_accepts_everything, ["contains_rejects"]),
    "project_domain_radial": (project_domain_radial, ["project_domain_nearest"]),
}

BREAKS = {name: laws for name, (_, laws) in ZOO.items()}


def build(name: str) -> Operator:
    return ZOO[name][0]()


# -- the input's form (verimono.checks.engine.forms): bugs that only arrays other than fresh contiguous float64 meet --

_BALL = sets.Ball([0.0, 0.0], 1.0)
_BALL_CONE = NormalCone(_BALL)


def _on_ball(resolvent, name: str) -> Operator:
    return operator_from_resolvent(resolvent, 2, min_norm=_BALL_CONE.min_norm, project_domain=_BALL_CONE.project_domain,
                                   contains=_BALL_CONE.contains, name=name)


def truncates_integers() -> Operator:
    """``N_B`` of the unit ball whose resolvent allocates its output with ``np.empty_like(x)``: an integer
    ``x`` gets an integer output, the projection ``x/|x|`` truncated toward 0 (``J(3, 0) = (1, 0)`` but
    ``J(2, 1) = (0, 0)``): ``Y_λx = x/λ`` is then no normal of the ball at ``0``."""
    def resolvent(x, lam, t):
        out = np.empty_like(x)
        out[...] = _BALL.project(np.asarray(x, dtype=float), t)
        return out
    return _on_ball(resolvent, "truncates_integers")


def reads_parent_buffer() -> Operator:
    """``N_B`` whose resolvent takes "the underlying array" of a view, ``x.base``, for the point: the first
    ``n`` entries of the caller's buffer, not ``x`` (the other entries of a strided view, the entries
    before a slice)."""
    def resolvent(x, lam, t):
        data = x if x.base is None else x.base
        return _BALL.project(np.asarray(data, dtype=float)[:2], t)
    return _on_ball(resolvent, "reads_parent_buffer")


def projects_in_place() -> Operator:
    """``N_B`` whose resolvent scales ``x`` into the ball in place (``x /= max(1, |x|)``) and returns it:
    the right value, but the caller's ``x`` is overwritten (and a read-only ``x`` raises)."""
    def resolvent(x, lam, t):
        x /= max(1.0, float(np.linalg.norm(x)))
        return x
    return _on_ball(resolvent, "projects_in_place")


def scratch_on_input() -> Operator:
    """``N_B`` of the ball centred at ``(1/2, 0)`` whose resolvent uses ``x`` as scratch space (``x -= c``)
    and restores it bit for bit before returning: the caller's writable ``x`` ends unchanged, but a
    read-only ``x`` raises ``ValueError``."""
    c = np.array([0.5, 0.0])
    ball = sets.Ball(c, 1.0)
    cone = NormalCone(ball)

    def resolvent(x, lam, t):
        saved = np.array(x, dtype=float)
        x -= c.astype(x.dtype)
        p = _BALL.project(np.asarray(x, dtype=float), t) + c
        x[...] = saved
        return p
    return operator_from_resolvent(resolvent, 2, min_norm=cone.min_norm, project_domain=cone.project_domain,
                                   contains=cone.contains, name="scratch_on_input")


ZOO.update({
    "truncates_integers": (truncates_integers, ["yosida_in_graph", "resolvent_firmly_nonexpansive"]),
    "reads_parent_buffer": (reads_parent_buffer, ["resolvent_nonexpansive", "yosida_in_graph"]),
    "projects_in_place": (projects_in_place, ["resolvent_nonexpansive", "yosida_in_graph"]),
    "scratch_on_input": (scratch_on_input, ["resolvent_nonexpansive"]),
})
BREAKS.update({name: laws for name, (_, laws) in ZOO.items() if name not in BREAKS})


def lawful_truncates_integers() -> Operator:
    def resolvent(x, lam, t):
        x = np.asarray(x, dtype=float)
        out = np.empty_like(x)
        out[...] = _BALL.project(x, t)
        return out
    return _on_ball(resolvent, "lawful_truncates_integers")


def lawful_reads_parent_buffer() -> Operator:
    def resolvent(x, lam, t):
        return _BALL.project(np.asarray(x, dtype=float), t)
    return _on_ball(resolvent, "lawful_reads_parent_buffer")


def lawful_projects_in_place() -> Operator:
    def resolvent(x, lam, t):
        x = np.array(x, dtype=float)       # a copy of its own to work on
        x /= max(1.0, float(np.linalg.norm(x)))
        return x
    return _on_ball(resolvent, "lawful_projects_in_place")


def lawful_scratch_on_input() -> Operator:
    c = np.array([0.5, 0.0])
    cone = NormalCone(sets.Ball(c, 1.0))

    def resolvent(x, lam, t):
        x = np.array(x, dtype=float)       # scratch space of its own
        x -= c
        return _BALL.project(x, t) + c
    return operator_from_resolvent(resolvent, 2, min_norm=cone.min_norm, project_domain=cone.project_domain,
                                   contains=cone.contains, name="lawful_scratch_on_input")


def layout_dependent(lawful: bool = False) -> Operator:
    """``∂|·|₁`` whose soft threshold takes the step ``2λ`` on non-contiguous input (a "copy avoided" branch with the
    step doubled): each form is a lawful resolvent by itself (``J_{2λ}`` on strided views), but ``J_λ`` is not a
    function of the values of ``x``.  ``lawful=True``: the step ``λ`` on every layout."""
    F = L1Subdifferential(1.0, 2)

    def resolvent(x, lam, t):
        x = np.asarray(x)
        step = lam if lawful or x.flags.c_contiguous else 2 * lam
        return np.sign(x) * np.maximum(np.abs(x) - step, 0.0)
    return operator_from_resolvent(resolvent, 2, min_norm=F.min_norm, project_domain=F.project_domain,
                                   contains=F.contains, name="lawful_layout" if lawful else "layout_dependent")


ZOO["layout_dependent"] = (layout_dependent, ["resolvent_single_valued"])
BREAKS["layout_dependent"] = ZOO["layout_dependent"][1]


def lawful_layout() -> Operator:
    return layout_dependent(lawful=True)


#: the form bugs' members written correctly (np.asarray(x, dtype=float) / a copy first): every law passes
FORM_CONTROLS = {"truncates_integers": lawful_truncates_integers, "reads_parent_buffer": lawful_reads_parent_buffer,
                 "projects_in_place": lawful_projects_in_place, "scratch_on_input": lawful_scratch_on_input,
                 "layout_dependent": lawful_layout}
#: the members whose bug only an input form meets: behind a boundary that copies its input into a fresh float64
#: array (tests/zoo_precision.float32) they are lawful operators, as the controls are
FORM_BUGS = frozenset(FORM_CONTROLS)
