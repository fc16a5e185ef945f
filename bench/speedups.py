#!/usr/bin/env python3
"""The SIMD backend's speed-ups from one simd_bench JSON file (see bench/simd_bench.cpp).

For each scene and method that has a scalar case: rays/s of scalar, of SIMD per instruction set
on one thread and of SIMD on all cores, then SIMD all cores / scalar and all cores / one thread
(best instruction set), and lane utilisation. Medians when the run has repetitions.

Usage: python3 bench/speedups.py simd.json [--min-speedup 12 --min-scaling 1.8]
Exit status 1 if a ratio falls below a given minimum.
"""
import argparse
import json
import re
import sys


def figures(path):
    """{name: counters} from the medians when present, else from the single runs."""
    with open(path) as f:
        data = json.load(f)
    runs = data["benchmarks"]
    medians = [b for b in runs if b.get("aggregate_name") == "median"]
    chosen = medians if medians else [b for b in runs if b.get("run_type", "iteration") == "iteration"]
    return {b["run_name"] if "run_name" in b else b["name"]: b for b in chosen}, data.get("context", {})


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("json")
    parser.add_argument("--min-speedup", type=float, default=0.0)
    parser.add_argument("--min-scaling", type=float, default=0.0)
    args = parser.parse_args()
    runs, context = figures(args.json)
    print(f"host: {context.get('host_name', '?')}, {context.get('num_cpus', '?')} CPUs, "
          f"{context.get('date', '?')}")
    simd = {}
    for name, b in runs.items():
        m = re.fullmatch(r"simd/(\w+)/(\w+)/(\w+)/threads:(\d+)(?:/real_time)?", name)
        if m:
            simd.setdefault((m[1], m[2]), {})[(m[3], int(m[4]))] = b
    failed = False
    header = f"{'scene':<16} {'method':<9} {'scalar':>10} {'1 thread':>28} {'all cores':>10} " \
             f"{'speedup':>8} {'scaling':>8} {'lanes used':>10}"
    print(header)
    for name, b in sorted(runs.items()):
        m = re.fullmatch(r"scalar/(\w+)/(\w+)(?:/real_time)?", name)
        if not m:
            continue
        method, scene = m[1], m[2]
        cases = simd.get((method, scene), {})
        if not cases:
            continue
        scalar = b["rays_per_s"]
        one = {isa: c["rays_per_s"] for (isa, threads), c in cases.items() if threads == 1}
        best_threads = max(threads for _, threads in cases)
        all_cores = [(isa, c) for (isa, threads), c in cases.items() if threads == best_threads]
        isa, top = all_cores[0]
        speedup = top["rays_per_s"] / scalar
        scaling = top["rays_per_s"] / one[isa] if isa in one else float("nan")
        ones = " ".join(f"{k}:{v / 1e6:.2f}M" for k, v in one.items())
        # "-" where the run has no one-thread case of this instruction set to scale from.
        scaled = f"{scaling:>7.2f}x" if isa in one else f"{'-':>8}"
        print(f"{scene:<16} {method:<9} {scalar / 1e6:>9.3f}M {ones:>28} "
              f"{top['rays_per_s'] / 1e6:>9.2f}M {speedup:>7.1f}x {scaled} "
              f"{top['lane_utilisation']:>10.2f}")
        failed |= speedup < args.min_speedup or scaling < args.min_scaling
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
