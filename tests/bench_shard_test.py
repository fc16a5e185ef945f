#!/usr/bin/env python3
"""A benchmark program's --shard=I/N (issue 24): kernel_bench's benchmarks of four scenes, run
unsharded and as three shards, each writing --benchmark_out; `flatmarch merge` must give the
same runs in the same order with the same deterministic counters (steps, crossings), timings
for every run; a missing shard, a shard run with other flags, or a bad --shard must be refused.

    bench_shard_test.py KERNEL_BENCH FLATMARCH OUT   exit 0: passed, 1: failed
"""
import json
import os
import shutil
import subprocess
import sys

FLAGS = ["--benchmark_filter=scalar/analytic/f32/(torus|cube|cone_pi|l_shape)$",
         "--benchmark_min_time=0.001"]
DETERMINISTIC = ("steps_mean", "steps_p99", "crossings_mean", "out_of_steps")


def run(command):
    return subprocess.run(command, capture_output=True, text=True, timeout=300)


def main():
    bench, flatmarch, out = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    r = run([bench, *FLAGS, f"--benchmark_out={out}/whole.json"])
    if r.returncode != 0:
        print("FAILED: the unsharded run:", r.stderr[-600:])
        return 1
    shards = []
    for i in (1, 2, 3):
        shards.append(f"{out}/shard-{i}.json")
        r = run([bench, *FLAGS, f"--shard={i}/3", f"--benchmark_out={shards[-1]}"])
        if r.returncode != 0 or f"shard {i}/3 holds" not in r.stderr:
            print(f"FAILED: shard {i}/3:", r.returncode, r.stderr[-600:])
            return 1
    r = run([flatmarch, "merge", *reversed(shards), "-o", f"{out}/merged.json"])
    if r.returncode != 0:
        print("FAILED: merge:", r.stderr[-600:])
        return 1
    whole = json.load(open(f"{out}/whole.json"))["benchmarks"]
    merged = json.load(open(f"{out}/merged.json"))["benchmarks"]
    strip = lambda runs: [(b["name"], {k: b.get(k) for k in DETERMINISTIC}) for b in runs]
    if len(whole) != 4 or strip(whole) != strip(merged):
        print("FAILED: the merged runs differ from the unsharded run's:",
              strip(whole), strip(merged))
        return 1
    if not all(b["real_time"] > 0 for b in merged):
        print("FAILED: a merged run without its time")
        return 1
    # Wrong sets: a shard missing; a shard run with other flags; a bad --shard.
    other = f"{out}/other-3.json"
    r = run([bench, *FLAGS, "--benchmark_repetitions=2", "--shard=3/3",
             f"--benchmark_out={other}"])
    for files, says in (([shards[0], shards[1]], "shard 3/3 is missing"),
                        ([shards[0], shards[1], other], other + ": its parameters differ from")):
        r = run([flatmarch, "merge", *files, "-o", f"{out}/wrong.json"])
        if r.returncode != 2 or says not in r.stderr:
            print(f"FAILED: merging {files} should fail saying {says!r}:", r.returncode, r.stderr)
            return 1
    r = run([bench, *FLAGS, "--shard=4/3"])
    if r.returncode != 2 or "--shard=I/N" not in r.stderr:
        print("FAILED: --shard=4/3 should be refused:", r.returncode, r.stderr)
        return 1
    print(f"{len(merged)} runs merged from 3 shards equal the unsharded run's")
    return 0


if __name__ == "__main__":
    sys.exit(main())
