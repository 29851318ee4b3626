"""The check core: a law declared once, one outcome type, one exception policy, one subject name.

Every law of verimono is one decorated *evaluator* returning an :class:`Outcome`::

    @operator_law("monotone", "(A1)")
    def check_monotone(op, s):
        \"\"\"⟨x_a − x_b, y_a − y_b⟩ ≥ 0 on graph points of F(t,·).\"\"\"
        ...
        return Outcome.compare(lhs, rhs, slack, "what was compared", counterexample)

The decorator (:func:`law`, specialised per subject kind by the module that owns the kind's *driver*)
registers a :class:`Law` — record name, the paper's label, subject kind, requirements, evaluator — and
returns the public ``check_<name>``: the driver applied to that law.  A driver decides *where* the
evaluator is evaluated (samples searched for an operator, the partitions of a stepper's battery, the
sampled times of a problem's assumptions) and keeps the worst outcome; this module decides everything
else, once:

* **requirements** (:class:`Member`, :class:`Claimed`, :class:`Holds`) are judged before anything runs,
  so a law that does not apply is a skip whose reason comes from the declaration;
* **the exception policy** (:func:`classify`) maps what an evaluation raised to a status, for a whole
  record (:func:`run`), for one sample of a search, for a unit of work and for a stage of a run alike;
* **the record** (:func:`record`) of an outcome: passed when its ratio is within its bound, failed with
  the counterexample otherwise, never passed on a non-finite ratio — made, as every record of verimono, by
  the one record builder :func:`new_record`.  The builder and the policy are defined in
  :mod:`verimono.records.verdicts` (the execution layer below the checks makes records too) and re-exported
  here;
* **the subject's name** (:func:`subject_name`), decided once whatever the status;
* **the precision** a law judges its subject at (:func:`verimono.core.tolerances.judged_precision`): the
  coarsest dtype the subject returned or was given while the law ran, stated in the record
  (``details["dtype"]``, ``details["rtol"]``; a failure's message names a precision other than float64).
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import time
from typing import Any, Callable, Iterable

from ..core.claims import Claim, claim_of
from ..core.naming import subject_name
from ..core.errors import InvalidCheckArgument, NotApplicable
from ..core.operators import provides
from ..records.results import FAILED, PASSED, SKIPPED, CheckResult
from ..records.verdicts import SUBJECT_EXITS, classify, new_record, record_of_exception
from ..core.tolerances import judged_at_scale, judged_precision
from .engine.data_scale import judged_at_data_scale, stated_scale

SUBJECTS = ("operator", "stepper", "problem", "system", "estimator")

#: the typed domains a law's statement quantifies over ("for all ..."), each searched by the engine
#: (:mod:`verimono.checks.engine`) when a law declares it (:attr:`Law.over`); the record's ``details["searched"]``
#: states what was reached on each
QUANTIFIERS = {
    "points": "x ∈ R^n: NumPy draws, hypothesis, the scale sweep (|x| from 10^-9 to 10^6, on and just outside the "
              "domain's boundary), the scale phase (whole points from 2^-1074 to 10^99: engine/scales.py)",
    "direction": "the direction of x2 − x1 (or of the exposed boundary point) over the sphere S^{n−1}",
    "lam": "the step λ over every decade the precision represents (float64 [1e-153, 1e7])",
    "mu": "the step μ, as λ",
    "nu": "the step ν, as λ",
    "t": "t ∈ [0, T], both ends (the operator laws: the horizon; the assumption laws: a stratified, jittered "
         "design by count, T/2048 at ci)",
    "offset": "the distance of x1 from the domain's boundary along its outer normal, 10^-12 to 10^3 (1 + |x|)",
    "scale": "|x| over 10^-9 to 10^6 (the kink 0 and far points)",
    "form": "the input's form: int64, strided and offset views, read-only, the declared dtype",
}


# -- the one outcome type ---------------------------------------------------------------------------

@dataclasses.dataclass
class Outcome:
    """What an evaluation of a law found.

    ``worst`` is the largest observed ``lhs / (rhs + slack)``; the law holds when ``worst ≤ bound``
    (a NaN never does); ``None`` for a law without a ratio, whose ``status`` then says.  ``k`` is the offending step of a trajectory, ``counter`` the counterexample (its
    ``"message"`` is the record's message on a failure), ``message`` the record's message when the law
    holds, ``what`` the inequality compared.  ``inconclusive`` marks an evaluation that can neither
    confirm nor refute the law there (counted, never a pass); ``status`` an explicit status where the
    ratio does not decide (an undecided search).  ``lhs``, ``rhs``, ``slack`` are kept when the law is
    one inequality (:meth:`compare`)."""

    worst: float | None
    k: int | None = None
    counter: dict[str, Any] = dataclasses.field(default_factory=dict)
    details: dict[str, Any] = dataclasses.field(default_factory=dict)
    what: str = ""
    inconclusive: bool = False
    lhs: float | None = None
    rhs: float | None = None
    slack: float | None = None
    bound: float = 1.0
    message: str = ""
    status: str | None = None

    @classmethod
    def compare(cls, lhs: float, rhs: float, slack: float, what: str, info: dict | None = None, *,
                inconclusive: bool = False) -> "Outcome":
        """The outcome of one inequality ``lhs ≤ rhs + slack``: ``worst = lhs / (rhs + slack)``, ``inf``
        when either side is not finite, and for ``rhs + slack = 0`` 0 or ``inf``."""
        return cls(ratio(lhs, rhs, slack), counter=dict(info or {}), what=what, inconclusive=inconclusive,
                   lhs=float(lhs), rhs=float(rhs), slack=float(slack))

    @classmethod
    def inconclusive_sample(cls, what: str, info: dict | None = None) -> "Outcome":
        """An evaluation that neither confirms nor refutes the law (``what`` says why)."""
        return cls.compare(0.0, 0.0, 1.0, what, info, inconclusive=True)

    @property
    def ratio(self) -> float:
        return self.worst

    @property
    def info(self) -> dict[str, Any]:
        return self.counter

    @property
    def failed(self) -> bool:
        if self.worst is None:
            return self.status == FAILED
        return not self.worst <= self.bound     # NaN fails


def ratio(lhs: float, rhs: float, slack: float) -> float:
    """``lhs / (rhs + slack)``; ``inf`` when a side is not finite; 0 or ``inf`` when the denominator is 0."""
    den = rhs + slack
    if not (math.isfinite(lhs) and math.isfinite(den)):
        return math.inf
    if den > 0.0:
        return lhs / den
    return 0.0 if lhs <= 0.0 else math.inf


def worst_of(outcomes: Iterable[Outcome]) -> Outcome | None:
    """The outcome with the largest ratio (a NaN ratio counts as the largest)."""
    worst = None
    for o in outcomes:
        if worst is None or not o.worst <= worst.worst:
            worst = o
    return worst


# -- the subject's name -----------------------------------------------------------------------------

def stepper_subject(stepper: Any, problem: Any) -> str:
    """The subject of a stepper's record on a problem (or a problem's name): ``"<stepper> on <problem>"``."""
    return f"{subject_name(stepper)} on {problem if isinstance(problem, str) else subject_name(problem)}"


# -- the one exception policy and the one record builder ---------------------------------------------
# (:mod:`verimono.records.verdicts`, below the execution layer, which makes records too: re-exported here)

# -- requirements -----------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Member:
    """The operator must provide ``name`` (a method it overrides, or a member it was given)."""

    name: str

    def unmet(self, ctx: "Context") -> str | None:
        op = ctx.operator
        if op is None or provides(op, self.name):
            return None
        return f"needs a member the operator lacks: {subject_name(op)} does not provide {self.name}"


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


@dataclasses.dataclass
class Context:
    """What a law's requirements are judged on."""

    operator: Any = None
    problem: Any = None
    claim: Claim | None = None


