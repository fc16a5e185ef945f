#!/usr/bin/env bash
# Packs what ci/gpu_check.sh runs on a GPU machine that installs nothing (the `device` tool's, lent
# for minutes): the programs of a Release build (flatmarch, gpu_bench, simd_bench and the GPU
# backends' test programs) with the three shared libraries they link beyond the C++ runtime
# (oneTBB, Highway, Google Benchmark), xz-compressed, and Debian's OpenGL, EGL and Vulkan loaders
# and Vulkan validation layer as .deb files (downloaded; amd64). No OpenImageIO: the report and
# conform measure without it (images left out).
#
# Usage: ci/gpu_bundle.sh BUILD_DIR DEST        (a Release build with the tests and benchmarks:
#   ci/build.sh build-gpu -DCMAKE_BUILD_TYPE=Release && ci/gpu_bundle.sh build-gpu .gpu)
# Then, on the GPU machine, from the repository root with DEST carried:
#   ci/gpu_check.sh --bundle DEST OUT_DIR [PEER_DIR]
set -euo pipefail
if (($# != 2)); then
  echo "usage: ci/gpu_bundle.sh BUILD_DIR DEST" >&2
  exit 2
fi
build=$(cd "$1" && pwd) dest=$2
root=$(cd "$(dirname "$0")/.." && pwd)
programs=(cli/flatmarch bench/gpu_bench bench/simd_bench backends/opengl/tests/opengl_test
  backends/vulkan/tests/vulkan_test conformance/tests/device_paths_test)
for p in "${programs[@]}"; do
  [[ -x $build/$p ]] || { echo "gpu_bundle: $build/$p is not built" >&2; exit 2; }
done
mkdir -p "$dest/debs"
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
for p in "${programs[@]}"; do
  mkdir -p "$stage/build/$(dirname "$p")"
  strip -o "$stage/build/$p" "$build/$p"
done
# The program finds its data beside its folder (build/share/flatmarch, links into the source
# tree here: copied whole), as an installed one does.
cp -rL "$build/share" "$stage/build/"
mkdir -p "$stage/lib"
for lib in $(ldd "$build/cli/flatmarch" "$build/bench/gpu_bench" | awk '/libtbb|libhwy|libbenchmark/ {print $3}' | sort -u); do
  cp -L "$lib" "$stage/lib/"
done
# The test programs and gpu_bench find the scenes through the source folder compiled into them.
grep -m1 '^CMAKE_HOME_DIRECTORY:INTERNAL=' "$build/CMakeCache.txt" | cut -d= -f2 > "$stage/source_dir"
tar -C "$stage" -cJf "$dest/bundle.tar.xz" .
# The loaders the backends open at run time, and the validation layer the Vulkan tests run under.
lists=$(mktemp -d)
opts=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists"
  -oAPT::Sandbox::User=root)
mkdir -p "$lists/partial"
apt-get "${opts[@]}" update -qq
(cd "$dest/debs" && apt-get "${opts[@]}" download -qq libvulkan1 libegl1 libglvnd0 libopengl0 \
  libgl1 libglx0 libgles2 vulkan-validationlayers)
rm -rf "$lists"
echo "gpu_bundle: $(du -sh "$dest" | cut -f1) in $dest (from $root's build $build)"
