"""Issue 42 item 2: ``thorough`` searches at least 10× the evaluations of ``ci`` on every declared coordinate —
including the coordinates a law's ratio does not read at its worst sample (``"read": False``), which were
covered by a fixed design (the direction by 4 points, ``t`` by 4, ``λ`` by 9 at every profile: ``yosida_in_graph``
got 6.6×, ``yosida_bounded_by_min_norm`` 4.4× thorough/ci evaluations on the ball, seen in the commit that added
this file).  A coordinate flat at its design is now covered by the budget's points more (one in each of
``points`` equal cells), the step decades get twice the budget log-evenly once that exceeds one point a decade,
and the direction search draws a quarter of the budget and refines again from drawn directions while its
budget lasts.  The input forms are a finite set, enumerated whole at every profile."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks import laws_of
from verimono.checks.engine.coordinates import coordinate_search
from verimono.checks.engine.directions import direction_search
from verimono.checks.engine.samples import Sample
from verimono.execution.config import using
from verimono.execution.profiles import get_profile
from verimono.records.results import PASSED, SKIPPED

BALL = vm.NormalCone(vm.sets.Ball(np.zeros(3), 1.0))
CI, THOROUGH = (get_profile(p).search["coordinate"] for p in ("ci", "thorough"))


def _sample() -> Sample:
    return Sample(np.array([2.0, 0.5, -1.0]), np.array([0.3, 1.0, 0.2]), 0.5, 1.0, 0.1, 0.25)


def _counts(found: list[dict]) -> dict[str, int]:
    return {c["coordinate"]: c["points"] for c in found}


def test_a_coordinate_the_law_does_not_read_is_covered_ten_times_more_at_thorough():
    """A ratio that reads no coordinate (flat everywhere): its every coordinate is covered by the budget's points."""
    flat = lambda s: 0.5        # noqa: E731
    counts = {b: _counts(coordinate_search(flat, BALL, _sample(), 1.0, b, 0, lambda: False)) for b in (CI, THOROUGH)}
    assert set(counts[CI]) == {"direction", "lam decades", "lam", "t", "offset"}, counts
    for name, n in counts[CI].items():
        assert counts[THOROUGH][name] >= 10 * n, (name, counts)
    for b in (CI, THOROUGH):
        assert counts[b]["t"] >= b and counts[b]["direction"] >= b


def test_a_direction_the_law_reads_is_searched_ten_times_more_at_thorough():
    """A ratio read through the direction only (``⟨x2 − x1, a⟩``, largest at ``a``): drawn, sketched and refined
    (from drawn directions again once refined to the finest angle)."""
    a = np.array([0.6, 0.0, 0.8])
    s = _sample()

    def ratio(t: Sample) -> float:
        d = t.x2 - t.x1
        return float(d @ a / np.linalg.norm(d))

    got = {b: direction_search(ratio, BALL, s, b, 0) for b in (CI, THOROUGH)}
    assert got[THOROUGH]["points"] >= 10 * got[CI]["points"], got
    assert got[THOROUGH]["restarts"] > 0 and got[CI]["restarts"] == 0


@pytest.mark.slow
def test_thorough_evaluates_ten_times_ci_on_every_declared_coordinate_of_every_operator_law():
    """Every operator law on the ball, at ``ci`` and ``thorough``: each declared coordinate the ci record searched
    has ≥ 10× the points at thorough (``mu``, ``nu`` and ``scale`` are searched only from a budget of 81 on: below
    it the draws, hypothesis and the scale sweep cover them); the forms are enumerated whole at both."""
    for name, decl in laws_of("operator").items():
        recs = {}
        for profile in ("ci", "thorough"):
            with using(profile=profile):
                recs[profile] = decl.check(BALL, seed=0)
        if recs["ci"].status == SKIPPED:        # the prox laws need a value the ball's normal cone has not
            continue
        assert recs["ci"].status == PASSED and recs["thorough"].status == PASSED, (name, recs)
        ci, th = (_counts(recs[p].details["searched"]["coordinates"]) for p in ("ci", "thorough"))
        assert {c.split()[0] for c in ci} <= set(decl.over) and "lam decades" in ci, (name, ci)   # (offset: when
        for c, n in ci.items():                    # the worst sample is outside the domain)
            if c.split()[0] == "offset" and c not in th:
                continue    # searched only from a worst sample outside the domain: thorough's worst may lie inside
            assert c == "form" and th[c] == n or th[c] >= 10 * n, (name, c, n, th)
