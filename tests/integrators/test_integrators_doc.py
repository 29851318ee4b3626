"""docs/integrators.md: its Python blocks run as written (fast ones; the rest are ```text)."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "integrators.md"


def test_integrators_doc_blocks_run():
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(), re.S)
    assert len(blocks) == 4      # the tolerance study, the inexact catching-up code, the ODE integrator declining
    #                              t|x|, work–precision
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(DOC), "exec"), namespace)
    assert namespace["inexact_ok"] and namespace["report"].counts["failed"] == 0
    assert namespace["ok"] and {v["work"] for v in namespace["wp"].verdicts()} == {"time", "steps"}
