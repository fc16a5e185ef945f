#!/usr/bin/env python3
"""The external renderer protocol (docs/external.md) end to end: `flatmarch conform --external`.

- The example adapter (docs/examples/render_adapter.py, `flatmarch render --backend scalar` as a
  command) gets the scalar backend's verdicts and figures, case by case.
- Its deliberately broken variants fail with the classes they should: rows flipped (hits and
  crossings wrong: wrong_edge, missed_object, phantom_hit; the colour of the sky and the object),
  a crossings AOV of zeros (wrong_edge alone; colour and hits right).
- Renderers that crash, hang past their timeout, exit 1, write nothing or a frame of the wrong
  size: `error` with why, and the run goes on; one that exits 77: skipped with its reason.
- An expectation file: expected failures are not changes; an unexpected pass is one, and makes
  conform exit 1; a manifest that cannot be used is refused (exit 2) naming its key.

    external_test.py FLATMARCH SOURCE OUT   exit 0: passed, 1: failed
"""
import json
import os
import shutil
import subprocess
import sys

FLATMARCH, SOURCE, OUT = sys.argv[1:4]
DATA = os.path.join(SOURCE, "tests", "data", "external")
EXAMPLE = os.path.join(SOURCE, "docs", "examples", "render_adapter.json")
CASE = ["--scene", "torus", "--scene", "l_shape", "--method", "sphere", "--size", "48x27"]
failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


def conform(*args):
    r = subprocess.run([FLATMARCH, "conform", *CASE, *args], cwd=OUT, capture_output=True,
                       text=True, timeout=600)
    return r


shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)

def externals(*names):
    return ["--external=" + os.path.join(DATA, n + ".json") for n in names]


r = conform("--backend", "scalar", "--json", "judged.json", "--external", "mine=" + EXAMPLE,
            *externals("flipped", "no_crossings"))
print(r.stdout[-3000:], r.stderr[-2000:])
check(r.returncode == 1, f"conform exits 1 with broken renderers (got {r.returncode})")
results = json.load(open(os.path.join(OUT, "judged.json")))
cases = {(c["backend"], c["method"], c["scene"]): c for c in results["cases"]}
# The renderers that do not answer, on one scene and method: errors, and the run goes on.
CASE = ["--scene", "torus", "--method", "analytic", "--size", "48x27"]
r = conform("--backend", "scalar", "--json", "broken.json",
            *externals("crashes", "hangs", "writes_nothing", "exits_1", "wrong_size", "cannot"))
print(r.stdout[-3000:], r.stderr[-2000:])
check(r.returncode == 1, f"conform exits 1 with renderers that do not answer (got {r.returncode})")
broken = json.load(open(os.path.join(OUT, "broken.json")))
cases.update({(c["backend"], c["method"], c["scene"]): c for c in broken["cases"]})
check(cases[("scalar", "analytic", "torus")]["verdict"] == "pass",
      "the scalar backend's case of that run passes beside them")

for method in ("sphere",):
    for scene in ("torus", "l_shape"):
        ours, theirs = cases[("scalar", method, scene)], cases[("mine", method, scene)]
        same = all(ours[k] == theirs[k] for k in
                   ("verdict", "hit_rate", "crossings_rate", "failures", "ambiguous"))
        check(same, f"the example adapter's {method}/{scene} is the scalar backend's: "
                    f"{theirs['verdict']} (scalar {ours['verdict']})")
        check(theirs["external"]["time"].startswith("the command's"),
              f"{method}/{scene}: its time is said to be its command's")
        unmeasured = {u["check"] for u in theirs["unmeasured"]}
        check({"steps", "traces"} <= unmeasured, f"{method}/{scene}: steps and traces unmeasured, "
                                                 f"saying why: {sorted(unmeasured)}")


def classes(case):
    return {k for k, n in case["failures"].items() if n}


for method in ("sphere",):
    flipped = cases[("flipped", method, "torus")]
    check(flipped["verdict"] == "fail", f"flipped {method}: fail")
    check({"wrong_edge", "missed_object", "phantom_hit"} <= classes(flipped),
          f"flipped {method}: wrong_edge, missed_object and phantom_hit ({classes(flipped)})")
    failed = {c["name"] for c in flipped["checks"] if not c["passed"]}
    check({"colour.sky", "image.failpercent", "hit_rate"} <= failed,
          f"flipped {method}: the sky's colour, the image and the hit rate fail")
    zeros = cases[("no_crossings", method, "torus")]
    check(zeros["verdict"] == "fail" and classes(zeros) <= {"wrong_edge", "stuck"}
          and "wrong_edge" in classes(zeros), f"no_crossings {method}: fail, wrong_edge alone "
                                              f"({classes(zeros)})")
    failed = {c["name"] for c in zeros["checks"] if not c["passed"]}
    check(not any(f.startswith(("colour", "image", "hit_rate")) for f in failed),
          f"no_crossings {method}: its colour and hits pass ({sorted(failed)})")

