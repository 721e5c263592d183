#!/usr/bin/env bash
# Run a campaign manifest as SLURM job arrays: each array task runs one
# manifest task, `mmtrack process manifest <manifest> -o <tables> --task N`
# (the same code a local `mmtrack process manifest` runs for that task), so
# the tables are byte-identical to a local run.
#
#   examples/slurm_campaign.sh --submit campaign.toml out/tables
#       submits one job array per level of `--print-levels` (ingest before
#       process before analyze, as the tasks' `needs` say), each starting
#       after the previous one succeeded (--dependency=afterok);
#   sbatch --array=0-9 examples/slurm_campaign.sh campaign.toml out/tables
#       submits the tasks 0-9 yourself (a manifest without `needs`: one level).
#
# In the job, SLURM sets SLURM_ARRAY_TASK_ID (the manifest task) and
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

if [[ ${1:-} == --submit ]]; then
    manifest=$2 tables=$3
    previous=
    while read -r level; do
        dependency=${previous:+--dependency=afterok:$previous}
        # shellcheck disable=SC2086  # MMTRACK_SBATCH_FLAGS holds several flags
        previous=$(sbatch --parsable --array="$level" $dependency ${MMTRACK_SBATCH_FLAGS:-} "$0" "$manifest" "$tables")
        echo "submitted tasks $level as job $previous"
    done < <("$mmtrack" process manifest "$manifest" --print-levels)
    exit 0
fi

if [[ $# -ne 2 || -z ${SLURM_ARRAY_TASK_ID:-} ]]; then
    echo "usage: sbatch --array=... $0 <manifest.toml> <tables>  (or: $0 --submit <manifest.toml> <tables>)" >&2
    exit 2
fi
exec "$mmtrack" process manifest "$1" -o "$2" --task "$SLURM_ARRAY_TASK_ID" \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --skip-existing
