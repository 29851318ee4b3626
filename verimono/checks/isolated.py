"""A battery run in worker processes: how the Python API bounds a subject that blocks in native code.

In the user's interpreter, :func:`verimono.check_stepper` and :func:`verimono.check_operator` stop a call
that overruns its time budget with ``SIGALRM`` — which cannot reach a call blocked in native code
(``os.system``, a C extension): verimono never ends the user's interpreter, it warns once
(:mod:`verimono.execution.watchdog`) and the call goes on until it returns.  With ``executor="process:N"`` the battery
runs in ``N`` spawned worker processes (:class:`verimono.execution.executors.ProcessRunner`) instead, where such a call
ends its worker: a failed record naming it, the records finished before it kept, and the battery goes on
(a script that uses it must guard its entry point with ``if __name__ == "__main__":``, as for any spawned
process; the subject travels with ``cloudpickle``).
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

from ..execution.executors import Unit, make_runner, ship_by_value
from ..execution.config import current as current_config
from ..records.results import Report
from ..execution.timeouts import run_unit


def isolating(executor: Any) -> bool:
    """Whether ``executor`` asks for the battery in worker processes (``"process:N"``)."""
    return isinstance(executor, str) and executor.startswith("process:")


def run_isolated(executor: str, units: Sequence[Unit], subject: Any = None) -> list[Report]:
    """The reports of ``units`` run on ``executor`` (``"process:N"``), in their order; the workers are
    stopped before it returns.  The run configuration of this process (:mod:`verimono.execution.config`: its
    profile, its explicit time budget) applies in the workers too.  ``subject``'s module, when it is the user's, travels by value
    (:func:`verimono.execution.executors.ship_by_value`: the workers need not import it)."""
    if subject is not None:
        ship_by_value(subject)
    runner = make_runner(executor)
    try:
        return runner.map(list(units), current_config(), _quiet)
    finally:
        runner.close()


def _quiet(done: int, total: int, label: str) -> None:
    pass


def run_check(check: Callable[[Any], Any], subject: Any, law: str, name: str) -> Report:
    """One check of a battery as a unit: ``check(subject)`` under the unit budget, as ``law[name]``."""
    return Report([run_unit(lambda: check(subject), check=law, subject=name)])


__all__ = ["isolating", "run_isolated", "run_check"]
