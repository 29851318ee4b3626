"""Run verimono on every entry of the blind set and tabulate what it catches.

    python tests/blind/run_blind.py [--seeds 0 1 2] [--cap SECONDS] [--only NAME ...]

Operators go to ``vm.check_operator(op, seed=s)``, steppers to ``vm.check_stepper(stepper, problems=catalog +
extra, seed=s)`` (the entry's extra problems beside the reference catalog; the catalog plus the generated
samples when it has none), each with the default profile, each (entry, seed) in its own subprocess under a time
cap.  A plant is caught when the report has a failed record; a control passes when ``report.ok`` and no record
failed.  A plant counts as caught (a control as passed) when it is so on every seed.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import pathlib
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent


def _plants():
    spec = importlib.util.spec_from_file_location("verimono_blind_plants", HERE / "plants.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["verimono_blind_plants"] = mod
    spec.loader.exec_module(mod)
    return mod


def run_one(name: str, seed: int) -> dict:
    import verimono as vm
    import verimono.reference

    entry = _plants().BY_NAME[name]
    t0 = time.perf_counter()
    if entry.kind == "operator":
        report = vm.check_operator(entry.build(), seed=seed)
    else:
        built = entry.build()
        stepper, extra = built if isinstance(built, tuple) else (built, None)
        problems = None if extra is None else list(verimono.reference.catalog()) + list(extra)
        report = vm.check_stepper(stepper, problems=problems, seed=seed)
    secs = time.perf_counter() - t0
    records = list(report)
    failed = sorted({r.check for r in records if r.status == "failed"})
    odd = sorted({r.status for r in records} - {"passed", "failed", "skipped", "xfail"})
    return {"ok": bool(report.ok), "failed": failed, "other_statuses": odd, "seconds": secs,
            "n_records": len(records)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--cap", type=float, default=300.0, help="seconds per (entry, seed)")
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--seed", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)

    if args.one is not None:                      # the child: one entry, one seed, a JSON line
        print("BLIND-RESULT " + json.dumps(run_one(args.one, args.seed)))
        return 0

    entries = _plants().PLANTS
    if args.only:
        entries = [e for e in entries if e.name in set(args.only)]
    header = f"{'name':34s} {'kind':8s} {'lawful':6s} {'caught':8s} {'secs':>7s}  failing checks"
    print(header)
    print("-" * len(header))
    n_plants = n_caught = n_ctrl = n_pass = 0
    for e in entries:
        verdicts, checks, secs, notes = [], set(), 0.0, set()
        for seed in args.seeds:
            t0 = time.perf_counter()
            try:
                cp = subprocess.run([sys.executable, str(HERE / "run_blind.py"), "--one", e.name, "--seed", str(seed)],
                                    capture_output=True, text=True, timeout=args.cap)
                line = [ln for ln in cp.stdout.splitlines() if ln.startswith("BLIND-RESULT ")]
                if not line:
                    tail = (cp.stderr.strip().splitlines() or ["no output"])[-1]
                    notes.add(f"crashed: {tail[:80]}")
                    res = None
                else:
                    res = json.loads(line[-1][len("BLIND-RESULT "):])
            except subprocess.TimeoutExpired:
                notes.add(f"timeout > {args.cap:g}s")
                res = None
            secs += time.perf_counter() - t0
            if res is None:
                verdicts.append(False if not e.lawful else False)
                continue
            checks |= set(res["failed"])
            notes |= {f"status {s}" for s in res["other_statuses"]}
            if e.lawful:
                verdicts.append(res["ok"] and not res["failed"])
            else:
                verdicts.append(bool(res["failed"]))
        k, S = sum(verdicts), len(verdicts)
        good = k == S
        if e.lawful:
            n_ctrl += 1
            n_pass += good
            word = ("passed" if good else "FAILED") if S == 1 else f"{k}/{S} ok"
        else:
            n_plants += 1
            n_caught += good
            word = ("yes" if good else "no") if S == 1 else f"{k}/{S}"
        extra = ", ".join(sorted(checks)) or "-"
        if notes:
            extra += "  [" + "; ".join(sorted(notes)) + "]"
        print(f"{e.name:34s} {e.kind:8s} {str(e.lawful):6s} {word:8s} {secs:7.1f}  {extra}", flush=True)
    print(f"blind set: caught {n_caught} of {n_plants} plants, controls passed {n_pass} of {n_ctrl}"
          + ("" if len(args.seeds) == 1 else f" (on every one of seeds {' '.join(map(str, args.seeds))})"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
