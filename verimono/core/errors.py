"""Typed errors raised on bad input.

Every error verimono raises because of what it was given derives from :class:`VerimonoError`, so a
caller can catch one class.  Messages say what was wrong and what was expected.  Every public exception
class of the package is defined here (the bottom layer, importing nothing), and re-exported where it is
used (``verimono.run.stages.StageUnavailable``, ``verimono.records.schema.SchemaError``, ...).
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


class UnverifiedSolution(SolverFailure):
    """verimono's own numerical machinery (its QP and LCP back-ends, its splitting iterations) produced no
    answer that passes its verification, on data that have one: a limit of the harness, not evidence against
    the operator or the problem.  A law evaluation that meets it is inconclusive (``undecided`` when no sample
    was decided), never a failure of the subject and never a pass."""


class InvalidClaim(VerimonoError, ValueError):
    """A stepper claim that cannot be stated (unknown scheme, nonpositive order, not callable)."""


class NotApplicable(Exception):
    """Raised by a law's evaluator when a requirement shows only while evaluating (e.g. ``x0 ∉ dom F(0,·)``
    where ``|F^0(0, x0)|`` is needed): the check driver (:mod:`verimono.checks.core`) makes the record a
    skip with this reason.  Not an error of the caller's input, so not a :class:`VerimonoError`."""


class UnknownProfile(VerimonoError, ValueError):
    """A profile name other than ``dev``, ``ci`` or ``thorough``."""


class UnknownStage(VerimonoError, ValueError):
    """A stage name that is not registered."""


class UndeclaredStageRead(VerimonoError, RuntimeError):
    """A stage read a result another stage of the same run writes (``context.costs``, ``context.partitions``)
    without declaring that stage in ``register_stage(..., after=...)``."""


class StageUnavailable(VerimonoError):
    """A stage cannot run here (its module is not installed yet, or its data are absent)."""


class BadTarget(VerimonoError, ValueError):
    """``MODULE:OBJECT`` does not name an importable operator or stepper."""


class BadExecutor(VerimonoError, ValueError):
    """An ``--executor`` that verimono cannot use: an unknown form, no dask installed, no scheduler
    answering, or worker processes that do not start."""


class SchemaError(VerimonoError, ValueError):
    """A results/baseline document is missing, not JSON, not verimono's, or of an incompatible version."""


class IncompatibleBaseline(SchemaError):
    """The baseline records a different kind of run (command, target, profile, selection) than the
    results, or no executed record at all."""


class MissingOptionalDependency(VerimonoError, ImportError):
    """An optional extra (e.g. cvxpy/clarabel for the KYP SDP) is not installed."""


class BatchStepError(VerimonoError, ArithmeticError):
    """Some rows of a batched ``LinearRelationSystem.simulate`` failed; the others ran to the end.

    ``failures``: the ``verimono.lcs.RowFailure`` (row, step, t, error) of each failed row;
    ``trajectory``: every row's results (``x (K+1, B, n)``, ``extras["z"], extras["w"] (K, B, m)``) with NaN
    after a row's failure; ``valid`` ``(K+1, B)``: which states were computed."""

    def __init__(self, failures: list, trajectory, valid) -> None:
        self.failures, self.trajectory, self.valid = failures, trajectory, valid
        shown = "; ".join(str(f) for f in failures[:5])
        more = f"; and {len(failures) - 5} more" if len(failures) > 5 else ""
        super().__init__(f"{len(failures)} of {valid.shape[1]} rows failed (the others ran to the end; "
                         f"results in .trajectory, .valid): {shown}{more}")

    @property
    def rows(self) -> list[int]:
        return [f.row for f in self.failures]


class ProxOutputError(VerimonoError, TypeError):
    """A prox (or its ``value``) returned something that is not one array of the operator's shape (a tuple,
    a list of arrays, a non-scalar value): verimono does not guess which part is the point."""


class InputModified(VerimonoError, RuntimeError):
    """A member of the subject wrote into the point it was given (or into the buffer around it): the caller's
    array changed (:mod:`verimono.checks.engine.forms`)."""


class InvalidCheckArgument(VerimonoError, ValueError):
    """A check was asked to verify nothing: ``examples <= 0``, an empty list of problems, ``T <= 0``, a
    non-positive time budget.  A check that evaluates nothing must not be able to pass."""


class UnitTimeout(VerimonoError, TimeoutError):
    """A unit of work (one law on one operator, one check of one stepper) exceeded its time budget.

    ``evidence`` (a dict, set by the limit that raised it and completed by its unit) is what the budget saw —
    the budget, the seconds the call in flight had run, how many evaluations finished and whether they all
    held — from which :func:`verimono.records.verdicts.classify` decides failed or undecided."""

    evidence: dict = {}


class OutputNotWritable(VerimonoError, OSError):
    """An output folder or file cannot be created or written (checked before any work is done, and when a
    write fails: a full disk, an unwritable folder).  Its text is one line naming the path; ``errno`` and
    ``filename`` are those of the ``OSError`` it stands for."""

    def __str__(self) -> str:
        return str(self.args[0]) if len(self.args) == 1 else OSError.__str__(self)


class NothingToResume(VerimonoError, ValueError):
    """``--resume`` without an incomplete results file of the same kind of run in the output folder."""


class IncompatibleResults(SchemaError):
    """The results (or baseline) are marked incomplete: an interrupted run verifies only part of the
    battery, so the gate cannot decide (exit status 2)."""


__all__ = [
    "InputModified",
    "ProxOutputError",
    "VerimonoError",
    "BatchStepError",
    "InvalidProblem",
    "InvalidGrid",
    "OutsideDomain",
    "NotMonotone",
    "InfeasibleStep",
    "SolverFailure",
    "InvalidClaim",
    "NotApplicable",
    "UnknownProfile",
    "UnknownStage",
    "UndeclaredStageRead",
    "StageUnavailable",
    "BadTarget",
    "BadExecutor",
    "SchemaError",
    "IncompatibleBaseline",
    "MissingOptionalDependency",
    "InvalidCheckArgument",
    "UnitTimeout",
    "OutputNotWritable",
    "NothingToResume",
    "IncompatibleResults",
]
