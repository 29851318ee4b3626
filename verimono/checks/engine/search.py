"""The driver of the operator laws: a search for a sample that breaks the law.

A law of an operator is an evaluator ``law(op, sample) -> Outcome`` (:mod:`verimono.checks.core`); the
search evaluates it, in order, on

1. ``examples`` NumPy draws from the distribution of :func:`verimono.checks.samples.law_samples`
   (:func:`verimono.checks.sweep.law_draws`, seeded by the record's seed), then the simplest sample alone
   (``x1 = x2 = 0``, ``λ = μ = ν = 1``, ``t = 0``) and :func:`~verimono.checks.sweep.edge_count` ``- 1`` more
   **edge samples** (:func:`verimono.checks.sweep.edge_draws`): the kinds of points hypothesis's generate phase
   contributed beyond the draws — its simplest example, identical points, hypothesis's extreme floats (the
   smallest normals of float64 and float32, epsilons, tiny ``10^-307 … 10^-10``) and subnormals beside ordinary
   entries, ``-0.0``, values next to the simple ones, coordinates of ``x2`` equal to ``x1``'s, tiny times —
   drawn by NumPy from the seed, the same on every machine (``details["searched"]["edge_samples"]``);
2. hypothesis (:func:`~verimono.checks.samples.law_samples`), only where its targeting and shrinking pay: when a
   draw or an edge sample broke the law, a search of all ``examples`` that climbs toward violations through
   :func:`hypothesis.target` on the ratio and shrinks a failing sample (a draw hypothesis does not meet again is
   shrunk greedily), and above :data:`NUMPY_DIM` coordinates, where the points are NumPy recipes that hypothesis
   draws (``details["searched"]["hypothesis_examples"]``); draws that found nothing go on to the sweep;
3. the scale sweep (:mod:`verimono.checks.sweep`), points from ``10^-9`` to ``10^6``, on and just outside
   the boundary of the domain;
4. the coordinate search (:mod:`verimono.checks.coordinates`): each coordinate of the worst sample — the
   step sizes across decades up to ``Λ = 10``, the time, the scale of the points, their offset from the
   boundary — maximised on its own (:func:`verimono.checks.supremum.maximise`), and the worst sample in every
   input form (:mod:`verimono.checks.forms`: integer, strided and offset views into garbage, read-only, the
   declared dtype — forms the NumPy draws cycle through too), the operator's input unchanged by every call.

Lists of samples known in advance — the draws, the sweep, each coordinate's design — are evaluated by the law's
vectorised form where it has one (:meth:`_Search.evaluate_many`, :mod:`verimono.checks.engine.batches`): a row
is accepted at its vectorised ratio only clearly inside the bound, every other row by the law's own evaluator.
The coordinate designs, the step decades, the edge samples, the sweep and the scale phase come as one block of arrays
each (:class:`verimono.checks.engine.blocks.SampleBlock`): the form reads the arrays, and a
:class:`~verimono.checks.engine.samples.Sample` is made only for a row the law's evaluator sees (the same sample,
field by field, as the list of samples would hold).

Every record says what was searched (``details["searched"]``: the range of ``|x|`` and of the step sizes,
the largest gap between the sampled times, each coordinate's range and resolution, the samples evaluated in
each input form).

Hypothesis's engine costs about 1.7 ms per example here (and ~0.7 ms to start a search) against about 0.02 ms per
NumPy draw, and a vectorised evaluation about 7 µs per sample (one batched call) to 25 µs (one call per distinct
step size): the edge samples replaced a search of ``max(3, examples // 4)`` hypothesis
examples on every law (docs/speed.md, "Edge samples in place of hypothesis's generate phase").  One given
``sample=`` (a :class:`~verimono.checks.samples.Sample` or its dict from a counterexample) is evaluated
alone instead: that is how a failure is replayed and how outer ``@given`` tests drive the laws.

A sample's exception is judged by the core's one policy (:func:`verimono.checks.core.classify`): a member
the operator lacks stops the search (skipped) — but only when it raises ``NotImplementedError`` at the
simplest sample too, before any sample was evaluated: a member that evaluates elsewhere and raises here
raises on part of its domain, and the sample fails —; a limit of verimono's own solvers makes the sample
inconclusive (counted in ``details["harness_limited"]``), anything else fails the sample, and so does a
declared batched call that raises (:mod:`verimono.checks.batches`).  Inconclusive samples are counted and
never pass: a record whose every sample was inconclusive is skipped, undecided when verimono's own solvers
decided none, and a law passes only with at least :data:`MIN_EVALUATED` samples evaluated to a verdict
(undecided otherwise, with the counts).  The unit's time budget (:mod:`verimono.execution.timeouts`) bounds the
whole search (in calibration units: a slower or busier machine gets more seconds), judged by the one policy
of a unit out of time (:func:`verimono.records.verdicts.timeout_verdict`): a search that runs out of time
after samples that all held, or before any sample while no call of the operator was running, is undecided
(time budget, ``k`` samples); an operator call that never returns fails — one that had run more than half
the budget and :data:`~verimono.records.verdicts.HANG_MULTIPLE` x longer than every sample before it.  The
budget's interrupt is raised only in the law's and the operator's code, never inside hypothesis's engine
(:mod:`verimono.execution.interrupts`; each sample starts at a safe point), and what the engine itself raises
— it gave up, or failed after an interrupt — is undecided (a limit of the harness), never failed.  The
root-cause probe before the search runs under the budget too (:func:`bounded_root_cause`): a resolvent that
does not return within it is the root cause, probed once per operator, so a battery on a hanging operator
costs one budget, not one per call.
"""

from __future__ import annotations

import dataclasses
import math
import random
import time
from typing import Any, Callable

import hypothesis
import hypothesis.errors
import numpy as np
from hypothesis import HealthCheck, Phase, Verbosity, given, settings

from ...core.arrays import library_hint
from ...core._small import abs_max, row_abs_max
from ...core._reproducible import no_local_constants
from ...core.tolerances import current_rtol
from ..arguments import valid_horizon, valid_seed
from ...core.errors import InvalidCheckArgument, UnitTimeout
from ...execution.config import current as current_config
from ...execution.profiles import LARGE_N, large_n_count
from ...records.results import FAILED, PASSED, SKIPPED, UNDECIDED, CheckResult
from ...execution.timeouts import (checkpoint, current_budget, interrupted, interruptible, note_progress,
                                  time_limit, unlimited)
from ...records.verdicts import timeout_verdict
from .blocks import SampleBlock, make_sample
from .batches import CLOCK, PER_PASS, ROW_CELLS, VECTORISED, Rows, _BatchFailure, batched, prefetched, rows_accepted
from .coordinates import COORDINATES, coordinate_search, searched
from ..core import REGISTRY, Law, Outcome, classify, law, new_record, run, subject_name
from .forms import CONTIGUOUS, cycled, form_note, form_search, forms_for, in_form
from .samples import NUMPY_DIM, Sample, law_samples
from .supremum import budget
from .sweep import edge_count, edge_draws, law_draws, shrink, sweep_count, sweep_samples
from .scales import SCALE_CAP, beyond_judgement, judged_by, scale_samples

