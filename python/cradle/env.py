"""The BabyBench env for Python: Gymnasium's Env protocol around the C++ env; cradle.make over
every env id (the other families' envs are cradle.registry's).

Observations: ``reset`` and ``step`` return fresh numpy arrays by default (one memcpy per key per
step, about 3 µs for the 17,000-value self-touch skin). With ``copy_observations=False`` they
return read-only views of the env's own buffers instead: no copy, but the next ``step``/``reset``
overwrites their contents, so copy what you keep (``obs["touch"].copy()``).
"""

import json
import numbers
import os

import numpy as np

from . import _cradle
from . import spaces

try:
    import gymnasium as _gymnasium
except ImportError:  # Gymnasium is optional.
    _gymnasium = None

# Env ids, as the reference registers them, and the config each starts from.
ENV_IDS = {
    "BabyBench": None,  # the documented defaults: MIMo v1, base scene, every actuator
    "BabyBench-SelfTouch": "config_selftouch.yml",
    "BabyBench-HandRegard": "config_handregard.yml",
}

CONFIG_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "configs")


def _json_value(value):
    """numpy scalars and paths in config dicts become plain JSON values."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"config value {value!r} of type {type(value).__name__} is not supported")


def load_config(config):
    """A parsed config from a dict (BabyBench keys), a YAML file path, or a parsed config.

    Bad keys or values raise ValueError with the one-line message the CLI prints; a missing file
    raises FileNotFoundError.
    """
    if isinstance(config, _cradle.Config):
        return config
    if isinstance(config, dict):
        for key in config:
            if not isinstance(key, str):
                raise ValueError(f"config dict: key {key!r} is not a string")
        try:
            text = json.dumps(config, default=_json_value, allow_nan=False)
        except (TypeError, ValueError) as error:
            raise ValueError(f"config dict: {error}") from None
        return _cradle.parse_config(text, "config dict")
    if isinstance(config, (str, os.PathLike)):
        path = os.fspath(config)
        if not os.path.exists(path):
            raise FileNotFoundError(f"config file '{path}' does not exist")
        return _cradle.load_config(path)
    raise TypeError(f"config must be a dict or a YAML file path, not {type(config).__name__}")


def config_dict(config):
    """Every key of a config (dict, path or parsed) as a plain dict, in the reference's order."""
    return json.loads(load_config(config).to_json())


class _FallbackEnv:
    """Gymnasium's Env protocol when gymnasium is not installed (attributes and defaults)."""

    metadata = {"render_modes": []}
    render_mode = None
    spec = None
    _np_random = None
    _np_random_seed = None

    @property
    def np_random(self):
        """The env's own numpy generator (seeded by reset(seed=...))."""
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    @np_random.setter
    def np_random(self, value):
        self._np_random = value

    @property
    def np_random_seed(self):
        return self._np_random_seed

    def reset(self, *, seed=None, options=None):
        if seed is not None:
            self._np_random = np.random.default_rng(seed)
            self._np_random_seed = seed

    def render(self):
        return None

    def close(self):
        pass

    @property
    def unwrapped(self):
        return self

    def get_wrapper_attr(self, name):
        return getattr(self, name)

    def __enter__(self):
        return self

    def __exit__(self, *args):
        self.close()
        return False

    def __str__(self):
        return f"<{type(self).__name__} instance>"


_EnvBase = _gymnasium.Env if _gymnasium is not None else _FallbackEnv


def _check_actions(actions, shape, what):
    """actions as a float64 array of `shape`; a one-line ValueError for strings, objects, another
    shape or non-finite values (which MuJoCo would silently zero)."""
    a = np.asarray(actions)
    if a.dtype.kind not in "fiu":
        raise ValueError(f"{what} must hold numbers, got dtype {a.dtype}")
    if a.shape != tuple(shape):
        raise ValueError(f"{what} has shape {a.shape}, expected {tuple(shape)}")
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not np.isfinite(a).all():
        bad = np.argwhere(~np.isfinite(a))[0]
        raise ValueError(f"{what} {tuple(int(i) for i in bad)} is {a[tuple(bad)]}; expected finite values")
    return a