# -- the law declaration ----------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Law:
    """A law declared once: record name, the paper's label, subject kind, requirements, evaluator, and the
    driver that evaluates it on a subject (``driver(law, subject, ...) -> CheckResult``)."""

    name: str
    label: str
    subject: str
    evaluate: Callable[..., Any]
    requires: tuple = ()
    doc: str = ""
    driver: Callable[..., CheckResult] | None = dataclasses.field(default=None, compare=False, repr=False)
    #: part of its kind's battery (``check_operator``, ``check_stepper``, ...); else run on its own
    battery: bool = True
    #: the public ``check_<name>`` the decorator made
    public: Callable[..., CheckResult] | None = dataclasses.field(default=None, compare=False, repr=False)
    #: the statement's quantifiers, as data: names of :data:`QUANTIFIERS` the engine searches for this law
    over: tuple = ()

    def unmet(self, ctx: Context) -> str | None:
        """The first unmet requirement's reason (``None`` when the law applies)."""
        for req in self.requires:
            why = req.unmet(ctx)
            if why:
                return why
        return None

    def check(self, *args: Any, **kwargs: Any) -> CheckResult:
        """The law on a subject, through its driver (what the public ``check_<name>`` does)."""
        return self.driver(self, *args, **kwargs)


REGISTRY: dict[str, dict[str, Law]] = {kind: {} for kind in SUBJECTS}


