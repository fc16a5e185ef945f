#!/usr/bin/env python3
"""Checks that the source folders stand in layers: each includes only itself and those below it.

Usage: ci/check_layers.py [ROOT]   (ROOT defaults to the checkout holding this script)

The layers, lowest first, are LAYERS below (the order in which the top CMakeLists.txt adds them).
Besides the order, three rules:
  - a backend's own folder (backends/<name>/) includes backends/ and itself, never another
    backend: each backend builds and is left out (FLATMARCH_WITH_<NAME>) on its own;
  - above backends/, a backend's folder is included only where BACKEND_USERS says so: the oracle
    and the scalar backend are always built (the truth and the reference), and the viewer draws
    with the OpenGL backend's kernel (it is built only with it);
  - test code (tests/, bench/, fuzz/ and every <folder>/tests/) stands above all and may include
    anything.
Prints each folder's layer and what it uses, then every include that breaks a rule as
FILE:LINE, and exits 1 if there is one.
"""

import collections
import pathlib
import re
import sys

# Lowest first. A folder may include those before it.
LAYERS = [
    "scene",  # the scene format, its validation, the surfaces' catalogue
    "interop",  # the peer app's scene files read as ours
    "kernels",  # the ray-marching kernel, one template for every backend
    "motion",  # walking, collisions, speeds and the render scale
    "output",  # frames, traces, images, loading the modules
    "web",  # the exported page (its kernel and controls)
    "backends",  # the interface, the registry and one folder per backend
    "conformance",  # the suite against the oracle
    "plan",  # floor plans
    "reports",  # sweeps, matrix, the report and the gate
    "history",  # every run kept, change points, the timeline
    "viewer",  # the first-person window
    "cli",  # the `flatmarch` program
]
TEST_FOLDERS = {"tests", "bench", "fuzz"}
# Backends whose folders code above backends/ may include, by folder, and by whom ("*":
# everyone): the viewer draws its window with the OpenGL backend's kernel.
BACKEND_USERS = {"backends/oracle": {"*"}, "backends/scalar": {"*"}, "backends/opengl": {"viewer"}}
SOURCE = re.compile(r"\.(cpp|hpp|h|inc|in)$")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def layer_of(path: pathlib.PurePath):
    """The folder's layer name, "tests" for test code, or None outside the layered folders."""
    parts = path.parts
    if not parts:
        return None
    if parts[0] in TEST_FOLDERS or "tests" in parts[1:-1]:
        return "tests"
    return parts[0] if parts[0] in LAYERS else None


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)
    if not (root / "CMakeLists.txt").is_file():
        print(f"check_layers.py: {root} holds no CMakeLists.txt (not a checkout?)", file=sys.stderr)
        return 2
    rank = {name: i for i, name in enumerate(LAYERS)}
    uses = collections.defaultdict(collections.Counter)
    broken = []
    files = 0
    for folder in LAYERS + sorted(TEST_FOLDERS):
        for path in sorted((root / folder).rglob("*")):
            if not path.is_file() or not SOURCE.search(path.name):
                continue
            relative = path.relative_to(root)
            here = layer_of(relative)
            if here is None:
                continue
            files += 1
            text = path.read_text(errors="replace")
            for match in INCLUDE.finditer(text):
                target = pathlib.PurePath(match.group(1))
                there = target.parts[0] if len(target.parts) > 1 else None
                if there not in rank:
                    continue  # a header beside the file, generated or third-party
                line = text.count("\n", 0, match.start()) + 1
                where = f"{relative}:{line}: includes {target}"
                if here != there:
                    uses[here][there] += 1
                if here != "tests" and rank[there] > rank[here]:
                    broken.append(f"{where}, but {there}/ is above {here}/")
                    continue
                if there != "backends" or len(target.parts) < 3:
                    continue
                backend = target.parts[1]
                mine = relative.parts[1] if here == "backends" and len(relative.parts) > 2 else None
                if here == "tests" or backend == mine:
                    continue
                if here == "backends":
                    if mine is not None:
                        broken.append(f"{where}: one backend's folder includes another's")
                    continue
                users = BACKEND_USERS.get(f"backends/{backend}", set())
                if "*" not in users and here not in users:
                    broken.append(f"{where}: only {sorted(users) or 'test code'} may use the "
                                  f"{backend} backend's folder (BACKEND_USERS)")
    print(f"{files} files in {len(LAYERS)} layers, lowest first:")
    for name in LAYERS + ["tests"]:
        below = ", ".join(f"{n} {c}" for n, c in sorted(uses[name].items(), key=lambda x: x[0]))
        print(f"  {name:12} uses {below or 'nothing else'}")
    for line in broken:
        print(line)
    if broken:
        print(f"check_layers.py: {len(broken)} includes break the layers (see ci/check_layers.py)")
        return 1
    print("check_layers.py: every include is of the file's own layer or one below it")
    return 0


if __name__ == "__main__":
    sys.exit(main())
