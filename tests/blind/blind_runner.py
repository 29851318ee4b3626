"""What the runners of blind sets 7 to 10 share (``tests/blind/set7/run_blind7.py``, ``set8/run_blind8.py``, ...): each
entry of a set's ``subjects.py`` through ``vm.check_operator`` / ``vm.check_stepper`` (or, for an entry with a
``run(subject, seed, profile)`` of its own, the reports it returns, merged) in a subprocess of its own under
a time cap, one at a time, and the verdict on it: a plant is caught when a record failed (the table names the check,
the subject of its worst failed record and its worst ratio); a control passes when no record failed and none is
undecided (any failed or undecided record of a control is a false alarm, printed with its record)."""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import json
import math
import pathlib
import subprocess
import sys
import time


@dataclasses.dataclass(frozen=True)
class BlindSet:
    """One blind set: its number, its folder (holding ``subjects.py``) and its runner script (run with ``--one`` in
    each entry's subprocess)."""
    number: int
    script: pathlib.Path
    doc: str = ""

    @property
    def tag(self) -> str:
        return f"BLIND{self.number}-RESULT "

    def subjects(self):
        name = f"verimono_blind_set{self.number}"
        if name not in sys.modules:
            spec = importlib.util.spec_from_file_location(name, self.script.parent / "subjects.py")
            mod = importlib.util.module_from_spec(spec)
            sys.modules[name] = mod
            spec.loader.exec_module(mod)
        return sys.modules[name]


def _num(v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else str(v)


def run_one(blind: "BlindSet", name: str, seed: int, profile: str) -> dict:
    import verimono as vm

    entry = blind.subjects().BY_NAME[name]
    profile = None if profile == "default" else profile      # "default": no profile given (the run configuration's)
    t0 = time.perf_counter()
    subject = entry.build()
    own = getattr(entry, "run", None)      # a subject neither an operator nor a stepper: its own entry points
    if own is not None:
        reports = own(subject, seed, profile)
        report = vm.Report([r for rep in reports for r in rep])
    elif entry.kind == "operator":
        report = vm.check_operator(subject, seed=seed, profile=profile)
    else:
        stepper, extra = subject if isinstance(subject, tuple) else (subject, None)
        problems = None
        if extra:
            import verimono.reference as ref
            problems = [ref.get(n) for n in ref.names()] + list(extra)
        report = vm.check_stepper(stepper, problems=problems, seed=seed, profile=profile)
    secs = time.perf_counter() - t0
    records = list(report)
    bad = [r for r in records if r.status in ("failed", "undecided")]
    return {"ok": bool(report.ok), "seconds": secs, "n_records": len(records),
            "counts": {s: sum(r.status == s for r in records) for s in sorted({r.status for r in records})},
            "records": [{"check": r.check, "subject": r.subject, "status": r.status, "worst": _num(r.worst),
                         "bound": _num(r.bound), "message": (r.message or "")[:300],
                         "counterexample": json.loads(json.dumps(r.counterexample, default=str))
                         if r.counterexample else None} for r in bad]}


def child(blind: "BlindSet", name, seed, profile, cap):
    t0 = time.perf_counter()
    try:
        cp = subprocess.run([sys.executable, str(blind.script), "--one", name, "--seed", str(seed),
                             "--profile", profile], capture_output=True, text=True, timeout=cap)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout > {cap:g}s", "seconds": time.perf_counter() - t0}
    line = [ln for ln in cp.stdout.splitlines() if ln.startswith(blind.tag)]
    if not line:
        tail = (cp.stderr.strip().splitlines() or ["no output"])[-1]
        return {"error": f"crashed: {tail[:200]}", "seconds": time.perf_counter() - t0}
    return json.loads(line[-1][len(blind.tag):])


def verdict(entry, res) -> tuple[bool, str]:
    """(as expected, what it shows): a plant caught by a failed record; a control with no failed/undecided."""
    if "error" in res:
        return False, res["error"]
    failed = [r for r in res["records"] if r["status"] == "failed"]
    undecided = [r for r in res["records"] if r["status"] == "undecided"]
    if entry.lawful:
        if not failed and not undecided:
            return True, "passed"
        worst = (failed or undecided)[0]
        return False, f"FALSE ALARM {worst['status']} {worst['check']}[{worst['subject']}] worst={worst['worst']}"
    if not failed:
        extra = f" ({len(undecided)} undecided: {undecided[0]['check']})" if undecided else ""
        return False, "MISSED" + extra
    by_check: dict[str, dict] = {}
    for r in failed:
        w = r["worst"] if isinstance(r["worst"], float) else math.inf
        cur = by_check.get(r["check"])
        if cur is None or w > (cur["worst"] if isinstance(cur["worst"], float) else math.inf):
            by_check[r["check"]] = r
    text = "; ".join(f"{c} {r['worst'] if not isinstance(r['worst'], float) else format(r['worst'], '.3g')}"
                     for c, r in sorted(by_check.items()))
    return True, "caught: " + text


def main(blind: "BlindSet", argv=None) -> int:
    ap = argparse.ArgumentParser(description=blind.doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", default="ci", help="dev, ci, thorough, or default (no profile argument)")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--cap", type=float, default=600.0, help="seconds per (entry, seed)")
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--json", default=None, help="write every result here")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--seed", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)

    if args.one is not None:
        print(blind.tag + json.dumps(run_one(blind, args.one, args.seed, args.profile)))
        return 0

    entries = blind.subjects().ENTRIES
    if args.only:
        entries = [e for e in entries if e.name in set(args.only)]
    out = {}
    n_plants = n_caught = n_ctrl = n_pass = 0
    for e in entries:
        for seed in args.seeds:
            res = child(blind, e.name, seed, args.profile, args.cap)
            good, text = verdict(e, res)
            out[f"{e.name}@{seed}"] = {"lawful": e.lawful, "kind": e.kind, "good": good, "text": text, **res}
            print(f"{e.name:34s} {'control' if e.lawful else 'plant':7s} s{seed} {res.get('seconds', 0):6.1f}s  {text}",
                  flush=True)
            if e.lawful:
                n_ctrl += 1
                n_pass += good
            else:
                n_plants += 1
                n_caught += good
    print(f"blind set {blind.number} ({args.profile}): caught {n_caught} of {n_plants} plant runs, "
          f"controls passed {n_pass} of {n_ctrl}")
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps(out, indent=1, default=str))
    return 0