why = {"crashes": "killed by signal 11", "hangs": "timed out", "exits_1": "cannot open the GPU",
       "writes_nothing": "wrote nothing", "wrong_size": "not the 48x27 asked"}
for name, words in why.items():
    for method in ("analytic",):
        case = cases.get((name, method, "torus"), {})
        check(words in case.get("error", ""), f"{name} {method}: an error saying '{words}' "
                                              f"({case.get('error', 'no error')[:120]})")
skipped = [s for s in broken["skipped"] if s["backend"] == "cannot"]
check(len(skipped) == 1 and all("no such scene in my world" in s["reason"] for s in skipped),
      "a renderer that exits 77 is skipped with its reason, each case")

# Expectations: the flipped renderer's failures are known; the good one is listed as failing one
# case, which it passes: an unexpected pass, a change.
manifests = {}
for name, source, lines in (
        ("known", os.path.join(DATA, "flipped.json"),
         ["# rows flipped: known", "known/sphere/torus,Fail", "flake known/analytic/.*"]),
        ("better", EXAMPLE, ["better/analytic/torus,Fail  # fixed since", "skip better/sphere/.*"])):
    m = json.load(open(source))
    m["name"] = name
    m["command"] = [os.path.join(os.path.dirname(source), a) if a.endswith(".py") else a
                    for a in m["command"]]
    m["expectations"] = name + ".txt"
    with open(os.path.join(OUT, name + ".txt"), "w") as f:
        f.write("\n".join(lines) + "\n")
    manifests[name] = os.path.join(OUT, name + ".json")
    with open(manifests[name], "w") as f:
        json.dump(m, f)
CASE = ["--scene", "torus", "--method", "sphere", "--method", "analytic", "--size", "32x18"]
r = conform("--backend", "known", "--json", "expect.json", "--external", manifests["known"])
check(r.returncode == 0, f"expected failures are no change: exit 0 (got {r.returncode}: "
                         f"{r.stderr[-300:]})")
r = conform("--backend", "better", "--json", "expect2.json", "--external", manifests["better"])
results = json.load(open(os.path.join(OUT, "expect2.json")))
check(r.returncode == 1 and results["changes"] == [
    "better/analytic/torus: unexpected pass (expected fail)"],
      f"an unexpected pass is a change, exit 1 ({r.returncode}, {results.get('changes')})")
check(sum(1 for s in results["skipped"] if s["backend"] == "better") == 1,
      "the expectation file's skip line skips the sphere cases")

# The report: the example adapter (as "better", with its expectation file) beside the scalar
# backend, in results.json and on the page, with where it goes wrong drawn, the expectation
# file's change, and the case its skip line skips.
r = subprocess.run([FLATMARCH, "report", "--scene", "torus", "--backend", "scalar", "--method",
                    "analytic", "--method", "sphere", "--external", manifests["better"],
                    "--no-sweep", "--no-scaling", "--size", "32x18", "--conform-size", "48x27",
                    "--repetitions", "2", "--min-time", "0.001", "-o", "report", "-q"],
                   cwd=OUT, capture_output=True, text=True, timeout=600)
print(r.stdout[-2000:], r.stderr[-2000:])
check(r.returncode == 1, f"report exits 1 on the expectation file's change (got {r.returncode})")
report = json.load(open(os.path.join(OUT, "report", "results.json")))
rcases = {(c["backend"], c["method"]): c for c in report["matrix"]["cases"]}
check(rcases[("better", "analytic")]["accuracy"]["verdict"] ==
      rcases[("scalar", "analytic")]["accuracy"]["verdict"] == "pass",
      "the report judges the example adapter as the backend it wraps")
check("the command's" in rcases[("better", "analytic")]["external"]["time"],
      "the report says the renderer's time is its command's")
diff = os.path.join(OUT, "report", "images", rcases[("better", "analytic")].get("diff", "none"))
check(os.path.exists(diff), f"where it goes wrong is drawn ({diff})")
check(report.get("expectations", {}).get("better", {}).get("changes") ==
      ["better/analytic/torus: unexpected pass (expected fail)"],
      f"the report's results hold the change ({report.get('expectations')})")
check([s["method"] for s in report["matrix"]["skipped"] if s.get("backend") == "better"] ==
      ["sphere"] and not any(c["backend"] == "better" and c["method"] == "sphere"
                             for c in report["matrix"]["cases"]),
      f"the report skips what the expectation file skips ({report['matrix']['skipped']})")
page = open(os.path.join(OUT, "report", "index.html")).read()
check("Renderers we did not write" in page and "unexpected pass" in page,
      "the page lists the renderers and the change")

r = conform("--external", os.path.join(DATA, "bad_manifest.json"))
check(r.returncode == 2 and "/channels/1" in r.stderr and "normals" in r.stderr,
      f"a bad manifest is refused naming its key: exit {r.returncode}, {r.stderr.strip()}")

print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)
