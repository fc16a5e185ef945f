#!/usr/bin/env bash
# Configures and builds. Usage: ci/build.sh BUILD_DIR [--target TARGET] [extra cmake arguments...]
# e.g. ci/build.sh build -DCMAKE_BUILD_TYPE=Release -DFLATMARCH_WERROR=ON; with --target, builds
# that target (and what it needs) instead of everything.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:?usage: ci/build.sh BUILD_DIR [--target TARGET] [cmake arguments...]}
shift
target=()
if [[ ${1:-} == --target ]]; then
  target=(--target "${2:?ci/build.sh: --target needs a target}")
  shift 2
fi
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$root" -B "$dir" "$@"
cmake --build "$dir" -j "$jobs" "${target[@]}"
