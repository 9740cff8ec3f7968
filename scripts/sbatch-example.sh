#!/usr/bin/env bash
# Data-parallel Cradle training on several nodes with Slurm (docs/distributed.md):
#   sbatch scripts/sbatch-example.sh
# One task per rank; each rank runs its own vector of envs (--envs) on --cpus-per-task cores.
# srun sets SLURM_NTASKS, SLURM_PROCID and SLURM_JOB_NODELIST; `cradle train --distributed`
# reads them (rank 0 on the first node is the master, port 20000 + job id % 10000 unless
# MASTER_PORT is set). save_dir must be on a file system every node sees (rank 0 writes the
# checkpoints; every rank reads them on --resume).
#SBATCH --job-name=cradle-dist
#SBATCH --nodes=4
#SBATCH --ntasks-per-node=2
#SBATCH --cpus-per-task=8
#SBATCH --time=24:00:00
#SBATCH --output=cradle-dist-%j.out
#SBATCH --signal=TERM@120
set -euo pipefail

CRADLE=${CRADLE:-cradle}
CONFIG=${CONFIG:-configs/config_selftouch.yml}
SAVE_DIR=${SAVE_DIR:-$PWD/results/dist_$SLURM_JOB_ID}
RESUME=()
# A requeued or resubmitted job continues from its last checkpoint.
if [ -e "$SAVE_DIR/checkpoints/latest.ckpt" ]; then RESUME=(--resume); fi

# --signal=TERM@120: Slurm warns every rank 2 minutes before the time limit; the ranks agree to
# stop at the next update, rank 0 writes a final checkpoint and every rank exits 130: Slurm records
# the job as FAILED, not COMPLETED, and resubmitting it resumes.
srun --kill-on-bad-exit=1 "$CRADLE" train --distributed \
  --config "$CONFIG" --save-dir "$SAVE_DIR" \
  --algo ppo --envs "$SLURM_CPUS_PER_TASK" --steps 50000000 \
  --checkpoint-every 1000000 --dist-timeout 300 "${RESUME[@]}"
