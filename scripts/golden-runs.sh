#!/bin/bash
# Golden runs: seeded short PPO and A2C runs (cradle train on self-touch, cradle illustrate on
# reach) and seeded evaluations with videos (self-touch, hand regard). Prints a sha256 prefix of
# every output (checkpoints, progress.csv, logs, evaluation.json, plots, trajectories, videos),
# timing columns and keys left out. The same lines before and after a refactor = behaviour
# unchanged. Usage: scripts/golden-runs.sh CRADLE OUT_DIR
set -euo pipefail
cradle=${1:?usage: golden-runs.sh CRADLE OUT_DIR}
out=${2:?usage: golden-runs.sh CRADLE OUT_DIR}
config=$(dirname "$0")/../configs/config_selftouch.yml
rm -rf "$out"
mkdir -p "$out"
run() {
  local name=$1
  shift
  "$cradle" train --config "$config" --save-dir "$out/$name" --seed 7 --envs 2 --threads 2 \
    --eval-episodes 1 --no-eval-video "$@" >"$out/$name.log" 2>&1
}
run ppo --algo ppo --steps 1536 --checkpoint-every 512 --intrinsic '' \
  --hp n_steps=128 --hp batch_size=64 --hp n_epochs=2
run ppo_touch --algo ppo --steps 512 --hp n_steps=64 --hp batch_size=32 --hp n_epochs=1
run a2c --algo a2c --steps 1200 --checkpoint-every 600 --intrinsic '' --hp n_steps=5 \
  --hp normalize_advantage=true
# cradle illustrate trains into models/<env>/<name> under the current folder.
cradle=$(realpath "$cradle")
(cd "$out" && "$cradle" illustrate --env reach --algorithm PPO --train_for 768 --save_every 256 \
  --test_for 300 --envs 2 --seed 5 --hp n_steps=64 --hp batch_size=32 --hp n_epochs=2 \
  --save_model ppo >illustrate_ppo.log 2>&1 && mv models/reach/ppo illustrate_ppo)
(cd "$out" && "$cradle" illustrate --env reach --algorithm A2C --train_for 600 --save_every 300 \
  --test_for 300 --envs 2 --seed 5 --save_model a2c >illustrate_a2c.log 2>&1 &&
  mv models/reach/a2c illustrate_a2c)
# cradle evaluate with videos: the trained self-touch policy over its training log, and random
# actions on hand regard (the tasks' panels, traces and plots).
cp -r "$out/ppo" "$out/eval_touch"
"$cradle" evaluate --config "$config" --save-dir "$out/eval_touch" --episodes 2 --duration 40 \
  --seed 3 --policy "$out/eval_touch/checkpoints/final.ckpt" >"$out/eval_touch.log" 2>&1
"$cradle" evaluate --config "$(dirname "$config")/config_handregard.yml" \
  --save-dir "$out/eval_regard" --episodes 2 --duration 40 --seed 3 >"$out/eval_regard.log" 2>&1
# Hash a run's outputs with what measures time (time/SPS/seconds columns and keys) left out
# and the output folder's path replaced, so that two folders compare.
digest() {
  python3 - "$1" "$2" <<'PY'
import csv, hashlib, json, re, sys
path, root = sys.argv[1], sys.argv[2]
timing = re.compile(r"time|sps|seconds", re.I)
def scrub(value):
    if isinstance(value, dict):
        return {k: scrub(v) for k, v in value.items() if not timing.search(k)}
    if isinstance(value, list):
        return [scrub(v) for v in value]
    if isinstance(value, str):
        return value.replace(root, "ROOT")
    return value
if path.endswith(".csv"):
    rows = list(csv.reader(open(path)))
    keep = [i for i, h in enumerate(rows[0]) if not timing.search(h)]
    text = "\n".join(",".join(r[i] for i in keep) for r in rows).encode()
elif path.endswith(".jsonl"):
    text = "\n".join(json.dumps(scrub(json.loads(l)), sort_keys=True) for l in open(path)).encode()
elif path.endswith(".json"):
    text = json.dumps(scrub(json.load(open(path))), sort_keys=True).encode()
else:
    text = open(path, "rb").read()
print(hashlib.sha256(text).hexdigest()[:16])
PY
}
for name in ppo ppo_touch a2c; do
  dir=$out/$name
  for file in "$dir"/checkpoints/*.ckpt "$dir"/logs/* "$dir"/evaluation.json "$dir"/plots/*; do
    echo "$name ${file#"$dir"/} $(digest "$file" "$dir")"
  done
  grep -h 'score:\|evaluation of' "$out/$name.log" | sed "s/^/$name /"
done
for name in eval_touch eval_regard; do
  dir=$out/$name
  for file in "$dir"/evaluation.json "$dir"/plots/* "$dir"/trajectories/* "$dir"/videos/*; do
    echo "$name ${file#"$dir"/} $(digest "$file" "$dir")"
  done
done
for name in illustrate_ppo illustrate_a2c; do
  dir=$out/$name
  for file in "$dir"/*; do echo "$name ${file#"$dir"/} $(digest "$file" "$dir")"; done
  grep -h 'test episodes' "$out/$name.log" | sed "s/^/$name /"
done
