#!/bin/bash
# Runs an egress batch on a Slurm cluster: one job-array task per shard, then a merge job.
#
#   deploy/slurm/egress-batch.sh --shards N --out DIR [--cpus C] [--partition P] [--wait]
#       [--egress PATH] -- SCENARIO.yaml... --trials T [--seed-base S]
#
# DIR must be on a file system every node sees. Prints the two job ids; with --wait, blocks
# until the merge has finished and prints its table (DIR/merged/batch.json, trials.csv).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
shards="" out="" cpus=1 partition="" wait=0
egress_bin=$(cd "$here/../.." && pwd)/build/apps/egress
die() { echo "egress-batch.sh: error: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --shards) shards=${2:?}; shift 2 ;;
    --out) out=${2:?}; shift 2 ;;
    --cpus) cpus=${2:?}; shift 2 ;;
    --partition) partition=${2:?}; shift 2 ;;
    --egress) egress_bin=${2:?}; shift 2 ;;
    --wait) wait=1; shift ;;
    --) shift; break ;;
    *) die "unknown option '$1' (the batch's own arguments go after --)" ;;
  esac
done
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || die "--shards N (a positive integer) is required"
[[ "$cpus" =~ ^[1-9][0-9]*$ ]] || die "--cpus must be a positive integer"
[ -n "$out" ] || die "--out DIR is required"
[ $# -gt 0 ] || die "no scenarios: pass them after --"
[ -x "$egress_bin" ] || die "no egress binary at '$egress_bin' (build it, or pass --egress)"
command -v sbatch > /dev/null || die "sbatch not found: is this a Slurm submit host?"
for a in "$@"; do
  case "$a" in --shard|--out|--resume|--jobs|-j) die "'$a' is set per shard by this script" ;; esac
done
mkdir -p "$out"
out=$(cd "$out" && pwd)
egress_bin=$(cd "$(dirname "$egress_bin")" && pwd)/$(basename "$egress_bin")
# Scenario paths must resolve on the nodes: make relative ones absolute.
args=()
for a in "$@"; do
  if [ -e "${a%%:*}" ] && [[ "$a" != /* ]]; then a=$(pwd)/$a; fi
  args+=("$a")
done
batch_args=$(IFS=$'\t'; echo "${args[*]}")
common=(--parsable --chdir "$out" --export "ALL,EGRESS_BIN=$egress_bin,EGRESS_OUT=$out,EGRESS_BATCH_ARGS=$batch_args")
[ -n "$partition" ] && common+=(--partition "$partition")
array=$(sbatch "${common[@]}" --array "1-$shards" --cpus-per-task "$cpus" \
  --output "$out/slurm-%A_%a.out" "$here/shard.sbatch")
array=${array%%;*}
merge_opts=(--dependency "afterok:$array" --output "$out/slurm-merge-%j.out")
[ "$wait" = 1 ] && merge_opts+=(--wait)
echo "shards: job array $array (1-$shards) -> $out/shard-*"
merge=$(sbatch "${common[@]}" "${merge_opts[@]}" "$here/merge.sbatch") || {
  echo "egress-batch.sh: the merge job failed: see $out/slurm-*.out" >&2; exit 1; }
merge=${merge%%;*}
echo "merge: job $merge -> $out/merged"
if [ "$wait" = 1 ]; then cat "$out/slurm-merge-$merge.out"; fi
