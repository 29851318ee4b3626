"""The engine's overhead per evaluation of an operator law (issue 43, item 1), measured on a subject: the CPU
time of ``check_operator`` split into the subject's own time (inside its resolvent, timed by a wrapper) and
verimono's (the rest), per law evaluation; and the search resolution the records state per CPU second.

Importable by the benchmarks (:mod:`test_bench_engine_overhead`) and runnable as a script under any version of
verimono (public names only), so that the code before the issue and today's are measured side by side::

    cd /tmp && /work/venv-old016/bin/python /path/to/engine_overhead.py     # the code before
    python tests/benchmarks/engine_overhead.py                               # today's

**Resolution** of a record: its ``details["searched"]["coordinates"]`` read as *cells* — a coordinate searched
to a resolution ``ρ`` over ``[lo, hi]`` holds ``log(hi/lo)/log ρ`` cells (a logarithmic one; a factor ``ρ``)
or ``(hi - lo)/ρ`` (a linear one: the direction's radians, the time); one the law does not read counts its
design points.  The resolution per second of a battery is the sum of its records' cells over its CPU seconds.
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable

import numpy as np


class SubjectClock:
    """Wraps a resolvent ``f(x, lam, t)``: counts the rows it mapped and the CPU time spent inside it.  With
    :meth:`member`, the operator's other members (``min_norm``, ``contains``, ``project_domain``, ``value``) are
    timed on the same clock (the subject's own code too; the outermost call only, so a member calling another is
    counted once)."""

    def __init__(self, f: Callable) -> None:
        self.f, self.seconds, self.calls, self.rows, self.depth = f, 0.0, 0, 0, 0
        self.member_seconds, self.member_calls = 0.0, 0

    def __call__(self, *args, **kwargs):
        if self.depth:
            return self.f(*args, **kwargs)
        self.depth += 1
        start = time.process_time()
        try:
            return self.f(*args, **kwargs)
        finally:
            self.depth -= 1
            self.seconds += time.process_time() - start
            self.calls += 1
            x = args[1] if len(args) > 1 and hasattr(args[1], "ndim") else args[0]
            self.rows += x.shape[0] if getattr(x, "ndim", 1) == 2 else 1

    def member(self, f: Callable) -> Callable:
        """``f`` (a member other than the resolvent) timed on this clock."""
        def timed(*args, **kwargs):
            if self.depth:
                return f(*args, **kwargs)
            self.depth += 1
            start = time.process_time()
            try:
                return f(*args, **kwargs)
            finally:
                self.depth -= 1
                spent = time.process_time() - start
                self.seconds += spent
                self.member_seconds += spent
                self.member_calls += 1
        return timed


def cells(searched: dict) -> float:
    """The resolution cells of one record's ``details["searched"]`` (module docstring)."""
    total = 0.0
    for c in (searched or {}).get("coordinates", []):
        if c.get("coordinate") == "form":
            continue
        lo, hi = c.get("range", [0.0, 0.0])
        res = c.get("resolution")
        if not c.get("read") or res is None:
            total += float(c.get("points", 0))
        elif c.get("log"):
            total += math.log(hi / lo) / math.log(res) if res > 1.0 else 0.0
        else:
            total += (hi - lo) / res if res > 0 else 0.0
    return total


