"""The check core: a law declared once, one outcome type, one driver.

Every law of verimono — a law of an operator's resolvent, of a stepper's trajectories, or sampled
evidence for an assumption of a problem — is a :class:`Law`: its record name, the paper's label, the
kind of subject it judges (``"operator"``, ``"stepper"``, ``"problem"``), what it *requires* and the
function that evaluates it.  Requirements are checked from the declaration **before anything runs**, so
a law that does not apply is a skip whose reason comes from the declaration:

* :class:`Member` — an operator member (``min_norm``, ``contains``, ``project_domain``);
* :class:`Claimed` — what a stepper claims (:mod:`verimono.claims`: ``scheme="proximal"``, or the
  contraction claim);
* :class:`Holds` — a condition on the problem with its reason (stated φ/σ/θ of (A3)/(LG)/(YB), a
  Lipschitz constant for ``f``, no initial jump, ...).

:func:`run` is the one driver: it owns the timing, the exception-to-status policy (a member the subject
lacks at run time is a skip; :class:`verimono.UnverifiedSolution` — verimono's own solvers gave no verified
answer — is ``undecided``; any other exception is a failure of the subject, with its type and message)
and stamps the law's label on the record.  Law bodies return an :class:`Outcome` (the one outcome type:
the worst observed ratio against the bound 1, where, and what was compared) or a finished record.

Adding a law is one decorated function in the module of its subject kind plus a member of the zoo of
broken subjects that it catches::

    @law("in_domain", "e:x k+1 props.1", subject="stepper", requires=(PROXIMAL_CLAIM,))
    def check_in_domain(stepper, problem, *, seed=0): ...
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any, Callable, Iterable

from ..claims import Claim, claim_of
from ..errors import NotApplicable, UnverifiedSolution
from ..results import FAILED, PASSED, SKIPPED, UNDECIDED, CheckResult

SUBJECTS = ("operator", "stepper", "problem")


# -- the one outcome type ---------------------------------------------------------------------------

@dataclasses.dataclass
class Outcome:
    """What one evaluation of a law found: ``worst`` is the largest observed ``lhs / (rhs + slack)``
    (the law holds when ``worst ≤ 1``), ``k`` the offending step (trajectory laws), ``counter`` the
    counterexample, ``what`` the inequality compared.  ``inconclusive`` marks an evaluation that can
    neither confirm nor refute the law there: counted, never a pass.  ``lhs``, ``rhs``, ``slack`` are
    kept when the law is one inequality (:meth:`compare`).  A non-finite ``worst`` is a failure."""

    worst: float
    k: int | None = None
    counter: dict[str, Any] = dataclasses.field(default_factory=dict)
    details: dict[str, Any] = dataclasses.field(default_factory=dict)
    what: str = ""
    inconclusive: bool = False
    lhs: float | None = None
    rhs: float | None = None
    slack: float | None = None

    @classmethod
    def compare(cls, lhs: float, rhs: float, slack: float, what: str, info: dict | None = None, *,
                inconclusive: bool = False) -> "Outcome":
        """The outcome of one inequality ``lhs ≤ rhs + slack``; ``worst = lhs / (rhs + slack)``, ``inf``
        when either side is not finite, and for ``rhs + slack = 0`` 0 or ``inf``."""
        return cls(_ratio(lhs, rhs, slack), counter=dict(info or {}), what=what, inconclusive=inconclusive,
                   lhs=float(lhs), rhs=float(rhs), slack=float(slack))

    @property
    def ratio(self) -> float:
        return self.worst

    @property
    def info(self) -> dict[str, Any]:
        return self.counter

    @property
    def failed(self) -> bool:
        return not self.worst <= 1.0     # NaN fails


def _ratio(lhs: float, rhs: float, slack: float) -> float:
    den = rhs + slack
    if not (math.isfinite(lhs) and math.isfinite(den)):
        return math.inf
    if den > 0.0:
        return lhs / den
    return 0.0 if lhs <= 0.0 else math.inf


# -- requirements -----------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Member:
    """The operator must provide ``name`` (a method it overrides, or a member it was given)."""

    name: str

    def unmet(self, ctx: "Context") -> str | None:
        op = ctx.operator
        if op is None or provides(op, self.name):
            return None
        return f"needs a member the operator lacks: {_subject_name(op)} does not provide {self.name}"


@dataclasses.dataclass(frozen=True)
class Claimed:
    """The stepper must claim ``what``: ``"proximal"`` (it is the paper's scheme) or ``"contracts"``."""

    what: str
    because: str

    def unmet(self, ctx: "Context") -> str | None:
        claim = ctx.claim
        if claim is None:
            return None
        ok = claim.proximal if self.what == "proximal" else claim.contracts
        if ok:
            return None
        need = "scheme='proximal'" if self.what == "proximal" else "the contraction claim (contracts=True)"
        return f"needs {need}; the stepper claims {claim.describe()}: {self.because}"


@dataclasses.dataclass(frozen=True)
class Holds:
    """A condition on the problem: ``test(problem)`` returns ``None`` when it holds, else the reason."""

    test: Callable[[Any], str | None]

    def unmet(self, ctx: "Context") -> str | None:
        return None if ctx.problem is None else self.test(ctx.problem)


PROXIMAL_CLAIM = Claimed("proximal", "the law is a property of the iterates of the paper's scheme "
                                     "(eq:iteration) on the given grid, not of every convergent scheme")
CONTRACTION_CLAIM = Claimed("contracts", "two solutions of a scheme that only converges need not contract "
                                         "step by step")


def provides(op: Any, member: str) -> bool:
    """Whether the operator provides ``member``: its ``provides(member)`` (:meth:`verimono.Operator.provides`)
    where it says, else whether it has the member at all (a duck-typed operator)."""
    says = getattr(op, "provides", None)
    return bool(says(member)) if callable(says) else callable(getattr(op, member, None))


@dataclasses.dataclass
class Context:
    """What a law's requirements are judged on."""

    operator: Any = None
    problem: Any = None
    claim: Claim | None = None


# -- the law declaration ----------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Law:
    """A law declared once: record name, the paper's label, subject kind, requirements, evaluator."""

    name: str
    label: str
    subject: str
    evaluate: Callable[..., Any]
    requires: tuple = ()
    doc: str = ""

    def unmet(self, ctx: Context) -> str | None:
        """The first unmet requirement's reason (``None`` when the law applies)."""
        for req in self.requires:
            why = req.unmet(ctx)
            if why:
                return why
        return None


REGISTRY: dict[str, dict[str, Law]] = {kind: {} for kind in SUBJECTS}


def law(name: str, label: str, *, subject: str, requires: Iterable = ()) -> Callable:
    """Declare the decorated function as the law ``name`` of ``subject`` kind (registered in order)."""
    if subject not in SUBJECTS:
        raise ValueError(f"subject must be one of {SUBJECTS}, got {subject!r}")

    def deco(fn: Callable) -> Callable:
        decl = Law(name, label, subject, fn, tuple(requires), (fn.__doc__ or "").strip())
        REGISTRY[subject][name] = decl
        fn.law = decl
        return fn
    return deco


def laws_of(subject: str) -> dict[str, Law]:
    """The registered laws of a subject kind, in declaration order."""
    return dict(REGISTRY[subject])


# -- the driver -------------------------------------------------------------------------------------

def _subject_name(obj: Any) -> str:
    return getattr(obj, "name", None) or getattr(obj, "__name__", None) or type(obj).__name__


def subject_of(decl: Law, *, operator: Any = None, stepper: Any = None, problem: Any = None) -> str:
    """The record's subject: the operator's name, ``"<stepper> on <problem>"``, or the problem's name."""
    if decl.subject == "operator":
        return _subject_name(operator)
    if decl.subject == "stepper":
        return f"{_subject_name(stepper)} on {problem.name}"
    return problem.name


def run(decl: Law | Callable, *args: Any, operator: Any = None, stepper: Any = None, problem: Any = None,
        call: Callable[[], CheckResult] | None = None, **kwargs: Any) -> CheckResult:
    """Run one law: requirements first (a skip with the declaration's reason), then the evaluator
    (``decl.evaluate(*args, **kwargs)``, or ``call()`` — a search driver around it) under the one
    exception policy; the record gets its duration and the law's label (``details["label"]``)."""
    decl = getattr(decl, "law", decl)
    start = time.perf_counter()
    op = operator if operator is not None else getattr(problem, "operator", None)
    ctx = Context(operator=op, problem=problem, claim=None if stepper is None else claim_of(stepper))
    subject = subject_of(decl, operator=operator, stepper=stepper, problem=problem)
    why = decl.unmet(ctx)
    if why:
        return CheckResult(decl.name, subject, SKIPPED, message=why, details={"label": decl.label},
                           duration=time.perf_counter() - start)
    try:
        rec = decl.evaluate(*args, **kwargs) if call is None else call()
    except NotApplicable as exc:
        rec = CheckResult(decl.name, subject, SKIPPED, message=str(exc))
    except NotImplementedError as exc:
        rec = CheckResult(decl.name, subject, SKIPPED, message=f"not available: {exc}")
    except UnverifiedSolution as exc:   # a limit of the harness: never a failure of the subject, never a pass
        rec = CheckResult(decl.name, subject, UNDECIDED, message=f"verimono's own solvers gave no verified answer: "
                          f"{exc}", details={"exception": type(exc).__name__})
    except Exception as exc:   # the subject raised on a valid input: a failure of the subject, never a crash
        rec = CheckResult(decl.name, subject, FAILED, message=f"{type(exc).__name__}: {exc}",
                          details={"exception": type(exc).__name__})
    rec.details.setdefault("label", decl.label)
    rec.duration = time.perf_counter() - start
    return rec


def record(name: str, subject: str, outcome: Outcome, *, passed: str, failed: str | None = None,
           bound: float = 1.0, **kw: Any) -> CheckResult:
    """The record of an :class:`Outcome` against ``bound``: passed with ``passed`` as message, or failed
    with the counterexample and ``failed`` (default: the counterexample's ``message``)."""
    if not outcome.failed:
        return CheckResult(name, subject, PASSED, worst=outcome.worst, bound=bound, message=passed,
                           details=dict(outcome.details), **kw)
    counter = dict(outcome.counter)
    msg = failed or counter.pop("message", "") or f"{name} violated"
    return CheckResult(name, subject, FAILED, worst=outcome.worst, bound=bound, counterexample=counter,
                       message=msg, details=dict(outcome.details), **kw)


__all__ = ["Outcome", "Law", "law", "laws_of", "REGISTRY", "run", "record", "Member", "Claimed", "Holds",
           "Context", "provides", "NotApplicable", "PROXIMAL_CLAIM", "CONTRACTION_CLAIM", "SUBJECTS", "subject_of"]
