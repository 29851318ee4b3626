"""The floor under issue 43's item 1: what the laws' own arithmetic costs per row, with no engine around it.

Item 1 asks verimono's own time per law evaluation to be at most the subject's.  Whatever the search does around
a law, each evaluated sample costs at least the law's own arithmetic: the differences, inner products and norms of
its statement, and the rounding bound of :func:`verimono.core.tolerances.row_tolerances` that judges them.  This
module times exactly that, with no engine: each operator law's vectorised form
(:data:`verimono.checks.engine.batches.VECTORISED`) over ``B`` rows whose points are handed over as arrays (no
``Sample`` objects made, none stacked: :func:`rows_of_arrays`), the subject's calls (its resolvent and members, a
block member as one call) on the clock of :mod:`engine_overhead`, so that

    floor own / row = (CPU of the form - the subject's CPU) / B,      floor ratio = that / the subject's per row.

``B = 12`` is the typical pass of a ci battery (about 12 rows a subject call, docs/speed.md), ``B = 1000`` a dense
design in one pass; ``one λ`` hands every row the same ``(λ, t)`` (one subject call a pass on an operator that maps
batches), ``λ per row`` a step of its own to each row (a call per row, as a step coordinate's design does).

Run it under any version with the vectorised forms (public names and ``verimono.checks.engine.batches``)::

    OPENBLAS_NUM_THREADS=1 python tests/benchmarks/law_floor.py          # a table, then one JSON line

A floor ratio above 1 on an operator means item 1's goal cannot be met there by the engine's work alone: the law's
own arithmetic, judged with its rounding bound, already costs more than the subject's.
"""

from __future__ import annotations

import math
import os
import sys
import time
from typing import Any

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import engine_overhead as eo  # noqa: E402 - the clock and the catalog of the item-1 benchmark

#: rows of a pass measured
SIZES = (12, 100, 1000)
#: CPU seconds a (law, B, steps) cell is repeated for at least
MIN_CPU = 0.05


def rows_of_arrays(X1: np.ndarray, X2: np.ndarray, lam: np.ndarray, mu: np.ndarray, nu: np.ndarray,
                   t: np.ndarray) -> Any:
    """A :class:`~verimono.checks.engine.batches.Rows` holding the arrays as they are (the state its constructor
    leaves, without a sample object per row)."""
    from verimono.checks.engine.batches import Rows
    r = Rows([])
    r.x1, r.x2, r.lam, r.mu, r.nu, r.t = X1, X2, lam, mu, nu, t
    r.ok = np.ones(X1.shape[0], dtype=bool)
    return r


def floor_cell(op: Any, clock: eo.SubjectClock, fn: Any, B: int, per_row: bool, seed: int = 0) -> dict | None:
    """The law form ``fn`` over ``B`` rows of ``op`` (``per_row``: a step of its own to every row), repeated for at
    least :data:`MIN_CPU`: its own and the subject's CPU per row (``None`` when the form raises here or answers no
    row: a law of members the operator does not provide)."""
    rng = np.random.default_rng([seed, B, per_row])
    n = op.dim
    X1, X2 = 2.0 * rng.standard_normal((B, n)), 2.0 * rng.standard_normal((B, n))
    if per_row:
        lam = 10.0 ** rng.uniform(-4, 1, B)
    else:
        lam = np.full(B, 0.5)
    mu, nu, t = np.full(B, 0.3), np.full(B, 0.7), np.zeros(B)
    reps, own, subject = 0, 0.0, 0.0
    while own + subject < MIN_CPU or reps < 3:
        r = rows_of_arrays(X1.copy(), X2.copy(), lam.copy(), mu.copy(), nu.copy(), t.copy())
        s0 = clock.seconds + clock.member_seconds
        c0 = time.process_time()
        try:
            with np.errstate(all="ignore"):
                q = np.asarray(fn(op, r), dtype=float)
            r.accepted(q, 1.0)
        except Exception:   # noqa: BLE001 - a form that needs a member this operator lacks: no cell
            return None
        total = time.process_time() - c0
        sub = clock.seconds + clock.member_seconds - s0
        if not r.ok.any():        # a law of members this operator does not provide: it evaluated nothing here
            return None
        own, subject, reps = own + total - sub, subject + sub, reps + 1
    return {"own_us_per_row": 1e6 * own / reps / B, "subject_us_per_row": 1e6 * subject / reps / B,
            "ratio": own / subject if subject > 0 else math.inf}


def measure(sizes: tuple = SIZES) -> dict:
    """Every law form on every catalog operator (and PyProximal's box), every size, one λ and λ per row:
    ``{operator: {law: {"B/steps": cell}}}``."""
    import verimono.checks.operator_laws  # noqa: F401 - registers the laws and their forms
    import verimono.checks.prox_laws  # noqa: F401
    from verimono.checks.engine.batches import VECTORISED
    out: dict = {}
    subjects = [(name, True) for name in eo.catalog()] + [("pyproximal.Box n=3", False)]
    for name, catalog in subjects:
        if catalog:
            op, clock, undo = eo.timed_catalog(name, members=True)
        else:
            lib = eo.pyproximal_box()
            if lib is None:
                continue
            (op, clock), undo = lib, (lambda: None)
        try:
            laws = {}
            for law, fn in sorted(VECTORISED.items()):
                cells = {}
                for B in sizes:
                    for per_row in (False, True):
                        got = floor_cell(op, clock, fn, B, per_row)
                        if got is not None:
                            cells[f"{B}/{'per row' if per_row else 'one'}"] = got
                if cells:
                    laws[law] = cells
            out[name] = laws
        finally:
            undo()
    return out


def summary(got: dict) -> dict:
    """Per operator and cell, the median over the laws of the floor ratio and of the own µs per row."""
    out: dict = {}
    for name, laws in got.items():
        keys = sorted({k for cells in laws.values() for k in cells}, key=lambda k: (int(k.split("/")[0]), k))
        out[name] = {}
        for k in keys:
            ratios = sorted(c[k]["ratio"] for c in laws.values() if k in c)
            owns = sorted(c[k]["own_us_per_row"] for c in laws.values() if k in c)
            subs = sorted(c[k]["subject_us_per_row"] for c in laws.values() if k in c)
            out[name][k] = {"laws": len(ratios), "ratio_median": ratios[len(ratios) // 2],
                            "ratio_min": ratios[0], "own_us_median": owns[len(owns) // 2],
                            "subject_us_median": subs[len(subs) // 2]}
    return out


def main() -> None:
    import json
    got = measure()
    table = summary(got)
    print("| operator | B / steps | laws | floor own/subject, median (min) | own µs/row | subject µs/row |")
    print("|---|---|---|---|---|---|")
    for name, cells in table.items():
        for k, c in cells.items():
            print(f"| {name} | {k} | {c['laws']} | {c['ratio_median']:.2f} ({c['ratio_min']:.2f}) | "
                  f"{c['own_us_median']:.2f} | {c['subject_us_median']:.2f} |")
    print(json.dumps({"summary": table, "cells": got}))


if __name__ == "__main__":
    main()
