#!/usr/bin/env bash
# Submit a morphosys sweep plan to Slurm: one array task per line of
# PLAN/jobs.txt, then `morphosys sweep --merge PLAN` once every task ended
# (whether or not it succeeded: the merge names the missing points).
#   docs/cluster/submit.sh PLAN [extra sbatch options, e.g. --partition=short]
# Prints the array job's id and the merge job's id. docs/cluster.md.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
plan=$(cd "${1:?usage: submit.sh PLAN_DIR [sbatch options]}" && pwd)
shift
n=$(grep -c . "$plan/jobs.txt")
# The morphosys that wrote the plan (its jobs run it) merges it too.
program=$(sed -n 's/^program = "\(.*\)"$/\1/p' "$plan/sweep.toml")
mkdir -p "$plan/slurm"
array=$(sbatch --parsable --array="1-$n" --output="$plan/slurm/%A_%a.out" "$@" \
  "$here/sweep-array.sbatch" "$plan")
merge=$(sbatch --parsable --dependency="afterany:$array" --job-name=morphosys-merge \
  --output="$plan/slurm/merge-%j.out" "$@" --wrap "'$program' sweep --merge '$plan'")
echo "array job $array ($n tasks), merge job $merge; logs in $plan/slurm/"
