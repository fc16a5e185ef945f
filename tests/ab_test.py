#!/usr/bin/env python3
"""bench/ab.py, the interleaved A/B timing of two builds of a benchmark program.

Stand-in programs that print Google Benchmark JSON with chosen times and counters check what the
script computes: the best time of each side over the rounds, the ratio, the flag on counters
that differ, the cases only one side has, a failing program and bad arguments. Then a real run
of kernel_bench against itself (the same work: every case "yes").

    ab_test.py AB_PY KERNEL_BENCH OUT    exit 0: passed, 1: failed
"""
import os
import shutil
import stat
import subprocess
import sys

# A stand-in benchmark program: each call takes the next of its times (a counter file beside
# it), notes its name in the file "order", and prints one run per case with the given
# steps_mean and lanes busy. It fails (exit 3) where asked.
FAKE = """#!/usr/bin/env python3
import json, os, sys
here = os.path.dirname(os.path.abspath(__file__))
count_file = os.path.join(here, os.path.basename(__file__) + ".calls")
calls = int(open(count_file).read()) if os.path.exists(count_file) else 0
open(count_file, "w").write(str(calls + 1))
open(os.path.join(here, "order"), "a").write(os.path.basename(__file__) + " ")
if {fail}:
    sys.stderr.write("stand-in failure\\n")
    sys.exit(3)
times = {times}
runs = [dict(name=name, run_type="iteration", real_time=times[calls % len(times)] * scale,
             time_unit="us", steps_mean=steps, lane_utilisation={lanes})
        for name, scale, steps in {cases}]
print(json.dumps(dict(context={{}}, benchmarks=runs)))
"""

failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAILED:", what)


def fake(out, name, times, cases, fail=False, lanes=0.5):
    path = os.path.join(out, name)
    with open(path, "w") as f:
        f.write(FAKE.format(times=times, cases=cases, fail=fail, lanes=lanes))
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
    return path


def ab(ab_py, *args):
    return subprocess.run([sys.executable, ab_py, *args], capture_output=True, text=True,
                          timeout=600)


def row(stdout, case):
    """The table row of `case` split into its cells, or None."""
    for line in stdout.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells and cells[0] == case:
            return cells
    return None


def main():
    ab_py, kernel_bench, out = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)

    # Base takes 10, 8, 9 ms over its three calls (best 8); new 5, 7, 4 (best 4): ratio 0.5.
    # Case b runs twice as long on both sides. Case c does different work on the new side. The
    # new side keeps more lanes busy: shown, and not a difference in work.
    base = fake(out, "base", [10000, 8000, 9000], [("a", 1, 5.0), ("b", 2, 5.0), ("c", 1, 7.0)])
    new = fake(out, "new", [5000, 7000, 4000], [("a", 1, 5.0), ("b", 2, 5.0), ("c", 1, 7.5)],
               lanes=0.875)
    r = ab(ab_py, base, new, "--rounds", "3", "--min-time", "0.01")
    check(r.returncode == 0, f"stand-ins: exit {r.returncode}, {r.stderr[-400:]}")
    a, b, c = row(r.stdout, "a"), row(r.stdout, "b"), row(r.stdout, "c")
    check(a is not None and a[1:] == ["8.000", "4.000", "0.500", "0.500 -> 0.875", "yes"],
          f"best of rounds, ratio and lanes of case a: {a}")
    check(b is not None and b[1:4] == ["16.000", "8.000", "0.500"], f"case b: {b}")
    check(c is not None and c[5] == "no: steps_mean", f"case c's different work: {c}")
    check("3 cases, best of 3 rounds: geometric mean 0.500, 3 faster" in r.stdout,
          f"summary: {r.stdout[-300:]}")
    check("1 cases did different work" in r.stdout, "the different work is said")
    # Three rounds, each running both programs once, the order swapped every other round.
    order = open(os.path.join(out, "order")).read().split()
    check(order == ["base", "new", "new", "base", "base", "new"], f"the runs' order: {order}")

    # A case only one side has is listed and fails the comparison.
    extra = fake(out, "extra", [1000], [("a", 1, 5.0), ("d", 1, 5.0)])
    r = ab(ab_py, base, extra, "--rounds", "1")
    check(r.returncode == 1 and "only in new: d" in r.stdout,
          f"a case only in new: exit {r.returncode}, {r.stdout[-300:]}")

    # A program that fails is reported with its error, not compared.
    broken = fake(out, "broken", [1000], [("a", 1, 5.0)], fail=True)
    r = ab(ab_py, base, broken, "--rounds", "1")
    check(r.returncode == 1 and "exited with 3" in r.stderr and "stand-in failure" in r.stderr,
          f"a failing program: exit {r.returncode}, {r.stderr[-300:]}")

    # A case the program reports as failed is said, and left out of the comparison.
    erring = os.path.join(out, "erring")
    with open(erring, "w") as f:
        f.write("#!/usr/bin/env python3\nimport json\nprint(json.dumps(dict(benchmarks=[dict(\n"
                "    name='a', run_type='iteration', error_occurred=True, error_message='boom',\n"
                "    real_time=0, time_unit='ns')])))\n")
    os.chmod(erring, os.stat(erring).st_mode | stat.S_IXUSR)
    r = ab(ab_py, base, erring, "--rounds", "1")
    check(r.returncode == 1 and "a failed: boom" in r.stderr and "only in base: a" in r.stdout,
          f"a failed case: exit {r.returncode}, {r.stderr[-300:]}, {r.stdout[-300:]}")

    # Bad arguments: a missing program, zero rounds, a filter that matches nothing.
    r = ab(ab_py, os.path.join(out, "missing"), new)
    check(r.returncode == 2 and "not an executable file" in r.stderr,
          f"a missing program: exit {r.returncode}, {r.stderr[-300:]}")
    r = ab(ab_py, base, new, "--rounds", "0")
    check(r.returncode == 2 and "--rounds must be 1 to 100" in r.stderr,
          f"zero rounds: exit {r.returncode}, {r.stderr[-300:]}")
    r = ab(ab_py, kernel_bench, kernel_bench, "--filter", "no_such_case$", "--rounds", "1")
    check(r.returncode == 1 and "no case matches" in r.stderr,
          f"an empty filter: exit {r.returncode}, {r.stderr[-300:]}")

    # The real program against itself, pinned to a CPU this process may use: the same work.
    cpu = min(os.sched_getaffinity(0))
    r = ab(ab_py, kernel_bench, kernel_bench, "--filter", "scalar/analytic/f32/(torus|cube)$",
           "--rounds", "2", "--min-time", "0.01", "--pin", str(cpu))
    check(r.returncode == 0, f"kernel_bench against itself: exit {r.returncode}, {r.stderr[-400:]}")
    for case in ("scalar/analytic/f32/torus", "scalar/analytic/f32/cube"):
        cells = row(r.stdout, case)
        check(cells is not None and len(cells) == 5 and cells[4] == "yes" and float(cells[3]) > 0,
              f"kernel_bench's {case}: {cells}")

    print("ab_test:", "passed" if not failures else f"{len(failures)} checks failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
