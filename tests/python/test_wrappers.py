"""A Python wrapper changes the reward (the reference's intrinsic-motivation pattern)."""

import numpy as np

import cradle


class TouchCount(cradle.Wrapper):
    """The reference example: reward = fraction of active touch values + extrinsic reward."""

    def __init__(self, env):
        super().__init__(env)
        self.calls = 0

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.calls += 1
        intrinsic = np.sum(obs["touch"] > 1e-6) / len(obs["touch"])
        return obs, reward + 1.0 + intrinsic, terminated, truncated, info


class Halve(cradle.RewardWrapper):
    def reward(self, reward):
        return reward / 2


def test_wrapper_changes_reward(make_config):
    env = cradle.make_env(make_config("selftouch"), training=False)
    wrapped = Halve(TouchCount(env))
    obs, _ = wrapped.reset(seed=0)
    total = 0.0
    for _ in range(20):
        obs, reward, terminated, truncated, info = wrapped.step(wrapped.action_space.sample())
        intrinsic = np.sum(obs["touch"] > 1e-6) / len(obs["touch"])
        assert reward == (1.0 + intrinsic) / 2
        total += reward
    assert total >= 10.0  # the bare env's reward is 0
    assert wrapped.env.calls == 20
    assert wrapped.unwrapped is env
    assert wrapped.observation_space is env.observation_space
    assert wrapped.env.env.model.nu == 30


def test_observation_wrapper(make_config):
    class Proprio(cradle.ObservationWrapper):
        def observation(self, observation):
            return observation["observation"]

    env = Proprio(cradle.make_env(make_config("selftouch"), training=False))
    obs, _ = env.reset(seed=0)
    assert obs.shape == (264,)
    obs, *_ = env.step(np.zeros(30))
    assert obs.shape == (264,)
