#!/usr/bin/env bash
# Configures and builds. Usage: ci/build.sh BUILD_DIR [extra cmake arguments...]
# e.g. ci/build.sh build -DCMAKE_BUILD_TYPE=Release -DFLATMARCH_WERROR=ON
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:?usage: ci/build.sh BUILD_DIR [cmake arguments...]}
shift
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$root" -B "$dir" "$@"
cmake --build "$dir" -j "$jobs"