def law(name: str, label: str, *, subject: str, driver: Callable[..., CheckResult],
        requires: Iterable = (), battery: bool = True,
        over: Iterable[str] = ()) -> Callable[[Callable], Callable[..., CheckResult]]:
    """Declare the decorated evaluator as the law ``name`` of ``subject`` kind (registered in declaration
    order) and return the public check: ``driver`` applied to the law, with the evaluator's docstring and
    the driver's keyword arguments (``check.law`` is the :class:`Law`).  ``battery=False``: a law run on
    its own (by a stage of the run), not by its kind's battery.  ``over``: the statement's quantifiers
    (:data:`QUANTIFIERS`), which the engine searches for it."""
    if subject not in SUBJECTS:
        raise ValueError(f"subject must be one of {SUBJECTS}, got {subject!r}")
    over = tuple(over)
    unknown = [q for q in over if q not in QUANTIFIERS]
    if unknown:
        raise ValueError(f"unknown quantifiers {unknown}: each is one of {tuple(QUANTIFIERS)}")

    def deco(evaluate: Callable) -> Callable[..., CheckResult]:
        @functools.wraps(evaluate)
        def check(*args: Any, **kwargs: Any) -> CheckResult:
            return driver(decl, *args, **kwargs)

        decl = Law(name, label, subject, evaluate, tuple(requires), inspect.cleandoc(evaluate.__doc__ or ""),
                   driver, battery, check, over)
        REGISTRY[subject][name] = decl
        params = list(inspect.signature(driver).parameters.values())[1:]
        check.__signature__ = inspect.Signature(params, return_annotation=CheckResult)
        check.__name__ = check.__qualname__ = f"check_{name}"
        check.__wrapped__ = driver
        check.law = decl
        return check
    return deco


def laws_of(subject: str, *, battery: bool | None = None) -> dict[str, Law]:
    """The registered laws of a subject kind, in declaration order (``battery=True``: those of its
    battery only)."""
    return {n: d for n, d in REGISTRY[subject].items() if battery is None or d.battery == battery}


# -- running one law --------------------------------------------------------------------------------

