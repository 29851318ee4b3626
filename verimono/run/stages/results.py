"""The results one stage writes for later stages (``context.costs``, ``context.partitions``): a dict that checks, during
a run, that a stage reading it declared the stages writing it (:class:`StageResults`)."""

from __future__ import annotations

from typing import Any

from ...core.errors import UndeclaredStageRead
from .current import _running_stage
from .ordering import _reads
from .table import STAGES


class StageResults(dict):
    """A :class:`RunContext` field one stage writes and later stages read (``costs``, ``partitions``: the
    convergence stage's, :attr:`Stage.writes`).  A stage that reads it must name the stages writing it in
    ``after=``: on worker processes it otherwise runs at once with them and reads whatever is there — maybe
    nothing, maybe part of it (the shared queue, :func:`run_stages`) — while one stage after another gives it
    everything: a silent difference between executors.  So, during :func:`run_stages`, a read (``[]``, ``get``,
    ``in``, iteration, ``len``) by a stage of a field that another stage of the same run writes (by its
    ``writes``, or seen writing it) and that the reader did not declare (directly or through another stage) raises
    :class:`verimono.core.errors.UndeclaredStageRead` — under every executor alike, so the missing ``after=``
    shows on the first serial run.  Outside a stage (before the run, ``restore_convergence``) nothing is checked."""

    def __init__(self, field: str, data: Any = ()) -> None:
        super().__init__(data)
        self.field = field
        #: the stages of the run under way (:func:`run_stages`), ``()`` outside one
        self.run: tuple[str, ...] = ()
        #: stages seen writing it (besides those whose :attr:`Stage.writes` names it)
        self.writers: set[str] = set()

    def _read(self) -> None:
        reader = _running_stage()
        if reader is None or not self.run or reader not in STAGES:
            return
        declared = _reads(reader)
        for w in self.run:
            if w == reader or w in declared or w not in STAGES:
                continue
            if self.field in STAGES[w].writes or w in self.writers:
                raise UndeclaredStageRead(
                    f"stage {reader!r} reads context.{self.field}, which stage {w!r} of this run writes, without "
                    f"declaring it: register it with register_stage(..., after=({w!r},)) — undeclared, it runs at "
                    f"once with {w!r} on worker processes and reads whatever is there (maybe nothing)")

    def _wrote(self) -> None:
        writer = _running_stage()
        if writer is not None:
            self.writers.add(writer)

    def __getitem__(self, key: Any) -> Any:
        self._read()
        return super().__getitem__(key)

    def get(self, key: Any, default: Any = None) -> Any:
        self._read()
        return super().get(key, default)

    def __contains__(self, key: object) -> bool:
        self._read()
        return super().__contains__(key)

    def __iter__(self):
        self._read()
        return super().__iter__()

    def __len__(self) -> int:
        self._read()
        return super().__len__()

    def keys(self):
        self._read()
        return super().keys()

    def values(self):
        self._read()
        return super().values()

    def items(self):
        self._read()
        return super().items()

    def __setitem__(self, key: Any, value: Any) -> None:
        self._wrote()
        super().__setitem__(key, value)

    def setdefault(self, key: Any, default: Any = None) -> Any:
        self._wrote()
        return super().setdefault(key, default)

    def __reduce__(self):       # pickled as a plain dict (a unit's arguments): the checks are this process's
        return dict, (dict(self),)
