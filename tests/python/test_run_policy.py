"""cradle.load_policy(run_folder): the trained policy of a run by env id, of any family, acts as the
run's own evaluation and `cradle evaluate --run` do; bad arguments are one-line errors."""

import json
import os
import subprocess

import numpy as np
import pytest

import cradle
from conftest import cradle_binary

PPO = {"n_steps": 64, "batch_size": 64, "n_epochs": 1}
# A SaMI context learner at a tiny budget: its actions depend on the episode so far.
SACCM = {"net_arch": "32,32", "lstm_hidden": 16, "batch_size": 4, "contrast_batch_size": 4,
         "buffer_size": 8, "train_freq": 10, "gradient_steps": 2, "learning_starts": 60}


def play(policy, env, seed):
    """One episode of the policy on env from reset(seed): (return, length)."""
    obs, _ = env.reset(seed=seed)
    policy.reset()
    total, length = 0.0, 0
    while True:
        obs, reward, terminated, truncated, _ = env.step(policy.predict(obs))
        total += reward
        length += 1
        if terminated or truncated:
            return total, length


@pytest.fixture(scope="module")
def tma_run(tmp_path_factory):
    run = tmp_path_factory.mktemp("tma") / "run"
    cradle.train(env="tma/stump-tracks:old_classic_bipedal", steps=256, envs=2,
                 hyperparameters=PPO, save_dir=run, progress_bar=False, eval_episodes=2)
    return run


@pytest.mark.parametrize("env_id, algo, hyperparameters", [
    ("sami/CrippleHalfCheetah:moderate", "ppo", PPO),
    ("sami/CrippleHalfCheetah:moderate", "saccm", SACCM),
])
def test_a_sami_runs_policy_replays_its_evaluation(tmp_path, env_id, algo, hyperparameters):
    run = tmp_path / "run"
    cradle.train(env=env_id, algo=algo, steps=300, envs=2, hyperparameters=hyperparameters,
                 save_dir=run, progress_bar=False, eval_episodes=2)
    evaluation = json.loads((run / "evaluation.json").read_text())
    policy = cradle.load_policy(run)
    assert (policy.env_id, policy.family, policy.algorithm) == (env_id, "sami", algo)
    env = cradle.make(policy.env_id)
    for episode in evaluation["episodes"]:
        assert play(policy, env, episode["seed"]) == (episode["return"], episode["length"])


def test_a_teachmyagent_runs_policy_replays_its_evaluation_and_the_cli(tma_run):
    evaluation = json.loads((tma_run / "evaluation.json").read_text())
    policy = cradle.load_policy(tma_run, checkpoint="final", deterministic=True)
    assert policy.env_id == "tma/stump-tracks:old_classic_bipedal" and policy.steps == 256
    assert policy.action_space.shape == (4,)
    env = cradle.make(policy.env_id)
    returns = [play(policy, env, e["seed"]) for e in evaluation["episodes"]]
    assert returns == [(e["return"], e["length"]) for e in evaluation["episodes"]]
    # `cradle evaluate --run` by default plays the seeds of the run's own evaluation.
    out = subprocess.run([cradle_binary(), "evaluate", "--run", str(tma_run), "--episodes", "2"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    cli = json.loads((tma_run / "evaluation_final.json").read_text())
    assert cli["checkpoint"] == "final" and cli["policy_actions"] == "mean"
    assert cli["episodes"] == evaluation["episodes"]
    assert not (tma_run / "videos").exists()
    # The latest checkpoint is the final one here; sampled actions repeat from a fresh load.
    latest = cradle.load_policy(tma_run, "latest")
    assert latest.checkpoint.endswith("latest.ckpt")
    sampled = [play(cradle.load_policy(tma_run, deterministic=False), env, 1000)
               for _ in range(2)]
    assert sampled[0] == sampled[1]


def test_bad_run_folders_and_arguments(tma_run, tmp_path):
    with pytest.raises(FileNotFoundError, match="expected a run folder"):
        cradle.load_policy(tmp_path / "missing")
    with pytest.raises(FileNotFoundError, match="run.json"):
        cradle.load_policy(tmp_path)
    (tmp_path / "run.json").write_text('{"env": "tma/stump-tracks:old_classic_bipedal"')
    with pytest.raises(ValueError, match="run.json is not valid JSON"):
        cradle.load_policy(tmp_path)
    good = json.loads((tma_run / "run.json").read_text())
    for key, value, message in [("algorithm", None, 'no key "algorithm"'),
                                ("seed", -1, '"seed" is -1; expected an integer'),
                                ("env", "tma/stump-trax", "closest"),
                                ("family", "sami", 'expected "tma"'),
                                ("algorithm", "dqn", "expected one of ppo")]:
        damaged = dict(good)
        if value is None:
            del damaged[key]
        else:
            damaged[key] = value
        (tmp_path / "run.json").write_text(json.dumps(damaged))
        with pytest.raises(ValueError, match=message):
            cradle.load_policy(tmp_path)
    with pytest.raises(FileNotFoundError, match=r"expected one of the run's checkpoints \(final, "):
        cradle.load_policy(tma_run, "step_7")
    with pytest.raises(ValueError, match="deterministic must be True or False"):
        cradle.load_policy(tma_run, deterministic="yes")
    with pytest.raises(ValueError, match="checkpoint must be"):
        cradle.load_policy(tma_run, checkpoint=3)
    with pytest.raises(ValueError, match="a BabyBench config needs the checkpoint file"):
        cradle.load_policy({"behavior": "self_touch"})
    policy = cradle.load_policy(tma_run)
    obs, _ = cradle.make(policy.env_id).reset(seed=0)
    with pytest.raises(ValueError, match="must be a dict"):
        policy.predict(obs["observation"])
    with pytest.raises(ValueError, match="has no key 'observation'"):
        policy.predict({})
    with pytest.raises(ValueError, match="expected 24 .*not a batch"):
        policy.predict({"observation": np.stack([obs["observation"]] * 2)})


def test_cli_evaluate_run_errors(tma_run, tmp_path):
    def cradle_evaluate(*args):
        out = subprocess.run([cradle_binary(), "evaluate", *args], capture_output=True, text=True)
        assert out.returncode == 1
        lines = out.stderr.strip().splitlines()
        assert len(lines) == 1, out.stderr
        return lines[0]

    assert "--config FILE" in cradle_evaluate()
    assert "excludes" in cradle_evaluate("--run", str(tma_run), "--config", "x.yml")
    assert "does not exist" in cradle_evaluate("--run", str(tmp_path / "missing"))
    assert "final, latest" in cradle_evaluate("--run", str(tma_run), "--checkpoint", "step_7")
    assert "--checkpoint requires --run" in cradle_evaluate("--config", "x.yml", "--checkpoint",
                                                            "final")
    assert not os.path.exists(tmp_path / "missing")
