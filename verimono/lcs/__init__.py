"""Linear systems with maximal monotone relations: complementarity and relay systems (Section 7).

``x' = Ax + Bz + u``, ``w = Cx + Dz + v``, ``(−z, w) ∈ graph 𝓜`` as ``x' ∈ −H(t,x) + u``; the one-step
LCP with its least-norm solution (Proposition ``p:lcp2``), Siconos' θ and θ-γ schemes, passivity (KYP,
Proposition ``p:pass``) and evidence for the hypotheses of Theorems ``thm: linear case`` and
``e: linear case-comp``.
"""

from .kernel import BatchStepError, RowFailure
from .lcp import LCPResult, box_residual, lcp_residual, lemke, solve_box, solve_lcp
from .passivity import PassivityResult, is_passive
from .relations import Complementarity, OperatorRelation, Relation, Relay
from .siconos import read_lcp, read_ref
from .system import LCSOperator, LinearRelationSystem


def __getattr__(name: str):
    """``check_hypotheses`` (the laws of Section 7, :mod:`verimono.checks.section7`) and ``check_siconos``
    (agreement with Siconos, :mod:`verimono.checks.siconos`), loaded on first use."""
    if name == "check_hypotheses":
        from ..checks.section7 import check_hypotheses

        return check_hypotheses
    if name == "check_siconos":
        from ..checks.siconos import check_siconos

        return check_siconos
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "LinearRelationSystem", "LCSOperator", "Relation", "Complementarity", "Relay", "OperatorRelation",
    "solve_lcp", "solve_box", "LCPResult", "lcp_residual", "box_residual", "lemke",
    "is_passive", "PassivityResult", "check_hypotheses", "read_ref", "read_lcp", "check_siconos",
    "BatchStepError", "RowFailure",
]
