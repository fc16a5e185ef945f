#!/usr/bin/env python3
"""Two builds of a Google Benchmark program timed against each other, in interleaved rounds.

Runs BASE and NEW in turn, round after round (the order swapped every other round, so that a
drift of the machine weighs on both), and prints per case the best time of each, NEW's time over
BASE's, the SIMD backend's lanes busy where the program reports them, and whether the two did the
same work: the counters that depend only on the frame (steps, crossings) must agree, or the ratio
compares different frames. This is how backends/simd/NOTES.md's "A against B, best of N
interleaved rounds" figures are measured; machines here are noisy, so only ratios from one run
mean anything.

    python3 bench/ab.py BASE NEW --filter='simd/analytic/(cube|l_shape)/avx512/' --rounds 3 --pin 0
    python3 bench/ab.py P P --new-env FLATMARCH_SIMD_TUNE=avx2.refill_at=5 --filter=...  # one knob

--pin runs both on one CPU (taskset), the steadiest figures on a shared machine; simd_bench then
registers its cases on one thread. bench/build_at.sh builds BASE from an earlier revision.
Exit status: 0 when every case ran in both, 1 when a run failed or the builds' cases differ,
2 on bad arguments.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys

# Counters that depend on the frame, not on the clock or the build's scheduling: where they
# differ, the builds marched different rays and their ratio is not a like-for-like comparison.
DETERMINISTIC = ("steps_mean", "steps_p99", "crossings_mean", "out_of_steps")
TO_MS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
LEVEL = 0.03  # within 3% either way: "level"


def parse_args(argv):
    parser = argparse.ArgumentParser(
        description="Time two builds of a Google Benchmark program against each other in "
        "interleaved rounds: best time of each, ratio, and whether their deterministic "
        "counters agree.")
    parser.add_argument("base", help="the program to compare against (e.g. an earlier build)")
    parser.add_argument("new", help="the program under test")
    parser.add_argument("--filter", default=".", help="--benchmark_filter for both (default: all)")
    parser.add_argument("--rounds", type=int, default=3, help="rounds, each running both (3)")
    parser.add_argument("--min-time", type=float, default=0.3,
                        help="--benchmark_min_time in seconds for each case (0.3)")
    parser.add_argument("--pin", type=int, metavar="CPU",
                        help="run both on this one CPU (taskset -c CPU)")
    parser.add_argument("--base-env", action="append", default=[], metavar="NAME=VALUE",
                        help="an environment variable for BASE's runs alone (repeatable); with "
                        "BASE and NEW one program, two settings of it: e.g. a tuning probe build "
                        "and FLATMARCH_SIMD_TUNE (backends/simd/tuning.hpp)")
    parser.add_argument("--new-env", action="append", default=[], metavar="NAME=VALUE",
                        help="the same for NEW's runs")
    parser.add_argument("--timeout", type=float, default=1800,
                        help="seconds one program run may take before it is stopped (1800)")
    args = parser.parse_args(argv)
    if args.rounds < 1 or args.rounds > 100:
        parser.error(f"--rounds must be 1 to 100, not {args.rounds}")
    if args.min_time <= 0:
        parser.error(f"--min-time must be positive, not {args.min_time}")
    for flag in ("base_env", "new_env"):
        pairs = {}
        for item in getattr(args, flag):
            name, eq, value = item.partition("=")
            if not eq or not name:
                parser.error(f"--{flag.replace('_', '-')} {item}: expected NAME=VALUE")
            pairs[name] = value
        setattr(args, flag, pairs)
    for path in (args.base, args.new):
        if not (os.path.isfile(path) and os.access(path, os.X_OK)):
            parser.error(f"{path}: not an executable file")
    if args.pin is not None:
        if shutil.which("taskset") is None:
            parser.error("--pin needs taskset (util-linux)")
        if args.pin not in os.sched_getaffinity(0):
            parser.error(f"--pin {args.pin}: this process may not run on CPU {args.pin} "
                         f"(allowed: {sorted(os.sched_getaffinity(0))})")
    return args


def run_once(program, args, env=None):
    """{case name: run} of one run of `program` (with `env` added to the environment), or raises
    RuntimeError saying why not."""
    command = [program, f"--benchmark_filter={args.filter}",
               f"--benchmark_min_time={args.min_time}", "--benchmark_format=json"]
    if args.pin is not None:
        command = ["taskset", "-c", str(args.pin)] + command
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=args.timeout,
                              env={**os.environ, **(env or {})})
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"{program}: still running after {args.timeout:.0f} s (--timeout)")
    if done.returncode != 0:
        raise RuntimeError(f"{program} exited with {done.returncode}: {done.stderr[-800:]}")
    if not done.stdout.strip():  # Google Benchmark prints nothing when the filter matches none
        return {}
    try:
        runs = json.loads(done.stdout)["benchmarks"]
    except (ValueError, KeyError) as e:
        raise RuntimeError(f"{program}: no Google Benchmark JSON on its output ({e})")
    cases = {}
    for run in runs:
        if run.get("run_type", "iteration") != "iteration":
            continue
        if run.get("error_occurred"):
            print(f"ab.py: {program}: {run['name']} failed: {run.get('error_message', '')}",
                  file=sys.stderr)
            continue
        cases[run["name"]] = run
    return cases


def milliseconds(run):
    return run["real_time"] * TO_MS[run.get("time_unit", "ns")]


def differing_counters(a, b):
    """The deterministic counters that both runs report and that differ."""
    return [c for c in DETERMINISTIC if c in a and c in b and not math.isclose(
        a[c], b[c], rel_tol=1e-9, abs_tol=1e-12)]


def main(argv):
    args = parse_args(argv)
    best = {"base": {}, "new": {}}  # case -> (ms, run)
    order = []
    for r in range(args.rounds):
        sides = ("base", "new") if r % 2 == 0 else ("new", "base")
        for side in sides:
            print(f"round {r + 1}/{args.rounds}: {side}", file=sys.stderr, flush=True)
            try:
                cases = run_once(getattr(args, side), args, getattr(args, side + "_env"))
            except RuntimeError as e:
                print(f"ab.py: {e}", file=sys.stderr)
                return 1
            for name, run in cases.items():
                if name not in order:
                    order.append(name)
                ms = milliseconds(run)
                if name not in best[side] or ms < best[side][name][0]:
                    best[side][name] = (ms, run)
    if not order:
        print(f"ab.py: no case matches --filter={args.filter}", file=sys.stderr)
        return 1

    lanes = any("lane_utilisation" in run for side in best.values() for _, run in side.values())
    print("| case | base ms | new ms | new / base |" + (" lanes busy |" if lanes else "") +
          " same work |")
    print("|---|---|---|---|" + ("---|" if lanes else "") + "---|")
    ratios, lonely, different = [], [], []
    for name in order:
        if name not in best["base"] or name not in best["new"]:
            lonely.append(name)
            continue
        (a, run_a), (b, run_b) = best["base"][name], best["new"][name]
        if a <= 0 or b <= 0:  # no time to compare (a case that measures nothing)
            print(f"| {name} | {a:.3f} | {b:.3f} | - |{' - |' if lanes else ''} - |")
            continue
        differ = differing_counters(run_a, run_b)
        if differ:
            different.append(name)
        ratios.append(b / a)
        busy = ""
        if lanes:
            busy = " " + " -> ".join(f"{run['lane_utilisation']:.3f}" if "lane_utilisation" in run
                                     else "-" for run in (run_a, run_b)) + " |"
        print(f"| {name} | {a:.3f} | {b:.3f} | {b / a:.3f} |{busy} "
              f"{'no: ' + ', '.join(differ) if differ else 'yes'} |")
    if ratios:
        mean = math.exp(sum(math.log(x) for x in ratios) / len(ratios))
        faster = sum(x < 1 - LEVEL for x in ratios)
        slower = sum(x > 1 + LEVEL for x in ratios)
        print(f"\n{len(ratios)} cases, best of {args.rounds} rounds: geometric mean "
              f"{mean:.3f}, {faster} faster, {slower} slower, {len(ratios) - faster - slower} "
              f"level (within {LEVEL:.0%})")
    if different:
        print(f"{len(different)} cases did different work (their counters differ): their ratio "
              "is not like for like")
    for name in lonely:
        print(f"only in {'base' if name in best['base'] else 'new'}: {name}")
    return 1 if lonely else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
