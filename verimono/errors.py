"""Typed errors raised on bad input.

Every error verimono raises because of what it was given derives from :class:`VerimonoError`, so a
caller can catch one class.  Messages say what was wrong and what was expected.
"""

from __future__ import annotations


class VerimonoError(Exception):
    """Base of every error verimono raises on bad input or an unsolvable step."""


class InvalidProblem(VerimonoError, ValueError):
    """A problem's data are malformed: wrong shapes, non-finite values, ``T <= 0``."""


class InvalidGrid(VerimonoError, ValueError):
    """A time grid is not an increasing partition ``0 = t_0 < ... < t_K = T``."""


class OutsideDomain(VerimonoError, ValueError):
    """A point lies outside the (closure of the) domain where it must lie inside."""


class NotMonotone(VerimonoError, ValueError):
    """An operator or relation that must be monotone is not (e.g. ``M + M^T`` not PSD)."""


class InfeasibleStep(VerimonoError, ArithmeticError):
    """A one-step problem has no solution (e.g. an LCP(q, M) with ``q`` outside ``Q_M^+``)."""


class SolverFailure(VerimonoError, ArithmeticError):
    """Every numerical back-end failed to produce a solution that passes verification."""


class InvalidCheckArgument(VerimonoError, ValueError):
    """A check was asked to verify nothing: ``examples <= 0``, an empty list of problems, ``T <= 0``, a
    non-positive time budget.  A check that evaluates nothing must not be able to pass."""


class UnitTimeout(VerimonoError, TimeoutError):
    """A unit of work (one law on one operator, one check of one stepper) exceeded its time budget."""


__all__ = [
    "VerimonoError",
    "InvalidProblem",
    "InvalidGrid",
    "OutsideDomain",
    "NotMonotone",
    "InfeasibleStep",
    "SolverFailure",
    "InvalidCheckArgument",
    "UnitTimeout",
]
