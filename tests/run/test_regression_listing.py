"""`verimono run` and `verimono check` name the regressions they find against the baseline, as `verimono gate`
does: the first LISTED_REGRESSIONS of them, then how many more and the gate command that lists all."""

from __future__ import annotations

import json

from verimono.cli import main
from verimono.run.gate import LISTED_REGRESSIONS, Change, Comparison


def test_regression_lines_list_the_first_ones_then_the_gate_command():
    changes = [Change("removed", f"siconos_lcp[f{i}.dat]", "was passed in the baseline, absent now", True)
               for i in range(5)] + [Change("new", "x[y]", "new record (passed)", False)]
    comparison = Comparison(changes, 5, {})
    lines = comparison.regression_lines("base.json", "out/results.json", limit=3)
    assert lines[:3] == [f"  {c}" for c in changes[:3]]
    assert all(f"siconos_lcp[f{i}.dat]" in lines[i] and "REGRESSION" in lines[i] for i in range(3))
    assert lines[3:] == ["  … and 2 more; `verimono gate --baseline base.json --results out/results.json` lists all"]
    assert comparison.regression_lines(limit=5) == [f"  {c}" for c in changes[:5]]  # all shown: no hint
    assert Comparison(changes[5:], 1, {}).regression_lines() == []


def test_run_names_the_regressed_records_and_the_gate_lists_the_rest(tmp_path, capsys):
    """A baseline with 12 siconos records that the run no longer has: `verimono run` prints the first 10
    regressions by key, then "… and N more" with the `verimono gate` command, which lists every one."""
    out = tmp_path / "out"
    args = ["run", "--profile", "ci", "--stage", "siconos", "--out", str(out)]
    assert main(args) == 0
    doc = json.loads((out / "results.json").read_text())
    record = next(r for r in doc["results"] if r["check"] == "siconos_lcp")
    doc["results"] += [dict(record, subject=f"lcp_gone_{i:02d}.dat") for i in range(12)]
    base = tmp_path / "baseline.json"
    base.write_text(json.dumps(doc))
    capsys.readouterr()

    main(args + ["--baseline", str(base)])
    printed = capsys.readouterr().out.splitlines()
    listed = [ln for ln in printed if ln.startswith("  REGRESSION")]
    gone = [f"siconos_lcp[lcp_gone_{i:02d}.dat]" for i in range(12)]
    assert len(listed) == LISTED_REGRESSIONS == 10
    assert [ln.split()[2].rstrip(":") for ln in listed] == gone[:10]
    # 12 removed records, and the executed counts of siconos_lcp and of the total fell: 14 regressions
    more = f"  … and 4 more; `verimono gate --baseline {base} --results {out / 'results.json'}` lists all"
    assert more in printed
    assert any(ln.startswith("verimono: ") and "against the baseline: 14 regressions" in ln for ln in printed)

    assert main(["gate", "--baseline", str(base), "--results", str(out / "results.json")]) == 1
    gated = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("  REGRESSION")]
    assert len(gated) == 14 and gated[:10] == listed
    assert [ln.split()[2].rstrip(":") for ln in gated[10:12]] == gone[10:]
