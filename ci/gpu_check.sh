#!/usr/bin/env bash
# The checks that need a real GPU, which CI has not: run after a build on a machine with one.
# Lists the devices; measures the OpenGL and Vulkan backends against the oracle on the default
# device (a GPU first) with `flatmarch conform`; runs their conformance, stability and unit tests
# there (Vulkan under the validation layer, as ctest does); times gpu_bench at 1920x1080 and on the
# web app's views (with the app's own shaders when PEER_DIR holds them, ../shared/peer-shaders.md);
# and times simd_bench's acceptance scenes on every core. Each step has a time limit; one that
# fails is reported and the others still run. Everything printed goes to OUT_DIR/log.txt too; the
# JSON beside it is read by bench/side_by_side.py, bench/peer_ratios.py and bench/speedups.py.
# Exits 1 if any step failed.
#
# Usage: ci/gpu_check.sh BUILD_DIR OUT_DIR [PEER_DIR]
set -uo pipefail
if (($# < 2)); then
  echo "usage: ci/gpu_check.sh BUILD_DIR OUT_DIR [PEER_DIR]" >&2
  exit 2
fi
build=$1 out=$2 peer=${3:-}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out" || exit 2
out=$(cd "$out" && pwd)
exec > >(tee "$out/log.txt") 2>&1
cd "$root" || exit 2

failed=()
step() {  # step NAME SECONDS COMMAND...: runs one check under a time limit
  local name=$1 limit=$2 start=$SECONDS rc
  shift 2
  echo "==== $name"
  timeout --kill-after=10 "$limit" "$@"
  rc=$?
  echo "---- $name: $( ((rc == 0)) && echo ok || echo "FAILED ($rc$( ((rc == 124)) && echo ", over ${limit} s"))") in $((SECONDS - start)) s"
  ((rc == 0)) || failed+=("$name")
}

flatmarch=$build/cli/flatmarch
gtest_brief=(--gtest_brief=1)

step machine 30 bash -c 'nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>&1;
  lscpu | grep -E "^(Model name|CPU\(s\)|Flags)" | cut -c1-160'
step devices 60 "$flatmarch" backends
for backend in opengl vulkan; do
  step "conform_$backend" 180 "$flatmarch" conform --backend "$backend" --json "$out/conform_$backend.json"
done
step gallery_conformance_test 180 env FLATMARCH_VULKAN_VALIDATION=1 \
  "$build/conformance/tests/gallery_conformance_test" "${gtest_brief[@]}" --gtest_filter='*/opengl_*:*/vulkan_*'
step stability_test 120 env FLATMARCH_VULKAN_VALIDATION=1 \
  "$build/conformance/tests/stability_test" "${gtest_brief[@]}" --gtest_filter='*/opengl:*/vulkan'
step device_paths_test 60 env FLATMARCH_VULKAN_VALIDATION=1 \
  "$build/conformance/tests/device_paths_test" "${gtest_brief[@]}"
step opengl_test 90 "$build/tests/opengl_test" "${gtest_brief[@]}"
step vulkan_test 90 env FLATMARCH_VULKAN_VALIDATION=1 "$build/tests/vulkan_test" "${gtest_brief[@]}"

peer_args=()
[[ -n $peer ]] && peer_args=(--peer-shaders="$peer")
step gpu_bench 300 "$build/bench/gpu_bench" "${peer_args[@]}" --benchmark_min_time=0.2 \
  --benchmark_filter='^((opengl|vulkan)/.*/1920x1080|peer/)' \
  --benchmark_out="$out/gpu.json" --benchmark_out_format=json
step simd_bench 150 "$build/bench/simd_bench" \
  --benchmark_filter='/(l_shape|double_pentagon|cube|staircase_32)/' \
  --benchmark_out="$out/simd.json" --benchmark_out_format=json

echo
if ((${#failed[@]})); then
  echo "gpu_check: FAILED: ${failed[*]}"
  exit 1
fi
echo "gpu_check: every step passed"