def run(decl: Law, subject: str, evaluate: Callable[[], Any], *, operator: Any = None, stepper: Any = None,
        problem: Any = None, seed: int | None = None, horizon: float | None = None,
        rejudge: bool = True) -> CheckResult:
    """Run one law on one subject: its requirements first (a skip with the declaration's reason), then
    ``evaluate()`` — an :class:`Outcome` or a finished record — under the one exception policy
    (:func:`classify`).  The record gets the law's label and, where the evaluation did not measure its
    own, its duration.

    A law with an operator (``operator``, or ``problem.operator``: the operator laws, a stepper's trajectory laws
    and order, the assumption laws, the bounds) is judged at the operator's own scale
    (:mod:`verimono.core.tolerances`, "the operator's own scale"): at its ``data_scale`` when stated (the record's
    ``details["data_scale"]`` says so); else, with ``rejudge``, a failure with finite sides is judged once more at
    the scale inferred from the domain's extent over ``[0, horizon]`` (default ``problem.T``, else 1), and is
    *undecided* when it holds there (:func:`verimono.checks.engine.data_scale.judged_at_data_scale`)."""
    op = operator if operator is not None else getattr(problem, "operator", None)
    if op is None:
        return _run(decl, subject, evaluate, operator, stepper, problem, seed)
    stated = stated_scale(op)
    with judged_at_scale(stated):
        rec = _run(decl, subject, evaluate, operator, stepper, problem, seed)
    if rec.status == SKIPPED:
        return rec
    if stated is not None:
        rec.details["data_scale"] = {"stated": stated}
        return rec
    if not rejudge:
        return rec
    if horizon is None:
        horizon = float(getattr(problem, "T", 1.0) or 1.0)
    # judged again at the precision it was judged at (runs kept by shared_runs are not computed, nor observed, again)
    return judged_at_data_scale(rec, op, horizon,
                                lambda: _run(decl, subject, evaluate, operator, stepper, problem, seed,
                                             rec.details.get("dtype")))


def _run(decl: Law, subject: str, evaluate: Callable[[], Any], operator: Any, stepper: Any, problem: Any,
         seed: int | None, precision: str | None = None) -> CheckResult:
    """:func:`run` at the operator's scale in force (and at least at ``precision``)."""
    start = time.perf_counter()
    op = operator if operator is not None else getattr(problem, "operator", None)
    ctx = Context(operator=op, problem=problem, claim=None if stepper is None else claim_of(stepper))
    why = decl.unmet(ctx)
    if why:
        rec = new_record(decl.name, subject, SKIPPED, message=why, seed=seed)
    else:
        with judged_precision(precision) as precision:
            try:
                out = evaluate()
                rec = out if isinstance(out, CheckResult) else record(decl.name, subject, out, seed=seed)
            except InvalidCheckArgument:
                raise
            except (Exception, *SUBJECT_EXITS) as exc:  # noqa: BLE001 - the one policy decides what it means
                rec = record_of_exception(decl.name, subject, exc, seed=seed)
        # the precision the subject was judged at, stated in every record it decided (tolerances.py)
        rec.details.update(precision.details())
        if rec.status == FAILED and precision.note():
            rec.message += precision.note()
    rec.details.setdefault("label", decl.label)
    if rec.duration is None:
        rec.duration = time.perf_counter() - start
    return rec


def record(name: str, subject: str, outcome: Outcome, **kw: Any) -> CheckResult:
    """The record of an :class:`Outcome`: its explicit status, else passed when its ratio is within its
    bound (message: ``outcome.message``), else failed with the counterexample (message: its
    ``"message"``, else ``outcome.message``)."""
    details = dict(outcome.details)
    status = outcome.status or (FAILED if outcome.failed else PASSED)
    ratio = {} if outcome.worst is None else {"worst": outcome.worst, "bound": outcome.bound}
    if status != FAILED:
        return new_record(name, subject, status, message=outcome.message, details=details,
                          **(ratio if status == PASSED else {}), **kw)
    counter = dict(outcome.counter)
    msg = counter.pop("message", "") or outcome.message or f"{name} violated"
    return new_record(name, subject, FAILED, counterexample=counter or None, message=msg, details=details,
                      **ratio, **kw)


__all__ = ["Outcome", "Law", "law", "laws_of", "REGISTRY", "QUANTIFIERS", "run", "record", "record_of_exception", "classify", "new_record",
           "Member", "Claimed", "Holds", "Context", "provides", "NotApplicable", "PROXIMAL_CLAIM",
           "CONTRACTION_CLAIM", "SUBJECTS", "subject_name", "stepper_subject", "ratio", "worst_of"]
