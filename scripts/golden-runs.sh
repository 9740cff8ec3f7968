#!/bin/bash
# Golden runs: seeded short PPO and A2C runs (cradle train on self-touch, cradle illustrate on
# reach), seeded evaluations with videos (self-touch, hand regard), a TeachMyAgent student run (SAC
# with ALP-GMM) and SaMI runs (TESAC and SaCCM, then SaCCM's evaluation on a split). Prints a sha256 prefix of
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
  --seed 3 --render --policy "$out/eval_touch/checkpoints/final.ckpt" >"$out/eval_touch.log" 2>&1
"$cradle" evaluate --config "$(dirname "$config")/config_handregard.yml" \
  --save-dir "$out/eval_regard" --episodes 2 --duration 40 --seed 3 --render \
  >"$out/eval_regard.log" 2>&1
# A TeachMyAgent student run (SAC + ALP-GMM) and SaMI runs, tiny budgets.
"$cradle" tma run --env stump-tracks --embodiment old_classic_bipedal --student sac \
  --teacher ALP-GMM --nb_env_steps 0.004 --test_every 2000 --nb_test_episodes 3 --seed 3 \
  --hp learning_starts=1000 --hp batch_size=64 --out "$out/tma_sac" --no-progress \
  >"$out/tma_sac.log" 2>&1
for method in TESAC SaCCM; do
  "$cradle" sami train --env CrippleHalfCheetah --method $method --seed 3 --steps-per-env 2200 \
    --hp learning_starts=1000 --hp train_freq=200 --hp gradient_steps=2 --hp batch_size=4 \
    --hp contrast_batch_size=4 --hp net_arch=64,64 --out "$out/sami_$method" --no-progress \
    >"$out/sami_$method.log" 2>&1
done
"$cradle" sami evaluate --run "$out/sami_SaCCM" --split moderate --episodes 1 --seed 5 \
  >"$out/sami_eval.log" 2>&1
# Hash a run's outputs with what measures time (time/SPS/seconds columns and keys) left out
# and the output folder's path replaced, so that two folders compare.
digest() {
  python3 - "$1" "$2" "${3:-}" <<'PY'
import csv, hashlib, json, re, sys
path, root, extra = sys.argv[1], sys.argv[2], sys.argv[3]
# extra: more keys and columns to leave out (the student runs' wall_s, commit, file sizes).
timing = re.compile(r"time|sps|seconds" + ("|" + extra if extra else ""), re.I)
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
elif path.endswith(".ckpt"):
    # A sealed checkpoint: its sections, the run state without the byte sizes of the logs (a
    # log's size counts its timing cells' digits).
    data = open(path, "rb").read()
    head, _, rest = data.partition(b"\n")
    count, _, rest = rest.partition(b"\n")
    sections, body = [], rest
    for _ in range(int(count)):
        line, _, body = body.partition(b"\n")
        name, size, _crc = line.split(b"\t")
        sections.append((name, int(size)))
    text = head
    for name, size in sections:
        content, body = body[:size], body[size:]
        if name == b"run":
            state = json.loads(content)
            state.pop("log_sizes", None)
            content = json.dumps(state, sort_keys=True).encode()
        text += b"\n" + name + b"\n" + content
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
  for file in $(cd "$dir" && find . -type f | sort); do
    echo "$name ${file#./} $(digest "$dir/$file" "$dir")"
  done
  grep -h 'test episodes' "$out/$name.log" | sed "s/^/$name /"
done
for name in tma_sac sami_TESAC sami_SaCCM; do
  dir=$out/$name
  for file in $(cd "$dir" && find . -type f ! -name summary.json | sort); do
    echo "$name ${file#./} $(digest "$dir/$file" "$dir" '_s$|^commit$|^cradle_version$|^sizes$')"
  done
done
