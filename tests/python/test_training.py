"""Training from Python (C++ PPO with a Python intrinsic reward) and the training-log loader."""

import csv
import json
import os
import pickle

import numpy as np
import pytest

import cradle


def test_train_with_python_intrinsic_reward(make_config):
    config = make_config("selftouch", max_episode_steps=200)
    calls = {"n": 0}

    def touch_fraction(obs):
        calls["n"] += 1
        assert not obs["touch"].flags.writeable  # views of the env's buffer
        return float(np.mean(obs["touch"] > 1e-6))

    def constant(obs, action, info):
        assert action.shape == (30,) and "steps" in info
        return 1.0

    result = cradle.train(
        config, algo="ppo", intrinsic=[touch_fraction, (constant, 0.5)], steps=2048, envs=2,
        threads=2, seed=1, hyperparameters={"n_steps": 256, "batch_size": 128, "n_epochs": 2},
        eval_episodes=0, progress_bar=False,
    )
    assert result["steps"] >= 2048
    assert calls["n"] >= 2048  # once per env step
    save_dir = config["save_dir"]
    rows = list(csv.DictReader(open(f"{save_dir}/logs/progress.csv")))
    assert rows and int(rows[-1]["global_step"]) == result["steps"]
    # The constant term alone gives 0.5 per step, so episodic returns are at least 100.
    returns = [float(r["charts/episodic_return"]) for r in rows if r["charts/episodic_return"]]
    assert returns and min(returns) >= 0.5 * 200 - 1e-6
    log = cradle.load_training_log(save_dir)
    # Each env's first reset records a 0-step entry; then 200-step episodes; close() records the
    # partial ones.
    assert [e["steps"] for e in log[:2]] == [0, 0]
    assert sum(e["steps"] == 200 for e in log) >= 8
    # The checkpoint evaluates (deterministic policy) through cradle.evaluate.
    report = cradle.evaluate(config, episodes=1, duration=20, render=False,
                             policy=result["checkpoint"], quiet=True)
    assert len(report["episodes"]) == 1
    mean_qpos = np.load(f"{save_dir}/trajectories/episode_0.npz")["qpos"]
    assert json.load(open(f"{save_dir}/evaluation.json"))["policy_actions"] == "mean"
    # Sampled actions: drawn by the checkpoint's generator, so they repeat, and differ from the
    # mean action's trajectory.
    sampled = []
    for _ in range(2):
        cradle.evaluate(config, episodes=1, duration=20, render=False,
                        policy=result["checkpoint"], quiet=True, stochastic=True)
        sampled.append(np.load(f"{save_dir}/trajectories/episode_0.npz")["qpos"])
        assert json.load(open(f"{save_dir}/evaluation.json"))["policy_actions"] == "sampled"
    assert np.array_equal(sampled[0], sampled[1])
    assert not np.allclose(sampled[0], mean_qpos)
    with pytest.raises(ValueError, match="stochastic=True needs policy to be a checkpoint path"):
        cradle.evaluate(config, episodes=1, duration=5, render=False, quiet=True, stochastic=True)


def test_python_reward_errors_propagate(make_config):
    def broken(obs):
        raise RuntimeError("broken reward")

    with pytest.raises(RuntimeError, match="broken reward"):
        cradle.train(make_config("selftouch"), intrinsic=[broken], steps=256, envs=1,
                     eval_episodes=0, progress_bar=False, hyperparameters={"n_steps": 128})
    with pytest.raises(ValueError, match="no_such_reward"):
        cradle.train(make_config("selftouch"), intrinsic=["no_such_reward"], steps=256,
                     progress_bar=False)


