"""SaMI environments (MuJoCo locomotion with hidden mass, damping and crippled joints, and Panda
push), stepped in C++ and shaped like Gymnasium envs.

    import cradle.sami
    env = cradle.sami.make("PandaPush", split="extreme")
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    info["friction"], info["cube_mass"], info["skill"]   # hidden: never in the observation

Splits are "train", "moderate", "extreme" or a YAML file of task sets (see docs/sami.md).
"""

import numbers

import numpy as np

from . import _cradle
from . import spaces
from .env import _EnvBase

ENV_NAMES = tuple(_cradle.sami_env_names())


class SamiEnv(_EnvBase):
    """One SaMI env drawing its hidden parameters from every task set of a split at each reset.

    Args:
      name: one of ENV_NAMES.
      split: "train", "moderate", "extreme" or a path to a task-set .yml file.
      seed: seed of the env's generator until reset(seed=...) reseeds it.
      render_mode: None or "rgb_array" (render() returns a 240x320 RGB image).
      contact_forces: fill cfrc_ext so the Ant / HumanoidStandup contact costs act (off in the
        published runs).
    """

    def __init__(self, name, split="train", seed=0, render_mode=None, contact_forces=False):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', not {render_mode!r}")
        if not isinstance(seed, numbers.Integral) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, not {seed!r}")
        self._core = _cradle.SamiEnv(str(name), str(split), int(seed), bool(contact_forces))
        self.name = self._core.name
        self.split = str(split)
        self.render_mode = render_mode
        self.action_space = spaces.from_core_box(self._core.action_space)
        self.observation_space = spaces.from_core_dict(self._core.observation_space)
        self.max_episode_steps = self._core.horizon
        self.dt = self._core.dt
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": round(1.0 / self.dt)}

    def reset(self, *, seed=None, options=None):
        if seed is not None and (not isinstance(seed, numbers.Integral) or seed < 0):
            raise ValueError(f"seed must be a non-negative integer, not {seed!r}")
        return self._core.reset(seed)

    def step(self, action):
        return self._core.step(np.asarray(action, dtype=np.float64).reshape(-1))

    def render(self, width=320, height=240):
        if self.render_mode != "rgb_array":
            return None
        return self._core.render(int(width), int(height))

    def close(self):
        pass

    def __repr__(self):
        return f"<SamiEnv {self.name} split={self.split}>"


def make(name, split="train", seed=0, **kwargs):
    """A SaMI env by name, e.g. make("CrippleHalfCheetah", split="moderate")."""
    return SamiEnv(name, split=split, seed=seed, **kwargs)
