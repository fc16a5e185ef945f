#!/usr/bin/env python3
"""ctest peer_adapter: the adapter renders the torus through the stand-in of the app
(tests/data/app_stub), writes an EXR whose hit and crossings hold codes, skips (77) a scene the
app cannot read, and fails loudly where the app's shader lacks a line it edits.

usage: adapter_test.py PEER_ADAPTER FLATMARCH OIIOTOOL TESTS_DATA_DIR
Exits 77 (skipped) where Node is missing: the adapter runs the app's generator in it.
"""
import json
import math
import pathlib
import shutil
import subprocess
import sys
import tempfile

WIDTH, HEIGHT = 32, 18


def fail(message):
    print(f"FAIL: {message}")
    sys.exit(1)


def channels(oiiotool, exr):
    """The EXR's channels by name, each a list of its pixels' values."""
    info = subprocess.run([oiiotool, "-v", "--info", exr], capture_output=True, text=True,
                          check=True).stdout
    names = next(line.split(":", 1)[1] for line in info.splitlines()
                 if "channel list:" in line).replace(" ", "").split(",")
    dump = subprocess.run([oiiotool, "--dumpdata", exr], capture_output=True, text=True,
                          check=True).stdout
    values = [[float(v) for v in line.split(":", 1)[1].split()]
              for line in dump.splitlines() if line.strip().startswith("Pixel (")]
    return {name: [pixel[k] for pixel in values] for k, name in enumerate(names)}


def main():
    adapter, flatmarch, oiiotool, data = sys.argv[1:5]
    if shutil.which("node") is None:
        print("node is not on the PATH: the adapter needs it")
        return 77
    data = pathlib.Path(data)
    geometry = data / "peer-geometries" / "torus.json"
    stub = data / "app_stub"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        scene = json.loads(subprocess.run([flatmarch, "import-peer", str(geometry)],
                                          capture_output=True, text=True, check=True).stdout)
        # The benchmarks' view (../shared/peer-shaders.md): from the start point + (0.5, 0.5, 0)
        # here, looking along (1, 0.3), which sees the cube's copies across glued walls.
        camera = dict(scene["camera"])
        camera["position"] = [camera["position"][0] + 0.5, camera["position"][1] + 0.5,
                              camera["position"][2]]
        camera["yaw_deg"] = math.degrees(math.atan2(0.3, 1.0))
        camera["pitch_deg"] = 0.0
        request = {
            "protocol": "flatmarch-external/1",
            "scene": scene,
            "imported_from": {"format": "peer-app", "file": str(geometry)},
            "camera": camera,
            "width": WIDTH,
            "height": HEIGHT,
            "method": "sphere",
            "params": {"eps": 1e-4, "offset": 2e-4, "max_steps": 1024, "max_distance": 100.0,
                       "omega": 1.6, "precision": "f32"},
            "channels": ["colour", "hit", "crossings", "steps"],
            "output": {"exr": str(tmp / "output.exr"), "png": str(tmp / "output.png")},
        }

        def run(app, req):
            return subprocess.run([adapter, f"--app={app}", json.dumps(req)], cwd=tmp,
                                  capture_output=True, text=True)

        done = run(stub, request)
        if done.returncode != 0:
            fail(f"the adapter exited {done.returncode}: {done.stderr}")
        exr = tmp / "output.exr"
        if not exr.exists():
            fail("the adapter wrote no output.exr")
        c = channels(oiiotool, str(exr))
        for name in ("R", "G", "B", "steps", "crossings", "hit"):
            if len(c.get(name, [])) != WIDTH * HEIGHT:
                fail(f"channel {name} lacks pixels: {len(c.get(name, []))}")
        objects = len(scene.get("objects", []))
        codes = set(c["hit"])
        if not all(h == int(h) and (-7 <= h <= -1 or 0 <= h < objects) for h in codes):
            fail(f"hit holds values that are no codes: {sorted(codes)}")
        if not all(x == int(x) and x >= 0 for x in c["crossings"]):
            fail("crossings holds values that are not counts")
        if not any(h >= 0 for h in codes) or max(c["crossings"]) < 1:
            fail(f"the view should see objects across glued walls: hit {sorted(codes)}, "
                 f"crossings up to {max(c['crossings'])}")

        # A scene not read from the app's files: the case is skipped, with a reason.
        skipped = run(stub, {k: v for k, v in request.items() if k != "imported_from"})
        if skipped.returncode != 77 or "the app reads only its own geometry files" not in \
                skipped.stderr:
            fail(f"without imported_from: exit {skipped.returncode}, {skipped.stderr!r}")

        # An app whose shader lacks a line the adapter edits: an error that says which.
        changed = tmp / "changed_app"
        shutil.copytree(stub, changed)
        template = changed / "public" / "shader" / "template.frag"
        template.write_text(template.read_text().replace("radians(75.0)", "radians(60.0)"))
        broken = run(changed, request)
        if broken.returncode in (0, 77) or "the app's shader has changed: cannot find" not in \
                broken.stderr:
            fail(f"with a changed template: exit {broken.returncode}, {broken.stderr!r}")
    print(f"peer_adapter: {WIDTH}x{HEIGHT}, hit codes {sorted(codes)}, crossings up to "
          f"{max(c['crossings']):.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
