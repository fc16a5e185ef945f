#!/usr/bin/env bash
# The test suite: installs what is missing, builds with warnings as errors and runs every test
# (ctest); runs the unit tests again under AddressSanitizer + UndefinedBehaviorSanitizer, in a
# build without the GPU and browser backends; builds the scene parser fuzzers with clang and runs
# each for a bounded time. Exits non-zero if any stage fails; ends with the test runner's summary.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
fuzz_seconds=${FLATMARCH_FUZZ_SECONDS:-30}
# Mesa's drivers keep allocations for the life of a process; see ci/lsan.supp.
export LSAN_OPTIONS="suppressions=$root/ci/lsan.supp"

summaries=()
failed=0
stage() {  # stage NAME COMMAND...: runs one stage, records its time and outcome
  local name=$1 start=$SECONDS rc
  shift
  echo "==== $name"
  "$@"
  rc=$?
  summaries+=("$(printf '%-28s %4ds  %s' "$name" $((SECONDS - start)) "$([[ $rc == 0 ]] && echo ok || echo "FAILED ($rc)")")")
  ((rc == 0)) || failed=1
  return $rc
}

ctest_summary=()
run_ctest() {  # run_ctest BUILD_DIR [ctest arguments...]: keeps ctest's closing summary line
  local dir=$1 log junit
  shift
  log=$(mktemp)
  junit=$(mktemp)
  (cd "$dir" && ctest --output-on-failure -j 2 --output-junit "$junit" "$@") 2>&1 | tee "$log"
  local rc=${PIPESTATUS[0]}
  # LeakSanitizer's own tracer now and then crashes at exit after a test has passed (a sanitizer
  # flake, not a leak: ci/lsan_tracer_crashes.py). Where that is all that failed, those tests run
  # once more, and their second run decides.
  if ((rc != 0)) && python3 ci/lsan_tracer_crashes.py "$junit"; then
    echo "run_ctest: the failures above are LeakSanitizer's tracer crashing at exit; once more:"
    (cd "$dir" && ctest --output-on-failure -j 2 --rerun-failed "$@") 2>&1 | tee "$log"
    rc=${PIPESTATUS[0]}
  fi
  rm -f "$junit"
  ctest_summary+=("$dir: $(grep -E 'tests passed|tests failed' "$log" | tail -n 1)")
  rm -f "$log"
  return $rc
}

# The fuzzers run side by side (one a core: each is one process), each for fuzz_seconds; their
# output is shown in turn afterwards.
run_fuzzers() {
  local dir=build-fuzz fuzzer rc=0 k=0
  local -a pids logs corpora
  for fuzzer in "$dir"/*/*_fuzzer; do
    corpora[k]=$(mktemp -d)
    logs[k]=$(mktemp)
    for seed in scenes/*.json tests/data/*/*.json; do cp "$seed" "${corpora[k]}/$(basename "$(dirname "$seed")")-$(basename "$seed")"; done
    echo "-- $(basename "$fuzzer") for ${fuzz_seconds}s" > "${logs[k]}"
    "$fuzzer" -max_total_time="$fuzz_seconds" -max_len=16384 -timeout=10 -rss_limit_mb=2048 \
      -print_final_stats=1 "${corpora[k]}" >> "${logs[k]}" 2>&1 &
    pids[k]=$!
    k=$((k + 1))
  done
  for ((k = 0; k < ${#pids[@]}; ++k)); do
    wait "${pids[k]}" || rc=1
    head -n 1 "${logs[k]}"
    grep -E '^(#|INFO: Running|stat::number_of_executed|==|SUMMARY|ERROR)' "${logs[k]}" | tail -n 8
    rm -rf "${corpora[k]}" "${logs[k]}"
  done
  return $rc
}

stage "install dependencies" ci/install-deps.sh || exit 1
# No debug information in this build, and -O1 (as RelWithDebInfo): -g was a third of the compile
# time and nothing here reads it; -O1 compiled this build in 966 CPU-seconds against -O2's 1274
# (packet.cpp 97 s against 196, scalar_f64.cpp 18 against 37) and its tests ran about as long
# (ctest 625-636 s in three runs against 617; the SIMD backend's cases slower, the browsers' as
# before), 2-core Zen 5. The Release build users run (-O3, packet.cpp -O2) is not this one:
# docs/tests.md.
stage "build (-Werror)" ci/build.sh build -DFLATMARCH_WERROR=ON "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -DNDEBUG" \
  && stage "ctest" run_ctest build
# Only what `ctest -L unit` runs (the unit_tests target): the benchmark programs and the other
# test programs took a sixth of this build's compile time. Built with Clang: it compiles this
# build in two thirds of GCC's time (scalar_f32.cpp 41 s against 76 s), its programs run the
# tests in about four fifths of GCC's time (388 s against 469 s in CI), and its warnings, as
# errors, are a second compiler's read of the code beside GCC's in the stage above.
# LeakSanitizer with use_tls=0: its tracer crashes scanning the thread-local storage of libraries
# loaded by dlopen (OpenImageIO's, through flatmarch_image.so), and loading them with every
# program instead made each process 0.65 s slower to start (output/CMakeLists.txt). Without TLS
# as a root nothing is missed, only more reported: what system libraries keep there is
# suppressed by library in ci/lsan.supp.
sanitized_ctest() { LSAN_OPTIONS="$LSAN_OPTIONS:use_tls=0" run_ctest "$@"; }
# The same build is the project without its GPU and browser backends (FLATMARCH_WITH_OPENGL,
# _VULKAN and _WEBGL off): it builds, and its unit tests pass with the oracle, the scalar and the
# SIMD backends alone registered. It used to be a build of its own, without the SIMD backend too
# (5 minutes of the CI's 37 on 2 cores); the GPU backends' host code, drawing on Mesa's software
# drivers, which are not instrumented, is tested in the first build, Vulkan's under the
# validation layers. docs/tests.md says how to build without the SIMD backend as well. Without
# line tables (FLATMARCH_SANITIZE_LINES=OFF: a fifth of this build's compile time): a report here
# names each frame's function and library; rebuild with them for its files and lines.
stage "build (ASan+UBSan, no GPU backends)" env CC=clang CXX=clang++ \
  ci/build.sh build-asan --target unit_tests -DFLATMARCH_WERROR=ON -DFLATMARCH_SANITIZE=ON \
  -DFLATMARCH_SANITIZE_LINES=OFF \
  -DFLATMARCH_WITH_OPENGL=OFF -DFLATMARCH_WITH_VULKAN=OFF -DFLATMARCH_WITH_WEBGL=OFF \
  && stage "ctest -L unit (ASan+UBSan)" sanitized_ctest build-asan -L unit
stage "build (fuzzers, clang)" env CC=clang CXX=clang++ ci/build.sh build-fuzz -DFLATMARCH_FUZZ=ON \
  && stage "fuzz (${fuzz_seconds}s each)" run_fuzzers

echo
echo "==== summary"
printf '%s\n' "${summaries[@]}"
# CI machines have little disk (a sanitizer build that linked every test whole filled one).
echo "disk: $(du -sh build build-asan build-fuzz 2>/dev/null | awk '{printf "%s %s  ", $2, $1}')"
if ((failed)); then
  printf '%s\n' "${ctest_summary[@]}"
  echo "test.sh: FAILED (see the stages above)"
  exit 1
fi
echo "test.sh: all stages passed"
printf '%s\n' "${ctest_summary[@]}"
