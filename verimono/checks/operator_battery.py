"""The battery of an operator: every operator law, one record each (scikit-learn's ``check_estimator``).

:func:`operator_checks` yields ``(name, check)`` pairs — the one source of :func:`check_operator`, of
:func:`verimono.testing.parametrize_with_checks` and of the ``operator_laws`` stage of ``verimono run``.
"""

from __future__ import annotations

import functools
from typing import Any, Callable, Iterator

from ..execution import watchdog
from ..core.errors import InvalidCheckArgument
from ..execution.config import chosen
from ..execution.executors import Unit
from ..execution.heap import heap_kept
from ..execution.workers import blas_limited
from ..records.results import Report
from . import operator_laws, prox_laws  # noqa: F401 - the laws join the registry on import
from .core import Law, laws_of, subject_name
from .isolated import isolating, run_isolated
from .arguments import valid_horizon, valid_seed
from .engine.search import default_examples, fresh_seed, positive_examples, run_law  # noqa: F401 - public here with its laws
from .subjects import require_operator

#: the operator laws (:class:`verimono.checks.core.Law`), in the order they run
LAWS: dict[str, Law] = laws_of("operator")
#: stable law name → its public check ``check(op, *, seed, examples, horizon, sample)``
OPERATOR_CHECKS: dict[str, Callable[..., Any]] = {name: decl.public for name, decl in LAWS.items()}


def operator_checks(op: Any = None, *, seed: int | None = None, examples: int | None = None,
                    horizon: float = 1.0) -> Iterator[tuple[str, Callable[[Any], Any]]]:
    """Yield ``(name, check)`` for every operator law, ``check(op) -> CheckResult`` with the given settings
    bound.  Names are stable and unique; ``op`` is accepted for symmetry with the other subjects'
    generators (every law applies to every operator; one that needs a member it lacks is a skip)."""
    for name, decl in LAWS.items():
        yield name, functools.partial(decl.public, seed=seed, examples=examples, horizon=horizon)


def check_operator(op: Any, *, seed: int | None = None, examples: int | None = None,
                   horizon: float = 1.0, executor: str | None = None, profile: str | None = None) -> Report:
    """Run every operator law on ``op`` and return the :class:`verimono.Report` of their records.

    ``seed`` makes the search reproducible (one fresh seed is drawn and recorded when ``None``);
    ``examples`` is the effort per law (default: the profile's ``law_examples``); times are sampled
    in ``[0, horizon]``.  ``profile`` (``"dev"``, ``"ci"``, ``"thorough"``) chooses the effort of this call —
    examples per law, the scale sweep, the time budget of each law — as ``--profile`` does for ``verimono
    check``; by default the current run configuration's (:mod:`verimono.execution.config`: the pytest
    plugin's, else ``$HYPOTHESIS_PROFILE``, else ``ci`` when ``$CI`` is set, else ``dev``).  What is not an operator is refused before any law runs
    (:class:`verimono.InvalidCheckArgument`, naming the wrapper that makes one).

    Every call of the resolvent runs under the unit time budget (:mod:`verimono.execution.timeouts`).  A resolvent
    blocked in native code, which the budget's interrupt cannot stop, is bounded only with
    ``executor="process:N"``: the battery then runs in a worker process (one: its laws share what the
    root-cause probe learnt, :mod:`verimono.checks.isolated`), which such a call ends — the records of the
    laws finished before it and a failed record naming it.  In this process verimono never ends the
    interpreter on such a call: it warns once and waits for it to return (:mod:`verimono.execution.watchdog`).

    The BLAS libraries loaded when it begins run on one thread for the battery, as under ``verimono run`` and
    ``verimono check``, and get the caller's limits back after (:func:`verimono.execution.workers.blas_limited`).
    Above ``LARGE_N`` coordinates glibc's allocator keeps the blocks the laws free for the battery's length
    (:func:`verimono.execution.heap.heap_kept`: no page faults for every sample's fresh arrays)."""
    if profile is not None:
        with chosen(profile):
            return check_operator(op, seed=seed, examples=examples, horizon=horizon, executor=executor)
    require_operator(op)
    seed = fresh_seed() if seed is None else valid_seed(seed)
    if examples is None:
        examples, profile = default_examples()
    else:
        examples, profile = positive_examples(examples), None
    horizon = valid_horizon(horizon)
    report = Report(meta={"subject": subject_name(op), "seed": seed, "examples": examples, "horizon": horizon,
                          **({"profile": profile} if profile else {})})
    if isolating(executor):
        (done,) = run_isolated(executor, [Unit("check_operator", subject_name(op), _battery,
                                               (op, seed, examples, horizon))], op)
        report.results.extend(done.results)
        return report
    if executor not in (None, "serial"):
        raise InvalidCheckArgument(f"check_operator: executor must be None, 'serial' or 'process:N', got {executor!r}")
    with blas_limited(), heap_kept(_dim(op)):           # as under the command line (BLAS_THREADS); freed blocks kept
        for _, check in operator_checks(op, seed=seed, examples=examples, horizon=horizon):
            watchdog.finished(report.add(check(op)))    # kept should a later law block in native code
    return report


def _dim(op: Any) -> int:
    """The operator's number of coordinates (0 when it does not say: then nothing is kept)."""
    try:
        return int(getattr(op, "dim", 0) or 0)
    except (TypeError, ValueError):
        return 0


def _battery(op: Any, seed: int, examples: int, horizon: float) -> Report:
    """The battery in a worker process (``check_operator(..., executor="process:N")``)."""
    return check_operator(op, seed=seed, examples=examples, horizon=horizon)


__all__ = ["LAWS", "OPERATOR_CHECKS", "operator_checks", "check_operator"]
