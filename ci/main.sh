#!/usr/bin/env bash
# The main job: installs what `flatmarch` needs (ci/packages.txt, not the test suite's), builds
# the program and its image module alone (Release, no tests), and runs `flatmarch report` —
# every available backend on the gallery, timed and measured against the oracle, the eps x offset
# sweep and the scaling series — into reports/out: index.html (self-contained) and results.json.
# Arguments go to `flatmarch report` (e.g. --full). Prints each step's time.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
step() {  # step NAME COMMAND...: runs it, then says how long it took
  local name=$1 start=$SECONDS
  shift
  "$@"
  echo "main: $name took $((SECONDS - start)) s"
}
step "installing" ci/install-deps.sh main
step "building" ci/build.sh build-release --target flatmarch -DCMAKE_BUILD_TYPE=Release \
  -DFLATMARCH_TESTS=OFF
step "the report" build-release/cli/flatmarch report "$@"
echo "main: open $root/reports/out/index.html"
