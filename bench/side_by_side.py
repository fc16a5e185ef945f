#!/usr/bin/env python3
"""The GPU backends side by side from one gpu_bench JSON file (see bench/gpu_bench.cpp).

For each size, scene and method: milliseconds a frame on each backend, the ratio of the second
backend's time to the first's, and the geometric mean of the ratios per size and method. Medians
when the run has repetitions. Prints a Markdown table.

Usage: python3 bench/side_by_side.py gpu.json [--backends FIRST SECOND]
(default: the first two backends the file times, in its order)
"""
import argparse
import json
import math
import re
from collections import defaultdict


def figures(path):
    """{name: run} from the medians when present, else from the single runs."""
    with open(path) as f:
        runs = json.load(f)["benchmarks"]
    medians = [b for b in runs if b.get("aggregate_name") == "median"]
    chosen = medians if medians else [b for b in runs if b.get("run_type", "iteration") == "iteration"]
    return {b.get("run_name", b["name"]): b for b in chosen}


def milliseconds(run):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[run.get("time_unit", "ns")]
    return run["real_time"] * scale


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("json")
    parser.add_argument("--backends", nargs=2, metavar=("FIRST", "SECOND"),
                        help="the two backends to compare (default: the first two the file times)")
    args = parser.parse_args()
    cases = defaultdict(dict)  # (size, method, scene) -> {backend: ms}
    timed = []  # the backends, in the file's order
    pattern = re.compile(r"^(\w+)/(\w+)/(\w+)/(\d+x\d+)(?:/(?:real|manual)_time)?$")
    for name, run in figures(args.json).items():
        m = pattern.match(name)
        if m:
            backend, method, scene, size = m.groups()
            cases[(size, method, scene)][backend] = milliseconds(run)
            if backend not in timed:
                timed.append(backend)
    if args.backends:
        first, second = args.backends
    elif len(timed) >= 2:
        first, second = timed[:2]
    else:
        parser.error(f"{args.json} times {len(timed)} backend(s): two are needed (--backends)")
    ratios = defaultdict(list)
    print(f"| size | method | scene | {first} ms | {second} ms | {second} / {first} |")
    print("| --- | --- | --- | --- | --- | --- |")
    for key in sorted(cases, key=lambda k: (int(k[0].split("x")[0]), k[1], k[2])):
        times = cases[key]
        a, b = times.get(first), times.get(second)
        ratio = b / a if a and b else None
        if ratio:
            ratios[key[:2]].append(ratio)
        show = lambda v: f"{v:.1f}" if v is not None else "-"
        print(f"| {key[0]} | {key[1]} | {key[2]} | {show(a)} | {show(b)} | "
              f"{f'{ratio:.2f}' if ratio else '-'} |")
    print()
    for (size, method), values in sorted(ratios.items()):
        mean = math.exp(sum(map(math.log, values)) / len(values))
        print(f"{size} {method}: {second} / {first} geometric mean {mean:.2f} "
              f"(range {min(values):.2f}-{max(values):.2f}, {len(values)} scenes)")


if __name__ == "__main__":
    main()