def measure(op: Any, seed: int = 0, profile: str = "ci", clock: SubjectClock | None = None,
            per_law: bool = False) -> dict:
    """``check_operator(op)`` at ``profile``: CPU seconds, law evaluations, subject seconds and calls (``clock``,
    when the subject's resolvent is wrapped by one), the engine's own time per evaluation and the resolution
    cells of the records.  With ``per_law``, ``laws``: each law's ``[CPU s, subject s]`` (the time from the record
    before to its own, read where the battery adds it to its report)."""
    import verimono as vm
    if clock is not None:
        clock.seconds = clock.calls = clock.rows = clock.member_seconds = clock.member_calls = 0
    laws: dict[str, list[float]] = {}
    report_cls = type(vm.Report())
    add = report_cls.__dict__.get("add")
    if per_law and add is not None:
        mark = [time.process_time(), 0.0]

        def timed_add(self, result):          # a law's record: the CPU and subject time since the last one
            now, sub = time.process_time(), clock.seconds if clock is not None else 0.0
            row = laws.setdefault(getattr(result, "check", "?"), [0.0, 0.0])
            row[0] += now - mark[0]
            row[1] += sub - mark[1]
            mark[0], mark[1] = now, sub
            return add(self, result)
        report_cls.add = timed_add
    start = time.process_time()
    try:
        rep = vm.check_operator(op, seed=seed, profile=profile)
    finally:
        if per_law and add is not None:
            report_cls.add = add
    cpu = time.process_time() - start
    evals = sum(int(r.details.get("evaluations", 0) or 0) for r in rep.results)
    res = sum(cells(r.details.get("searched", {})) for r in rep.results)
    out = {"cpu_s": cpu, "evaluations": evals, "cells": res, "cells_per_cpu_s": res / cpu,
           "evaluations_per_cpu_s": evals / cpu, "failed": rep.counts.get("failed", 0),
           "passed": rep.counts.get("passed", 0)}
    if clock is not None:
        own = cpu - clock.seconds
        out.update(subject_s=clock.seconds, subject_calls=clock.calls, subject_rows=clock.rows,
                   member_s=clock.member_seconds, member_calls=clock.member_calls,
                   own_us_per_eval=1e6 * own / max(1, evals), subject_us_per_eval=1e6 * clock.seconds / max(1, evals),
                   own_over_subject=own / clock.seconds if clock.seconds > 0 else math.inf)
    if per_law:
        out["laws"] = laws
    return out


def single_call_us(f: Callable, x: np.ndarray, rounds: int = 2000) -> float:
    """The subject's own cost of one call at ``x`` (median of 5 batches of ``rounds`` calls), µs."""
    times = []
    for _ in range(5):
        start = time.process_time()
        for _ in range(rounds):
            f(x, 0.5, 0.0)
        times.append((time.process_time() - start) / rounds)
    return 1e6 * sorted(times)[2]


def catalog() -> dict[str, Callable[[], Any]]:
    """Cheap catalog operators in R^3 (public names, as old as the package)."""
    import verimono as vm
    from verimono.core.sets import Ball, Box
    return {
        "NormalCone(Ball) n=3": lambda: vm.NormalCone(Ball(np.zeros(3), 1.0)),
        "NormalCone(Box) n=3": lambda: vm.NormalCone(Box(-np.ones(3), np.ones(3))),
        "NormSubdifferential n=3": lambda: vm.NormSubdifferential(1.0, dim=3),
        "Linear n=3": lambda: vm.Linear(np.array([[2.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.5]])),
    }


#: the members besides the resolvent timed as the subject's own by ``timed_catalog(..., members=True)``
MEMBERS = ("min_norm", "contains", "project_domain", "value")

#: the catalog's members of a block of rows (one call for many rows, bit-identical to the member per row), timed
#: as the subject's own with ``members=True``; ``_value_at`` returns the function it times
BLOCKS = ("_contains_rows", "_value_rows")


