#!/usr/bin/env python3
"""The CI matrix of sharded runs (.github/workflows/bench.yml, issue 24), run here: its jobs in the
order their `needs` give, each matrix entry in a workspace of its own (the checkout: this source
tree, with the build folder under test as its build/), every `run` step through bash as GitHub
runs it (`${{ matrix.* }}` and `${{ strategy.job-total }}` filled in, the workflow's env with
CONFORM_OPTIONS made small), artifacts uploaded and downloaded through a folder. The build step is
left out (the tree is built, and a configure would touch the build under test). The merged
results must equal an unsharded run's, case by case (all but the seconds each took).

    workflow_test.py BUILD_DIR SOURCE OUT   exit 0: passed, 1: failed
"""
import fnmatch
import glob
import itertools
import json
import os
import re
import shutil
import subprocess
import sys

import yaml

SMALL = ("--backend scalar --method sphere --method analytic --size 48x27 "
         "--scene torus --scene l_shape --scene mirror_pentagon --scene cone_pi")


def job_order(jobs):
    order, done = [], set()
    for _ in range(len(jobs)):  # a pass per level of `needs`, at most as many as jobs
        for name, job in jobs.items():
            needs = job.get("needs", [])
            needs = [needs] if isinstance(needs, str) else needs
            if name not in done and all(n in done for n in needs):
                order.append(name)
                done.add(name)
    if len(order) != len(jobs):
        raise ValueError("the jobs' needs form a cycle or name a job that is not there")
    return order


def entries(job):
    matrix = job.get("strategy", {}).get("matrix", {})
    keys = [k for k in matrix if k not in ("include", "exclude")]
    for values in itertools.product(*(matrix[k] for k in keys)):
        yield dict(zip(keys, values))


def fill(text, matrix, total):
    def value(m):
        expr = m.group(1).strip()
        if expr == "strategy.job-total":
            return str(total)
        if expr.startswith("matrix."):
            return str(matrix[expr[len("matrix."):]])
        raise ValueError("an expression the test does not know: " + expr)
    return re.sub(r"\$\{\{(.*?)\}\}", value, text)


def main():
    build, source, out = (os.path.abspath(a) for a in sys.argv[1:4])
    workflow = yaml.safe_load(open(os.path.join(source, ".github", "workflows", "bench.yml")))
    shutil.rmtree(out, ignore_errors=True)
    artifacts = os.path.join(out, "artifacts")
    os.makedirs(artifacts)
    env = dict(os.environ, **{k: str(v) for k, v in workflow.get("env", {}).items()})
    env["CONFORM_OPTIONS"] = SMALL
    jobs = workflow["jobs"]
    workspace = None
    for name in job_order(jobs):
        job = jobs[name]
        runs = list(entries(job))
        for k, matrix in enumerate(runs):
            workspace = os.path.join(out, f"{name}-{k + 1}")
            os.makedirs(workspace)
            for step in job["steps"]:
                uses, w = step.get("uses", ""), step.get("with", {})
                if uses.startswith("actions/checkout@"):
                    for entry in os.listdir(source):
                        if entry not in (".git", "build"):
                            os.symlink(os.path.join(source, entry), os.path.join(workspace, entry))
                    os.symlink(build, os.path.join(workspace, "build"))
                elif uses.startswith("actions/upload-artifact@"):
                    into = os.path.join(artifacts, fill(w["name"], matrix, len(runs)))
                    os.makedirs(into, exist_ok=True)
                    files = glob.glob(os.path.join(workspace, fill(w["path"], matrix, len(runs))))
                    if not files:
                        print(f"FAILED: {name} {matrix}: nothing to upload at {w['path']}")
                        return 1
                    for f in files:
                        shutil.copy(f, into)
                elif uses.startswith("actions/download-artifact@"):
                    into = os.path.join(workspace, w["path"])
                    os.makedirs(into, exist_ok=True)
                    for a in sorted(os.listdir(artifacts)):
                        if fnmatch.fnmatch(a, w.get("pattern", "*")):
                            for f in os.listdir(os.path.join(artifacts, a)):
                                shutil.copy(os.path.join(artifacts, a, f), into)
                elif uses:
                    print(f"FAILED: {name}: a step the test cannot run here: {uses}")
                    return 1
                elif re.match(r"\s*ci/build\.sh\b", step["run"]):
                    print(f"{name} {matrix}: {step.get('name', 'build')}: left out, the tree is built")
                else:
                    script = fill(step["run"], matrix, len(runs))
                    r = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c",
                                        script], cwd=workspace, env=env, capture_output=True,
                                       text=True, timeout=900)
                    print(f"{name} {matrix}: {step.get('name', 'run')}: exit {r.returncode}")
                    if r.returncode != 0:
                        print(f"FAILED: {r.stdout[-800:]}{r.stderr[-800:]}")
                        return 1
    merged = os.path.join(workspace, "results", "conform.json")
    if not os.path.exists(merged):
        print("FAILED: the last job wrote no results/conform.json")
        return 1
    whole = os.path.join(out, "whole.json")
    subprocess.run([os.path.join(build, "cli", "flatmarch"), "conform", *SMALL.split(), "--json",
                    whole, "-q"], cwd=source, check=True, capture_output=True, timeout=900)
    strip = lambda doc: [{k: v for k, v in c.items() if k != "seconds"} for c in doc["cases"]]
    a, b = json.load(open(merged)), json.load(open(whole))
    if strip(a) != strip(b):
        print("FAILED: the merged results differ from an unsharded run's")
        return 1
    print(f"{len(a['cases'])} cases merged from {len(a['merged_from'])} shards equal the unsharded run's")
    return 0


if __name__ == "__main__":
    sys.exit(main())
