#!/usr/bin/env bash
# Runs one hairbench command (compare, sweep or stress) as a Slurm job array, one shard
# per array task, then merges the shards' reports in a job that starts only when every
# task has succeeded (--dependency=afterok). Copy it next to your checkout's build.
#
#   ci/slurm-sweep.sh N OUT_DIR SUBCOMMAND [ARGS...]
#   e.g. ci/slurm-sweep.sh 8 /scratch/sweep1 sweep --scenario shake --knob substeps=3,6,12
#
# Task i (SLURM_ARRAY_TASK_ID 0 to N-1) runs `hairbench SUBCOMMAND ARGS... --shard
# i+1/N --no-charts --out OUT_DIR/shard-(i+1)`; the merge job runs `hairbench merge
# OUT_DIR/merged` on their reports and draws the charts (OUT_DIR/merged/report.html).
# Logs go to OUT_DIR/logs. Every task runs the same binary: shards of different builds
# are refused by the merge.
#
# Environment: HAIRBENCH, the binary (default: build/release/hairbench beside this
# script); SBATCH_OPTIONS, extra sbatch options for every job (partition, account, time
# limit, e.g. "--partition=cpu --time=01:00:00"); HAIRBENCH_MERGE_OPTIONS, extra merge
# options (e.g. --mix-machines). Prints the two job ids.
set -euo pipefail

usage() {
  echo "usage: ci/slurm-sweep.sh N OUT_DIR compare|sweep|stress [ARGS...]" >&2
  exit 2
}

# Inside the jobs (sbatch runs a copy of this script, so every path arrives absolute).
if [ "${1:-}" = "--task" ]; then
  shift
  count=$1 out=$2 exe=$3
  shift 3
  index=$((SLURM_ARRAY_TASK_ID + 1))
  exec srun "$exe" "$@" --shard "$index/$count" --no-charts --out "$out/shard-$index"
fi
if [ "${1:-}" = "--merge" ]; then
  count=$2 out=$3 exe=$4
  reports=()
  for ((i = 1; i <= count; i++)); do
    for name in report.json stress.json; do
      if [ -f "$out/shard-$i/$name" ]; then reports+=("$out/shard-$i/$name"); fi
    done
  done
  # A shard that wrote nothing is named by the merge, which refuses the missing runs.
  # shellcheck disable=SC2086  # HAIRBENCH_MERGE_OPTIONS holds separate options
  exec srun "$exe" merge "$out/merged" ${HAIRBENCH_MERGE_OPTIONS:-} "${reports[@]}"
fi

[ $# -ge 3 ] || usage
count=$1 out=$2
case "$count" in '' | *[!0-9]* | 0) echo "ci/slurm-sweep.sh: N must be a whole number >= 1, not '$count'" >&2; exit 2 ;; esac
case "$3" in compare | sweep | stress) ;; *) echo "ci/slurm-sweep.sh: '$3' has no --shard (compare, sweep or stress)" >&2; exit 2 ;; esac
shift 2
here="$(cd "$(dirname "$0")" && pwd)"
exe="${HAIRBENCH:-$here/../build/release/hairbench}"
[ -x "$exe" ] || { echo "ci/slurm-sweep.sh: no hairbench binary at $exe (build it: ci/build release, or set HAIRBENCH)" >&2; exit 2; }
exe="$(cd "$(dirname "$exe")" && pwd)/$(basename "$exe")"
mkdir -p "$out/logs"
out="$(cd "$out" && pwd)"
# The plan first: a bad command fails here, once, instead of in N tasks.
"$exe" "$@" --shard "1/$count" --plan >"$out/plan.txt"

# shellcheck disable=SC2086  # SBATCH_OPTIONS holds separate options
shards=$(sbatch --parsable ${SBATCH_OPTIONS:-} --job-name=hairbench-shard --array="0-$((count - 1))" \
  --output="$out/logs/shard-%a.out" "$here/slurm-sweep.sh" --task "$count" "$out" "$exe" "$@")
shards=${shards%%;*}  # --parsable prints JOBID or JOBID;CLUSTER
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTIONS:-} --job-name=hairbench-merge --dependency="afterok:$shards" \
  --output="$out/logs/merge.out" "$here/slurm-sweep.sh" --merge "$count" "$out" "$exe")
merge=${merge%%;*}
echo "shards: job $shards (array 0-$((count - 1))), merge: job $merge after them; plan in $out/plan.txt," \
  "report in $out/merged/report.html"
