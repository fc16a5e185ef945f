#!/usr/bin/env bash
# Builds benchmark programs as an earlier revision had them, to time that revision against this
# checkout with bench/ab.py (e.g. the build an issue was filed on):
#
#   bench/build_at.sh REV DIR [TARGET...]     (default target: simd_bench)
#   python3 bench/ab.py DIR/build/bench/simd_bench build/bench/simd_bench --filter=... --pin 0
#
# The revision's files are exported into DIR/src (git archive: no worktree to clean up) and
# built in DIR/build with the default build type, as ci/build.sh builds this checkout. A DIR
# that already holds another revision is refused rather than mixed.
set -euo pipefail
usage="usage: bench/build_at.sh REV DIR [TARGET...]"
if [ $# -lt 2 ]; then
  echo "$usage" >&2
  exit 2
fi
rev=$1
dir=$2
shift 2
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(simd_bench)
root=$(cd "$(dirname "$0")/.." && pwd)

if ! commit=$(git -C "$root" rev-parse --verify --quiet "$rev^{commit}"); then
  echo "build_at.sh: $rev is not a revision of $root" >&2
  exit 2
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
if [ -f "$dir/REVISION" ] && [ "$(cat "$dir/REVISION")" != "$commit" ]; then
  echo "build_at.sh: $dir holds revision $(cat "$dir/REVISION"), not $commit; use another DIR" >&2
  exit 2
fi
if [ ! -f "$dir/REVISION" ]; then
  echo "build_at.sh: exporting $commit into $dir/src" >&2
  rm -rf "$dir/src"
  mkdir -p "$dir/src"
  git -C "$root" archive "$commit" | tar -x -C "$dir/src"
  echo "$commit" > "$dir/REVISION"
fi

generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
[ -f "$dir/build/CMakeCache.txt" ] || cmake -S "$dir/src" -B "$dir/build" "${generator[@]}" > /dev/null
cmake --build "$dir/build" -j "$(nproc 2>/dev/null || echo 2)" --target "${targets[@]}"
for t in "${targets[@]}"; do
  found=$(find "$dir/build" -name "$t" -type f -perm -u+x | head -n 1)
  echo "${found:-$dir/build (no program named $t)}"
done