def timed_catalog(name: str, members: bool = False):
    """The catalog operator ``name`` with its class's resolvent wrapped by a :class:`SubjectClock` (on the class,
    so that the operator keeps its fast paths) — with ``members``, its other :data:`MEMBERS`, its block members
    (:data:`BLOCKS`) and the functions its ``_value_at`` returns on the same clock.  A member the class marks as
    its own (``_<member>_written``, which its block members check before they answer for it) is marked with its
    wrapper, so that the blocks still answer as in a user's run, a block call counted as one subject call;
    returns ``(op, clock, undo)``."""
    op = catalog()[name]()
    cls = type(op)
    names = ("resolvent",) + MEMBERS + BLOCKS + ("_value_at",) + tuple(f"_{m}_written" for m in MEMBERS)
    originals = {m: cls.__dict__.get(m) for m in names}
    inner = getattr(cls, "resolvent")
    clock = SubjectClock(inner)

    def resolvent(self, x, lam, t=0.0):
        return clock(self, x, lam, t)
    cls.resolvent = resolvent
    if members:
        provides = getattr(op, "provides", None)
        for m in MEMBERS + BLOCKS:
            f = getattr(cls, m, None)
            # a member the operator does not provide stays unwrapped: a wrapper would look provided to the laws
            if callable(f) and (m in BLOCKS or not callable(provides) or provides(m)):
                w = clock.member(f)
                setattr(cls, m, w)
                if originals.get(f"_{m}_written") is not None and originals[f"_{m}_written"] is f:
                    setattr(cls, f"_{m}_written", w)
        value_at = getattr(cls, "_value_at", None)
        if callable(value_at):
            def timed_value_at(self, t=0.0, _at=value_at):
                g = clock.member(_at)(self, t)
                return None if g is None else clock.member(g)
            cls._value_at = timed_value_at

    def undo() -> None:
        for m, original in originals.items():
            if original is None:
                if m in cls.__dict__:
                    delattr(cls, m)
            else:
                setattr(cls, m, original)
    return op, clock, undo


def pyproximal_box(dim: int = 3):
    """PyProximal's projection onto the box ``[-1, 1]^n`` as an operator (its resolvent timed), or ``None``."""
    try:
        import pyproximal
    except ImportError:
        return None
    import verimono as vm
    box = pyproximal.Box(-1.0, 1.0)
    clock = SubjectClock(lambda x, lam, t: box.prox(x, lam))
    return vm.operator_from_resolvent(clock, dim, name="pyproximal.Box"), clock


def torch_soft_threshold(dim: int = 3):
    """A PyTorch prox (soft thresholding, ``F = ∂|·|_1``) as an operator, or ``None`` without torch."""
    try:
        import torch
    except ImportError:
        return None
    import verimono as vm

    def prox(x, lam, t):
        x = torch.as_tensor(x, dtype=torch.float64)
        return torch.sign(x) * torch.clamp(torch.abs(x) - lam, min=0.0)
    clock = SubjectClock(prox)
    return vm.operator_from_resolvent(clock, dim, name="torch soft threshold"), clock


def main(rounds: int = 3) -> None:
    import json
    import verimono as vm
    rows = {}
    for name in catalog():
        got = []
        for r in range(rounds):
            op, clock, undo = timed_catalog(name)
            try:
                got.append(measure(op, seed=r, clock=clock))
            finally:
                undo()
        rows[name] = got
    lib = pyproximal_box()
    if lib is not None:
        rows["pyproximal.Box n=3"] = [measure(lib[0], seed=r, clock=lib[1]) for r in range(rounds)]
    print(json.dumps({"verimono": getattr(vm, "__version__", "?"), "rows": rows}))


def main_members(rounds: int = 3, seeds: tuple = (0, 1, 2), per_law: bool = False) -> None:
    """As :func:`main`, with every member of the catalog's operators timed as the subject's own (``members=True``,
    the block members too): prints one JSON row per operator and seed (with ``per_law``, each law's CPU and
    subject seconds)."""
    import json
    import verimono as vm
    vm.check_operator(catalog()["NormalCone(Ball) n=3"](), seed=99, profile="ci")     # warm: imports, caches
    for name in catalog():
        for r in seeds[:rounds]:
            op, clock, undo = timed_catalog(name, members=True)
            try:
                print(json.dumps({"operator": name, "seed": r,
                                  **measure(op, seed=r, clock=clock, per_law=per_law)}), flush=True)
            finally:
                undo()
    lib = pyproximal_box()
    if lib is not None:
        for r in seeds[:rounds]:
            print(json.dumps({"operator": "pyproximal.Box n=3", "seed": r,
                              **measure(lib[0], seed=r, clock=lib[1], per_law=per_law)}), flush=True)


if __name__ == "__main__":
    import sys
    if "--members" in sys.argv:
        main_members(per_law="--laws" in sys.argv)
    else:
        main()
