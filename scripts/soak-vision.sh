#!/bin/sh
# The long-running vision soak: hand-regard envs rendering both eyes on a
# thread pool while evaluation envs with video renderers are built, run and freed beside them,
# the pattern that crashed in libOSMesa. Every stage must finish (exit 0).
#
#   scripts/soak-vision.sh [OUT]            500,000 env steps with 2 envs on 2 threads, then with
#                                           4 envs on 2 threads, then 4 envs in 4 worker
#                                           processes, an evaluation with video every 100,000
#                                           steps and at the end of each
#   STAGES=procs scripts/soak-vision.sh     only the process stage (STAGES=threads: only those)
#   STEPS=50000 scripts/soak-vision.sh      a shorter run
#   TRAIN=1 scripts/soak-vision.sh          also the run that crashed: PPO + hand_visibility,
#                                           300,000 steps on 2 envs, evaluation and random baseline
#
# About 1 h per 500,000-step stage on threads on 2 idle cores (≈150-250 env steps/s with vision),
# about 20 min in processes (≈450-500).
set -eu
cd "$(dirname "$0")/.."
CRADLE=${CRADLE:-build/cradle}
OUT=${1:-results/soak}
STEPS=${STEPS:-500000}
EVERY=${EVERY:-100000}
CONFIG=configs/config_handregard.yml

STAGES=${STAGES:-threads procs}

case " $STAGES " in *" threads "*)
  for envs in 2 4; do
    echo "== soak: $STEPS steps, $envs envs on 2 threads"
    "$CRADLE" soak --config "$CONFIG" --save-dir "$OUT/envs$envs" --steps "$STEPS" \
      --envs "$envs" --threads 2 --eval-every "$EVERY" --eval-episodes 1
  done
esac
case " $STAGES " in *" procs "*)
  echo "== soak: $STEPS steps, 4 envs in 4 worker processes"
  "$CRADLE" soak --config "$CONFIG" --save-dir "$OUT/procs4" --steps "$STEPS" --envs 4 \
    --procs 4 --eval-every "$EVERY" --eval-episodes 1
esac
if [ "${TRAIN:-0}" = 1 ]; then
  echo "== soak: PPO + hand_visibility, 300,000 steps on 2 envs"
  "$CRADLE" train --config "$CONFIG" --save-dir "$OUT/train" --algo ppo \
    --intrinsic hand_visibility --steps 300000 --envs 2 --eval-episodes 5 --no-eval-video \
    --compare-random --seed 0
fi
echo "== soak passed"
