#!/usr/bin/env python3
"""An external renderer for flatmarch (docs/external.md): `flatmarch render` called as a command.

flatmarch runs it as `render_adapter.py [--backend=B] REQUEST` and judges the EXR it writes as it
judges a backend. --break=rows or --break=crossings make it wrong on purpose, for the protocol's
tests (with oiiotool, which OpenImageIO's tools bring).
"""
import json
import os
import subprocess
import sys

request = json.loads(sys.argv[-1])
options = dict(a[2:].split("=", 1) for a in sys.argv[1:-1])
camera, params, out = request["camera"], request["params"], request["output"]
subprocess.run(
    [os.environ["FLATMARCH"], "render", request["scene_file"], "-q", "-o", out["png"],
     "--backend", options.get("backend", "scalar"), "--method", request["method"],
     "--size", f"{request['width']}x{request['height']}",
     "--eps", str(params["eps"]), "--offset", str(params["offset"]),
     "--max-steps", str(params["max_steps"]), "--max-distance", str(params["max_distance"]),
     "--omega", str(params["omega"]), "--precision", params["precision"],
     "--camera-polygon", str(camera["polygon"]),
     "--position", ",".join(map(str, camera["position"])), "--yaw", str(camera["yaw_deg"]),
     "--pitch", str(camera["pitch_deg"]), "--fov", str(camera["fov_deg"])],
    check=True)  # writes out["png"] and, beside it, out["exr"]

broken = options.get("break")
if broken == "rows":  # the image upside down, as a renderer that forgets GL's bottom-up rows
    for image in (out["png"], out["exr"]):
        subprocess.run(["oiiotool", image, "--flip", "-o", image], check=True)
elif broken == "crossings":  # a crossings AOV that counts nothing
    subprocess.run(["oiiotool", out["exr"], "--ch", "R,G,B,steps,crossings=0,hit,t",
                    "-o", out["exr"]], check=True)