def test_training_log_round_trip(make_config, tmp_path):
    config = make_config("selftouch", max_episode_steps=25)
    env = cradle.make_env(config, training=True)
    finals = []
    rng = np.random.default_rng(0)
    env.reset(seed=0)
    for episode in range(3):
        truncated = False
        while not truncated:
            _, _, _, truncated, info = env.step(rng.uniform(env.action_space.low,
                                                            env.action_space.high))
        finals.append(info)
        env.reset()
    env.step(np.zeros(30))
    env.close()  # records the last, partial (1-step) episode
    log = cradle.load_training_log(config["save_dir"] + "/logs/training.jsonl")
    assert [e["steps"] for e in log] == [0, 25, 25, 25, 1]
    for entry, info in zip(log[1:4], finals):
        assert list(entry) == ["right_hand_touches", "left_hand_touches", "steps"]
        assert entry["right_hand_touches"] == info["right_hand_touches"]
        assert entry["left_hand_touches"] == info["left_hand_touches"]
    extras = cradle.load_training_log(config["save_dir"], extras=True)
    assert "score" in extras[1] and "wall_time" in extras[1]
    # The reference's pickle round-trips through the same loader, with the same score.
    pkl = tmp_path / "training.pkl"
    pkl.write_bytes(pickle.dumps(log, protocol=-1))
    assert cradle.load_training_log(pkl) == log
    union = len({g for e in log[-4:] for g in e["right_hand_touches"]}) + len(
        {g for e in log[-4:] for g in e["left_hand_touches"]})
    assert cradle.training_score(str(pkl), "self_touch") == pytest.approx(union / 68)
    with pytest.raises(FileNotFoundError):
        cradle.load_training_log(tmp_path / "nothing_here.jsonl")


def test_evaluate_with_python_policy(make_config):
    config = make_config("selftouch")
    seen = []

    def policy(obs):
        seen.append(obs["observation"].copy())
        return np.zeros(30, dtype=np.float32)

    report = cradle.evaluate(config, episodes=2, duration=15, render=False, policy=policy,
                             quiet=True)
    assert len(report["episodes"]) == 2 and len(seen) == 30
    assert report["episodes"][0]["steps"] == 15
    with pytest.raises(ValueError, match="policy must return 30 action values"):
        cradle.evaluate(config, episodes=1, duration=5, render=False,
                        policy=lambda obs: np.zeros(3), quiet=True)
    with pytest.raises(FileNotFoundError):
        cradle.evaluate(config, episodes=1, duration=5, render=False,
                        policy=config["save_dir"] + "/missing.ckpt", quiet=True)


def test_train_with_async_batches(make_config):
    # PPO collecting through the async vector (batches of 2 of 3 envs), a Python term beside a
    # named one; each env fills 128 rows: its first reset's 0-step entry, two 50-step episodes
    # (each with its autoreset row) and a 26-step one cut short by the final checkpoint.
    config = make_config("selftouch", max_episode_steps=50)
    calls = {"n": 0}

    def touch_fraction(obs):
        calls["n"] += 1
        return float(np.mean(obs["touch"] > 1e-6))

    result = cradle.train(
        config, algo="ppo", intrinsic=[touch_fraction, "episode_coverage"], steps=384, envs=3,
        threads=2, async_batch=2, seed=1,
        hyperparameters={"n_steps": 64, "batch_size": 96, "n_epochs": 1}, eval_episodes=0,
        progress_bar=False,
    )
    assert result["steps"] == 384
    assert calls["n"] == 384  # once per env step
    log = cradle.load_training_log(config["save_dir"])
    assert sorted(e["steps"] for e in log) == [0] * 3 + [26] * 3 + [50] * 6
    with pytest.raises(ValueError, match="--async-batch 3 must be between 1 and --envs - 1"):
        cradle.train(config, steps=64, envs=3, async_batch=3, progress_bar=False)


def test_evaluate_films_only_when_asked(make_config):
    config = make_config("selftouch")
    videos = os.path.join(config["save_dir"], "videos")
    os.makedirs(videos)  # an empty one, as an older evaluation left it
    cradle.evaluate(config, episodes=1, duration=2, quiet=True)
    assert not os.path.exists(videos)
    report = cradle.evaluate(config, episodes=1, duration=2, render=True, quiet=True)
    assert len(report["episodes"]) == 1
    assert os.listdir(videos) == ["episode_0.mp4"]
    cradle.evaluate(config, episodes=1, duration=2, quiet=True)
    assert os.listdir(videos) == ["episode_0.mp4"]  # films are kept
    with pytest.raises(ValueError, match="render must be True or False"):
        cradle.evaluate(config, episodes=1, duration=2, render="yes")
