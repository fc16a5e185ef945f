#!/usr/bin/env bash
# Installs the Debian packages that are missing. Usage: ci/install-deps.sh [main|test]
#   main: what `flatmarch` needs to build and run (ci/packages.txt): ci/main.sh's
#   test (the default): that and what the test suite needs (ci/packages-test.txt): ci/test.sh's
# Idempotent: when everything is installed it changes nothing and needs no network.
set -euo pipefail
cd "$(dirname "$0")"
lists=(packages.txt)
case ${1:-test} in
  main) ;;
  test) lists+=(packages-test.txt) ;;
  *) echo "usage: ci/install-deps.sh [main|test]" >&2; exit 2 ;;
esac

mapfile -t packages < <(cat "${lists[@]}" | grep -v '^\s*#' | grep -v '^\s*$')
missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ $status == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo=()
((EUID == 0)) || sudo=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -q
"${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
