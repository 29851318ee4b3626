"""Issue 43 item 1 (branch blocks): a coordinate design's samples as one block of arrays
(:class:`verimono.checks.engine.blocks.SampleBlock`) — the rows the vectorised form reads are the samples' own numbers,
a row made a sample is the sample the one-point code makes, and the records are those of the designs as lists."""

from __future__ import annotations

import numpy as np

from verimono import NormalCone
from verimono.checks.engine import coordinates, search
from verimono.checks.engine.batches import Rows
from verimono.checks.engine.blocks import SampleBlock
from verimono.checks.engine.samples import Sample, with_field, with_fields
from verimono.core.sets import Ball, Box


def _start():
    return Sample(np.array([0.3, -1.7, 2.5]), np.array([0.31, -1.69, 2.4]), 0.25, 3.0, 0.7, 0.4)


def _same(a: Sample, b: Sample) -> bool:
    """Field by field, to the bit (and the numbers' Python types: a record prints them)."""
    return (a.x1.tobytes() == b.x1.tobytes() and a.x2.tobytes() == b.x2.tobytes() and a.form == b.form
            and all(type(getattr(a, k)) is type(getattr(b, k)) and repr(getattr(a, k)) == repr(getattr(b, k))
                    for k in ("lam", "mu", "nu", "t")) and a.recipe == b.recipe)


def _rows_equal(r: Rows, q: Rows) -> bool:
    return all(getattr(r, k).tobytes() == getattr(q, k).tobytes() and getattr(r, k).shape == getattr(q, k).shape
               for k in ("x1", "x2", "lam", "mu", "nu", "t"))


def test_a_step_design_block_is_the_samples_with_field_makes():
    s, vs = _start(), [1e-153, 1e-4, 0.031, 1.0 / 3.0, 10.0, 1e7]
    for name in ("lam", "mu", "nu", "t"):
        block = SampleBlock.along(s, name, vs)
        one = [with_field(s, name, float(v)) for v in vs]
        assert len(block) == len(vs)
        assert all(_same(block[i], one[i]) for i in range(len(vs))), name
        assert all(block[i].x1 is s.x1 and block[i].x2 is s.x2 for i in range(len(vs)))   # the start's own points
        assert _rows_equal(Rows(block), Rows(one)), name        # the form reads the same numbers
        assert block[2] is block[2] and block[1:4][1] is block[2]      # made once, shared by slices
        assert [x.lam for x in block] == [x.lam for x in one]         # iteration makes every row


def test_a_points_design_block_is_the_samples_the_one_point_lambda_makes():
    s, vs = _start(), [1e-9, 1e-3, 0.5, 2.0, 1e6]
    r = float(np.linalg.norm(s.x1))
    one = [with_fields(s, x1=s.x1 * (v / r), x2=s.x2 * (v / r)) for v in vs]
    block = coordinates._rows_of(s, vs, lambda f: f[:, None] * s.x1, lambda f: f[:, None] * s.x2, np.array(vs) / r)
    assert isinstance(block, SampleBlock)
    assert all(_same(block[i], one[i]) for i in range(len(vs)))
    assert len({id(block[i].x1) for i in range(len(vs))}) == len(vs)      # a row of its own each
    assert _rows_equal(Rows(block), Rows(one))
    stacked = SampleBlock.stacked(one)
    assert all(stacked[i] is one[i] for i in range(len(one))) and _rows_equal(Rows(stacked), Rows(one))


def _records(cases, seed=3):
    from verimono.checks import run_law
    from verimono.execution.config import using
    out = []
    with using(profile="ci"):
        for op, law in cases:
            d = run_law(law, op, seed=seed).to_dict()
            d.pop("duration", None)
            out.append(d)
    return out


def _band(x, lam, t):
    """Soft thresholding (``F = ∂|·|₁``) using ``3λ`` for ``λ ∈ [0.031, 0.036]`` only: broken in a band of one
    coordinate, which the step designs meet (not the draws)."""
    x = np.asarray(x, dtype=float)
    return np.sign(x) * np.maximum(np.abs(x) - (3 * lam if 0.031 <= lam <= 0.036 else lam), 0.0)


def test_the_records_of_the_designs_as_blocks_are_those_of_the_designs_as_lists(monkeypatch):
    """On lawful operators and on one broken in a band of step sizes (found by the step designs, shrunk from the row
    the block made): every field but ``duration`` the same with the designs as blocks and as lists of samples — and
    with blocks, fewer samples made than rows evaluated."""
    from verimono import operator_from_resolvent
    band = operator_from_resolvent(_band, 3, name="band")
    ball, box = NormalCone(Ball(np.zeros(3), 1.0)), NormalCone(Box(-np.ones(3), np.ones(3)))
    cases = [(band, "resolvent_identity"), (ball, "monotone"), (box, "resolvent_firmly_nonexpansive"),
             (ball, "min_norm_least"), (box, "yosida_limit")]
    made = [0]
    real_make = SampleBlock._make

    def counted(self, i):
        made[0] += 1
        return real_make(self, i)
    monkeypatch.setattr(SampleBlock, "_make", counted)
    blocks = _records(cases)
    made_with_blocks = made[0]
    real_samples = coordinates._samples
    monkeypatch.setattr(coordinates, "_samples", lambda at, design: list(real_samples(at, design)))
    lists = _records(cases)
    assert blocks == lists
    assert [r["status"] for r in blocks] == ["failed", "passed", "passed", "passed", "passed"]
    assert "coordinate" in blocks[0]["counterexample"]["found_by"]
    evaluated = sum(r["details"]["evaluations"] for r in blocks)
    assert made_with_blocks < evaluated / 4, (made_with_blocks, evaluated)
    assert search.SampleBlock is SampleBlock


def test_the_seeded_lists_as_blocks_are_the_lists_row_for_row():
    """The edge samples, the sweep and the scale phase asked for by :func:`make_sample` answer one block whose made
    rows are the list's samples to the bit, each owning its points (the draws are shared by every law of a battery)."""
    from verimono.checks.engine import sweep
    from verimono.checks.engine.blocks import make_sample
    from verimono.checks.engine.scales import scale_samples
    op = NormalCone(Box(-np.ones(3), np.ones(3)))
    start = Sample(np.array([3.0, -1e-300, 0.5]), np.array([2.0, 0.0, -4.0]), 0.5, 2.0, 1.0, 0.25)
    pairs = {"edge": lambda make: sweep.edge_draws(3, 7, 2.0, 16, make),
             "sweep": lambda make: sweep.sweep_samples(op, 7, 2.0, 33, make),
             "scales": lambda make: scale_samples(start, 27, 3, make)[0]}
    for name, draw in pairs.items():
        block, one = draw(make_sample), draw(Sample)
        assert isinstance(block, SampleBlock) and len(block) == len(one), name
        assert all(_same(block[i], one[i]) for i in range(len(one))), name
        assert _rows_equal(Rows(block), Rows(one)), name
        made = list(block)
        assert len({id(s.x1) for s in made} | {id(s.x2) for s in made}) == 2 * len(made), name
        assert all(s.x1.base is None and s.x2.base is None for s in made), name      # copies, no views
    odd = Sample(start.x1, start.x2, np.float64(0.5), 2.0, 1.0, 0.25)     # a number that is no Python float: a list
    assert isinstance(scale_samples(odd, 27, 3, make_sample)[0], list)
