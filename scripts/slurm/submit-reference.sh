#!/bin/bash
# Renders a reference as N shards, one Slurm array task each, and merges them once all succeeded:
#   scripts/slurm/submit-reference.sh N DIR REF.exr [glint render options...]
# e.g. submit-reference.sh 64 shards ref.exr builtin:atelier --spp 16384 --size 960x540
# --spp is the whole reference's; each shard renders its share. Prints the two job ids. Extra
# sbatch options (a partition, a time limit) go in SBATCH_OPTIONS, e.g. "--partition=cpu --time=4:00:00".
set -eu
[ $# -ge 3 ] || { echo "usage: $0 N DIR REF.exr [glint render options...]" >&2; exit 2; }
n=$1 dir=$2 ref=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$dir"
# shellcheck disable=SC2086
shards=$(sbatch --parsable ${SBATCH_OPTIONS:-} --array="0-$((n - 1))" "$here/reference.sbatch" "$n" "$dir" "$@")
shards=${shards%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTIONS:-} --dependency="afterok:$shards" "$here/merge.sbatch" "$dir" "$ref")
echo "shards: job $shards (array 0-$((n - 1))), merge: job ${merge%%;*}"
