"""The order of the stages of a run by what they read (``after=``, :class:`verimono.run.stages.Stage`): the stages a
stage reads, directly or through others (:func:`_reads`), the run's stages with each after those it reads
(:func:`_dependencies_first`), and whether two of a group may run at once (:func:`_some_run_at_once`)."""

from __future__ import annotations

from .table import STAGES


def _reads(name: str) -> set[str]:
    """The stages ``name`` declares it reads (``after``), directly or through those stages' own."""
    seen: set[str] = set()
    todo = list(STAGES[name].after) if name in STAGES else []
    while todo:
        d = todo.pop()
        if d not in seen:
            seen.add(d)
            todo.extend(STAGES[d].after if d in STAGES else ())
    return seen


def _dependencies_first(names: list[str]) -> list[str]:
    """``names`` with every stage moved after the stages of the run it reads (``after``), otherwise in their order:
    ``--stage trajectory_laws --stage convergence`` ran trajectory_laws first, without the convergence studies'
    grids (21 worst ratios other than a whole run's), though ``after`` promises it starts once they have ended."""
    left: dict[str, int] = {}
    for n in names:
        left[n] = left.get(n, 0) + 1
    out: list[str] = []

    def place(n: str, path: tuple[str, ...]) -> None:
        for d in STAGES[n].after:
            if left.get(d, 0) > 0 and d not in path:       # (a cycle of after's: left in the given order)
                place(d, path + (d,))
        if left[n] > 0:
            left[n] -= 1
            out.append(n)

    for n in names:
        if left[n] > 0:
            place(n, (n,))
    return out


def _some_run_at_once(group: list[str]) -> bool:
    """Whether two stages of ``group`` may run at once: neither reads the other's results, even through a third
    (``verimono check``'s convergence and trajectory_laws, the second after the first, run one after the other
    as before, without a thread or a queue's gathering wait)."""
    reads = {n: {d for d in STAGES[n].after if d in group} for n in group}
    changed = True
    while changed:                     # what each reads, directly or through another stage of the group
        changed = False
        for n in group:
            more = set().union(*(reads[d] for d in reads[n])) - reads[n]
            if more:
                reads[n] |= more
                changed = True
    return any(a not in reads[b] and b not in reads[a] for i, a in enumerate(group) for b in group[i + 1:])
