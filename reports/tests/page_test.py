#!/usr/bin/env python3
"""The report's page as a browser sees it: a small real report run (two scenes, the scalar
backend, a tiny sweep) checked against the committed baseline fixture data/page_baseline.json
(made to regress one figure and improve another), the SIMD backend beside the scalar one and compared with the earlier run
data/page_previous.json (one case failed there, one passed that is now at its method's limit),
loaded in headless Chromium. Checks that the verdicts are counted apart, each non-pass case shows
every failed check, the regression section shows the gate's verdict and the regressed figure,
the earlier run's verdict changes are listed, the recommended method's gallery is there, and no
image of the page is broken.

    page_test.py FLATMARCH OUT      exit 0: passed, 1: failed, 77: skipped (no Chromium)
"""
import html
import json
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "..", "scenes")
SKIP = 77


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def dump_dom(browser, page, profile):
    """The page's DOM after load, with the number of images and of broken ones (not decoded, or
    of no size) written into the body by a script added to a copy of the page."""
    probe = page.replace(".html", ".probe.html")
    with open(page) as f:
        text = f.read()
    script = ("<script>window.addEventListener('load', () => {const imgs = [...document.images];"
              "document.body.dataset.images = imgs.length;"
              "document.body.dataset.broken = imgs.filter(i => !i.complete || i.naturalWidth === 0)"
              ".map(i => i.alt).join('|') || 'none';});</script>")
    with open(probe, "w") as f:
        f.write(text.replace("</body>", script + "</body>"))
    run = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", f"--user-data-dir={profile}",
                          "--dump-dom", "file://" + probe], capture_output=True, text=True, timeout=60)
    if run.returncode != 0 or "<body" not in run.stdout:
        sys.exit(f"FAILED: chromium --dump-dom exited {run.returncode}: {run.stderr[-2000:]}")
    return run.stdout


def section(dom, anchor):
    """The text from the heading with id `anchor` to the next h2."""
    m = re.search(rf'<h2 id="{anchor}">(.*?)(?=<h2 |$)', dom, re.S)
    return m.group(1) if m else ""


