#!/bin/bash
# Runs flatmarch's main job (`report`) or the conformance run (`conform`) across a Slurm cluster
# (issue 24): a job array of N shards, each `flatmarch JOB --shard I/N` (report.sbatch,
# conform.sbatch), and a merge job that depends on the whole array (--dependency=afterok) and
# puts the shards together (merge.sbatch): OUT/results.json, OUT/images and OUT/index.html for a
# report, OUT/conform.json for conform, as one unsharded run writes them.
#
#   ci/slurm/submit.sh JOB N OUT [options of flatmarch JOB...]
#   ci/slurm/submit.sh report 8 results/cluster --full
#   ci/slurm/submit.sh conform 4 results/conform --backend simd --size 320x180
#
# FLATMARCH is the program (default: build/cli/flatmarch); OUT must be on a file system every
# node sees. FLATMARCH_BASELINE (a report's): the merge gates against this baseline (exit 1 on a
# regression, the merge job FAILED). sbatch's own settings come from its environment
# (SBATCH_PARTITION, SBATCH_ACCOUNT, SBATCH_TIMELIMIT, ...). Prints the array's and the merge's
# job ids; `squeue --me` follows them, OUT/shard-I.log and OUT/merge.log say what each did.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
usage="usage: $0 report|conform N OUT [options...]  (N from 1 to 1000 shards)"
if (($# < 3)) || [[ $1 != report && $1 != conform ]]; then
  echo "$usage" >&2
  exit 2
fi
if ! [[ $2 =~ ^[1-9][0-9]*$ ]] || (($2 > 1000)); then
  echo "$usage" >&2
  exit 2
fi
job=$1 shards=$2 out=$3
shift 3
flatmarch=$(realpath "${FLATMARCH:-$here/../../build/cli/flatmarch}")
[[ -x $flatmarch ]] || { echo "$0: no flatmarch program at $flatmarch (set FLATMARCH)" >&2; exit 2; }
mkdir -p "$out"
out=$(realpath "$out")
rm -rf "$out"/shard-* "$out/conform.json" "$out/results.json" "$out/images" "$out/index.html"
export FLATMARCH=$flatmarch FLATMARCH_OUT=$out
array=$(sbatch --parsable --array="1-$shards" --output="$out/shard-%a.log" \
  "$here/$job.sbatch" "$@")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterok:$array" --output="$out/merge.log" \
  "$here/merge.sbatch" "$job")
merge=${merge%%;*}
echo "array $array merge $merge"
