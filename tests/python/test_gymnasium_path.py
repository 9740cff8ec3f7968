"""The Gymnasium and SB3 branches of the package, exercised against minimal stand-in modules
(neither is a Debian package): the env, spaces, wrappers, vector env, registration and the SB3
VecEnv adapter are built from what those modules provide."""

import os
import subprocess
import sys
import textwrap

import cradle

STUB = '''
import numpy as np

registry = {}


def register(id, entry_point, kwargs=None):
    registry[id] = (entry_point, kwargs)


class Env:
    spec = None
    _np_random = None

    @property
    def np_random(self):
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    def reset(self, *, seed=None, options=None):
        if seed is not None:
            self._np_random = np.random.default_rng(seed)

    @property
    def unwrapped(self):
        return self


class Wrapper(Env):
    def __init__(self, env):
        assert isinstance(env, Env)
        self.env = env

    def step(self, action):
        return self.env.step(action)

    def reset(self, **kwargs):
        return self.env.reset(**kwargs)


class ObservationWrapper(Wrapper):
    pass


class RewardWrapper(Wrapper):
    pass


class ActionWrapper(Wrapper):
    pass
'''

SPACES = '''
import numpy as np


class Box:
    def __init__(self, low, high, shape=None, dtype=np.float32):
        self.low = np.broadcast_to(np.asarray(low, dtype=dtype), shape)
        self.high = np.broadcast_to(np.asarray(high, dtype=dtype), shape)
        self.shape = tuple(shape)
        self.dtype = np.dtype(dtype)


class Dict:
    def __init__(self, spaces):
        self.spaces = dict(spaces)

    def __getitem__(self, key):
        return self.spaces[key]
'''

VECTOR = '''
class VectorEnv:
    pass
'''

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


def test_gymnasium_branch(tmp_path):
    package = tmp_path / "gymnasium"
    (package / "vector").mkdir(parents=True)
    (package / "__init__.py").write_text(STUB + "\nfrom . import spaces, vector\n")
    (package / "spaces.py").write_text(SPACES)
    (package / "vector" / "__init__.py").write_text(VECTOR)
    env = dict(os.environ)
    package_root = os.path.dirname(os.path.dirname(os.path.abspath(cradle.__file__)))
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), package_root])
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(SCRIPT)], env=env,
                            capture_output=True, text=True, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


# Stable-Baselines3 2.x's VecEnv constructor, as far as the adapter relies on it.
SB3_VEC_ENV = '''
class VecEnv:
    def __init__(self, num_envs, observation_space, action_space):
        self.num_envs = num_envs
        self.observation_space = observation_space
        self.action_space = action_space
        self.reset_infos = [{} for _ in range(num_envs)]
        self._seeds = [None for _ in range(num_envs)]
        render_modes = self.get_attr("render_modes")
        self.metadata = {"render_modes": render_modes[0]}

    def seed(self, seed=None):
        self._seeds = [seed + i for i in range(self.num_envs)]

    def _reset_seeds(self):
        self._seeds = [None for _ in range(self.num_envs)]

    def step(self, actions):
        self.step_async(actions)
        return self.step_wait()
'''

SB3_SCRIPT = '''
import numpy as np, cradle
from cradle.sb3 import SB3VecEnv
config = cradle.config_dict(cradle.env.CONFIG_DIR + "/config_selftouch.yml")
config.update(save_dir="run", max_episode_steps=2)
venv = SB3VecEnv(config, num_envs=2, training=True)
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
print("ok")
'''


def test_sb3_adapter(tmp_path):
    vec_env = tmp_path / "stable_baselines3" / "common" / "vec_env"
    vec_env.mkdir(parents=True)
    (tmp_path / "stable_baselines3" / "__init__.py").write_text("")
    (tmp_path / "stable_baselines3" / "common" / "__init__.py").write_text("")
    (vec_env / "__init__.py").write_text(SB3_VEC_ENV)
    env = dict(os.environ)
    package_root = os.path.dirname(os.path.dirname(os.path.abspath(cradle.__file__)))
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), package_root])
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(SB3_SCRIPT)], env=env,
                            capture_output=True, text=True, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