def main():
    flatmarch, out = sys.argv[1], sys.argv[2]
    browser = chromium()
    if not browser:
        print("SKIPPED: no chromium on this machine (Debian: apt-get install chromium; ci/packages.txt lists it)")
        return SKIP
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    # Every CPU backend of the kernel this build has (the registry's, `flatmarch backends`).
    listed = json.loads(subprocess.run([flatmarch, "backends", "--json"], capture_output=True, text=True,
                                       check=True, timeout=60).stdout)
    cpu = [a for b in listed if b["cpu"] and b["available"] for a in ("--backend", b["name"])]
    run = subprocess.run(
        [flatmarch, "report", "--scene", os.path.join(SCENES, "torus.json"),
         "--scene", os.path.join(SCENES, "l_shape_prism.json")] + cpu + [
         "--method", "sphere", "--method", "analytic", "--size", "48x27", "--conform-size", "48x27",
         "--repetitions", "2", "--min-time", "0.001", "--sweep-size", "16x9", "--no-scaling", "-q",
         "-o", os.path.join(out, "run"), "--baseline", os.path.join(HERE, "data", "page_baseline.json"),
         "--previous", os.path.join(HERE, "data", "page_previous.json")],
        capture_output=True, text=True, timeout=240)
    failures = []

    def expect(ok, what):
        if not ok:
            failures.append(what)

    # The fixture's baseline holds one figure far below what any run measures: the gate fails.
    expect(run.returncode == 1 and "figures regressed" in run.stderr,
           f"the run should fail its gate (exit 1), got {run.returncode}: {run.stderr[-1500:]}")
    if not os.path.exists(os.path.join(out, "run", "index.html")):
        sys.exit(f"FAILED: the report run wrote no page (exit {run.returncode}): {run.stderr[-2000:]}")
    with open(os.path.join(out, "run", "results.json")) as f:
        results = json.load(f)
    dom = dump_dom(browser, os.path.join(out, "run", "index.html"), os.path.join(out, "profile"))
    cases = results["matrix"]["cases"]
    verdicts = [c["accuracy"]["verdict"] for c in cases]

    summary = section(dom, "summary")
    for v in ("pass", "limit", "fail"):
        m = re.search(rf'<div class="count {v}"><b>(\d+)</b> {v}</div>', summary)
        expect(m and int(m.group(1)) == verdicts.count(v),
               f"summary: {verdicts.count(v)} {v} expected, page says {m.group(1) if m else 'nothing'}")
    expect("limit" in verdicts, "the run should have a case at its method's limit (sphere in the prism)")
    for v in ("pass", "limit", "fail"):
        expect(f'<span class="verdict {v}">{v}</span>' in dom, f"no {v} verdict shown anywhere")

    reasons = section(dom, "failures")
    for c in cases:
        a = c["accuracy"]
        if a["verdict"] == "pass":
            continue
        row = re.search(rf'<td data-cases="[^"]*\b{re.escape(c["name"])}\b[^"]*">(.*?)</tr>', reasons, re.S)
        expect(row, f"failures: no row for {c['name']}")
        for line in a["failed_checks"] + ([a["limit"]] if a["verdict"] == "limit" else []):
            expect(row and html.escape(line, quote=False) in row.group(1),
                   f"failures: {c['name']} does not show {line!r}")

    gate = section(dom, "regression")
    expect('Gate: <span class="verdict fail">fail</span>' in gate, "regression: the gate's verdict is not fail")
    row = re.search(r"<td>scalar/sphere/torus/48x27</td><td>steps_mean</td><td>0.5</td><td>([\d.]+)</td>"
                    r"<td>\+[\d.]+</td><td>0.06</td>", gate)
    expect(row, "regression: the regressed steps_mean of scalar/sphere/torus/48x27 against 0.5 "
                "with tolerance 0.06 is not shown")
    expect("1 improvements" in gate, "regression: the improvement is not counted")

    earlier = section(dom, "previous")
    changes = re.findall(r'<tr><td>([^<]+)</td><td><span class="verdict (\w+)">\w+</span></td>'
                         r'<td><span class="verdict (\w+)">\w+</span></td><td>(\w+)</td>', earlier)
    expect(changes[:1] == [("scalar/sphere/l_shape_prism/48x27", "pass", "limit", "worse")] and
           ("scalar/analytic/l_shape_prism/48x27", "fail", "pass", "better") in changes,
           f"previous: verdict changes (worse first) not as expected: {changes}")
    expect("1 no longer measured" in earlier, "previous: the case no longer measured is not counted")

    gallery = section(dom, "recommended")
    rec = results["recommendation"]
    for scene in results["options"]["scenes"]:
        for alt in (f"{scene}, oracle", f'{scene}, {rec["backend"]} {rec["method"]}', f"{scene}, difference"):
            expect(f'alt="{alt}"' in gallery, f"recommended gallery: no image {alt!r}")
    # The map's legend in the one palette the results carry (conformance/vocabulary.hpp).
    for c in results["vocabulary"]["pixel_classes"]:
        if c["name"] != "agree" and not c["traces_only"]:
            expect(f'background:{c["colour"]}' in gallery.replace(" ", ""),
                   f'recommended gallery: no {c["colour"]} swatch for {c["name"]}')

    for anchor in ("ambiguity", "definitions", "sweep"):
        expect(section(dom, anchor), f"no {anchor} section")
    for failure in ("stuck", "wrong_edge", "missed_object", "phantom_hit", "early_escape", "late_escape", "leak"):
        expect(f"<td>{failure}</td>" in section(dom, "definitions"), f"definitions: no failure class {failure}")

    # A SIMD backend's lane efficiency (issue 73): one thread over the scalar backend, over its
    # lanes, per case in the steps section and per method in the ranking, as results.json has it.
    vector = [c for c in cases if "lanes" in c.get("counters", {})]
    scalar_rays = {(c["scene"], c["method"]): c["counters"]["rays_per_s"] for c in cases
                   if c["backend"] == "scalar" and "counters" in c}
    expect(vector, "no timed case of a backend with lanes (a SIMD backend) in the run")
    steps = section(dom, "steps")
    for c in vector:
        k = c["counters"]
        one = k.get("one_thread_rays_per_s", k["rays_per_s"])
        want = f'{100 * one / scalar_rays[(c["scene"], c["method"])] / k["lanes"]:.3g}% of {int(k["lanes"])} lanes'
        expect(want in steps, f"steps: {c['name']} should show {want!r}")
    for name in sorted({c["backend"] for c in vector}):
        ranked = next((b for b in results["ranking"] if b["backend"] == name), {})
        expect(all("lane_efficiency" in m for m in ranked.get("methods", {}).values()),
               f"ranking: the {name} backend's methods have no lane_efficiency: {ranked}")
    expect("of its lanes" in dom, "the ranking does not show a SIMD backend's lane efficiency")

    images = re.search(r'<body data-images="(\d+)" data-broken="([^"]*)"', dom)
    expect(images and int(images.group(1)) >= 12, f"too few images on the page: {images and images.group(1)}")
    expect(images and images.group(2) == "none", f"broken images: {images and images.group(2)}")
    expect('class="missing"' not in dom, "an image file the page wanted is missing")

    # A case a supervised run's worker did not finish (issue 74): the run's results with one case as
    # the report writes a crashed one (reports::unfinished_part and unfinished_entry), drawn again.
    crashed = json.loads(json.dumps(results))
    victim = crashed["matrix"]["cases"][0]
    for k in ("accuracy", "counters", "time_ms", "time_samples_ms"):
        victim.pop(k, None)
    victim.update(verdict="crash", error="crash (SIGSEGV) after 0.4 s")
    key = f'matrix/{victim["backend"]}/{victim["method"]}/{victim["scene"]}'
    crashed["unfinished"] = [{"key": key, "stage": "matrix", "verdict": "crash",
                              "error": "crash (SIGSEGV) after 0.4 s", "signal_name": "SIGSEGV",
                              "stderr_tail": "drawing\nthe worker's last line\n"}]
    crashed.pop("regression", None)
    with open(os.path.join(out, "crashed.json"), "w") as f:
        json.dump(crashed, f)
    drawn = subprocess.run([flatmarch, "report", "-o", os.path.join(out, "crashed"), os.path.join(out, "crashed.json")],
                           capture_output=True, text=True, timeout=240)
    expect(drawn.returncode == 0, f"the page of a crashed case: {drawn.stderr[-1500:]}")
    if drawn.returncode == 0:
        dom = dump_dom(browser, os.path.join(out, "crashed", "index.html"), os.path.join(out, "profile"))
        expect('<div class="count crash"><b>1</b> crash</div>' in section(dom, "summary"),
               "summary: the crashed case is not counted as a crash")
        row = re.search(rf'<td data-cases="[^"]*\b{re.escape(victim["name"])}\b[^"]*">(.*?)</tr>',
                        section(dom, "failures"), re.S)
        expect(row and '<span class="verdict crash">crash</span>' in row.group(1)
               and "SIGSEGV" in row.group(1), "failures: the crashed case's row has not its verdict and why")
        unfinished = section(dom, "unfinished")
        expect(f"<td>{key}</td>" in unfinished and "the worker's last line" in unfinished,
               f"unfinished: {key} and its worker's last words are not listed")

    for f in failures:
        print("FAILED:", f)
    if not failures:
        print(f"page_test: {len(cases)} cases, verdicts {sorted(set(verdicts))}, {images.group(1)} images: passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
