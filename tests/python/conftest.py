"""Shared helpers for the Python tests: the reference configs with save_dir in a temp folder, and
stand-ins for Gymnasium and Stable-Baselines3."""

import importlib
import os
import pathlib
import subprocess
import sys
import textwrap
import types

import pytest

import cradle

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIGS = {
    "test_installation": ROOT / "configs" / "config_test_installation.yml",
    "selftouch": ROOT / "configs" / "config_selftouch.yml",
    "handregard": ROOT / "configs" / "config_handregard.yml",
}


def cradle_binary():
    """The CLI built next to the package (ctest sets CRADLE_BINARY)."""
    return os.environ.get("CRADLE_BINARY", str(ROOT / "build" / "cradle"))


@pytest.fixture
def make_config(tmp_path):
    """make_config(name, **overrides): a config dict of a reference config, saving under tmp."""

    def make(name, **overrides):
        config = cradle.config_dict(CONFIGS[name])
        config["save_dir"] = str(tmp_path / name)
        config.update(overrides)
        return config

    return make


# Stand-ins for the optional packages (neither Gymnasium nor Stable-Baselines3 is a Debian
# package): as much of their API as Cradle relies on, shared by every test of those branches.

# Gymnasium 1.x: the registry and id grammar (ENV_ID_RE; ":" in an id names a module for make),
# Env, the wrappers, spaces.Box / Dict and vector.VectorEnv.
GYMNASIUM = '''
import importlib
import re

import numpy as np

from . import spaces, vector

ENV_ID_RE = re.compile(
    r"^(?:(?P<namespace>[\\w:-]+)\\/)?(?:(?P<name>[\\w:.-]+?))(?:-v(?P<version>\\d+))?$")
registry = {}


def register(id, entry_point, kwargs=None):
    assert ENV_ID_RE.fullmatch(id), id
    registry[id] = (entry_point, kwargs or {})


def make(id, **kwargs):
    assert ":" not in id, "make reads 'module:name' ids as a module to import"
    entry_point, defaults = registry[id]
    module, name = entry_point.split(":")
    return getattr(importlib.import_module(module), name)(**{**defaults, **kwargs})


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

GYMNASIUM_SPACES = '''
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

# Stable-Baselines3 2.x's VecEnv, as far as cradle.sb3 relies on it.
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


def _write_gymnasium(root):
    package = root / "gymnasium"
    (package / "vector").mkdir(parents=True)
    (package / "__init__.py").write_text(GYMNASIUM)
    (package / "spaces.py").write_text(GYMNASIUM_SPACES)
    (package / "vector" / "__init__.py").write_text("class VectorEnv:\n    pass\n")


@pytest.fixture
def with_gymnasium(tmp_path):
    """run(script): runs `script` in a fresh interpreter (cradle looks for Gymnasium when it is
    imported) that finds the Gymnasium stand-in and this cradle package; returns its stdout and
    fails the test with its stderr when it fails."""
    packages = tmp_path / "stand_ins"
    _write_gymnasium(packages)

    def run(script):
        env = dict(os.environ)
        package_root = os.path.dirname(os.path.dirname(os.path.abspath(cradle.__file__)))
        env["PYTHONPATH"] = os.pathsep.join([str(packages), package_root])
        result = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], env=env,
                                capture_output=True, text=True, cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        return result.stdout

    return run


@pytest.fixture
def sb3(monkeypatch):
    """cradle.sb3 imported against the Stable-Baselines3 stand-in, injected into sys.modules for
    this test only (cradle.sb3 imports SB3 lazily, so no fresh interpreter is needed)."""
    names = ["stable_baselines3", "stable_baselines3.common", "stable_baselines3.common.vec_env"]
    modules = [types.ModuleType(name) for name in names]
    exec(SB3_VEC_ENV, modules[2].__dict__)
    modules[0].common, modules[1].vec_env = modules[1], modules[2]
    for name, module in zip(names, modules):
        monkeypatch.setitem(sys.modules, name, module)
    monkeypatch.delitem(sys.modules, "cradle.sb3", raising=False)
    module = importlib.import_module("cradle.sb3")
    yield module
    # The next import of cradle.sb3 must not see the stand-in.
    sys.modules.pop("cradle.sb3", None)
    if "sb3" in vars(cradle):
        delattr(cradle, "sb3")
