"""The assumption records of a reference as plain dicts, with the modules that ask ``accepts_times`` patched: what
tests/checks/test_time_vectorised.py and tests/lcs/test_lcs_times_per_row.py compare (a block of times against
the per-time path), shared here as the zoo is (tests/conftest.py puts this folder on ``sys.path``)."""

from __future__ import annotations

import importlib
import json

#: the modules that ask ``accepts_times`` (each patched where it has the attribute)
ASKERS = ("verimono.checks.assumptions", "verimono.checks.assumption_a2", "verimono.checks.assumption_bounds",
          "verimono.checks.assumption_samples")


def assumption_records(name, monkeypatch, time, points=8, **patches) -> list[dict]:
    """The five assumption records of reference ``name`` (``check_assumptions(..., composite=False)`` under the
    time budget ``time`` and ``points`` points) as dicts without ``duration``, with ``patches`` (attribute →
    value) set on every module of :data:`ASKERS` that has the attribute, for the call only."""
    from verimono import reference
    from verimono.checks.assumptions import check_assumptions
    from verimono.checks.engine.supremum import budgets

    with monkeypatch.context() as m:
        for mod in ASKERS:
            for attr, value in patches.items():
                if hasattr(importlib.import_module(mod), attr):
                    m.setattr(f"{mod}.{attr}", value)
        with budgets(time=time, points=points):
            report = check_assumptions(reference.get(name), composite=False)
    out = []
    for r in report:
        d = json.loads(json.dumps(r.to_dict(), default=str))
        d.pop("duration", None)
        out.append(d)
    return out
