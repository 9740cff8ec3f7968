"""Cradle from Python: envs stepped in C++, Gymnasium-shaped.

    import cradle
    env = cradle.make_env("configs/config_selftouch.yml")      # or a dict of BabyBench keys
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    env = cradle.make("tma/parkour:fish")                      # any id of cradle.env_ids()

See docs/python.md.
"""

import importlib

from . import registry, sami, spaces, teach
from ._cradle import __version__
from .env import (
    ENV_IDS,
    BabyBenchEnv,
    config_dict,
    load_config,
    make,
    make_env,
    register_gymnasium_envs,
)
from .policy import Policy
from .registry import RegistryEnv, env_ids, env_spec, env_specs, gymnasium_id
from .spaces import HAS_GYMNASIUM
from .training import evaluate, load_policy, load_training_log, train, training_score
from .vector import VectorEnv
from .wrappers import ActionWrapper, ObservationWrapper, RewardWrapper, Wrapper

register_gymnasium_envs()

# Submodules loaded on first use, so `cradle.tma.make(...)` works after `import cradle`:
# TeachMyAgent, its campaign analysis (needs pandas) and the SB3 vector env (needs SB3).
_LAZY_SUBMODULES = ("tma", "tma_analysis", "sb3")


def __getattr__(name):
    if name in _LAZY_SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "ENV_IDS",
    "HAS_GYMNASIUM",
    "ActionWrapper",
    "BabyBenchEnv",
    "ObservationWrapper",
    "Policy",
    "RegistryEnv",
    "RewardWrapper",
    "VectorEnv",
    "Wrapper",
    "__version__",
    "config_dict",
    "env_ids",
    "env_spec",
    "env_specs",
    "evaluate",
    "gymnasium_id",
    "load_config",
    "load_policy",
    "load_training_log",
    "make",
    "make_env",
    "spaces",
    "train",
    "training_score",
]
