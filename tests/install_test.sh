#!/usr/bin/env bash
# The install: `cmake --install` into a temporary prefix, then, from / with the source and build
# trees out of sight (a private mount namespace with empty folders over them, where the test may
# make one; else only the check that no installed file names them), the installed flatmarch's
# inspect, render and a tiny report; and `cpack -G DEB`'s package, its files and dependencies.
# Usage: install_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$(cd "${1:?usage: install_test.sh SOURCE_DIR BUILD_DIR}" && pwd)
build=$(cd "${2:?usage: install_test.sh SOURCE_DIR BUILD_DIR}" && pwd)
work=$(mktemp -d /tmp/flatmarch-install-XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() { echo "install_test: FAILED: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$work/prefix" > "$work/install.log" || fail "cmake --install"
for f in bin/flatmarch lib/flatmarch/flatmarch_image.so share/flatmarch/scenes/torus.json \
  share/flatmarch/conformance/thresholds.json share/flatmarch/conformance/scenes \
  share/flatmarch/reports/make_report.py share/flatmarch/reports/baseline.json \
  share/flatmarch/history/make_timeline.py share/flatmarch/history/timeline.html.j2; do
  [[ -e $work/prefix/$f ]] || fail "the install has no $f"
done
# No installed file may find its way back to the source or build tree.
for f in "$work/prefix/bin/flatmarch" "$work/prefix/lib/flatmarch/flatmarch_image.so"; do
  if grep -q -a -F -e "$src/" -e "$build/" "$f"; then
    fail "$f names the source or build tree: $(grep -a -o -F -e "$src/" -e "$build/" "$f" | head -n 1)"
  fi
done
echo "install_test: installed into $work/prefix; no installed program names $src or $build"

# The checks, run from / by the installed program alone.
cat > "$work/run.sh" << 'EOF'
set -euo pipefail
work=$1
flatmarch=$work/prefix/bin/flatmarch
cd /
"$flatmarch" inspect torus --compact | grep -q '"euler_characteristic":0' \
  || { echo "install_test: inspect torus did not say the torus's Euler characteristic" >&2; exit 1; }
"$flatmarch" render torus --backend scalar --size 64x36 -o "$work/out/torus.png" -q
[[ -s $work/out/torus.png ]] || { echo "install_test: render wrote no image" >&2; exit 1; }
"$flatmarch" report --scene torus --backend scalar --method analytic --size 32x18 \
  --conform-size 32x18 --no-sweep --no-scaling --min-time 0.001 --repetitions 2 -q \
  -o "$work/out/report" > "$work/out/report.log"
for f in results.json index.html; do
  [[ -s $work/out/report/$f ]] || { echo "install_test: the report wrote no $f" >&2; exit 1; }
done
grep -q 'ranking' "$work/out/report/results.json"
echo "install_test: inspect, render and report ran from / by $flatmarch"
EOF
mkdir -p "$work/out"
if unshare -m true 2> /dev/null; then
  # Empty folders over the trees, in a namespace of this test's own: the program cannot reach them.
  unshare -m bash -c "mount -t tmpfs tmpfs '$src' && { [[ '$build' == '$src'/* ]] || \
    mount -t tmpfs tmpfs '$build'; } && [[ ! -e '$src/CMakeLists.txt' ]] && \
    echo 'install_test: the source and build trees are hidden' && bash '$work/run.sh' '$work'" \
    || fail "the installed program, with the trees hidden"
else
  echo "install_test: no mount namespace here (unshare -m needs root): the trees stay in sight"
  bash "$work/run.sh" "$work" || fail "the installed program"
fi

# The Debian package: built from the same install rules, with the dependencies it declares.
if command -v dpkg-shlibdeps > /dev/null && command -v dpkg-deb > /dev/null; then
  (cd "$work" && cpack -G DEB --config "$build/CPackConfig.cmake" -B "$work/deb" > cpack.log 2>&1) \
    || { cat "$work/cpack.log"; fail "cpack -G DEB"; }
  deb=$(ls "$work"/deb/flatmarch_*.deb)
  contents=$(dpkg-deb -c "$deb")
  for f in ./usr/bin/flatmarch ./usr/lib/flatmarch/flatmarch_image.so \
    ./usr/share/flatmarch/scenes/torus.json ./usr/share/flatmarch/reports/make_report.py; do
    grep -q -F " $f" <<< "$contents" || fail "$(basename "$deb") has no $f"
  done
  depends=$(dpkg-deb -f "$deb" Depends)
  for d in libtbb libvulkan1 python3-matplotlib; do
    grep -q "$d" <<< "$depends" || fail "$(basename "$deb") does not depend on $d: $depends"
  done
  echo "install_test: $(basename "$deb"): $(wc -l <<< "$contents") entries; depends on $depends"
else
  echo "install_test: no dpkg-dev here: the .deb is not checked (ci/packages-test.txt installs it)"
fi
echo "install_test: passed"
