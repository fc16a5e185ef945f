#!/bin/bash
# Runs `flatmarch conform` across a Slurm cluster (issue 24): a job array of N shards, each
# `conform --shard I/N`, and a merge job that depends on the whole array (afterok) and writes
# OUT/conform.json, as one unsharded run writes it.
#
#   ci/slurm/submit.sh N OUT [conform options...]
#   ci/slurm/submit.sh 8 results/conform --backend simd --size 320x180
#
# FLATMARCH is the program (default: build/cli/flatmarch); OUT must be on a file system every
# node sees. sbatch's own settings come from its environment (SBATCH_PARTITION, SBATCH_ACCOUNT,
# SBATCH_TIMELIMIT, ...). Prints the array's and the merge's job ids; `squeue --me` follows them.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if (($# < 2)) || ! [[ $1 =~ ^[1-9][0-9]*$ ]] || (($1 > 1000)); then
  echo "usage: $0 N OUT [conform options...]  (N from 1 to 1000 shards)" >&2
  exit 2
fi
shards=$1 out=$2
shift 2
flatmarch=$(realpath "${FLATMARCH:-$here/../../build/cli/flatmarch}")
[[ -x $flatmarch ]] || { echo "$0: no flatmarch program at $flatmarch (set FLATMARCH)" >&2; exit 2; }
mkdir -p "$out"
out=$(realpath "$out")
rm -f "$out"/shard-*.json "$out/conform.json"
export FLATMARCH=$flatmarch FLATMARCH_OUT=$out
array=$(sbatch --parsable --array="1-$shards" --output="$out/shard-%a.log" \
  "$here/conform.sbatch" "$@")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterok:$array" --output="$out/merge.log" \
  "$here/merge.sbatch")
merge=${merge%%;*}
echo "array $array merge $merge"
