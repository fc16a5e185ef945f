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
        if expr.startswith("github."):
            return str(GITHUB_CONTEXT[expr[len("github."):]])
        raise ValueError("an expression the test does not know: " + expr)
    return re.sub(r"\$\{\{(.*?)\}\}", value, text)


def job_runs(job):
    """Whether a job's `if` holds for the event the test simulates (workflow_dispatch: no
    schedule): terms joined by &&, each !cancelled() or github.event.schedule == or != 'CRON'."""
    condition = str(job.get("if", "true")).strip()
    condition = re.sub(r"^\$\{\{(.*)\}\}$", r"\1", condition).strip()
    result = True
    for term in (t.strip() for t in condition.split("&&")):
        m = re.fullmatch(r"github\.event\.schedule\s*(==|!=)\s*'([^']*)'", term)
        if term in ("true", "!cancelled()", "always()"):
            continue
        if not m:
            raise ValueError("a job condition the test does not know: " + term)
        same = GITHUB_CONTEXT.get("event.schedule", "") == m.group(2)
        result = result and (same if m.group(1) == "==" else not same)
    return result


def checkout(workspace, ctx):
    """actions/checkout: this source tree, with the build folder under test as its build/."""
    for entry in os.listdir(ctx["source"]):
        if entry not in (".git", "build"):
            os.symlink(os.path.join(ctx["source"], entry), os.path.join(workspace, entry))
    os.symlink(ctx["build"], os.path.join(workspace, "build"))


def run_steps(name, steps, workspace, env, matrix, total, ctx):
    """A job's steps in `workspace` as GitHub runs them: after a step fails only those whose `if`
    asks for `!cancelled()` or `always()` run. Artifacts go through ctx["artifacts"], the Actions
    cache through ctx["cache"] (a folder per key; a restore takes the key, else the newest entry
    a restore-key begins). Returns the number of steps that failed."""
    failed = 0
    for step in steps:
        uses, w = step.get("uses", ""), step.get("with", {})
        if failed and not re.search(r"!cancelled\(\)|always\(\)", step.get("if", "")):
            continue
        if uses.startswith("actions/checkout@"):
            checkout(workspace, ctx)
        elif uses.startswith(("actions/upload-artifact@", "actions/upload-pages-artifact@")):
            pages = uses.startswith("actions/upload-pages-artifact@")
            into = os.path.join(ctx["artifacts"], "github-pages" if pages else fill(w["name"], matrix, total))
            os.makedirs(into, exist_ok=True)
            files = glob.glob(os.path.join(workspace, fill(w["path"], matrix, total)))
            if not files:
                print(f"FAILED: {name} {matrix}: nothing to upload at {w['path']}")
                failed += 1
            for f in files:  # a folder's contents, as upload-artifact takes them
                if os.path.isdir(f):
                    shutil.copytree(f, into, dirs_exist_ok=True)
                else:
                    shutil.copy(f, into)
        elif uses.startswith("actions/download-artifact@"):
            into = os.path.join(workspace, w["path"])
            for a in sorted(os.listdir(ctx["artifacts"])):
                if fnmatch.fnmatch(a, w.get("pattern", "*")):
                    # Each artifact in a folder of its name, unless merge-multiple.
                    to = into if w.get("merge-multiple") else os.path.join(into, a)
                    shutil.copytree(os.path.join(ctx["artifacts"], a), to, dirs_exist_ok=True)
        elif uses.startswith("actions/cache/restore@"):
            key = fill(w["key"], matrix, total)
            entries = sorted(os.listdir(ctx["cache"]), key=lambda e: os.path.getmtime(os.path.join(ctx["cache"], e)))
            hits = [e for e in entries if e == key] or [e for e in reversed(entries)
                                                        if any(e.startswith(p) for p in w.get("restore-keys", "").split())]
            if hits:
                shutil.copytree(os.path.join(ctx["cache"], hits[0]), os.path.join(workspace, w["path"]),
                                dirs_exist_ok=True)
            print(f"{name}: cache restore {key}: {hits[0] if hits else 'nothing cached'}")
        elif uses.startswith("actions/cache/save@"):
            key = fill(w["key"], matrix, total)
            into = os.path.join(ctx["cache"], key)
            if os.path.exists(into):  # the cache keeps an entry's first save
                continue
            shutil.copytree(os.path.join(workspace, w["path"]), into)
        elif uses.startswith("actions/deploy-pages@"):
            site = os.path.join(ctx["artifacts"], "github-pages")
            if not os.path.exists(os.path.join(site, "index.html")):
                print(f"FAILED: {name}: no page to deploy (no index.html in the Pages artifact)")
                failed += 1
                continue
            ctx["published"] = site
            print(f"{name}: deploy: the page and {len(os.listdir(site))} entries")
        elif uses:
            print(f"FAILED: {name}: a step the test cannot run here: {uses}")
            failed += 1
        elif re.match(r"\s*ci/build\.sh\b", step["run"]):
            print(f"{name} {matrix}: {step.get('name', 'build')}: left out, the tree is built")
        else:
            script = fill(step["run"], matrix, total)
            r = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c", script], cwd=workspace,
                               env=env, capture_output=True, text=True, timeout=900)
            print(f"{name} {matrix}: {step.get('name', 'run')}: exit {r.returncode}")
            ctx.setdefault("logs", []).append((step.get("name", "run"), r.returncode, r.stdout + r.stderr))
            if r.returncode != 0:
                print(f"FAILED: {r.stdout[-800:]}{r.stderr[-800:]}")
                failed += 1
            if "flatmarch merge" in script:
                ctx["merged"] = os.path.join(workspace, "site", "results.json")
    return failed


