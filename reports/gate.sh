#!/usr/bin/env bash
# The regression gate: measures the deterministic figures (steps, crossings, conformance rates of
# every backend x method x gallery scene; timings too, which only warn) and checks them against
# reports/baseline.json. `reports/gate.sh --write` measures the same way and writes the baseline
# instead: do it on purpose, in a commit that says why the figures changed.
#   reports/gate.sh [--write] [FLATMARCH [OUT]]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
write=0
if [[ ${1:-} == --write ]]; then
  write=1
  shift
fi
flatmarch=${1:-$root/build/cli/flatmarch}
out=${2:-$root/build/gate}
cd "$root"
# webgl is left out: Chromium compiles each of its pages' shaders for seconds on SwiftShader (3
# minutes more on 2 cores); the web_export and gallery conformance tests hold it to the oracle.
# Three repetitions: the timings only warn, and a case slower in all three than in all of the
# baseline's still does (Mann-Whitney p = 0.037 against five); alone on 2 cores 118 s -> 102 s.
# Frames of 96x54: every figure the gate holds is deterministic at any size, and the suite's
# gallery tests judge each case's verdict at 160x90; alone on 2 cores 132 s -> 84 s.
options=(report --no-sweep --no-scaling --no-html -q --size 96x54 --conform-size 96x54
         --repetitions 3 --min-time 0.01 --skip-backend webgl -o "$out")
if ((write)); then
  "$flatmarch" "${options[@]}" --write-baseline reports/baseline.json
else
  "$flatmarch" "${options[@]}" --baseline reports/baseline.json
fi
