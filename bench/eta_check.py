#!/usr/bin/env python3
"""How true the time-left estimates of a `flatmarch report` run were.

Reads the run's progress log (`flatmarch report --progress-log FILE`: a JSON line per finished
case, with the stage's estimate of the time left then) and prints, per stage, the estimates'
error against the time that was in fact left, over the lines after the first tenth of the stage's
cases: the worst and the median, and whether the worst is within --within (0.3: 30%). The line
says whole seconds, so an estimate within a second of the truth is right whatever its share of
the truth (the last case of a stage whose cases run several at once: 0.3 s against 0.6 s).

  build/cli/flatmarch report --progress-log /tmp/progress.jsonl
  python3 bench/eta_check.py /tmp/progress.jsonl

Exits 1 when a stage's worst error is over --within, 2 on a log it cannot read.
"""
import argparse
import json
import statistics
import sys


def stages(lines):
    """The log's lines grouped by stage, in the run's order."""
    out = {}
    for line in lines:
        out.setdefault(line["stage"], []).append(line)
    return out


def errors(stage_lines, after=0.1, slack=1.0):
    """The relative errors of a stage's estimates after the first `after` of its cases, less
    `slack` seconds (the line's resolution)."""
    end = stage_lines[-1]["t"]
    total = stage_lines[-1]["total"]
    found = []
    for line in stage_lines:
        actual = end - line["t"]
        if line["done"] < after * total or line["done"] >= total or actual <= 0.0:
            continue
        found.append(max(0.0, abs(line["left"] - actual) - slack) / actual)
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("log", help="the progress log (JSON lines)")
    parser.add_argument("--within", type=float, default=0.3,
                        help="the largest error allowed, as a share of the time left (0.3)")
    args = parser.parse_args()
    try:
        with open(args.log) as f:
            lines = [json.loads(line) for line in f if line.strip()]
    except (OSError, ValueError) as e:
        print(f"eta_check: cannot read {args.log}: {e}", file=sys.stderr)
        return 2
    if not lines:
        print(f"eta_check: {args.log} has no lines", file=sys.stderr)
        return 2
    failed = False
    for name, stage_lines in stages(lines).items():
        found = errors(stage_lines)
        seconds = stage_lines[-1]["t"] - (stage_lines[0]["t"] - stage_lines[0]["seconds"])
        if not found:
            print(f"{name:8} {stage_lines[-1]['total']:4} cases  {seconds:7.1f} s  "
                  "(too few cases to judge)")
            continue
        worst = max(found)
        ok = worst <= args.within
        failed |= not ok
        print(f"{name:8} {stage_lines[-1]['total']:4} cases  {seconds:7.1f} s  after the first "
              f"tenth: worst error {100 * worst:5.1f}%, median {100 * statistics.median(found):5.1f}%"
              f"  {'ok' if ok else 'OVER'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