# What GitHub sets in a job's environment that the workflow's steps read, and its `github`
# context's fields the workflow's expressions use.
GITHUB_ENV = {"GITHUB_SHA": "0123456789abcdef0123456789abcdef01234567", "GITHUB_SERVER_URL": "https://github.com",
              "GITHUB_REPOSITORY": "flatmarch/flatmarch", "GITHUB_RUN_ID": "1"}
GITHUB_CONTEXT = {"run_id": "1"}


def main():
    build, source, out = (os.path.abspath(a) for a in sys.argv[1:4])
    flatmarch = os.path.join(build, "cli", "flatmarch")
    workflow = yaml.safe_load(open(os.path.join(source, ".github", "workflows", "bench.yml")))
    shutil.rmtree(out, ignore_errors=True)
    ctx = {"source": source, "build": build, "artifacts": os.path.join(out, "artifacts"),
           "cache": os.path.join(out, "cache")}
    os.makedirs(ctx["artifacts"])
    os.makedirs(ctx["cache"])
    # The unsharded run first: the merge is held to it, and gated against its baseline.
    whole = os.path.join(out, "whole")
    subprocess.run([flatmarch, "report", *SMALL.split(), "-q", "--no-html", "-o", whole,
                    "--write-baseline", os.path.join(whole, "baseline.json")],
                   cwd=source, check=True, capture_output=True, timeout=900)
    env = dict(os.environ, **GITHUB_ENV, **{k: str(v) for k, v in workflow.get("env", {}).items()})
    env["REPORT_OPTIONS"] = SMALL
    env["BASELINE"] = os.path.join(whole, "baseline.json")
    jobs = workflow["jobs"]
    for name in job_order(jobs):
        job = jobs[name]
        if not job_runs(job):
            print(f"{name}: skipped ({job['if']})")
            continue
        runs = list(entries(job))
        for k, matrix in enumerate(runs):
            workspace = os.path.join(out, f"{name}-{k + 1}")
            os.makedirs(workspace)
            if run_steps(name, job["steps"], workspace, env, matrix, len(runs), ctx):
                return 1
    merged, published = ctx.get("merged"), ctx.get("published")
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
    if not os.path.exists(os.path.join(published, "history", "index.html")):
        print("FAILED: the published site has no timeline (history/index.html)")
        return 1
    print(f"{len(a['matrix']['cases'])} matrix cases merged from {len(a['merged_from'])} shards "
          f"equal the unsharded run's; gated against its baseline; kept in the history; the page "
          f"and the timeline published")
    return 0


if __name__ == "__main__":
    sys.exit(main())