#: examples per law when ``examples`` is not given and the run configuration's profile is not one of
#: verimono's (a user's own); otherwise the profile's ``law_examples`` governs (:func:`default_examples`)
DEFAULT_EXAMPLES = 50
#: every law's ratio ``lhs / (rhs + slack)`` must not exceed this
BOUND = 1.0
#: ratios handed to hypothesis.target are clipped to this (observations must be finite)
TARGET_CAP = 1e12
#: the law that reports an operator whose resolvent raises on plain inputs (its statement: ``J_λ`` is
#: defined on all of ``R^n``); every other law is then not evaluated, so the cause is reported once
ROOT_LAW = "resolvent_single_valued"
#: marks an evaluation that verimono's own numerical machinery could not decide
HARNESS_LIMIT = "harness_limit"
#: a law passes only when at least this many samples were evaluated to a verdict (fewer when fewer
#: ``examples`` were asked for); fewer is undecided, with the counts
MIN_EVALUATED = 10
#: laws whose one evaluation is expensive (an independent minimiser per sample) skip the coordinate phase
COORDINATE_CAP = {"prox_minimiser": 0}
#: a member raising NotImplementedError at a sample is "not provided" only when it raises at this simple
#: sample too (x1 = 0, x2 = 10^-2, λ = μ = ν = 1, t = 0); else it raises on part of its domain: a failure
_SIMPLE = dict(lam=1.0, mu=1.0, nu=1.0, t=0.0)


def fresh_seed() -> int:
    """A new 32-bit seed (recorded in every result so that a run can be repeated)."""
    return random.SystemRandom().getrandbits(32)


def default_examples() -> tuple[int, str]:
    """``(examples per law, profile)`` when ``examples`` is not given: the ``law_examples`` of the run
    configuration's profile (``dev``/``ci``/``thorough``, :func:`verimono.execution.config.current`), else
    ``DEFAULT_EXAMPLES`` (a user's own hypothesis profile)."""
    cfg = current_config()
    return (DEFAULT_EXAMPLES if cfg.effort is None else cfg.effort.law_examples), cfg.profile


def positive_examples(examples: Any) -> int:
    """``examples`` as a positive integer; :class:`InvalidCheckArgument` otherwise (0 examples verify
    nothing)."""
    try:
        n = int(examples)
    except (TypeError, ValueError, OverflowError):
        raise InvalidCheckArgument(f"examples must be a positive integer, got {examples!r}") from None
    if isinstance(examples, bool) or n != examples or n < 1:
        raise InvalidCheckArgument(f"examples must be a positive integer, got {examples!r}")
    return n


def evaluate_sample(decl: Law, op: Any, s: Sample) -> Outcome:
    """``decl.evaluate(op, s)``, an exception judged by the core's policy: a member the operator lacks is
    raised (it stops the search), a limit of verimono's solvers or a hypothesis that does not hold there
    is an inconclusive sample, anything else a failed one.  A sample in another input form than contiguous
    is evaluated on the operator seen through that form (:func:`verimono.checks.forms.in_form`)."""
    try:
        out = decl.evaluate(op if s.form == CONTIGUOUS else in_form(op, s.form), s)
        if not isinstance(out, Outcome):     # verimono's own law answered no outcome: a limit of the harness, never the
            what = (f"verimono's law {decl.name} returned {type(out).__name__} instead of an outcome (a limit of "
                    "the harness, not the subject's fault)")                # subject's failure (nor a pass)
            return Outcome.inconclusive_sample(what, {HARNESS_LIMIT: what})
        return out
    except (InvalidCheckArgument, NotImplementedError):
        raise
    except Exception as exc:  # noqa: BLE001 - the core's policy decides
        if interrupted():     # raised after the unit's budget interrupted the sample: the timeout's, not the sample's
            raise
        status, message = classify(exc)
        message += form_note(s.form)
        if status == UNDECIDED:
            return Outcome.inconclusive_sample(message, {HARNESS_LIMIT: str(exc)})
        if status == SKIPPED:
            return Outcome.inconclusive_sample(message)
        return Outcome.compare(math.inf, 0.0, 1.0, f"raised {message}")


def root_cause(op: Any, horizon: float = 1.0) -> str | None:
    """Why ``op.resolvent`` cannot be evaluated at all — it raises (or returns no point of shape ``(n,)``)
    at ``x = 0`` or ``x = (1, ..., 1)`` with ``λ = 1``, ``t ∈ {0, horizon}`` — or ``None``.  A limit of
    verimono's own solvers there is no cause of the operator's: the laws meet it sample by sample."""
    for x in (np.zeros(op.dim), np.ones(op.dim)):
        for t in (0.0, float(horizon)):
            try:
                y = np.asarray(op.resolvent(x.copy(), 1.0, t))
            except Exception as exc:  # noqa: BLE001 - any exception is the root cause we report
                if classify(exc)[0] == UNDECIDED:
                    continue
                return (f"the resolvent raises {type(exc).__name__}: {exc} at x = {x[:3].tolist()}..., λ = 1, t = {t:g}"
                        + library_hint(exc, getattr(op, "array", "numpy")))
            if y.shape != x.shape:
                return f"the resolvent returns shape {y.shape} for a point of shape {x.shape} (λ = 1, t = {t:g})"
    return None


#: operators whose root-cause probe ran out of time, ``id → (operator, horizon, cause)`` (the most recent
#: :data:`SLOW_MEMORY`): the other laws of the battery take the cause without calling the operator again
_SLOW: dict[int, tuple[Any, float, str]] = {}
SLOW_MEMORY = 16


def bounded_root_cause(op: Any, horizon: float = 1.0) -> str | None:
    """:func:`root_cause` under the unit's time budget: a resolvent that does not return within it is the
    root cause (remembered for ``op``, so the next law does not wait for it again)."""
    hit = _SLOW.get(id(op))
    if hit is not None and hit[0] is op and hit[1] == horizon:
        return hit[2]
    try:
        with time_limit(current_budget(), f"the root-cause probe of {subject_name(op)}"):
            return root_cause(op, horizon)
    except UnitTimeout as exc:
        if classify(exc)[0] != FAILED:    # the budget ran out, but not in a call that does not return
            raise
        cause = f"the resolvent does not return within the time budget at x = 0, λ = 1 ({exc})"
    _SLOW.pop(id(op), None)
    _SLOW[id(op)] = (op, horizon, cause)
    while len(_SLOW) > SLOW_MEMORY:
        _SLOW.pop(next(iter(_SLOW)))
    return cause


def _amax(x: np.ndarray) -> float:
    """``max |x_i|`` (0 for an empty point), without ``np.max``'s dispatch (once per point of every sample)."""
    return abs_max(x) if x.size else 0.0


class _Violation(Exception):
    """Raised inside the hypothesis test when a sample breaks the law (so hypothesis shrinks it)."""


