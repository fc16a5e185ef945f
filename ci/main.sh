#!/usr/bin/env bash
# The main job: installs what is missing, builds, and renders the whole gallery (scenes/) with the
# exact oracle into out/gallery: NAME.png, NAME.exr (AOVs), NAME.svg (floor plan), index.html.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
ci/install-deps.sh
ci/build.sh build-release -DCMAKE_BUILD_TYPE=Release
build-release/cli/flatmarch gallery scenes -o out/gallery
echo "main: open $root/out/gallery/index.html"
