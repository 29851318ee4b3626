"""Copy the Siconos reference data from ``../shared/siconos`` into the package (``verimono/data/siconos``).

Reads only the source folder; writes only the data folder:

* ``refs/NAME.ref`` -> ``refs/NAME.ref.gz`` (gzip level 9, header time 0 and no file name: the same bytes
  on every run of one zlib; the decompressed text is the source file byte for byte);
* ``lcp/*.dat`` and ``CASES.md`` -> copied unchanged (the LCP files are 37 kB in all: not worth compressing);
* ``MANIFEST.json``: for every file written, its source path, the SHA-256 and size of the source and of
  the stored bytes, and for data files the shape and SHA-256 of every array the verimono reader returns
  (little-endian float64 bytes), computed from the *source* file.  ``tests/test_siconos_data.py`` checks
  the packaged files against it.

Usage (from the repository root): ``python tools/pack_siconos_data.py [SOURCE]`` (default
``../shared/siconos``).  ``PROVENANCE.md`` and ``LICENSE-Apache-2.0`` beside the data are written by hand.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import shutil
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from verimono.lcs.siconos import read_lcp, read_ref  # noqa: E402

DEST = REPO / "verimono" / "data" / "siconos"


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def array_entry(a: np.ndarray) -> dict:
    """Shape and SHA-256 of ``a`` as contiguous little-endian float64 bytes."""
    return {"shape": list(a.shape), "sha256": sha256(np.ascontiguousarray(a, dtype="<f8").tobytes())}


def main(source: Path) -> None:
    files: dict[str, dict] = {}

    def record(src: Path, dest: Path, stored: bytes, arrays=None) -> None:
        dest.parent.mkdir(parents=True, exist_ok=True)
        dest.write_bytes(stored)
        raw = src.read_bytes()
        entry = {"source": src.relative_to(source).as_posix(), "source_bytes": len(raw),
                 "source_sha256": sha256(raw), "stored_bytes": len(stored), "stored_sha256": sha256(stored)}
        if arrays is not None:
            entry["arrays"] = [array_entry(a) for a in arrays]
        files[dest.relative_to(DEST).as_posix()] = entry

    for src in sorted((source / "refs").glob("*.ref")):
        record(src, DEST / "refs" / (src.name + ".gz"), gzip.compress(src.read_bytes(), compresslevel=9, mtime=0),
               [read_ref(src)])
    for src in sorted((source / "lcp").glob("*.dat")):
        record(src, DEST / "lcp" / src.name, src.read_bytes(), list(read_lcp(src)))
    record(source / "CASES.md", DEST / "CASES.md", (source / "CASES.md").read_bytes())
    rows = ",\n".join(f"  {json.dumps(k)}: {json.dumps(files[k], sort_keys=True)}" for k in sorted(files))
    (DEST / "MANIFEST.json").write_text('{"source": "../shared/siconos (see PROVENANCE.md)",\n "files": {\n'
                                        + rows + "\n }\n}\n")
    before = sum(e["source_bytes"] for e in files.values())
    after = sum(e["stored_bytes"] for e in files.values())
    print(f"{len(files)} files: {before} bytes in {source}, {after} bytes stored in {DEST}")


if __name__ == "__main__":
    src = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO.parent / "shared" / "siconos"
    if not (src / "refs").is_dir():
        sys.exit(f"{src} holds no refs/ folder")
    if DEST.exists():
        for old in [DEST / "refs", DEST / "lcp"]:
            shutil.rmtree(old, ignore_errors=True)
    main(src.resolve())