@dataclasses.dataclass
class _Search:
    """The state of one law's search on one operator: what was evaluated, the worst and the failing sample."""

    decl: Law
    op: Any
    runs: int = 0
    worst: Outcome | None = None
    worst_sample: Sample | None = None
    failure: Outcome | None = None
    failing: Sample | None = None
    unsupported: str | None = None
    found_by: str = ""
    inconclusive: int = 0
    inconclusive_what: str = ""
    harness_limited: int = 0
    #: when the sample being evaluated now started (``None`` between samples), and the slowest that returned
    in_flight: float | None = None
    slowest: float = 0.0
    violated: bool = False
    #: what was evaluated: |x1|, |x2| of every sample, its step sizes and time (details["searched"])
    xs: list = dataclasses.field(default_factory=list)
    lams: list = dataclasses.field(default_factory=list)
    ts: list = dataclasses.field(default_factory=list)
    #: the same of the rows a vectorised pass accepted, as the pass's arrays (:meth:`_commit`; read by :meth:`searched`)
    xs_rows: list = dataclasses.field(default_factory=list)
    lams_rows: list = dataclasses.field(default_factory=list)
    ts_rows: list = dataclasses.field(default_factory=list)
    coordinates: list = dataclasses.field(default_factory=list)
    #: the coordinate budget's cap at large n (:func:`verimono.execution.profiles.large_n_count`), stated in the record
    budget_note: str = ""
    horizon: float = 1.0
    #: samples evaluated in each input form (verimono.checks.forms)
    forms: dict = dataclasses.field(default_factory=dict)
    #: the last sample seen breaking the law while shrinking, with its outcome
    seen_failing: tuple | None = None
    #: lists of samples announced by :meth:`prefetch`, whose vectorised form the first of them to reach
    #: :meth:`evaluate_many` computes over all of them in one pass; ``pre``: ``id(sample) -> (sample, row)`` of that
    #: pass, and ``pre_rows`` its rows' ``(q, accepted, |x1|, |x2|, λ, μ, ν, t, inconclusive)``
    pending: list = dataclasses.field(default_factory=list)
    pre: dict = dataclasses.field(default_factory=dict)
    pre_rows: tuple = ()
    #: the announced :class:`SampleBlock` lists, ``id(block) -> (block, its first row in the pass)``
    pre_blocks: dict = dataclasses.field(default_factory=dict)
    #: the evaluator's message for the rows a vectorised pass found inconclusive by the law's own test (``Rows.inconclusive``)
    form_inconclusive_what: str = ""
    #: the law's budget and when it runs out (:func:`time.perf_counter`; ``None``: unlimited), shared by its phases
    deadline: tuple[float, float] | None = None
    #: in the scale phase (:func:`_scales`): above the sweep's ``|x|`` a sample is judged on ``J_λ`` finite there only
    #: (:func:`judged_by`), and a violation where the law's own side overflows is inconclusive (:func:`beyond_judgement`)
    scaling: bool = False
    #: the worst sample before the scale phase: where the coordinate phase starts (``None``: the worst sample)
    start: Sample | None = None

    @interruptible   # the law's and the subject's code: the unit's budget may stop it even under hypothesis
    def evaluate(self, s: Sample, climb: bool = False) -> float | None:
        """Evaluate one sample and return its ratio (``None`` when inconclusive or not evaluable);
        :class:`_Violation` when it breaks the law (``climb``: inside hypothesis, whose ``target`` then climbs
        toward large ratios).  A safe point of the unit's budget first
        (:func:`verimono.execution.timeouts.checkpoint`): an interrupt that waited for hypothesis's engine
        to return stops the search here."""
        checkpoint()
        start = self.in_flight = time.perf_counter()   # left set when the unit's budget interrupts the sample
        try:
            out = evaluate_sample(judged_by(self.decl, s) if self.scaling else self.decl, self.op, s)
        except NotImplementedError as exc:
            self.in_flight = None
            out = self.not_implemented(s, exc)
            if out is None:
                return None
        self.in_flight, self.slowest = None, max(self.slowest, time.perf_counter() - start)
        if not out.inconclusive and not out.ratio <= BOUND:
            # the scale phase's own limits (verimono.checks.engine.scales); elsewhere the law's own overflow
            why = beyond_judgement(out, s) if self.scaling else own_overflow(out)
            if why is not None:
                out = Outcome.inconclusive_sample(why, {HARNESS_LIMIT: why})
        self.runs += 1
        self.xs += [_amax(s.x1), _amax(s.x2)]
        self.lams += [s.lam, s.mu, s.nu]
        self.ts.append(s.t)
        self.forms[s.form] = self.forms.get(s.form, 0) + 1
        if out.inconclusive:
            self.inconclusive += 1
            self.inconclusive_what = out.what
            self.harness_limited += HARNESS_LIMIT in out.info
            self.note()
            return None
        r = out.ratio
        if self.worst is None or not r <= self.worst.ratio:
            self.worst, self.worst_sample = out, s
        if climb:
            hypothesis.target(min(r, TARGET_CAP) if r == r else TARGET_CAP, label=self.decl.name)
        if not r <= BOUND:
            self.failure, self.failing, self.violated = out, s, True
            self.note()
            raise _Violation(self.decl.name)
        self.note()
        return r

    def evaluate_many(self, samples: list[Sample]) -> list[float | None]:
        """:meth:`evaluate` of every sample, in order, with the law's vectorised form where it has one
        (:data:`verimono.checks.engine.batches.VECTORISED`; not for a declared batched subject, whose calls the
        prefetch batches, nor for the input forms): the rows its arithmetic shows clearly inside the bound
        (ratio finite and, with its rounding bound, within it: :meth:`Rows.accepted`) are counted as evaluated at that ratio, and every other sample is
        evaluated by the law's own evaluator (a failure is only ever decided, and recorded, there).  Returns the
        ratios (``None`` where :meth:`evaluate` would).  Rows of a list announced by :meth:`prefetch` take the
        form's values from the one pass over all the announced lists (the same values: the form is row by row).
        A row the form states inconclusive by the law's own test (:attr:`Rows.inconclusive`) is counted, in its
        turn, as the evaluator's inconclusive sample with its message (:meth:`inconclusive_row`), without
        evaluating it again."""
        fn = VECTORISED.get(self.decl.name)
        if fn is None or len(samples) < 2 or batched(self.op):
            return [self.evaluate(s) for s in samples]
        if isinstance(samples, SampleBlock):
            return self._evaluate_block(fn, samples)
        rows = [i for i, s in enumerate(samples) if s.form == CONTIGUOUS]
        if self.pending and rows and id(samples[rows[0]]) in self.pre:
            self._prefetched(fn)
        vals: dict[int, float] = {}
        undecidable: set[int] = set()
        chunk = max(1, ROW_CELLS // max(1, int(self.op.dim)))
        for lo in range(0, len(rows), chunk):
            idx = rows[lo:lo + chunk]
            known = [self.pre.pop(id(samples[i]), None) for i in idx] if self.pre_rows else []
            if known and all(k is not None and k[0] is samples[i] for k, i in zip(known, idx)):
                at = np.array([k[1] for k in known], dtype=np.intp)
                got, inc = self._vectorised(fn, [samples[i] for i in idx], idx, tuple(a[at] for a in self.pre_rows))
            else:
                got, inc = self._vectorised(fn, [samples[i] for i in idx], idx)
            vals.update(got)
            undecidable.update(inc)
        if undecidable:
            return [vals[i] if i in vals else self.inconclusive_row(s) if i in undecidable else self.evaluate(s)
                    for i, s in enumerate(samples)]
        return [vals[i] if i in vals else self.evaluate(s) for i, s in enumerate(samples)]

    def _evaluate_block(self, fn: Callable, block: SampleBlock) -> list[float | None]:
        """:meth:`evaluate_many` of a block (:class:`SampleBlock`): the form's pass over its arrays (or the rows of
        the :meth:`prefetch` pass that announced it), the accepted rows counted from the arrays, and a
        :class:`Sample` made only for a row the law's evaluator sees — the same rows in the same order as
        :meth:`evaluate_many` of the block's samples as a list."""
        if block.form != CONTIGUOUS:
            return [self.evaluate(s) for s in block]
        if self.pending and id(block) in self.pre_blocks:
            self._prefetched(fn)
        hit = self.pre_blocks.pop(id(block), None) if self.pre_rows else None
        if hit is not None and hit[0] is not block:
            hit = None
        B = len(block)
        vals: dict[int, float] = {}
        undecidable: set[int] = set()
        chunk = max(1, ROW_CELLS // max(1, int(self.op.dim)))
        for lo in range(0, B, chunk):
            hi = min(B, lo + chunk)
            idx = range(lo, hi)
            known = None if hit is None else tuple(a[hit[1] + lo:hit[1] + hi] for a in self.pre_rows)
            got, inc = self._vectorised(fn, block if hi - lo == B else block[lo:hi], idx, known)
            vals.update(got)
            undecidable.update(inc)
        if len(vals) == B:      # every row accepted: the ratios in row order (the chunks' dicts were filled in order)
            return list(vals.values())
        return [vals[i] if i in vals else self.inconclusive_row(block[i]) if i in undecidable else
                self.evaluate(block[i]) for i in range(B)]

    @interruptible
    def inconclusive_row(self, s: Sample) -> None:
        """Count ``s`` as :meth:`evaluate` counts a sample its law's evaluator finds inconclusive (with the message
        of :attr:`form_inconclusive_what`): the vectorised form decided it by the evaluator's own test."""
        checkpoint()
        self.runs += 1
        self.xs += [_amax(s.x1), _amax(s.x2)]
        self.lams += [s.lam, s.mu, s.nu]
        self.ts.append(s.t)
        self.forms[s.form] = self.forms.get(s.form, 0) + 1
        self.inconclusive += 1
        self.inconclusive_what = self.form_inconclusive_what
        self.note()
        return None

    def prefetch(self, lists: list[list[Sample]]) -> None:
        """Announce lists of samples that :meth:`evaluate_many` will be given (each as it is): the first of them to arrive there evaluates the law's vectorised form over the rows of all of
        them in one pass (instead of one pass each: ~200 µs of fixed NumPy work a pass), and each list is then
        counted, in its turn, from that pass's values — the same rows accepted at the same ratios, and the same
        samples given to the law's evaluator, in the same order, as by a pass of its own, because a form is
        computed row by row (a form that decides a row by the other rows of its pass, :data:`PER_PASS` —
        ``yosida_limit``'s last open row — is not prefetched).  A pass that raised, or rows no longer announced,
        fall back to a pass per list (that list's own pass then meets what the form raises)."""
        fn = VECTORISED.get(self.decl.name)
        self.pending, self.pre, self.pre_rows, self.pre_blocks = [], {}, (), {}
        if fn is None or batched(self.op) or self.decl.name in PER_PASS:
            return
        lists = [l if isinstance(l, SampleBlock) else [s for s in l if s.form == CONTIGUOUS]
                 for l in lists if len(l) >= 2 and not (isinstance(l, SampleBlock) and l.form != CONTIGUOUS)]
        lists = [l for l in lists if len(l)]
        if len(lists) < 2:        # nothing to merge
            return
        k = 0
        for l in lists:           # a block is announced as a whole, a list's samples one by one
            if isinstance(l, SampleBlock):
                self.pre_blocks[id(l)] = (l, k)
            else:
                self.pre.update((id(s), (s, k + j)) for j, s in enumerate(l))
            k += len(l)
        if self.pre_blocks:       # blocks (n <= ROWS_OF_N): one block of every row, joined when the pass runs
            self.pending = [l if isinstance(l, SampleBlock) else SampleBlock.stacked(l) for l in lists]
        else:                     # lists only (any n): their samples, stacked a chunk at a time by the pass
            self.pending = [s for l in lists for s in l]

    @interruptible
    def _prefetched(self, fn: Callable) -> None:
        """The one pass over the rows :meth:`prefetch` announced (chunked as :meth:`evaluate_many` chunks a list)."""
        samples = SampleBlock.joined(self.pending) if self.pre_blocks else self.pending
        self.pending = []
        checkpoint()
        chunk = max(1, ROW_CELLS // max(1, int(self.op.dim)))
        parts = []
        for lo in range(0, len(samples), chunk):
            got = self._pass(fn, samples[lo:lo + chunk], quiet=True)
            if got is None:         # the form raised: every list its own pass, as without the prefetch
                self.pre, self.pre_rows, self.pre_blocks = {}, (), {}
                return
            parts.append(got)
        self.pre_rows = tuple(np.concatenate(a) for a in zip(*parts))

    def _pass(self, fn: Callable, batch: list[Sample], quiet: bool = False) -> tuple | None:
        """The vectorised form over the rows of ``batch``: ``(q, accepted, |x1|, |x2|, λ, μ, ν, t)`` per row, or
        ``None`` when the form raised (``quiet``: whatever it raised but an interrupt; else it re-raises
        :class:`InvalidCheckArgument` and ``NotImplementedError``)."""
        self.in_flight = time.perf_counter()     # each subject call of the pass restarts it (batches._call_starts)
        r = Rows(batch)
        CLOCK.append(self)
        try:
            with np.errstate(all="ignore"):
                q = np.asarray(fn(self.op, r), dtype=float)
        except (InvalidCheckArgument, NotImplementedError):
            if not quiet or interrupted():
                raise
            self.in_flight = None
            return None
        except Exception:   # noqa: BLE001 - the law's evaluator of one sample meets it (and judges it)
            if interrupted():
                raise
            self.in_flight = None
            return None
        finally:
            CLOCK.pop()
        self.in_flight, self.slowest = None, max(self.slowest, time.perf_counter() - self.in_flight)
        good = r.accepted(q, BOUND)
        if r.inconclusive is None:
            inc = np.zeros(len(good), dtype=bool)
        else:
            inc = r.inconclusive & ~r.ok & ~good
            self.form_inconclusive_what = r.inconclusive_what
        return q, good, row_abs_max(r.x1), row_abs_max(r.x2), r.lam, r.mu, r.nu, r.t, inc

    @interruptible
    def _vectorised(self, fn: Callable, batch: Any, idx: Any,
                    known: tuple | None = None) -> tuple[dict[int, float], list[int]]:
        """The vectorised form on ``batch`` (a list of samples or a :class:`SampleBlock`), row ``j`` the caller's
        sample ``idx[j]``: the ratios of the rows it decides (those clearly inside the bound), each such sample
        counted as evaluated (``known``: the rows' values from the pass of :meth:`prefetch`), and the ``i`` of the
        rows it found inconclusive by the law's own test (counted later, in their turn, by
        :meth:`inconclusive_row`)."""
        if not len(idx):
            return {}, []
        checkpoint()
        got = self._pass(fn, batch) if known is None else known
        if got is None:
            return {}, []
        inc = got[-1]
        return self._commit(batch, idx, *got[:-1]), ([idx[j] for j in np.flatnonzero(inc).tolist()] if inc.any() else [])

    def _commit(self, batch: Any, idx: Any, q: np.ndarray, good: np.ndarray, a1: np.ndarray,
                a2: np.ndarray, lam: np.ndarray, mu: np.ndarray, nu: np.ndarray, t: np.ndarray) -> dict[int, float]:
        """The rows of ``batch`` (row ``j`` the caller's sample ``idx[j]``) its pass accepted (``good``) counted as
        evaluated at their ratios ``q`` (what was searched kept as the pass's arrays: :meth:`searched`); the worst of
        them evaluated by the law for the record's numbers when it is the worst so far (the one row made a
        :class:`Sample` here)."""
        k = int(good.sum())
        if not k:
            return {}
        all_rows = k == len(good)
        g = None if all_rows else np.flatnonzero(good)
        self.runs += k
        self.xs_rows += [a1, a2] if all_rows else [a1[g], a2[g]]
        self.lams_rows += [lam, mu, nu] if all_rows else [lam[g], mu[g], nu[g]]
        self.ts_rows.append(t if all_rows else t[g])
        self.forms[CONTIGUOUS] = self.forms.get(CONTIGUOUS, 0) + k
        top = int(np.argmax(q)) if all_rows else int(g[np.argmax(q[g])])
        if self.worst is None or q[top] > self.worst.ratio:
            row = batch[top]
            out = evaluate_sample(self.decl, self.op, row)     # the worst row's own numbers, for the record
            if not out.inconclusive and out.ratio <= BOUND and (self.worst is None or out.ratio > self.worst.ratio):
                self.worst, self.worst_sample = out, row
        self.note()
        if all_rows:
            return dict(zip(idx, q.tolist()))
        return {idx[j]: float(q[j]) for j in g.tolist()}

    def searched(self, horizon: float) -> dict:
        """:func:`verimono.checks.engine.coordinates.searched` of everything evaluated: the one-sample lists and the
        arrays of the vectorised passes' accepted rows."""
        if not self.xs_rows:
            return searched(self.xs, self.lams, self.ts, horizon, self.coordinates)
        return searched(self.xs, self.lams, self.ts, horizon, self.coordinates,
                        (np.concatenate(self.xs_rows), np.concatenate(self.lams_rows), np.concatenate(self.ts_rows)))

    def not_implemented(self, s: Sample, exc: NotImplementedError) -> Outcome | None:
        """A member raised NotImplementedError at ``s``: the operator lacks it (``None``; the search stops,
        skipped) only when it raises at the simple sample too and no sample was evaluated before; otherwise
        the operator raises on part of its domain (a resolvent defined only for ``|x| ≤ 5``), and the
        sample fails."""
        what = str(exc) or type(exc).__name__
        if self.runs == 0:
            simple = Sample(np.zeros(self.op.dim), np.full(self.op.dim, 1e-2), **_SIMPLE)
            try:
                evaluate_sample(self.decl, self.op, simple)
            except NotImplementedError:
                self.unsupported = what
                return None
        return Outcome.compare(math.inf, 0.0, 1.0, f"raised NotImplementedError ({what}) at this sample although "
                               "it evaluates elsewhere: the operator raises on part of its domain")

    def note(self) -> None:
        """The progress so far, for an outer unit whose budget may stop the search (verimono.execution.timeouts)."""
        note_progress(self.runs, not self.violated and self.inconclusive < self.runs)

    def fails(self, s: Sample) -> bool:
        out = evaluate_sample(self.decl, self.op, s)
        if not out.ratio <= BOUND:
            self.seen_failing = (s, out)
            return True
        return False

    def shrunk_into(self, failing: Sample, outcome: Outcome, how: str) -> None:
        """Record the violation ``outcome`` seen at ``failing``, shrunk greedily (:func:`verimono.checks.sweep.
        shrink`).  The record keeps the outcome *seen failing* at the shrunk sample (the last candidate the shrink
        kept, or ``failing`` itself), never a fresh evaluation there: on an operator whose calls disagree that
        could hold, and the record would state a violation its own numbers deny."""
        self.seen_failing = (failing, outcome)
        small, _ = shrink(failing, self.fails, dataclasses.replace)
        seen, out = self.seen_failing
        if seen is not small:       # not expected (the shrink keeps only candidates that failed): evaluate there
            out = evaluate_sample(self.decl, self.op, small)
            if out.ratio <= BOUND:
                small, out = failing, outcome
        self.failing, self.failure = small, out
        self.found_by = how

    def first_violation(self, samples: list[Sample]) -> tuple[Sample, Outcome] | None:
        """Evaluate ``samples`` in order; the first that breaks the law with its outcome (taken out of the
        state, so that a later phase searches afresh), or ``None``.  A batched operator evaluates their
        points in batched calls first (:func:`verimono.checks.batches.prefetched`)."""
        try:
            with prefetched(self.op, samples):
                try:
                    if self.runs or not samples:
                        self.evaluate_many(samples)
                    else:       # the first sample alone: a member the operator lacks stops the search there
                        self.evaluate(samples[0])
                        if self.unsupported is None:
                            self.evaluate_many(samples[1:])
                except _Violation:
                    found = (self.failing, self.failure)
                    self.failure = self.failing = None
                    return found
        except _BatchFailure as exc:       # a declared batched call that raised: the subject fails
            self.runs += 1
            return exc.sample, Outcome.compare(math.inf, 0.0, 1.0, str(exc), {"batch_size": exc.size,
                                                                              "batch_sizes_tried": exc.sizes})
        return None


def _hypothesis_search(state: _Search, seed: int, horizon: float, budget: int) -> None:
    """Hypothesis's search: its simplest examples, its climb toward large ratios, its shrinking."""
    def climb(s: Sample) -> None:
        state.evaluate(s, climb=True)

    test = settings(database=None, max_examples=max(1, budget), deadline=None, derandomize=False,
                    verbosity=Verbosity.quiet, print_blob=False, suppress_health_check=list(HealthCheck),
                    phases=(Phase.generate, Phase.target, Phase.shrink))(given(law_samples(state.op.dim, horizon))(climb))
    hypothesis.seed(seed)(test)()


def _search(decl: Law, op: Any, seed: int, examples: int, horizon: float) -> tuple[_Search, dict]:
    """The three phases of the search (module docstring) under the unit's time budget."""
    state, how = _Search(decl, op, horizon=horizon), {"timed_out": "", "harness": "", "flaky": "", "sweep": 0,
                                                      "minimum": min(MIN_EVALUATED, examples)}
    drawn = None
    state.deadline = _deadline(current_budget())
    try:
        with no_local_constants(), _phase_limit(state, f"{decl.name} on {subject_name(op)}"):
            if op.dim <= NUMPY_DIM:
                edges = edge_draws(op.dim, seed, horizon, edge_count(examples), make_sample)   # one block
                # in hypothesis's order: the draws, the simplest sample alone (the worst so far when it ties the
                # ratio 0 that pairs x1 = x2 give: the coordinates start from its pair), the other edge samples
                parts = (cycled(law_draws(op.dim, seed, horizon, examples, Sample), forms_for(op)), edges[:1], edges[1:])
                state.prefetch([parts[0][1:], parts[2]])    # the lists evaluate_many is given: one vectorised pass
                for i, part in enumerate(parts):
                    drawn = state.first_violation(part)
                    if i:       # the edge samples searched (none when a draw broke the law)
                        how["edge"] = how.get("edge", 0) + len(part)
                    if drawn is not None or state.unsupported is not None:
                        break
            if drawn is not None or op.dim > NUMPY_DIM:     # hypothesis where it pays: its climb and its shrinking
                how["hypothesis"] = examples
                _hypothesis_search(state, seed, horizon, examples)
    except _Violation:
        pass
    except UnitTimeout as exc:
        _timed_out(how, exc, state)
    except hypothesis.errors.Flaky as exc:  # a failure that did not reproduce on replay
        how["flaky"] = f" (not reproducible on replay: {type(exc).__name__}; the operator is not deterministic)"
    except InvalidCheckArgument:
        raise
    except Exception as exc:  # noqa: BLE001 - what the search engine raised (a sample's exception never gets here)
        # the search engine itself gave up (inputs it cannot draw, memory, its own state): a limit of the harness
        how["harness"] = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
    stopped = how["timed_out"] or how["harness"]
    if state.failure is None and drawn is not None:      # hypothesis did not meet the draw's violation
        if "batch_size" in drawn[1].info:                 # a batched call that raised: not one sample's doing
            (state.failing, state.failure), state.found_by = drawn, "a batched call of the NumPy draws"
        elif stopped:
            (state.failing, state.failure), state.found_by = drawn, "NumPy draws"
        else:
            state.shrunk_into(*drawn, "NumPy draws (shrunk greedily)")
    # the scale sweep spells out its points: for n > NUMPY_DIM the NumPy recipes cover the scales instead
    if state.failure is None and state.unsupported is None and not stopped and op.dim <= NUMPY_DIM:
        try:          # the sweep under what is left of the law's budget, as every phase
            with _phase_limit(state, f"{decl.name} on {subject_name(op)}"):
                how["sweep"] = _sweep(state, seed, horizon)
        except UnitTimeout as exc:
            _timed_out(how, exc, state)
        stopped = how["timed_out"]
    if state.failure is None and state.unsupported is None and not stopped and op.dim <= NUMPY_DIM \
            and "points" in (decl.over or OPERATOR_DOMAIN):
        try:          # whole points over every decade of the precision (verimono.checks.engine.scales)
            with _phase_limit(state, f"{decl.name} on {subject_name(op)}"):
                how["scales"] = _scales(state, horizon)
        except UnitTimeout as exc:
            _timed_out(how, exc, state)
        stopped = how["timed_out"]
    if state.failure is None and state.unsupported is None and not stopped and state.worst_sample is not None \
            and COORDINATE_CAP.get(decl.name, 1):
        _coordinates(state, seed, horizon, how)
    return state, how


def _coordinates(state: _Search, seed: int, horizon: float, how: dict) -> None:
    """The coordinate phase (:mod:`verimono.checks.coordinates`) from the worst sample; a violation is
    shrunk greedily into ``state``."""
    def ratio(s: Sample) -> float:
        r = state.evaluate(s)
        return -math.inf if r is None else r

    def ratios(ss: list[Sample]) -> list[float]:
        return [-math.inf if r is None else r for r in state.evaluate_many(ss)]

    start, before = dataclasses.replace(state.start or state.worst_sample, form=CONTIGUOUS), state.runs
    try:
        with _phase_limit(state, f"{state.decl.name} on {subject_name(state.op)}"):
            over = state.decl.over or OPERATOR_DOMAIN          # the law's declared quantifiers
            formed = form_search(ratio, start, forms_for(state.op)) if "form" in over else None   # a few samples
            points, n = budget("coordinate"), int(np.size(start.x1))
            capped = large_n_count(points, n)       # design rows fall above LARGE_N coordinates: each costs O(n)
            if capped < points:
                state.budget_note = (f"coordinate budget capped at {capped} points for n = {n} "
                                     f"({current_config().profile} promises {points} for n <= {LARGE_N})")
            state.coordinates = coordinate_search(ratio, state.op, start, horizon, capped, seed,
                                                  lambda: state.unsupported is not None, ratios,
                                                  dense=state.decl.name in VECTORISED and not batched(state.op),
                                                  rows=rows_accepted(state.op), over=over, prefetch=state.prefetch)
            state.coordinates += [formed] if formed else []
    except _Violation:
        state.shrunk_into(state.failing, state.failure, "the search over each coordinate of the worst sample (shrunk greedily)")
    except UnitTimeout as exc:
        _timed_out(how, exc, state)
    how["coordinate"] = state.runs - before


def _sweep(state: _Search, seed: int, horizon: float) -> int:
    """The scale sweep after a search that found nothing; a violation is shrunk greedily into ``state``.
    Returns the number of sweep samples."""
    swept = sweep_samples(state.op, seed, horizon, sweep_count(current_config().profile, state.decl.name),
                          make_sample)      # one block
    found = state.first_violation(swept)
    if found is not None and "batch_size" in found[1].info:
        (state.failing, state.failure), state.found_by = found, "a batched call of the sweep"
    elif found is not None:
        state.shrunk_into(*found, "sweep (shrunk greedily)")
    return len(swept)


def _scales(state: _Search, horizon: float) -> dict:
    """The scale phase (:mod:`verimono.checks.engine.scales`) after a sweep that found nothing: the worst sample
    scaled over every decade, whole points of one shape at the landmarks; a violation is shrunk greedily into
    ``state``.  Returns what was searched."""
    start = None if state.worst_sample is None else dataclasses.replace(state.worst_sample, form=CONTIGUOUS)
    state.start = state.worst_sample        # the coordinates search from the worst unscaled sample, as before
    samples, covered = scale_samples(start, budget("coordinate"), int(state.op.dim), make_sample,
                                     SCALE_CAP.get(state.decl.name))      # one block
    state.scaling = True
    try:
        found = state.first_violation(samples)
    finally:
        state.scaling = False
    if found is not None and "batch_size" in found[1].info:
        (state.failing, state.failure), state.found_by = found, "a batched call of the scale phase"
    elif found is not None:
        state.shrunk_into(*found, "the scale phase (every decade of the precision; shrunk greedily)")
    return covered


def _replay(decl: Law, op: Any, sample: Sample | dict) -> tuple[_Search, dict]:
    """The evaluation of one given sample (a replay), under the unit's time budget."""
    state, how = _Search(decl, op), {"timed_out": "", "harness": "", "flaky": "", "sweep": 0}
    s = Sample.from_dict(sample) if isinstance(sample, dict) else sample
    try:
        with time_limit(current_budget(), f"{decl.name} on {subject_name(op)}"):
            state.evaluate(s)
    except _Violation:
        pass
    except UnitTimeout as exc:
        _timed_out(how, exc, state)
    return state, how


def _deadline(seconds: float | None) -> tuple[float, float] | None:
    """``(seconds, when it runs out)`` of a law's budget of ``seconds`` (:func:`current_budget`) started now;
    ``None``: no limit."""
    return None if unlimited(seconds) else (seconds, time.perf_counter() + seconds)


def _phase_limit(state: _Search, unit: str):
    """The time limit of a phase of the law's search: what is left of the law's budget.  The search, the sweep
    and the coordinate phase share one budget (each armed a whole budget of its own before, and the sweep
    none: a law called on its own, outside :func:`verimono.execution.timeouts.run_unit`, hung on a resolvent
    that stopped returning in the sweep).  The timeout states, and is judged against, the whole budget; a spent
    budget stops the phase at once (a millisecond)."""
    if state.deadline is None:
        return time_limit(None, unit)
    seconds, end = state.deadline
    return time_limit(max(end - time.perf_counter(), 1e-3), unit, part_of=seconds)


def _timed_out(how: dict, exc: UnitTimeout, state: _Search) -> None:
    """What the search knows when its budget stopped it: the limit's text and evidence, and how long the
    sample in flight had run (``None``: none was, the budget ran out in the harness)."""
    how["timed_out"] = str(exc)
    evidence = getattr(exc, "evidence", {})
    stopped_at = evidence.get("stopped_at") or time.perf_counter()    # the interrupt, not the unwinding after it
    how["evidence"] = {**evidence, "in_flight": None if state.in_flight is None else stopped_at - state.in_flight}


def own_overflow(out: Outcome) -> str | None:
    """Why the violation ``out`` is no verdict on the subject (inconclusive), or ``None``: its left side — the
    subject's values, finite by :func:`verimono.checks.members.point` — is a finite number while the law's own side
    (``rhs``, ``slack``) overflowed in verimono's arithmetic.  Measured (probe7): ``resolvent_identity`` on a box at
    ``10^12`` searched down to ``λ = 10^-153`` forms ``z ≈ 10^165`` and a slack ``tolerance(x, J, z)·(4 + μ/λ) = inf``;
    ``lhs ≤ rhs + inf`` then judges nothing, and failing it blamed correct code.  A non-finite left side (a NaN, an
    ``inf`` the subject's values made) still fails."""
    lhs, rhs, slack = out.lhs, out.rhs, out.slack
    if lhs is None or rhs is None or not math.isfinite(lhs):
        return None
    if math.isfinite(rhs) and math.isfinite(0.0 if slack is None else slack):
        return None
    return (f"the law's own arithmetic overflowed at these magnitudes ({out.what}: lhs {lhs:.3g}, rhs {rhs:.3g}, "
            f"slack {0.0 if slack is None else slack:.3g}): no judgement")


def violation_text(out: Outcome) -> str:
    """What a violated inequality ``lhs ≤ rhs + slack`` is, true as written: ``"<what>: lhs A > rhs B + slack
    C"`` with as many digits as make ``A > B + C`` hold for the printed numbers (6 significant digits, more when
    the sides are closer than that shows; ``lhs inf`` too), or, when the right side is not finite or the left is NaN,
    the sides and that they are not finite (never a pass, and ``lhs 1 > rhs inf`` would be false)."""
    lhs, rhs, slack = out.lhs, out.rhs, out.slack
    if lhs is None or rhs is None or slack is None:
        return f"{out.what}: ratio {out.ratio:.6g} > {out.bound:g}"
    if math.isnan(lhs) or not (math.isfinite(rhs) and math.isfinite(slack)):
        return (f"{out.what}: lhs {lhs:.6g}, rhs {rhs:.6g}, slack {slack:.3g}: a side is not finite (never a pass)")
    for digits in (6, 9, 12, 17):
        a, b, c = (f"{v:.{digits}g}" for v in (lhs, rhs, slack))
        if float(a) > float(b) + float(c):
            break
    return f"{out.what}: lhs {a} > rhs {b} + slack {c}"


def _verdict(state: _Search, how: dict, base: dict, details: dict, cex_extra: dict) -> CheckResult:
    """The record of a finished search (the statuses of the module docstring)."""
    runs = state.runs
    if how["timed_out"] and state.failure is None:
        # the one policy of a unit out of time: undecided unless a violation was seen or the sample in flight
        # is a call that does not return (0 samples and none in flight: the harness spent the budget)
        evidence = how["evidence"]
        status, message, extra = timeout_verdict(how["timed_out"], **{
            **evidence, "evaluated": runs, "held": not state.violated, "slowest": state.slowest})
        details.update(timeout=True, **extra)
        if evidence.get("harness_error"):
            details["harness_error"] = evidence["harness_error"]
        return new_record(status=status, details=details, message=message, **base)
    if state.failure is None and how["harness"]:
        return new_record(status=UNDECIDED, details=details, **base,
                           message=f"the harness could not search this operator ({how['harness']}; {runs} samples "
                                   "evaluated before); a limitation of verimono, not a failure of the operator")
    if state.failure is None and state.unsupported is not None:
        return new_record(status=SKIPPED, details=details, **base,
                           message=f"needs a member the operator lacks: {state.unsupported} ({runs} samples "
                                   "evaluated before)")
    if state.failure is not None:
        out, s = state.failure, state.failing
        cex = {**s.to_dict(), **cex_extra, "ratio": out.ratio, "lhs": out.lhs, "rhs": out.rhs, "slack": out.slack,
               **out.info}
        if state.found_by:
            cex["found_by"] = state.found_by
        worst = out.ratio if state.worst is None else max(state.worst.ratio, out.ratio)
        return new_record(status=FAILED, worst=worst, bound=BOUND, counterexample=cex, details=details, **base,
                           message=f"{violation_text(out)} at {s!r}{how['flaky']}")
    if runs == 0:        # nothing was evaluated: never a pass
        return new_record(status=UNDECIDED, message="no sample was evaluated", details=details, **base)
    if state.harness_limited == runs:
        return new_record(status=UNDECIDED, details=details, **base,
                           message=f"verimono's own solvers decided none of the {runs} samples (e.g. "
                                   f"{state.inconclusive_what}); a limitation of verimono, not a failure of the "
                                   "operator")
    if state.inconclusive == runs:
        return new_record(status=SKIPPED, details=details, **base,
                           message=f"all {runs} samples inconclusive (e.g. {state.inconclusive_what})")
    decided = runs - state.inconclusive
    if decided < how.get("minimum", 0):
        return new_record(status=UNDECIDED, details=details, **base,
                          message=f"only {decided} of {runs} samples were evaluated to a verdict ({state.inconclusive} "
                                   f"inconclusive, e.g. {state.inconclusive_what}); a law passes only with at least "
                                   f"{how['minimum']}")
    if state.worst is not None:
        details["worst_sample"] = state.worst_sample.to_dict()
        details["worst_info"] = {"what": state.worst.what, "lhs": state.worst.lhs, "rhs": state.worst.rhs,
                                 "slack": state.worst.slack}
    counted = f"{runs} samples" + (f" ({state.inconclusive} inconclusive)" if state.inconclusive else "")
    if state.harness_limited:
        counted += f", {state.harness_limited} of them undecided by verimono's own solvers"
    read = [c for c in state.coordinates if c.get("read")]
    if read:        # what the coordinate search resolved: a narrower violation is outside what was searched
        counted += "; searched " + ", ".join(
            f"{c['coordinate']} to within a factor {c['resolution']:.3g}" if c["log"] else
            f"{c['coordinate']} to {c['resolution']:.3g}{' ' + c['unit'] if c.get('unit') else ''}" for c in read) + " (narrower bands are outside what was searched)"
    return new_record(status=PASSED, worst=None if state.worst is None else state.worst.ratio, bound=BOUND,
                       message=counted + (f"; {how['flaky']}" if how["flaky"] else ""), details=details, **base)


def run_law(decl: Law | str, op: Any, *, seed: int | None = None, examples: int | None = None,
            horizon: float = 1.0, sample: Sample | dict | None = None) -> CheckResult:
    """One law on ``op``: NumPy draws and edge samples (hypothesis after a violation), the scale sweep and the
    coordinates, or one given ``sample``.

    ``seed`` makes the search reproducible (a fresh one is drawn and recorded when ``None``); ``examples``
    is the effort (default: the active profile's, :func:`default_examples`); times are sampled in
    ``[0, horizon]``."""
    if isinstance(decl, str):
        if decl not in REGISTRY["operator"]:
            raise InvalidCheckArgument(f"no operator law named {decl!r}; registered: {sorted(REGISTRY['operator'])} "
                                       "(the laws register when verimono.checks.operator_laws is imported; "
                                       "verimono.checks.run_law imports it)")
        decl = REGISTRY["operator"][decl]
    horizon = valid_horizon(horizon)
    profile = None
    if examples is None:
        examples, profile = default_examples()
    examples = positive_examples(examples)
    if sample is None:
        seed = fresh_seed() if seed is None else valid_seed(seed)
    elif seed is not None:
        seed = valid_seed(seed)
    subject = subject_name(op)
    details = {"item": decl.label, "examples": examples, "evaluations": 0, "horizon": horizon}
    if profile is not None:
        details["profile"] = profile

    def evaluate() -> CheckResult:
        start = time.perf_counter()
        base = dict(check=decl.name, subject=subject, seed=seed)
        cause = bounded_root_cause(op, horizon) if sample is None else None
        if cause is not None:
            why = {**details, "root_cause": cause}
            if decl.name == ROOT_LAW:
                return new_record(status=FAILED, worst=math.inf, bound=BOUND, counterexample={"operator": repr(op)},
                                   message=f"root cause: {cause}; the other laws are not evaluated", details=why,
                                   **base)
            return new_record(status=SKIPPED, details=why, **base,
                               message=f"not evaluated: {cause} (the root cause is recorded once, as {ROOT_LAW})")
        state, how = _search(decl, op, seed, examples, horizon) if sample is None else _replay(decl, op, sample)
        rec = _verdict(state, how, base, {**details, "evaluations": state.runs, "inconclusive": state.inconclusive,
                                          "harness_limited": state.harness_limited, "sweep": how["sweep"],
                                          "coordinate": how.get("coordinate", 0),
                                          "searched": {**state.searched(horizon), "forms": dict(state.forms),
                                                 **({"edge_samples": how["edge"]} if how.get("edge") else {}),
                                                 **({"scales": how["scales"]} if how.get("scales") else {}),
                                                 **({"hypothesis_examples": how["hypothesis"]}
                                                    if how.get("hypothesis") else {}),
                                                 **({"budget": state.budget_note} if state.budget_note else {})}},
                       {"seed": seed, "examples": examples, "horizon": horizon, "operator": repr(op)})
        if rec.status == PASSED and decl.name in YOSIDA_SLACK:
            _state_yosida_resolution(rec, YOSIDA_SLACK[decl.name])
        rec.duration = time.perf_counter() - start
        return rec

    # at the operator's own scale (core.run); a replayed sample is judged as given, never re-judged
    rec = run(decl, subject, evaluate, operator=op, seed=seed, horizon=horizon, rejudge=sample is None)
    if rec.status == SKIPPED and "examples" not in rec.details:   # skipped from the declaration
        rec.details.update(details)
    return rec


#: the Yosida laws, name → ``K``: their slack on ``Y_λx = (x − J_λx)/λ`` is ``K·rtol·(1 + |x|)/λ`` (a resolvent within
#: ``rtol`` of ``|x|`` — an iterative solver's — must not be failed, and ``1/λ`` amplifies it), registered by
#: :mod:`verimono.checks.operator_laws`.  A passed record of one states its real resolution in ``λ``
#: (:func:`_state_yosida_resolution`): the decades below it were evaluated but cannot show a violation of ``|Y|``
YOSIDA_SLACK: dict[str, float] = {}


def _state_yosida_resolution(rec: CheckResult, k: float) -> None:
    """State in ``rec`` (passed) the smallest ``λ`` at which a violation of relative size 1 (``|ΔY| = |Y_λx|``) is
    judgeable: ``λ ≥ K·rtol·(1 + |x|)/|Y_λx|`` — at ``|x| = |Y| = 1``, and at the largest ``|x|`` searched with
    ``|Y| = 1`` (``details["searched"]["yosida_resolution"]``, and the message)."""
    rtol = current_rtol()
    searched_ = rec.details.get("searched") or {}
    x_max = float((searched_.get("x_range") or [0.0, 1.0])[1])
    unit, far = 2.0 * k * rtol, k * rtol * (1.0 + x_max)
    searched_["yosida_resolution"] = {"slack": f"{k:g}·rtol·(1 + |x|)/λ", "rtol": rtol,
                                      "lambda_min_at_unit": unit, "lambda_min_at_largest_x": far,
                                      "largest_x": x_max}
    rec.message += (f"; Y_λ judged to {k:g}·rtol·(1 + |x|)/λ: a violation |ΔY| = |Y| is judgeable only for "
                    f"λ ≥ {k:g}·rtol·(1 + |x|)/|Y| ({unit:.2g} at |x| = |Y| = 1, {far:.2g} at |x| = {x_max:.3g})")


#: what an operator law quantifies over unless it says otherwise: points (the draws, the edge samples, the sweep),
#: the input's form and every coordinate of :func:`verimono.checks.engine.coordinates.coordinate_search`
OPERATOR_DOMAIN = ("points", "form") + COORDINATES


def operator_law(name: str, label: str, *requires: Any, over: tuple = OPERATOR_DOMAIN) -> Callable:
    """Declare ``check_<name>(op, s) -> Outcome`` as an operator law driven by :func:`run_law`; ``over``: the
    statement's quantifiers (:data:`verimono.checks.core.QUANTIFIERS`) — the coordinates the search maximises
    and the input forms are searched only when declared."""
    return law(name, label, subject="operator", driver=run_law, requires=requires, over=over)


__all__ = ["run_law", "operator_law", "evaluate_sample", "root_cause", "bounded_root_cause", "fresh_seed", "default_examples",
           "positive_examples", "valid_seed", "valid_horizon", "DEFAULT_EXAMPLES", "BOUND", "ROOT_LAW",
           "HARNESS_LIMIT", "OPERATOR_DOMAIN", "YOSIDA_SLACK"]
