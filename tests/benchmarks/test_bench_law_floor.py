"""The floor under issue 43's item 1 (:mod:`law_floor`): each operator law's vectorised arithmetic over ``B`` rows,
with no engine around it, against the subject's own calls on the same rows.

The numbers land in ``benchmark.extra_info`` (per operator and cell, the median over the laws of the floor ratio
own/subject and of the own µs per row).  Gate: every operator has law forms that evaluated rows (a floor measured
on nothing is no floor) and every cell's own time is finite; no bound on the ratio itself — it is what the item-1
goal is read against (docs/speed.md, "The floor under item 1"), not a target of this benchmark.
"""

from __future__ import annotations

import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import law_floor as lf  # noqa: E402 - the measurement module next to this file


def test_law_floor_on_the_catalog(gate):
    sizes = gate.size(lf.SIZES, (12,))
    got: dict = {}
    gate.benchmark.pedantic(lambda: got.update(lf.measure(sizes)), rounds=1, iterations=1, warmup_rounds=0)
    table = lf.summary(got)
    gate.benchmark.extra_info.update(table)
    assert set(lf.eo.catalog()) <= set(table), table
    for name, cells in table.items():
        assert cells and all(c["laws"] >= 5 for c in cells.values()), (name, cells)
        assert all(math.isfinite(c["own_us_median"]) and c["subject_us_median"] > 0 for c in cells.values()), cells