class BabyBenchEnv(_EnvBase):
    """A BabyBench env (behaviour from the config) stepped in C++.

    Args:
      config: a dict of BabyBench keys, a YAML file path, or None for the documented defaults.
      training: as babybench.utils.make_env: prepare save_dir (scene/, logs/, videos/) and
        record every episode in save_dir/logs/training.jsonl.
      render_mode: None or "rgb_array" (render() then returns a render_size^2 RGB image).
      seed: seed of the env's generator (random start actions) until reset(seed=...) reseeds it.
      copy_observations: True: fresh arrays each step; False: read-only views of the env's
        buffers, overwritten by the next step.
      camera: the model camera render() draws ("corner", "top", "side1", "side2", "closeup",
        "eye_left", "eye_right").
      overwrite: with training, replace a training log already in save_dir (without it such a
        folder is refused: a finished run's log is never replaced silently).
    """

    def __init__(
        self,
        config=None,
        training=True,
        render_mode=None,
        seed=0,
        copy_observations=True,
        camera="corner",
        overwrite=False,
    ):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', not {render_mode!r}")
        if not isinstance(seed, numbers.Integral) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, not {seed!r}")
        self._config = _cradle.default_config() if config is None else load_config(config)
        # As the reference's env.config: every key as a plain dict (parsed, defaults filled in).
        self.config = json.loads(self._config.to_json())
        self.training = bool(training)
        self._closed = False
        log = os.path.join(self._config.save_dir, "logs", "training.jsonl")
        if self.training and not overwrite and os.path.isfile(log) and os.path.getsize(log) > 0:
            raise ValueError(f"{log} holds the training log of an earlier run; pass "
                             "overwrite=True to replace it, or give another save_dir")
        self._core = _cradle.Env(self._config, self.training, int(seed), bool(copy_observations))
        self.render_mode = render_mode
        self.camera = camera
        self.behavior = self._config.behavior
        self.action_space = spaces.from_core_box(self._core.action_space)
        self.observation_space = spaces.from_core_dict(self._core.observation_space)
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": round(1.0 / self._core.dt)}
        self.max_episode_steps = self._config.max_episode_steps
        self.dt = self._core.dt

    # The reference's documented attributes (views of the C++ state; see docs/python.md).
    @property
    def model(self):
        """The compiled model: nu, nq, nv, nbody, ..., actuator(i).name, joint(name).id, ..."""
        return self._core.model

    @property
    def data(self):
        """The simulation state: read-only qpos, qvel, ctrl, xpos, ... (they follow the env)."""
        return self._core.data

    @property
    def proprioception(self):
        """joint_names, sensor_names, size."""
        return self._core.proprioception

    @property
    def touch(self):
        """The skin (None when touch is off): sensor_positions, sensor_outputs, sensor_count."""
        return self._core.touch

    @property
    def steps(self):
        """Env steps in the current episode."""
        return self._core.episode_steps

    def reset(self, *, seed=None, options=None):
        """Starts an episode: (observation, info). A seed reseeds the env's generator (and
        np_random); None continues its stream. `options` is accepted and ignored."""
        if seed is not None and (not isinstance(seed, numbers.Integral) or seed < 0):
            raise ValueError(f"seed must be a non-negative integer, not {seed!r}")
        if self._closed:
            raise ValueError("reset() after close(): this env is closed; make a new one")
        if seed is not None and seed > 2**64 - 1:
            raise ValueError(f"seed must be at most 2**64 - 1, not {seed!r}")
        super().reset(seed=seed)
        return self._core.reset(None if seed is None else int(seed))

    def step(self, action):
        """One env step: (observation, reward, terminated, truncated, info). The action is any
        array-like of action_space.shape (converted to float64); the GIL is released while C++
        steps. truncated is True at max_episode_steps (the reference's TimeLimit)."""
        if self._closed:
            raise ValueError("step() after close(): this env is closed; make a new one")
        return self._core.step(_check_actions(action, self.action_space.shape, "action"))

    def render(self):
        """An RGB image (render_size x render_size x 3, uint8) of `camera` for
        render_mode="rgb_array"; None otherwise."""
        if self.render_mode != "rgb_array":
            return None
        size = self._config.render_size
        return self._core.render(self.camera, size, size)

    def close(self):
        """Records the last (partial) episode in the training log and flushes it."""
        self._core.close()
        self._closed = True

    def __repr__(self):
        return f"<BabyBenchEnv behavior={self.behavior!r} training={self.training}>"


