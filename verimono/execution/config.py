"""One run configuration: the profile, the unit budget, the seed and the executor, chosen once.

A verification is started from an *entry point* — the command line (``verimono run/check/baseline``,
:mod:`verimono.cli`), a Python API call (:func:`verimono.check_operator`, :func:`verimono.check_stepper`,
:func:`verimono.run.execute.execute`) or the pytest plugin (:mod:`verimono.plugin`) — and the entry point alone
decides how hard it searches.  What it decides is one :class:`RunConfig`, held for the duration of the work
(:func:`using`) and read by everything that depends on it: the operator search's examples and scale sweep
(:mod:`verimono.checks.engine.search`), every unit's time budget (:mod:`verimono.execution.timeouts`) and the worker
processes, which receive it with each unit (:mod:`verimono.execution.executors`).

The environment only supplies the default, here and nowhere else (:func:`from_environment`):
``$HYPOTHESIS_PROFILE`` if set, else ``ci`` when ``$CI`` is set, else ``dev``.  So ``verimono check
--profile thorough`` runs thorough's budget and sweep whatever ``$CI`` or ``$HYPOTHESIS_PROFILE`` say, and
``--profile`` left out takes the profile they name.
"""

from __future__ import annotations

import dataclasses
from contextlib import contextmanager
from typing import Any, Iterator

from .profiles import Profile, UnknownProfile, active_profile, get_profile

#: what a field left to :func:`using` keeps (``None`` is a value: "no explicit budget", "a fresh seed")
_KEEP: Any = object()


@dataclasses.dataclass(frozen=True)
class RunConfig:
    """What an entry point chose for a run.

    ``profile``: a profile name (``dev``/``ci``/``thorough``, :mod:`verimono.execution.profiles`; a user's own
    hypothesis profile is accepted, with verimono's defaults for the effort it does not state);
    ``budget``: seconds per unit of work when stated explicitly (``--timeout``; ``inf``: no limit), ``None``
    for the profile's ``unit_budget`` in calibration units; ``seed``: the seed of the randomized batteries
    (``None``: the profile decides — 0 when it is derandomized, else a fresh one); ``executor``: where units
    run (a spec such as ``"process:2"``; ``None``: serially in this process); ``source``: where the profile
    came from (``"--profile"``, ``"argument"``, ``"$HYPOTHESIS_PROFILE"``, ``"$CI"``, ``"default"``), so a
    record of the run can say why it ran at that effort."""

    profile: str = "dev"
    budget: float | None = None
    seed: int | None = None
    executor: Any = None
    source: str = "default"

    @property
    def effort(self) -> Profile | None:
        """The :class:`~verimono.execution.profiles.Profile` named ``profile`` (``None`` for a user's own
        hypothesis profile, which states no effort of verimono's)."""
        try:
            return get_profile(self.profile)
        except UnknownProfile:
            return None

    def to_dict(self) -> dict[str, Any]:
        """What a run records of its configuration (``report.meta["config"]``)."""
        executor = self.executor if self.executor is None or isinstance(self.executor, str) else \
            type(self.executor).__name__
        return {"profile": self.profile, "source": self.source, "budget": self.budget, "seed": self.seed,
                "executor": executor}


def from_environment() -> RunConfig:
    """The default configuration: the profile ``$HYPOTHESIS_PROFILE`` names, else ``ci`` when ``$CI`` is set
    (non-empty, not ``0``/``false``/``no``), else ``dev`` — the one place the environment is read."""
    import os

    name = active_profile()
    source = ("$HYPOTHESIS_PROFILE" if os.environ.get("HYPOTHESIS_PROFILE") else
              "$CI" if name == "ci" else "default")
    return RunConfig(profile=name, source=source)


#: the configurations in force, innermost last (:func:`using`); :func:`install` sets the bottom one
_STACK: list[RunConfig] = []
_INSTALLED: list[RunConfig] = []


def current() -> RunConfig:
    """The configuration in force: the innermost :func:`using` block's, else the one an entry point installed
    for the whole process (:func:`install`: the pytest plugin, a worker), else :func:`from_environment`."""
    if _STACK:
        return _STACK[-1]
    if _INSTALLED:
        return _INSTALLED[-1]
    return from_environment()


@contextmanager
def using(config: RunConfig | None = None, *, profile: Any = _KEEP, budget: Any = _KEEP, seed: Any = _KEEP,
          executor: Any = _KEEP, source: Any = _KEEP) -> Iterator[RunConfig]:
    """Within the block, the configuration is ``config`` (default: the current one) with the fields given
    here replaced; a ``profile`` given without a ``source`` has the source ``"argument"``.  Yields it."""
    base = config if config is not None else current()
    changes = {k: v for k, v in (("profile", profile), ("budget", budget), ("seed", seed),
                                 ("executor", executor), ("source", source)) if v is not _KEEP}
    if "profile" in changes and "source" not in changes and changes["profile"] != base.profile:
        changes["source"] = "argument"
    cfg = dataclasses.replace(base, **changes)
    _STACK.append(cfg)
    try:
        yield cfg
    finally:
        for i in range(len(_STACK) - 1, -1, -1):     # its own entry (blocks nest; identity, not equality)
            if _STACK[i] is cfg:
                del _STACK[i]
                break


def chosen(profile: str | None) -> Any:
    """The block of an API call's ``profile=`` argument: :func:`using` that profile (one of
    :data:`verimono.execution.profiles.PROFILES`, else :class:`verimono.UnknownProfile`), or nothing new
    when it is ``None`` (the current configuration stands)."""
    from contextlib import nullcontext

    if profile is None:
        return nullcontext(current())
    get_profile(profile)           # UnknownProfile names the choices
    return using(profile=profile, source="argument")


def install(config: RunConfig) -> None:
    """Make ``config`` the process's configuration outside any :func:`using` block (the pytest plugin for its
    session; replaces an earlier one)."""
    _INSTALLED[:] = [config]


__all__ = ["RunConfig", "current", "using", "chosen", "install", "from_environment"]
