#!/usr/bin/env python3
"""The history steps of .github/workflows/bench.yml's merge job (the results database restored
from the Actions cache, the run added, the timeline drawn, the run checked, the database saved)
run over 12 simulated commits, as tests/workflow_test.py runs the whole workflow once.

Each commit's merged results are one real small report's, its timings redrawn: every run off by
1% (a steady machine's mood) and its 3 repetitions 1% apart. From the 6th commit one case is 10%
slower; at the 9th one case's mean steps change; at the 11th another's change with the baseline
rewritten (a baseline commit). Both changes must be found at their commits, the baseline commit's
accepted, and nothing else flagged: `history check` fails at the 9th commit alone. The timeline of
the 12 runs is then loaded in headless Chromium (DOM and a screenshot, OUT/timeline.png).

    history_workflow_test.py BUILD_DIR SOURCE OUT   exit 0: passed, 1: failed
"""
import copy
import json
import os
import random
import shutil
import subprocess
import sys

import yaml

import workflow_test as wt

SMALL = ("--backend scalar --method sphere --method analytic --size 32x18 --conform-size 32x18 "
         "--repetitions 3 --min-time 0.001 --no-sweep --no-scaling --scene torus --scene l_shape")
COMMITS = 12
SLOWER_FROM, STEPS_AT, BASELINE_AT = 5, 8, 10  # 0-based: the 6th, 9th and 11th commits


def commit(k):
    return f"c{k:02d}" + "0123456789abcdef" * 2 + "abcdef"


def simulated(base, k, rng, slow_case, steps_case, accepted_case):
    r = copy.deepcopy(base)
    r["created"] = f"2026-12-{k + 1:02d}T03:17:00Z"
    for c in r["matrix"]["cases"]:
        mood = 1 + 0.01 * rng.gauss(0, 1)
        if c["name"] == slow_case and k >= SLOWER_FROM:
            mood *= 1.10
        # From the base's median alone: its own samples' spread (tiny frames on a busy machine)
        # is not this simulation's noise.
        samples = [c["time_ms"] * mood * (1 + 0.01 * rng.gauss(0, 1)) for _ in c["time_samples_ms"]]
        c["counters"]["rays_per_s"] *= c["time_ms"] / sorted(samples)[1]
        c["time_samples_ms"], c["time_ms"] = samples, sorted(samples)[1]
        if c["name"] == steps_case and k >= STEPS_AT:
            c["counters"]["steps_mean"] += 0.5
        if c["name"] == accepted_case and k >= BASELINE_AT:
            c["counters"]["steps_mean"] -= 0.25
    return r


def fail(why):
    print("FAILED:", why)
    return 1


