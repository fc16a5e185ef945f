#!/usr/bin/env bash
# The checks that need a real GPU, which CI has not, in one run that fits a machine lent for
# minutes (the `device` tool's: 10 minutes a command). In order of what they tell, each under a
# time limit, none started that the whole run's budget cannot hold:
#   machine, devices    the GPU, the driver, the CPU; `flatmarch backends` (devices, kernel shapes)
#   gpu_bench           every gallery scene and method at 1920x1080 and a frame's fixed cost
#                       (max_steps 0) at 640x360 and 1920x1080 on both GPU backends in the shape
#                       the device gets (gpu), wall and device time (gpu.json)
#   gpu_bench_software  the same cases that decide the shape, in the software shape (gpu_software.json)
#   peer                the original app's views beside its own shaders (peer.json; PEER_DIR)
#   report              the quick `flatmarch report` without webgl or images: ranks both GPU backends
#                       on the GPU (report/results.json)
#   device_paths        both kernel shapes march alike on the default devices (Vulkan validated)
#   opengl_test, vulkan_test, simd_bench
# Everything printed goes to OUT_DIR/log.txt too; the JSON is read by bench/side_by_side.py,
# bench/peer_ratios.py, bench/speedups.py and `flatmarch report RESULTS`. Exits 1 if a step failed.
#
# Usage: ci/gpu_check.sh [--budget SECONDS] (BUILD_DIR | --bundle DEST) OUT_DIR [PEER_DIR]
#   --bundle DEST: the programs packed by ci/gpu_bundle.sh (a machine that installs nothing):
#   unpacked, with DEST's loaders and validation layer, before the checks. On the device tool:
#     ci/gpu_bundle.sh build-release .gpu   # here, once; `.gpu` in .git/info/exclude
#     run(command="ci/gpu_check.sh --bundle .gpu $OUT [PEER_DIR]", carry=[".gpu"], timeout_s=600)
set -uo pipefail
budget=560 bundle=""
while (($#)); do
  case $1 in
    --budget) budget=${2:?}; shift 2 ;;
    --bundle) bundle=${2:?}; shift 2 ;;
    *) break ;;
  esac
done
if { [[ -n $bundle ]] && (($# < 1)); } || { [[ -z $bundle ]] && (($# < 2)); }; then
  echo "usage: ci/gpu_check.sh [--budget SECONDS] (BUILD_DIR | --bundle DEST) OUT_DIR [PEER_DIR]" >&2
  exit 2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
if [[ -n $bundle ]]; then
  build=/tmp/flatmarch-gpu/build
else
  build=$(cd "$1" && pwd) || exit 2
  shift
fi
out=$1 peer=${2:-}
mkdir -p "$out" || exit 2
out=$(cd "$out" && pwd)
exec > >(tee "$out/log.txt") 2>&1
cd "$root" || exit 2
started=$SECONDS

if [[ -n $bundle ]]; then
  rm -rf /tmp/flatmarch-gpu && mkdir -p /tmp/flatmarch-gpu &&
    tar -C /tmp/flatmarch-gpu -xJf "$bundle/bundle.tar.xz" || exit 2
  for deb in "$bundle"/debs/*.deb; do dpkg -x "$deb" /; done
  ldconfig
  export LD_LIBRARY_PATH=/tmp/flatmarch-gpu/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  # The programs find the scenes through the source folder they were built in.
  source_dir=$(cat /tmp/flatmarch-gpu/source_dir)
  if [[ ! -d $source_dir/scenes ]]; then
    mkdir -p "$(dirname "$source_dir")" && ln -sfn "$root" "$source_dir"
  fi
fi
# NVIDIA's drivers where the loaders do not find them by themselves (as on the lent machines).
nvidia=/usr/local/nvidia/share
[[ -z ${VK_DRIVER_FILES:-} && -f $nvidia/vulkan/icd.d/nvidia_icd.json ]] &&
  export VK_DRIVER_FILES=$nvidia/vulkan/icd.d/nvidia_icd.json
[[ -z ${__EGL_VENDOR_LIBRARY_FILENAMES:-} && -f $nvidia/glvnd/egl_vendor.d/10_nvidia.json ]] &&
  export __EGL_VENDOR_LIBRARY_FILENAMES=$nvidia/glvnd/egl_vendor.d/10_nvidia.json

failed=() skipped=()
step() {  # step NAME SECONDS COMMAND...: one check under a time limit, if the budget holds it
  local name=$1 limit=$2 start=$SECONDS rc
  shift 2
  if ((SECONDS - started + limit > budget)); then
    echo "==== $name: skipped, $((budget - SECONDS + started)) s of the budget left for its $limit"
    skipped+=("$name")
    return
  fi
  echo "==== $name"
  timeout --kill-after=10 "$limit" "$@"
  rc=$?
  echo "---- $name: $( ((rc == 0)) && echo ok || echo "FAILED ($rc$( ((rc == 124)) && echo ", over ${limit} s"))") in $((SECONDS - start)) s"
  ((rc == 0)) || failed+=("$name")
}

flatmarch=$build/cli/flatmarch
brief=(--gtest_brief=1)
# The cases that decide the OpenGL backend's shape on a GPU: the fixed cost, the L-shape analytic,
# sphere tracing in the rooms and prisms where the fragment shader lost most.
deciding='^(fixed/|(opengl|vulkan)/(sphere|analytic)/(l_shape|double_pentagon|cube|l_shape_prism|double_pentagon_prism)/1920x1080)'

step machine 15 bash -c 'nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>&1;
  lscpu | grep -E "^(Model name|CPU\(s\)|Flags)" | cut -c1-160'
step devices 30 "$flatmarch" backends
step gpu_bench 150 "$build/bench/gpu_bench" --benchmark_min_time=0.1 \
  --benchmark_filter='^(fixed/|(opengl|vulkan)/.*/1920x1080)' \
  --benchmark_out="$out/gpu.json" --benchmark_out_format=json
step gpu_bench_software 70 "$build/bench/gpu_bench" --kernel-shape=software --benchmark_min_time=0.1 \
  --benchmark_filter="$deciding" --benchmark_out="$out/gpu_software.json" --benchmark_out_format=json
if [[ -n $peer ]]; then
  step peer 60 "$build/bench/gpu_bench" --peer-shaders="$peer" --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true --benchmark_filter='^peer/' \
    --benchmark_out="$out/peer.json" --benchmark_out_format=json
fi
step report 200 "$flatmarch" report --skip-backend webgl --no-html -q -o "$out/report"
step device_paths 45 env FLATMARCH_VULKAN_VALIDATION=1 \
  "$build/conformance/tests/device_paths_test" "${brief[@]}" --gtest_filter='*Shapes*'
step opengl_test 40 "$build/backends/opengl/tests/opengl_test" "${brief[@]}"
step vulkan_test 40 env FLATMARCH_VULKAN_VALIDATION=1 "$build/backends/vulkan/tests/vulkan_test" \
  "${brief[@]}"
step simd_bench 90 "$build/bench/simd_bench" \
  --benchmark_filter='/(l_shape|double_pentagon|cube|staircase_32)/' --benchmark_min_time=0.1 \
  --benchmark_out="$out/simd.json" --benchmark_out_format=json

echo
echo "gpu_check: $((SECONDS - started)) s of a ${budget} s budget${skipped:+; skipped: ${skipped[*]}}"
if ((${#failed[@]})); then
  echo "gpu_check: FAILED: ${failed[*]}"
  exit 1
fi
echo "gpu_check: every step run passed"
