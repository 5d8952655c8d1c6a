#!/bin/bash
# Runs a bench plan on Slurm: one array task per line of DIR/jobs.txt (written by glint bench ...
# --jobs DIR), then glint bench --collect DIR once all succeeded:
#   scripts/slurm/submit-bench.sh DIR
# Extra sbatch options go in SBATCH_OPTIONS, as for submit-reference.sh.
set -eu
[ $# -eq 1 ] || { echo "usage: $0 DIR (a glint bench --jobs DIR)" >&2; exit 2; }
dir=$1
[ -s "$dir/jobs.txt" ] || { echo "glint: error: $dir/jobs.txt: missing or empty" >&2; exit 1; }
here=$(cd "$(dirname "$0")" && pwd)
n=$(wc -l <"$dir/jobs.txt")
# shellcheck disable=SC2086
runs=$(sbatch --parsable ${SBATCH_OPTIONS:-} --array="0-$((n - 1))" "$here/bench.sbatch" "$dir")
runs=${runs%%;*}
# shellcheck disable=SC2086
collect=$(sbatch --parsable ${SBATCH_OPTIONS:-} --dependency="afterok:$runs" --job-name=glint-collect \
  --output=glint-collect-%j.log --wrap="exec \"${GLINT:-glint}\" bench --collect \"$dir\"")
echo "runs: job $runs (array 0-$((n - 1))), collect: job ${collect%%;*}"