def main():
    build, source, out = (os.path.abspath(a) for a in sys.argv[1:4])
    flatmarch = os.path.join(build, "cli", "flatmarch")
    shutil.rmtree(out, ignore_errors=True)
    base_dir = os.path.join(out, "base")
    subprocess.run([flatmarch, "report", *SMALL.split(), "-q", "--no-html", "-o", base_dir,
                    "--write-baseline", os.path.join(base_dir, "baseline.json")],
                   cwd=source, check=True, capture_output=True, timeout=600)
    base = json.load(open(os.path.join(base_dir, "results.json")))
    names = [c["name"] for c in base["matrix"]["cases"]]
    slow_case, steps_case, accepted_case = names[0], names[1], names[2]
    workflow = yaml.safe_load(open(os.path.join(source, ".github", "workflows", "bench.yml")))
    merge = workflow["jobs"]["merge"]["steps"]
    steps = [s for s in merge if s.get("uses", "").startswith("actions/cache/") or s.get("name") == "History"]
    if len(steps) != 3:
        return fail(f"the merge job has not its cache restore, History and cache save steps: {steps}")
    ctx = {"source": source, "build": build, "artifacts": os.path.join(out, "artifacts"),
           "cache": os.path.join(out, "cache")}
    os.makedirs(ctx["cache"])
    rng = random.Random(77)
    checks = []
    for k in range(COMMITS):
        workspace = os.path.join(out, f"commit-{k + 1:02d}")
        os.makedirs(os.path.join(workspace, "site"))
        wt.checkout(workspace, ctx)
        with open(os.path.join(workspace, "site", "results.json"), "w") as f:
            json.dump(simulated(base, k, rng, slow_case, steps_case, accepted_case), f)
        baseline = json.load(open(os.path.join(base_dir, "baseline.json")))
        if k >= BASELINE_AT:  # the baseline commit: `reports/gate.sh --write` rewrote it
            baseline["rewritten"] = commit(BASELINE_AT)
        with open(os.path.join(workspace, "baseline.json"), "w") as f:
            json.dump(baseline, f)
        wt.GITHUB_CONTEXT["run_id"] = str(k + 1)
        env = dict(os.environ, **wt.GITHUB_ENV)
        env.update(GITHUB_SHA=commit(k), GITHUB_RUN_ID=str(k + 1), BASELINE=os.path.join(workspace, "baseline.json"))
        ctx["logs"] = []
        wt.run_steps("merge", steps, workspace, env, {}, 1, ctx)
        history = [(code, text) for name, code, text in ctx["logs"] if name == "History"]
        if not history:
            return fail(f"commit {k + 1}: the History step did not run")
        checks.append(history[0][0])
        if k == COMMITS - 1:
            print(history[0][1][-1500:])
    expected = [1 if k == STEPS_AT else 0 for k in range(COMMITS)]
    if checks != expected:
        return fail(f"history check's exit per commit {checks}, not {expected} (fails at the changed steps alone)")
    last = os.path.join(out, f"commit-{COMMITS:02d}")
    timeline = json.load(open(os.path.join(last, "site", "history", "timeline.json")))
    if len(timeline["runs"]) != COMMITS:
        return fail(f"the database holds {len(timeline['runs'])} runs, not {COMMITS}")
    found = sorted((f["case"], f["figure"], f["kind"], tuple(f["commits"]), f["worse"], f["accepted"], f["open"])
                   for f in timeline["findings"])
    want = sorted([
        ("report/" + slow_case, "rays_per_s", "timing", (commit(SLOWER_FROM - 1), commit(SLOWER_FROM)), True, False, True),
        ("report/" + steps_case, "steps_mean", "deterministic", (commit(STEPS_AT - 1), commit(STEPS_AT)), True, False,
         True),
        ("report/" + accepted_case, "steps_mean", "deterministic", (commit(BASELINE_AT - 1), commit(BASELINE_AT)),
         False, True, False)])
    if found != want:
        return fail("the findings are not the injected changes alone:\n  found " +
                    "\n        ".join(map(str, found)) + "\n  want  " + "\n        ".join(map(str, want)))
    # The page as a reader sees it: the open regressions first, the slowdown and the steps.
    page = os.path.join(last, "site", "history", "index.html")
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser:
        profile = os.path.join(out, "profile")
        dom = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", f"--user-data-dir={profile}",
                              "--dump-dom", "file://" + page], capture_output=True, text=True, timeout=60).stdout
        first = dom.split('<h2 id="open">', 1)[-1].split("<h2", 1)[0]
        if "Open regressions (2)" not in dom or slow_case not in first or steps_case not in first:
            return fail("the timeline's first section does not list the two open regressions")
        subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", f"--user-data-dir={profile}",
                        "--window-size=1400,1000", "--screenshot=" + os.path.join(out, "timeline.png"),
                        "file://" + page], capture_output=True, timeout=60)
    else:
        print("no Chromium: the page's DOM was not checked")
    print(f"{COMMITS} simulated commits: the 10% slowdown found at commit {SLOWER_FROM + 1}, the steps change at "
          f"{STEPS_AT + 1} (check failed there alone), the baseline commit's change at {BASELINE_AT + 1} accepted; "
          f"nothing else flagged")
    return 0


if __name__ == "__main__":
    sys.exit(main())
