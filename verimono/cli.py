"""Command line: ``verimono run`` — solve every analytic reference and verify its convergence order."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .checks.orders import check_stepper
from .stepping import solve


def _run(args: argparse.Namespace) -> int:
    from verimono.reference import catalog

    problems = catalog()
    report = check_stepper(solve, problems)
    rows = [("problem", "expected", "measured order [95% interval]", "verdict")]
    for p, rec in zip(problems, report):
        study = rec.details.get("study", {})
        fit = study.get("fits", {}).get("sup", {})
        if fit.get("exact"):
            measured = "exact (round-off)"
        elif fit:
            measured = f"{float(fit['slope']):.3f} [{float(fit['low']):.3f}, {float(fit['high']):.3f}]"
        else:
            measured = "-"
        rows.append((p.name, str(p.order), measured, rec.status.upper()))
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    for r in rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)))
    print(report.summary())
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps({"results": [r.to_dict() for r in report]}, indent=1))
    return 0 if report.ok else 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="verimono", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="verify the convergence orders of the analytic references")
    run.add_argument("--profile", choices=["dev", "ci", "thorough"], default="dev")
    run.add_argument("--out", default="reports")
    run.set_defaults(func=_run)
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
