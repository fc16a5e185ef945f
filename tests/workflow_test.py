#!/usr/bin/env python3
"""The CI matrix of sharded reports (.github/workflows/bench.yml, issue 24), run here: its jobs in
the order their `needs` give, each matrix entry in a workspace of its own (the checkout: this
source tree, with the build folder under test as its build/), every `run` step through bash as
GitHub runs it (`${{ matrix.* }}` and `${{ strategy.job-total }}` filled in; the workflow's env
with REPORT_OPTIONS made small and BASELINE a baseline that an unsharded run of those options
wrote), artifacts (the Pages one too) uploaded and downloaded through a folder, the deployment
checked to find the page. The build step is left out (the tree is built, and a configure would
touch the build under test). The merged results must pass the gate and equal the unsharded
run's in every field a rerun measures alike (all but the timings).

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

from sharded_results import deterministic_report

SMALL = ("--backend scalar --backend simd --method sphere --method analytic --size 32x18 "
         "--conform-size 32x18 --sweep-size 16x9 --repetitions 2 --min-time 0.001 --no-scaling "
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
    flatmarch = os.path.join(build, "cli", "flatmarch")
    workflow = yaml.safe_load(open(os.path.join(source, ".github", "workflows", "bench.yml")))
    shutil.rmtree(out, ignore_errors=True)
    artifacts = os.path.join(out, "artifacts")
    os.makedirs(artifacts)
    # The unsharded run first: the merge is held to it, and gated against its baseline.
    whole = os.path.join(out, "whole")
    subprocess.run([flatmarch, "report", *SMALL.split(), "-q", "--no-html", "-o", whole,
                    "--write-baseline", os.path.join(whole, "baseline.json")],
                   cwd=source, check=True, capture_output=True, timeout=900)
    env = dict(os.environ, **{k: str(v) for k, v in workflow.get("env", {}).items()})
    env["REPORT_OPTIONS"] = SMALL
    env["BASELINE"] = os.path.join(whole, "baseline.json")
    jobs = workflow["jobs"]
    merged = published = None
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
                elif uses.startswith(("actions/upload-artifact@", "actions/upload-pages-artifact@")):
                    pages = uses.startswith("actions/upload-pages-artifact@")
                    into = os.path.join(artifacts, "github-pages" if pages
                                        else fill(w["name"], matrix, len(runs)))
                    os.makedirs(into, exist_ok=True)
                    files = glob.glob(os.path.join(workspace, fill(w["path"], matrix, len(runs))))
                    if not files:
                        print(f"FAILED: {name} {matrix}: nothing to upload at {w['path']}")
                        return 1
                    for f in files:  # a folder's contents, as upload-artifact takes them
                        if os.path.isdir(f):
                            shutil.copytree(f, into, dirs_exist_ok=True)
                        else:
                            shutil.copy(f, into)
                elif uses.startswith("actions/download-artifact@"):
                    into = os.path.join(workspace, w["path"])
                    for a in sorted(os.listdir(artifacts)):
                        if fnmatch.fnmatch(a, w.get("pattern", "*")):
                            # Each artifact in a folder of its name, unless merge-multiple.
                            to = into if w.get("merge-multiple") else os.path.join(into, a)
                            shutil.copytree(os.path.join(artifacts, a), to, dirs_exist_ok=True)
                elif uses.startswith("actions/deploy-pages@"):
                    site = os.path.join(artifacts, "github-pages")
                    if not os.path.exists(os.path.join(site, "index.html")):
                        print(f"FAILED: {name}: no page to deploy (no index.html in the Pages artifact)")
                        return 1
                    published = site
                    print(f"{name}: deploy: the page and {len(os.listdir(site))} entries")
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
                    if "flatmarch merge" in script:
                        merged = os.path.join(workspace, "site", "results.json")
    if not merged or not os.path.exists(merged):
        print("FAILED: no job merged the shards into site/results.json")
        return 1
    if not published:
        print("FAILED: no job published the page")
        return 1
    a, b = json.load(open(merged)), json.load(open(os.path.join(whole, "results.json")))
    if deterministic_report(a) != deterministic_report(b) or a["options"] != b["options"]:
        print("FAILED: the merged results differ from an unsharded run's")
        return 1
    if not a["regression"]["checked"] or a["regression"]["regressions"]:
        print("FAILED: the gate did not pass:", json.dumps(a["regression"])[:400])
        return 1
    print(f"{len(a['matrix']['cases'])} matrix cases merged from {len(a['merged_from'])} shards "
          f"equal the unsharded run's; gated against its baseline; the page published")
    return 0


if __name__ == "__main__":
    sys.exit(main())
