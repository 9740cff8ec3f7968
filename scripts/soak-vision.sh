#!/bin/sh
# The long-running vision soak: hand-regard envs rendering both eyes on a
# thread pool while evaluation envs with video renderers are built, run and freed beside them,
# the pattern that crashed in libOSMesa. Every stage must finish (exit 0).
#
#   scripts/soak-vision.sh [OUT]            500,000 env steps with 2 envs on 2 threads, then with
#                                           4 envs on 2 threads, an evaluation with video every
#                                           100,000 steps and at the end of each
#   STEPS=50000 scripts/soak-vision.sh      a shorter run
#   TRAIN=1 scripts/soak-vision.sh          also the run that crashed: PPO + hand_visibility,
#                                           300,000 steps on 2 envs, evaluation and random baseline
#
# About 1 h per 500,000-step stage on 2 idle cores (≈150-250 env steps/s with vision).
set -eu
cd "$(dirname "$0")/.."
CRADLE=${CRADLE:-build/cradle}
OUT=${1:-results/soak}
STEPS=${STEPS:-500000}
EVERY=${EVERY:-100000}
CONFIG=configs/config_handregard.yml

for envs in 2 4; do
  echo "== soak: $STEPS steps, $envs envs on 2 threads"
  "$CRADLE" soak --config "$CONFIG" --save-dir "$OUT/envs$envs" --steps "$STEPS" --envs "$envs" \
    --threads 2 --eval-every "$EVERY" --eval-episodes 1
done
if [ "${TRAIN:-0}" = 1 ]; then
  echo "== soak: PPO + hand_visibility, 300,000 steps on 2 envs"
  "$CRADLE" train --config "$CONFIG" --save-dir "$OUT/train" --algo ppo \
    --intrinsic hand_visibility --steps 300000 --envs 2 --eval-episodes 5 --no-eval-video \
    --compare-random --seed 0
fi
echo "== soak passed"