def make_env(config, training=True, **kwargs):
    """As babybench.utils.make_env(config, training): a BabyBenchEnv from a config dict or YAML
    path. Extra keyword arguments go to BabyBenchEnv (render_mode, seed, copy_observations,
    camera)."""
    return BabyBenchEnv(config, training=training, **kwargs)


def make(env_id, **kwargs):
    """As gym.make(env_id): any listed env id or alias (cradle.env_specs()), or a Gymnasium id
    (cradle/...-v0).

    BabyBench ids ("BabyBench", "BabyBench-SelfTouch", "BabyBench-HandRegard",
    "babybench/<config>" or a YAML path) give a BabyBenchEnv: make(env_id, training=False,
    render_mode=None, seed=0, copy_observations=True, **overrides) with config keys overridden by
    keyword, e.g. make("BabyBench-SelfTouch", touch_scale=2.0, save_dir="/tmp/st"); unlike
    make_env, training defaults to False (gym.make writes no logs).

    Every other id ("mimo/reach", "MIMoReach-v0", "tma/parkour:fish", "sami/CrippleAnt:moderate")
    gives a cradle.RegistryEnv: make(env_id, seed=0, render_mode=None, **options) with the family's
    constructor options by keyword. An unknown id raises ValueError naming the closest ids.
    """
    if not isinstance(env_id, str):
        raise ValueError(f"env id must be a string such as 'mimo/reach', not {env_id!r}")
    name = env_id[len("cradle/"):] if env_id.startswith("cradle/") else env_id
    name = name.rsplit("-v", 1)[0] if name.rsplit("-v", 1)[-1].isdigit() else name
    if name in ENV_IDS:
        file = ENV_IDS[name]
        return _make_babybench(None if file is None else os.path.join(CONFIG_DIR, file), **kwargs)
    from . import registry

    spec = registry.env_spec(env_id)
    if spec.family == "babybench":
        return _make_babybench(spec.config or None, **kwargs)
    return registry.RegistryEnv(spec.id, **kwargs)


def _make_babybench(config_file, training=False, render_mode=None, seed=0, copy_observations=True,
                    **overrides):
    """A BabyBenchEnv of a config file (None: the documented defaults) with keys overridden."""
    base = _cradle.default_config() if config_file is None else load_config(config_file)
    config = json.loads(base.to_json())
    unknown = sorted(set(overrides) - set(_cradle.config_keys()))
    if unknown:
        raise ValueError(f"unknown config key '{unknown[0]}' in make() overrides")
    config.update(overrides)
    return BabyBenchEnv(
        config,
        training=training,
        render_mode=render_mode,
        seed=seed,
        copy_observations=copy_observations,
    )


def register_gymnasium_envs():
    """Registers "cradle/BabyBench-v0", "cradle/BabyBench-SelfTouch-v0",
    "cradle/BabyBench-HandRegard-v0" and every listed id (cradle.registry.gymnasium_id) with
    Gymnasium (done on import when it is installed)."""
    if _gymnasium is None:
        return
    for env_id in ENV_IDS:
        full_id = f"cradle/{env_id}-v0"
        if full_id not in _gymnasium.registry:
            _gymnasium.register(
                id=full_id, entry_point="cradle.env:make", kwargs={"env_id": env_id}
            )
    from . import registry

    registry.register_gymnasium_envs()
