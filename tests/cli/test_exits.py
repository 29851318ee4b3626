"""What the command line says of itself and of what it was given (issue 41, items 1, 2, 6): ``--version``,
references by a short ASCII id, messages that agree with the exit status, output that never costs the results,
and a subject's own exit that never ends a run with a false status."""

from __future__ import annotations

import importlib.metadata
import re

import pytest

from verimono.cli import main
from verimono.reference import catalog, get, ids


# -- 6. --version, --reference by id ----------------------------------------------------------------------------------

def test_version_prints_the_installed_package_version(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"verimono {importlib.metadata.version('verimono')}"


def test_every_reference_has_a_stable_ascii_id_and_get_takes_either():
    refs = catalog()
    table = ids()
    assert sorted(table.values()) == sorted(p.name for p in refs)      # one id per reference, no other
    for rid, name in table.items():
        assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", rid), rid
        assert get(rid).name == name and get(name).name == name
    # the display name with an ASCII minus for the Unicode one (what a keyboard types) is the same reference
    assert get("Example ex, v = (-t, 0)").name == "Example ex, v = (\u2212t, 0)"
    assert table["example-ramp"] == "Example ex, v = (\u2212t, 0)" and table["tnorm-1"] == "t|x| (n=1)"
    with pytest.raises(KeyError, match="example-ramp"):       # the ids are listed when a name is unknown
        get("no such reference")


def test_the_command_line_resolves_references_by_id():
    import argparse

    from verimono.cli import _context

    ctx = _context(argparse.Namespace(reference=["tnorm-1", "example-ramp", "moving box"]))
    assert [p.name for p in ctx.problems] == ["t|x| (n=1)", "Example ex, v = (\u2212t, 0)", "moving box"]


@pytest.mark.slow
def test_run_takes_a_reference_by_its_id(tmp_path, capsys):
    code = main(["run", "--profile", "ci", "--stage", "convergence", "--reference", "tnorm-1",
                 "--reference", "example-ramp", "--executor", "serial", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "t|x| (n=1)" in out and "Example ex, v = (\u2212t, 0)" in out
