#!/usr/bin/env python3
"""bench/speedups.py, the SIMD backend's speed-ups and lane efficiency from simd_bench JSON.

A hand-made simd_bench file with chosen rates checks what the script computes, each figure
worked out here by hand: the one-thread speed-up over the scalar backend, the lane efficiency
(that over the lanes) and its two factors (the cheapest step per lane against the scalar
backend's steps a second, and the share of that peak the frame keeps), two threads over one, the
medians chosen over the other aggregates, the minimums' failures and exit status, the Markdown
table, and a file with nothing to compare.

    speedups_test.py SPEEDUPS_PY OUT    exit 0: passed, 1: failed
"""
import json
import os
import subprocess
import sys

failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAILED:", what)


def near(a, b):
    return a is not None and abs(a - b) <= 1e-9 * max(1.0, abs(b))


def runs(name, **counters):
    """A case's three aggregates: the median (the figures), and a mean and stddev that differ."""
    out = []
    for aggregate, scale in (("mean", 3.0), ("median", 1.0), ("stddev", 0.01)):
        out.append(dict(name=f"{name}_{aggregate}", run_name=name, run_type="aggregate",
                        aggregate_name=aggregate, real_time=1.0, time_unit="ms",
                        **{k: v * scale for k, v in counters.items()}))
    return out


def main():
    script, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    # The scalar backend: 1 M rays/s of 100 steps each, 100 M steps/s. AVX2 (8 lanes): 4 M rays/s
    # on one thread (4x, 0.5 a lane), its cheapest step 800 M lane-steps/s (100 M a lane: 1.0 of
    # the scalar backend's), its frame 400 M steps/s (0.5 of that peak); 7.6 M on two threads
    # (1.9x). AVX-512 (16 lanes): 6.4 M rays/s (6.4x, 0.4 a lane), peak 1.28 G (80 M a lane:
    # 0.8), of peak 0.5; 7.0 M on two threads (1.09375x).
    benchmarks = []
    benchmarks += runs("scalar/sphere/cube/real_time", rays_per_s=1e6, steps_mean=100.0)
    benchmarks += runs("simd/sphere/cube/avx512/threads:1/real_time", rays_per_s=6.4e6,
                       steps_mean=100.0, lanes=16.0, lane_utilisation=0.9, peak_steps_per_s=1.28e9,
                       of_peak=0.5)
    benchmarks += runs("simd/sphere/cube/avx2/threads:1/real_time", rays_per_s=4e6,
                       steps_mean=100.0, lanes=8.0, lane_utilisation=0.95, peak_steps_per_s=8e8,
                       of_peak=0.5)
    benchmarks += runs("simd/sphere/cube/avx512/threads:2/real_time", rays_per_s=7e6,
                       steps_mean=100.0, lanes=16.0)
    benchmarks += runs("simd/sphere/cube/avx2/threads:2/real_time", rays_per_s=7.6e6,
                       steps_mean=100.0, lanes=8.0)
    # A SIMD case with no scalar case beside it: not compared.
    benchmarks += runs("simd/sphere/torus/avx512/threads:1/real_time", rays_per_s=9e6,
                       steps_mean=50.0, lanes=16.0)
    path = os.path.join(out, "simd.json")
    with open(path, "w") as f:
        json.dump({"context": {"host_name": "test", "num_cpus": 2}, "benchmarks": benchmarks}, f)

    def run(*args):
        return subprocess.run([sys.executable, script, *args], capture_output=True, text=True,
                              timeout=60)

    rows_path = os.path.join(out, "rows.json")
    r = run(path, "--json", rows_path)
    check(r.returncode == 0, f"no minimums: exit 0, not {r.returncode} ({r.stderr.strip()})")
    check("step" in r.stdout and "of peak" in r.stdout, "the table names the two factors")
    with open(rows_path) as f:
        rows = {row["isa"]: row for row in json.load(f)["rows"]}
    check(sorted(rows) == ["avx2", "avx512"],
          f"one row per instruction set of the cube: {sorted(rows)}")
    hand = {
        "avx2": dict(speedup_one_thread=4.0, lane_efficiency=0.5, step_per_lane=1.0, of_peak=0.5,
                     scaling=1.9, lanes_busy=0.95),
        "avx512": dict(speedup_one_thread=6.4, lane_efficiency=0.4, step_per_lane=0.8, of_peak=0.5,
                       scaling=7.0 / 6.4, lanes_busy=0.9),
    }
    for isa, want in hand.items():
        row = rows.get(isa, {})
        for key, value in want.items():
            check(near(row.get(key), value), f"{isa} {key}: {row.get(key)}, by hand {value}")
        # The lane efficiency is the product of its two factors.
        if all(row.get(k) is not None for k in ("lane_efficiency", "step_per_lane", "of_peak")):
            check(near(row["lane_efficiency"], row["step_per_lane"] * row["of_peak"]),
                  f"{isa}: lane efficiency {row['lane_efficiency']} is step x of peak")

    # Minimums: the lane efficiency per method, two threads over one.
    r = run(path, "--min-efficiency", "sphere=0.45")
    below = [line for line in r.stdout.splitlines() if line.startswith("below:")]
    check(r.returncode == 1, f"a lane efficiency under its minimum: exit 1, not {r.returncode}")
    check(len(below) == 1 and "avx512" in below[0] and "0.400" in below[0],
          f"only AVX-512's 0.4 is under 0.45: {below}")
    r = run(path, "--min-efficiency", "sphere=0.4,analytic=0.9", "--min-scaling", "1.85")
    below = [line for line in r.stdout.splitlines() if line.startswith("below:")]
    check(r.returncode == 1 and len(below) == 1 and "avx512" in below[0] and "scaling" in below[0],
          f"0.4 is not under 0.4, no analytic case, AVX-512's 1.09x is under 1.85: {below}")
    r = run(path, "--min-efficiency", "sphere=0.4", "--min-scaling", "1.09")
    check(r.returncode == 0, f"every figure at or above its minimum: exit 0, not {r.returncode}")

    r = run(path, "--markdown")
    check(r.returncode == 0 and "| cube | sphere | 6.40x (0.40) | 4.00x (0.50) | 1.09x / 1.90x |"
          in r.stdout, f"the Markdown row of the cube:\n{r.stdout}")

    lone = os.path.join(out, "lone.json")
    with open(lone, "w") as f:
        json.dump({"benchmarks": runs("simd/sphere/torus/avx512/threads:1/real_time",
                                      rays_per_s=1.0)}, f)
    r = run(lone)
    check(r.returncode == 2 and "no scalar" in r.stderr,
          f"nothing to compare: exit 2 and why, not {r.returncode} ({r.stderr.strip()})")

    print(f"speedups_test: {len(failures)} failed" if failures else "speedups_test: passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
