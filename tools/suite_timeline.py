"""Where the test suite's time goes: a report of the timeline `tests/conftest.py` records.

    FISHGEN_SUITE_TIMELINE=out/timeline bash tools/test.sh
    python tools/suite_timeline.py out/timeline

Each pytest-xdist worker writes one JSON line as each test starts and ends (its wall clock) and the
machine's CPU counters (/proc/stat) at its first and last test. The report gives each worker's span
and how long it ended after the other (the tail, where one core idles), the machine's idle share
over the run, and the groups (tests sharing a fixture, run on one worker), modules and tests that
took longest.
"""
from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Test:
    worker: str
    nodeid: str
    start: float
    end: float

    @property
    def seconds(self) -> float:
        return self.end - self.start

    @property
    def group(self) -> str:
        """The xdist group pytest-xdist's loadgroup gave it (after '@'), or the test itself."""
        return self.nodeid.split("@", 1)[1] if "@" in self.nodeid else self.nodeid

    @property
    def module(self) -> str:
        return self.nodeid.split("::", 1)[0]


def read(folder: Path) -> tuple[list[Test], list[list[int]]]:
    """The tests of every worker's log in ``folder``, and the /proc/stat counters its workers saw."""
    tests: list[Test] = []
    counters: list[list[int]] = []
    for log in sorted(folder.glob("*.jsonl")):
        started: dict[str, float] = {}
        for number, line in enumerate(log.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            try:
                event = json.loads(line)
                if "cpu" in event:
                    counters.append([int(v) for v in event["cpu"]])
                elif event["event"] == "start":
                    started[event["id"]] = float(event["t"])
                elif event["id"] in started:
                    tests.append(Test(log.stem, event["id"], started.pop(event["id"]), float(event["t"])))
            except (ValueError, KeyError, TypeError):
                found = line[:40]
                raise ValueError(f"{log}:{number}: expected one JSON event a line, found {found!r}") from None
    return tests, counters


def idle_share(counters: list[list[int]]) -> float | None:
    """The machine's idle share (idle and iowait jiffies) between the first and last counters."""
    if len(counters) < 2:
        return None
    first, last = min(counters, key=sum), max(counters, key=sum)
    spent = [b - a for a, b in zip(first, last, strict=False)]
    return (spent[3] + spent[4]) / sum(spent) if sum(spent) > 0 else None


def report(tests: list[Test], counters: list[list[int]], top: int = 12) -> str:
    """The report as text."""
    if not tests:
        return "no tests in the timeline"
    begin = min(t.start for t in tests)
    lines = []
    ends = {}
    for worker in sorted({t.worker for t in tests}):
        mine = [t for t in tests if t.worker == worker]
        ends[worker] = max(t.end for t in mine) - begin
        lines.append(f"{worker}: {len(mine)} tests, {sum(t.seconds for t in mine):.1f} s in tests, "
                     f"last ended at {ends[worker]:.1f} s")
    tail = max(ends.values()) - min(ends.values())
    lines.append(f"tail: the last worker ended {tail:.1f} s after the first")
    share = idle_share(counters)
    if share is not None:
        lines.append(f"machine idle over the run: {100 * share:.1f} %")
    for title, key in (("groups", "group"), ("modules", "module"), ("tests", "nodeid")):
        sums: Counter[str] = Counter()
        for t in tests:
            sums[getattr(t, key)] += t.seconds
        lines.append(f"longest {title}:")
        lines += [f"  {seconds:7.1f} s  {name}" for name, seconds in sums.most_common(top)]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path, help="the folder FISHGEN_SUITE_TIMELINE named")
    parser.add_argument("--top", type=int, default=12, help="rows in each longest list (default 12)")
    args = parser.parse_args(argv)
    if not args.folder.is_dir():
        print(f"{args.folder}: expected the timeline's folder, found none", file=sys.stderr)
        return 2
    try:
        tests, counters = read(args.folder)
    except ValueError as err:
        print(err, file=sys.stderr)
        return 2
    print(report(tests, counters, top=args.top))
    return 0


if __name__ == "__main__":
    sys.exit(main())
