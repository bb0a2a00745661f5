"""`python -m fishgen.fuzz`: the nightly fuzz run (see docs/fuzzing.md)."""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

from fishgen.fuzz.cases import NEW_TARGETS, TARGETS, make_case, run_case
from fishgen.fuzz.inputs import DEFAULT_CORPUS, load_seeds
from fishgen.fuzz.runner import DEFAULT_BUDGET_MB, Report, run


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m fishgen.fuzz", description=__doc__)
    ap.add_argument("--minutes", type=float, default=None, help="Run for this long (all targets share it).")
    ap.add_argument("--count", type=int, default=None,
                    help="Instead of --minutes: this many inputs per target (the seed corpus first).")
    ap.add_argument("--seed", type=int, default=None, help="Generator seed [default: from the clock].")
    ap.add_argument("--target", default="all", choices=[*TARGETS, "all", "parsers", "readers", "new"])
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="Worker processes.")
    ap.add_argument("--findings", type=Path, default=Path("out/fuzz-findings"),
                    help="Folder each distinct finding's input is saved in.")
    ap.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS, help="Seed corpus folder.")
    ap.add_argument("--budget-mb", type=int, default=DEFAULT_BUDGET_MB,
                    help="Address-space limit of a worker (RLIMIT_AS), MiB; 0 for none.")
    ap.add_argument("--replay", metavar="TARGET:SEED:INDEX",
                    help="Run one case in this process and show what it raised.")
    args = ap.parse_args(argv)

    if args.replay:
        return replay(args.replay, args.corpus)
    targets = {"all": list(TARGETS), "parsers": ["species", "cubes"], "readers": ["gltf", "obj", "ply"],
               "new": list(NEW_TARGETS)}.get(args.target, [args.target])
    seed = args.seed if args.seed is not None else int(time.time())
    if (args.minutes is None) == (args.count is None):
        ap.error("give one of --minutes or --count")
    counts = {t: args.count for t in targets} if args.count is not None else None
    print(f"fuzzing {', '.join(targets)} with seed {seed}, {args.jobs} job(s), "
          f"{args.budget_mb} MiB per worker; findings go to {args.findings}", flush=True)

    def announce(f) -> None:
        where = f" -> {f.folder}" if f.folder else ""
        print(f"  new finding [{f.target} #{f.index}]: {f.key}{where}", flush=True)

    report = run(targets, seed=seed, minutes=args.minutes, counts=counts, jobs=args.jobs,
                 corpus=args.corpus, findings_dir=args.findings, budget_mb=args.budget_mb,
                 on_finding=announce)
    print(summary(report))
    return 1 if report.findings else 0


def summary(report: Report) -> str:
    lines = [f"{'target':8} {'inputs':>9} {'ok':>8} {'refused':>8} {'findings':>8} {'per s':>8}"]
    for target, st in report.stats.items():
        lines.append(f"{target:8} {st.inputs:9,} {st.ok:8,} {st.errors:8,} {st.findings:8,} {st.rate:8,.0f}")
    lines.append(f"total {report.total:,} inputs in {report.wall:.1f} s wall "
                 f"({report.total / max(report.wall, 1e-9):,.0f}/s); "
                 f"'per s' is per worker process")
    if report.findings:
        lines.append(f"{len(report.findings)} distinct finding(s):")
        for f in report.findings.values():
            lines.append(f"  {f.key}  (x{f.count}; first {f.target}:{f.seed}:{f.index}"
                         f"{'; ' + str(f.folder) if f.folder else ''})")
    else:
        lines.append("no findings")
    return "\n".join(lines)


def replay(spec: str, corpus: Path) -> int:
    target, seed, index = spec.split(":")
    case = make_case(load_seeds(corpus), target, int(seed), int(index))
    with tempfile.TemporaryDirectory() as tmp:
        outcome = run_case(case, Path(tmp))
    said = {"ok": "accepted", "error": f"refused in one line: {outcome.detail}"}
    print(f"{case.target} case {index} of seed {seed}: "
          f"{said.get(outcome.status, f'finding: {outcome.key}')}")
    if outcome.status == "finding":
        print(outcome.detail)
    return 1 if outcome.status == "finding" else 0


if __name__ == "__main__":
    sys.exit(main())
