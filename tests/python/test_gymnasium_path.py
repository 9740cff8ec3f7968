"""The Gymnasium and SB3 branches of the package, exercised against the minimal stand-in modules
of conftest.py (neither is a Debian package): the env, spaces, wrappers, vector env, registration
and the SB3 VecEnv adapter are built from what those modules provide."""

import numpy as np
import pytest

import cradle

SCRIPT = '''
import gymnasium, numpy as np, cradle
from gymnasium import spaces
assert cradle.HAS_GYMNASIUM
env = cradle.make("BabyBench-SelfTouch", max_episode_steps=3)
assert isinstance(env, gymnasium.Env)
assert isinstance(env.action_space, spaces.Box) and env.action_space.shape == (30,)
assert isinstance(env.observation_space, spaces.Dict)
assert env.observation_space["touch"].dtype == np.float32
obs, info = env.reset(seed=1)
assert isinstance(env.np_random, np.random.Generator)


class Bonus(gymnasium.Wrapper):
    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        return obs, reward + 1.0, terminated, truncated, info


assert cradle.Wrapper is gymnasium.Wrapper
assert Bonus(env).step(np.zeros(30))[1] == 1.0
vec = cradle.VectorEnv({"behavior": "self_touch", "scene": "crib", "vision_active": False}, 2)
assert isinstance(vec, gymnasium.vector.VectorEnv)
assert vec.single_observation_space["observation"].shape == (292,)  # every v1 actuator
assert vec.observation_space["observation"].shape == (2, 292)
assert vec.action_space.shape == (2, 44)
assert {"cradle/BabyBench-v0", "cradle/BabyBench-SelfTouch-v0",
        "cradle/BabyBench-HandRegard-v0"} <= set(gymnasium.registry)
assert all(name.startswith("cradle/") for name in gymnasium.registry)
print("ok")
'''


def test_gymnasium_branch(with_gymnasium):
    assert with_gymnasium(SCRIPT).strip() == "ok"


def test_sb3_adapter(sb3, tmp_path):
    config = cradle.config_dict(cradle.env.CONFIG_DIR + "/config_selftouch.yml")
    config.update(save_dir=str(tmp_path / "run"), max_episode_steps=2)
    venv = sb3.SB3VecEnv(config, num_envs=2, training=True)
    venv.seed(5)
    obs = venv.reset()
    assert obs["touch"].shape[0] == 2 and venv._seeds == [None, None]
    obs, rewards, dones, infos = venv.step(np.zeros((2, 30)))
    assert not dones.any() and rewards.dtype == np.float32 and infos[0]["steps"] == 0
    obs, rewards, dones, infos = venv.step(np.zeros((2, 30)))
    assert dones.all()
    assert infos[0]["terminal_observation"]["observation"].shape == (264,)
    assert infos[0]["TimeLimit.truncated"] and infos[1]["steps"] == 1
    obs, rewards, dones, infos = venv.step(np.zeros((2, 30)))
    assert not dones.any() and infos[0]["steps"] == 0  # stepped, not reset: the reset was same-step
    venv.close()


def test_sb3_over_any_env_id(sb3):
    """An env id's vector as an SB3 VecEnv: the same batches as cradle.VectorEnv in same-step mode,
    with SB3's terminal_observation and TimeLimit.truncated for the envs whose episode ended."""
    venv = sb3.SB3VecEnv("tma/stump-tracks:old_classic_bipedal", num_envs=2, seed=3)
    reference = cradle.VectorEnv("tma/stump-tracks:old_classic_bipedal", 2, seed=3,
                                 autoreset_mode="same_step")
    obs = venv.reset()
    expected, _ = reference.reset(seed=3)
    assert all(np.array_equal(obs[k], expected[k]) for k in expected)
    rng = np.random.default_rng(0)
    ended = 0
    for _ in range(400):
        actions = rng.uniform(-1, 1, (2, 4))
        obs, rewards, dones, infos = venv.step(actions)
        expected, r, terminated, truncated, expected_infos = reference.step(actions)
        assert all(np.array_equal(obs[k], expected[k]) for k in expected)
        assert np.array_equal(rewards, r.astype(np.float32))
        assert np.array_equal(dones, terminated | truncated)
        for i in np.flatnonzero(dones):
            ended += 1
            final = expected_infos["final_obs"][i]
            assert all(np.array_equal(infos[i]["terminal_observation"][k], final[k])
                       for k in final)
            assert infos[i]["TimeLimit.truncated"] == bool(truncated[i] and not terminated[i])
    assert ended > 0  # random actions topple the walker well within 400 steps
    venv.close()
    reference.close()


def test_sb3_truncation_and_an_existing_vector(sb3):
    vec = cradle.VectorEnv("sami/HalfCheetah", 2, seed=1, autoreset_mode="same_step")
    venv = sb3.SB3VecEnv(vec)
    assert venv.num_envs == 2 and venv.observation_space is vec.single_observation_space
    venv.reset()
    for step in range(1, 1001):
        obs, rewards, dones, infos = venv.step(np.zeros((2, 6)))
        if dones.any():
            break
    assert step == 1000 and dones.all()  # HalfCheetah never ends but at its time limit
    assert all(info["TimeLimit.truncated"] for info in infos)
    assert infos[0]["terminal_observation"]["observation"].shape == obs["observation"][0].shape
    venv.close()
    assert vec.closed


def test_sb3_refuses_what_it_cannot_use(sb3):
    with pytest.raises(ValueError, match="autoreset_mode=\"same_step\""):
        sb3.SB3VecEnv(cradle.VectorEnv("sami/HalfCheetah", 1))
    vec = cradle.VectorEnv("sami/HalfCheetah", 1, autoreset_mode="same_step")
    with pytest.raises(ValueError, match="num_envs: the vector is given"):
        sb3.SB3VecEnv(vec, num_envs=4)
    vec.close()
    with pytest.raises(ValueError, match="closed"):
        sb3.SB3VecEnv(vec)
    with pytest.raises(ValueError, match="closest"):
        sb3.SB3VecEnv("tma/stump-trax", num_envs=2)
    with pytest.raises(ValueError, match="training=True is for BabyBench"):
        sb3.SB3VecEnv("mimo/reach", training=True)
