#!/usr/bin/env python3
"""`flatmarch export-web` as a browser sees it (issue 23): scenes of each kind (translation,
prism, mirror, cone, affine, singularities) exported, each page drawn by headless Chromium
(WebGL2; SwiftShader where there is no GPU) at 160x90 from the scene's camera with the network
disabled, and compared with `flatmarch render` on the OpenGL backend at the same camera and size:
at least 99% of the pixels within 3/255 on every channel. ?bench=N must time frames. The pages must reference nothing outside
themselves, and bad options must exit 2 with the reason.

    web_export_test.py FLATMARCH OUT   exit 0: passed, 1: failed, 77: skipped (no Chromium or
                                       no OpenGL backend)
"""
import json
import os
import re
import shutil
import subprocess
import sys

from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "scenes")
SKIP = 77
NAMES = ["torus", "l_shape_prism", "mirror_pentagon", "cone_pi", "affine_two_rooms",
         "double_pentagon_singularities"]
WIDTH, HEIGHT = 160, 90


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, timeout=300, **kw)


def pixels(png):
    image = Image.open(png).convert("RGB")
    return image.size, list(image.getdata())


def main():
    flatmarch, out = sys.argv[1], sys.argv[2]
    browser = chromium()
    if not browser:
        print("skipped: no Chromium (Debian's chromium package; ci/packages.txt installs it)")
        return SKIP
    # The page's reference: the backend that runs the same kernel through native OpenGL.
    listed = json.loads(run([flatmarch, "backends", "--json"]).stdout)
    reference = next((b["name"] for b in listed
                      if b["available"] and b.get("device", {}).get("api", "").startswith("OpenGL")), None)
    if not reference:
        print("skipped: no backend draws with OpenGL here, the page's reference")
        return SKIP
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    failures = []
    scenes = [os.path.join(SCENES, n + ".json") for n in NAMES]
    r = run([flatmarch, "export-web", *scenes, "-o", out])
    if r.returncode != 0:
        print("export-web failed:", r.stderr)
        return 1
    # Each page's size is reported.
    for name in NAMES:
        size = re.search(re.escape(os.path.join(name, "index.html")) + r" \((\d+) KB\)", r.stderr)
        if not size:
            failures.append(f"{name}: export-web did not report the page's size: {r.stderr}")
        else:
            print(f"{name}: {size.group(1)} KB")
    index = open(os.path.join(out, "index.html")).read()
    for name in NAMES:
        page = os.path.join(out, name, "index.html")
        text = open(page).read()
        if re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", text):
            failures.append(f"{name}: the page references something outside itself")
        if f'href="{name}/index.html"' not in index:
            failures.append(f"{name}: not linked from the index page")
        shot = os.path.join(out, name + ".web.png")
        # No network: every host resolves to nothing.
        run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
             "--host-resolver-rules=MAP * ~NOTFOUND",
             f"--window-size={WIDTH},{HEIGHT}", f"--screenshot={shot}",
             f"file://{os.path.abspath(page)}?frame={WIDTH}x{HEIGHT}"])
        ref = os.path.join(out, name + ".gl.png")
        r = run([flatmarch, "render", os.path.join(SCENES, name + ".json"), "--backend", reference,
                 "--size", f"{WIDTH}x{HEIGHT}", "-o", ref, "-q"])
        if r.returncode != 0 or not os.path.exists(shot):
            failures.append(f"{name}: no image (render: {r.stderr.strip()})")
            continue
        (size, web), (_, gl) = pixels(shot), pixels(ref)
        if size != (WIDTH, HEIGHT):
            failures.append(f"{name}: the page's screenshot is {size}")
            continue
        close = sum(max(abs(a - b) for a, b in zip(p, q)) <= 3 for p, q in zip(web, gl))
        share = close / len(gl)
        print(f"{name}: {100 * share:.2f}% of the pixels within 3/255 of the {reference} backend's")
        if share < 0.99:
            failures.append(f"{name}: only {100 * share:.2f}% of the pixels agree")
    # The eps and offset keys: eight presses of ] take eps from 1e-4 to 1e-2 in quarter decades,
    # carrying offset up to the first quarter decade above it, 2e-4 * 10^(7/4); the page's shader
    # is then the opengl backend's at those parameters.
    keyed = os.path.join(out, "keys.web.png")
    run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
         f"--window-size={WIDTH},{HEIGHT}", f"--screenshot={keyed}",
         "file://" + os.path.abspath(os.path.join(out, "torus", "index.html")) +
         f"?frame={WIDTH}x{HEIGHT}&keys=" + ",".join("]" * 8)])
    ref = os.path.join(out, "keys.gl.png")
    run([flatmarch, "render", os.path.join(SCENES, "torus.json"), "--backend", reference,
         "--size", f"{WIDTH}x{HEIGHT}", "--eps", "1e-2", "--offset", repr(2e-4 * 10 ** (7 / 4)),
         "-o", ref, "-q"])
    if os.path.exists(keyed) and os.path.exists(ref):
        (_, web), (_, gl) = pixels(keyed), pixels(ref)
        (_, plain) = pixels(os.path.join(out, "torus.web.png"))
        same = sum(max(abs(a - b) for a, b in zip(p, q)) <= 3 for p, q in zip(web, gl)) / len(gl)
        before = sum(max(abs(a - b) for a, b in zip(p, q)) <= 3 for p, q in zip(plain, gl)) / len(gl)
        print(f"keys ]x8: {100 * same:.2f}% of the pixels as opengl's at eps 1e-2 "
              f"(the page before the keys: {100 * before:.2f}%)")
        if same < 0.99 or before >= same:
            failures.append(f"keys ]x8: {100 * same:.2f}% agree with eps 1e-2, {100 * before:.2f}% before")
    else:
        failures.append("keys ]x8: no image")
    # Timed frames: ?bench=N puts the median frame time in the title.
    page = os.path.abspath(os.path.join(out, NAMES[0], "index.html"))
    dom = run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom",
               f"file://{page}?frame={WIDTH}x{HEIGHT}&bench=3"]).stdout
    timed = re.search(r"<title>flatmarch: rendered; median ([0-9.]+) ms over 3 frames", dom)
    if not timed or float(timed.group(1)) <= 0.0:
        failures.append(f"?bench=3 gave no frame time: {dom[:200]}")
    else:
        print(f"{NAMES[0]}: median {timed.group(1)} ms a {WIDTH}x{HEIGHT} frame in this browser")
    for args, words in [(["--method", "oracle"], "--method"), (["--eps", "-1"], "eps")]:
        r = run([flatmarch, "export-web", os.path.join(SCENES, "torus.json"), "-o", out + "/bad",
                 *args])
        if r.returncode != 2 or words not in r.stderr:
            failures.append(f"export-web {' '.join(args)}: exit {r.returncode}, {r.stderr.strip()}")
    for f in failures:
        print("FAILED:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
