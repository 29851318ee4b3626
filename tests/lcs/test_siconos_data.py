"""The Siconos reference data ship in the package (verimono/data/siconos): they load bit for bit as the
source files did (MANIFEST.json), and the siconos stage finds them with nothing beside the checkout."""

from __future__ import annotations

import gzip
import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pytest

from verimono.checks import siconos as siconos_checks
from verimono.lcs import siconos_cases
from verimono.lcs.siconos import PACKAGED_DATA, read_lcp, read_ref, ref_path, siconos_root

REPO = Path(__file__).resolve().parents[2]
DATA = PACKAGED_DATA / "siconos"
MANIFEST = json.loads((DATA / "MANIFEST.json").read_text())["files"]
SICONOS_CHECKS = ("siconos_agreement", "siconos_lcp")


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _arrays(path: Path) -> list[np.ndarray]:
    return [read_ref(path)] if ".ref" in path.name else list(read_lcp(path))


def test_manifest_lists_exactly_the_packaged_data_files():
    on_disk = {p.relative_to(DATA).as_posix() for p in DATA.rglob("*") if p.is_file()}
    assert on_disk - set(MANIFEST) == {"MANIFEST.json", "PROVENANCE.md", "LICENSE-Apache-2.0"}
    assert set(MANIFEST) <= on_disk
    assert {f"refs/{name}.gz" for name in siconos_cases.CASES} == {k for k in MANIFEST if k.startswith("refs/")}
    assert sum(k.startswith("lcp/") for k in MANIFEST) == 20


@pytest.mark.parametrize("name", sorted(MANIFEST))
def test_packaged_file_loads_bit_identically_to_its_source(name):
    """The stored bytes are the recorded ones; a gzipped file decompresses to the source file's bytes; and
    every array the reader returns has the shape and float64 bytes recorded from the source file."""
    entry, path = MANIFEST[name], DATA / name
    stored = path.read_bytes()
    assert (len(stored), _sha(stored)) == (entry["stored_bytes"], entry["stored_sha256"])
    source = gzip.decompress(stored) if name.endswith(".gz") else stored
    assert (len(source), _sha(source)) == (entry["source_bytes"], entry["source_sha256"])
    if "arrays" in entry:
        got = [{"shape": list(a.shape), "sha256": _sha(np.ascontiguousarray(a, dtype="<f8").tobytes())}
               for a in _arrays(path)]
        assert got == entry["arrays"]


def _shared_siconos() -> Path | None:
    env = os.environ.get("VERIMONO_SHARED")
    for base in ([Path(env)] if env else []) + [REPO.parent / "shared"]:
        if (base / "siconos" / "refs").is_dir():
            return base / "siconos"
    return None


@pytest.mark.skipif(_shared_siconos() is None, reason="no ../shared/siconos beside the repository to compare with")
def test_packaged_arrays_equal_the_shared_originals():
    """Where the original folder is at hand: every array equals the original's, bit for bit."""
    src = _shared_siconos()
    for name in MANIFEST:
        if name.endswith((".ref.gz", ".dat")):
            original = src / name.removesuffix(".gz")
            for a, b in zip(_arrays(original), _arrays(DATA / name), strict=True):
                assert a.shape == b.shape and np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()


def test_locate_data_defaults_to_the_packaged_data_and_checks_a_given_folder(tmp_path, monkeypatch):
    from verimono.run.stages import StageUnavailable, locate_data

    monkeypatch.delenv("VERIMONO_SHARED", raising=False)
    monkeypatch.chdir(tmp_path)
    assert locate_data() == PACKAGED_DATA and siconos_root(locate_data()) == DATA
    with pytest.raises(StageUnavailable, match="holds no Siconos reference data"):
        locate_data(tmp_path)
    # a folder of the same layout, with plain-text trajectories: read as the packaged ones
    (tmp_path / "siconos" / "refs").mkdir(parents=True)
    (tmp_path / "siconos" / "lcp").mkdir()
    plain = tmp_path / "siconos" / "refs" / "CircuitRLCD.ref"
    plain.write_bytes(gzip.decompress((DATA / "refs" / "CircuitRLCD.ref.gz").read_bytes()))
    (tmp_path / "siconos" / "lcp" / "lcp_deudeu.dat").write_bytes((DATA / "lcp" / "lcp_deudeu.dat").read_bytes())
    assert locate_data(tmp_path) == tmp_path
    monkeypatch.setenv("VERIMONO_SHARED", str(tmp_path))
    assert locate_data() == tmp_path
    assert ref_path(siconos_root(tmp_path), "CircuitRLCD.ref") == plain
    mine = siconos_checks.check_siconos_case("CircuitRLCD.ref", tmp_path)
    packaged = siconos_checks.check_siconos_case("CircuitRLCD.ref")
    assert mine.status == "passed" and mine.details == packaged.details
    assert [r.subject for r in siconos_checks.check_siconos_lcps(tmp_path)] == ["lcp_deudeu.dat"]
    (tmp_path / "siconos" / "lcp" / "lcp_deudeu.dat").unlink()   # an empty lcp/ fails, never passes silently
    (rec,) = siconos_checks.check_siconos_lcps(tmp_path)
    assert rec.status == "failed" and "no LCP test file" in rec.message


def test_siconos_stage_runs_from_a_bare_directory_with_the_baseline_records(tmp_path, monkeypatch, capsys):
    """`verimono run --stage siconos` from a folder with no ../shared and no $VERIMONO_SHARED: the 29 records
    of the committed baseline's siconos stage, with their statuses, and no regression against them."""
    from verimono.cli import main
    from verimono.run.gate import compare
    from verimono.records.results import Report, load

    monkeypatch.delenv("VERIMONO_SHARED", raising=False)
    work = tmp_path / "clone"
    work.mkdir()
    monkeypatch.chdir(work)
    assert not (tmp_path / "shared").exists()
    status = main(["run", "--profile", "ci", "--stage", "siconos", "--out", str(work / "out")])
    assert status == 0, capsys.readouterr().out
    results = load(work / "out" / "results.json")
    assert results.meta["data_dir"] == str(PACKAGED_DATA)
    baseline = load(REPO / "reports" / "baseline.json")
    expected = Report([r for r in baseline.results if r.check in SICONOS_CHECKS])
    got = Report([r for r in results.results if r.check in SICONOS_CHECKS])
    assert len(expected) == 29
    assert {r.key: r.status for r in got} == {r.key: r.status for r in expected}
    assert compare(expected, got).regressions == []
