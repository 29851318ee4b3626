"""Same seed → same records, whatever the user imported.  Hypothesis mixes numeric literals of imported
"local" modules into generation; verimono's searches switch that off (verimono.core._reproducible), so a record's
seed reproduces it in a fresh process.  Shown in fresh processes with and without an unrelated module of
many constants, and — so the test is seen able to fail — without the guard the samples hypothesis draws differ.
Hypothesis searches only where it pays (a violation of the draws, or above NUMPY_DIM coordinates): the subjects
are a lawful prox in R^65 and, in R^2, a prox whose value laws break."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

SCRIPT = textwrap.dedent('''
    import json, sys
    import numpy as np
    if sys.argv[1] == "import":
        import user_constants          # an unrelated module of the user, full of numeric literals
    if sys.argv[2] == "unguarded":     # the mechanism verimono switches off, left on
        import contextlib, verimono.checks.engine.search as search
        search.no_local_constants = contextlib.nullcontext
    import verimono as vm
    import verimono.checks.engine.search as engine
    drawn, evaluate = [], engine._Search.evaluate
    def logged(self, s, climb=False):     # the samples hypothesis draws (climb: inside hypothesis's search)
        if climb:
            drawn.append(s.to_dict())
        return evaluate(self, s, climb)
    engine._Search.evaluate = logged
    soft = lambda x, lam: np.sign(x) * np.maximum(np.abs(x) - lam, 0.0)
    # above NUMPY_DIM = 64 coordinates hypothesis searches every law (draws and edge samples below: no hypothesis)
    op = vm.operator_from_prox(soft, value=lambda x: float(np.abs(x).sum()), shape=65, name="soft")
    # the prox of 2|x|_1 stated as |x|_1's: its value laws break at the draws, so hypothesis searches them
    bad = vm.operator_from_prox(lambda x, lam: soft(x, 2 * lam), value=lambda x: float(np.abs(x).sum()), shape=2,
                                name="soft at 2 lam")
    reps = [vm.check_operator(o, seed=7, examples=15, profile="dev") for o in (op, bad)]
    print(json.dumps([[r.check, r.status, r.worst, r.details.get("worst_sample"), r.counterexample]
                      for rep in reps for r in rep] + [drawn]))
''')


def _constants_module(tmp_path):
    lines = [f"C{i} = {v!r}" for i, v in enumerate([0.125 * k for k in range(-80, 81)] + [1e-3 * k for k in range(1, 60)])]
    (tmp_path / "user_constants.py").write_text("\n".join(lines) + "\n")


def _records(tmp_path, imported: bool, guarded: bool = True):
    out = subprocess.run([sys.executable, "-c", SCRIPT, "import" if imported else "plain",
                          "guarded" if guarded else "unguarded"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=600,
                         env={**__import__("os").environ, "PYTHONPATH": str(tmp_path), "HYPOTHESIS_PROFILE": "dev"})
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_the_guard_empties_the_local_constants_and_restores_them():
    """The in-process part of the tests below (fresh processes, tier ``slow``): within the guard hypothesis'
    pool of local constants is empty, and afterwards it is hypothesis' own again."""
    from verimono.core._reproducible import no_local_constants

    providers = pytest.importorskip("hypothesis.internal.conjecture.providers")
    before = getattr(providers, "_get_local_constants", None)
    with no_local_constants() as found:
        if not found:
            pytest.skip("this hypothesis has no local-constants mechanism to switch off")
        from hypothesis.internal.constants_ast import Constants

        assert providers._get_local_constants is not before
        assert providers._get_local_constants() == Constants()
    assert providers._get_local_constants is before


@pytest.mark.slow
def test_same_seed_same_records_with_and_without_an_unrelated_module(tmp_path):
    _constants_module(tmp_path)
    plain, imported = _records(tmp_path, False), _records(tmp_path, True)
    assert plain == imported
    assert any(r[3] for r in plain)       # the records carry their worst samples: the comparison is not vacuous


@pytest.mark.slow
def test_without_the_guard_the_import_changes_the_samples(tmp_path):
    from verimono.core._reproducible import no_local_constants

    with no_local_constants() as found:
        if not found:
            pytest.skip("this hypothesis has no local-constants mechanism to switch off")
    _constants_module(tmp_path)
    assert _records(tmp_path, False, guarded=False) != _records(tmp_path, True, guarded=False)


@pytest.mark.slow
def test_a_fresh_process_reproduces_the_records_of_this_one(tmp_path):
    """This pytest process has imported many modules; a fresh one with the record's seed gets the same."""
    import numpy as np
    import verimono as vm

    soft = lambda x, lam: np.sign(x) * np.maximum(np.abs(x) - lam, 0.0)   # noqa: E731
    op = vm.operator_from_prox(soft, value=lambda x: float(np.abs(x).sum()), shape=65, name="soft")
    bad = vm.operator_from_prox(lambda x, lam: soft(x, 2 * lam), value=lambda x: float(np.abs(x).sum()), shape=2,
                                name="soft at 2 lam")
    reps = [vm.check_operator(o, seed=7, examples=15, profile="dev") for o in (op, bad)]   # whatever $CI says
    here = json.loads(json.dumps([[r.check, r.status, r.worst, r.details.get("worst_sample"), r.counterexample]
                                  for rep in reps for r in rep]))
    _constants_module(tmp_path)
    assert here == _records(tmp_path, False)[:-1]      # (the fresh process's last entry: hypothesis's samples)
