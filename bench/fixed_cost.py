#!/usr/bin/env python3
"""A GPU frame's fixed cost from gpu_bench JSON (its fixed/BACKEND/WxH cases: the L-shape at
max_steps 0, nothing marched): wall milliseconds a frame per backend and size, the device's own
time and its split where the run has it, and with two files the second's wall time over the
first's (e.g. a build before a change and after it, run on the same machine).

Usage: python3 bench/fixed_cost.py gpu.json [after.json]
Medians when the runs have repetitions. Prints a Markdown table.
"""
import json
import re
import sys

TO_MS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
PATTERN = re.compile(r"^fixed/(\w+)/(\d+x\d+)(?:/(?:real|manual)_time)?$")


def fixed_cases(path):
    """{(backend, size): run} of the fixed-cost cases, medians where there are repetitions."""
    with open(path) as f:
        runs = json.load(f)["benchmarks"]
    medians = [r for r in runs if r.get("aggregate_name") == "median"]
    chosen = medians or [r for r in runs if r.get("run_type", "iteration") == "iteration"]
    cases = {}
    for r in chosen:
        m = PATTERN.match(r.get("run_name", r["name"]))
        if m:
            cases[(m.group(1), m.group(2))] = r
    return cases


def wall_ms(run):
    return run["real_time"] * TO_MS[run.get("time_unit", "ns")]


def split(run):
    if "device_ms" not in run:
        return "-"
    return (f'{run["device_ms"]:.3g} (march {run.get("march_ms", 0):.3g}, read-back '
            f'{run.get("readback_ms", 0):.3g}, rest {run.get("rest_ms", 0):.3g})')


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__.strip().splitlines()[-3], file=sys.stderr)
        return 2
    first = fixed_cases(argv[1])
    second = fixed_cases(argv[2]) if len(argv) == 3 else None
    if not first:
        print(f"{argv[1]}: no fixed/ cases (gpu_bench --benchmark_filter=^fixed/)", file=sys.stderr)
        return 1
    key = lambda k: (k[0], int(k[1].split("x")[0]))
    if second is None:
        print("| backend | size | wall ms | device ms |")
        print("| --- | --- | ---: | --- |")
        for k in sorted(first, key=key):
            print(f"| {k[0]} | {k[1]} | {wall_ms(first[k]):.3g} | {split(first[k])} |")
        return 0
    print("| backend | size | before ms | after ms | after / before | after's device ms |")
    print("| --- | --- | ---: | ---: | ---: | --- |")
    for k in sorted(set(first) | set(second), key=key):
        a, b = first.get(k), second.get(k)
        ratio = f"{wall_ms(b) / wall_ms(a):.2f}" if a and b else "-"
        print(f"| {k[0]} | {k[1]} | {f'{wall_ms(a):.3g}' if a else '-'} | "
              f"{f'{wall_ms(b):.3g}' if b else '-'} | {ratio} | {split(b) if b else '-'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
