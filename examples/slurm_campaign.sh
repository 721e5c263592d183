#!/usr/bin/env bash
# Run a campaign manifest as SLURM job arrays: each array task runs one
# manifest task, `mmtrack process manifest <manifest> -o <tables> --task N`
# (the same code a local `mmtrack process manifest` runs for that task), so
# the tables are byte-identical to a local run.
#
#   examples/slurm_campaign.sh --submit campaign.toml out/tables
#       submits one job array per level of `--print-levels` (ingest before
#       process before analyze, as the tasks' `needs` say), each starting
#       after the previous level succeeded (--dependency=afterok). A level
#       of more tasks than SLURM's MaxArraySize (default 1001; set
#       MMTRACK_MAX_ARRAY_SIZE to your cluster's) is split into several
#       arrays; each array's index picks a task of the list it is given. A
#       manifest that `--print-levels` refuses stops here (its exit code),
#       before anything is submitted;
#   sbatch --array=0-9 examples/slurm_campaign.sh campaign.toml out/tables
#       submits the tasks 0-9 yourself (a manifest without `needs`: one level).
#
# In the job, SLURM sets SLURM_ARRAY_TASK_ID (the manifest task, or with a
# third argument, the position in that comma-separated list of tasks) and
# SLURM_CPUS_PER_TASK (the threads of a task without its own --threads).
# Every task runs with --skip-existing: a re-submitted campaign skips the
# tasks that finished and redoes the ones a killed job left started (see
# docs/campaigns.md). Paths in the manifest are relative to the directory you
# submit from (sbatch runs the job there); the recordings and the tables must
# be on a file system every node sees. MMTRACK names the binary (default:
# mmtrack on PATH); MMTRACK_SBATCH_FLAGS adds sbatch flags in --submit.
#
#SBATCH --job-name=mmtrack-campaign
#SBATCH --cpus-per-task=4
#SBATCH --output=mmtrack-campaign-%A_%a.log
set -euo pipefail

mmtrack=${MMTRACK:-mmtrack}

usage="usage: sbatch --array=... $0 <manifest.toml> <tables> [<tasks>]  (or: $0 --submit <manifest.toml> <tables>)"

if [[ ${1:-} == --submit ]]; then
    if [[ $# -ne 3 ]]; then
        echo "$usage" >&2
        exit 2
    fi
    manifest=$2 tables=$3
    max_array=${MMTRACK_MAX_ARRAY_SIZE:-1001}
    if ! [[ $max_array =~ ^[1-9][0-9]*$ ]]; then
        echo "error: MMTRACK_MAX_ARRAY_SIZE '$max_array': expected a positive whole number" >&2
        exit 2
    fi
    # Read whole before submitting: a manifest `--print-levels` refuses ends
    # the script with its exit code (a process substitution would hide it).
    levels=$("$mmtrack" process manifest "$manifest" --print-levels)
    previous=
    while read -r level; do
        [[ -n $level ]] || continue
        dependency=${previous:+--dependency=afterok:$previous}
        IFS=, read -r -a ids <<<"$level"
        jobs=
        # At most max_array tasks per array, indices 0..n-1 (below MaxArraySize).
        for ((first = 0; first < ${#ids[@]}; first += max_array)); do
            chunk=("${ids[@]:first:max_array}")
            tasks=$(IFS=,; echo "${chunk[*]}")
            # shellcheck disable=SC2086  # MMTRACK_SBATCH_FLAGS holds several flags
            job=$(sbatch --parsable --array="0-$((${#chunk[@]} - 1))" $dependency ${MMTRACK_SBATCH_FLAGS:-} \
                "$0" "$manifest" "$tables" "$tasks")
            echo "submitted tasks $tasks as job $job"
            jobs=${jobs:+$jobs:}$job
        done
        previous=$jobs
    done <<<"$levels"
    exit 0
fi

if [[ $# -lt 2 || $# -gt 3 || -z ${SLURM_ARRAY_TASK_ID:-} ]]; then
    echo "$usage" >&2
    exit 2
fi
task=$SLURM_ARRAY_TASK_ID
if [[ $# -eq 3 ]]; then
    IFS=, read -r -a ids <<<"$3"
    if ! [[ $task =~ ^[0-9]+$ ]] || ((task >= ${#ids[@]})); then
        echo "error: array index $task: the task list '$3' has ${#ids[@]} tasks" >&2
        exit 2
    fi
    task=${ids[task]}
fi
exec "$mmtrack" process manifest "$1" -o "$2" --task "$task" \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --skip-existing
