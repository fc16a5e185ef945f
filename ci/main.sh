#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs `flatmarch report` — every available
# backend on the gallery, timed and measured against the oracle, the eps x offset sweep and the
# scaling series — into reports/out: index.html (self-contained) and results.json. Arguments go
# to `flatmarch report` (e.g. --full).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
ci/install-deps.sh
ci/build.sh build-release -DCMAKE_BUILD_TYPE=Release
build-release/cli/flatmarch report "$@"
echo "main: open $root/reports/out/index.html"
