"""TeachMyAgent's two environments (Box2D, stepped in C++), Gymnasium-shaped.

    import numpy as np
    from cradle import tma
    env = tma.make("parametric-continuous-parkour-v0", agent_body_type="fish", movable_creepers=True)
    env.set_environment(input_vector=np.zeros(3), water_level=0.1)   # before reset()
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    frame = env.render()                                              # (400, 600, 3) uint8

Observations are float32, as the reference's observation space. ``make`` also takes the
reference's body options (``motors_torque``, ``nb_of_bodies``, ``nb_pairs_of_legs``,
``nb_steps_under_water``, ``nb_steps_outside_water``) and Parkour options (``CPPN_weights_path``,
``input_CPPN_dim``, ``ceiling_offset``, ``ceiling_clip_offset``); docs/tma_run.md says what each
does. ``info["success"]`` is "episode return so far > 230". ``tma.gym.make(...)`` returns the
same env with the reference's old Gym API (``reset() -> obs``, ``step() -> obs, reward, done,
info``), so the TeachMyAgent README example runs with ``from cradle.tma import gym``.
"""

import numbers
import os
import sys
import types

import numpy as np

from . import _cradle
from . import spaces

STUMP_TRACKS = "parametric-continuous-stump-tracks-v0"
PARKOUR = "parametric-continuous-parkour-v0"
ENV_IDS = (STUMP_TRACKS, PARKOUR)
LIDAR_TYPES = ("down", "up", "full")


def embodiments():
    """Every embodiment name (the seed's ten, then classic_bipedal)."""
    return list(_cradle.tma_embodiments())


# The reference's body and Parkour constructor options (see TmaEnv), their Python types.
_INT_OPTIONS = ("nb_of_bodies", "nb_pairs_of_legs", "nb_steps_under_water",
                "nb_steps_outside_water", "input_CPPN_dim")
_FLOAT_OPTIONS = ("motors_torque", "ceiling_offset", "ceiling_clip_offset")
OPTIONS = ("motors_torque",) + _INT_OPTIONS[:4] + (
    "CPPN_weights_path", "input_CPPN_dim", "ceiling_offset", "ceiling_clip_offset")


def _option_text(name, value):
    """An option's value as the text the C++ env parses; ValueError for a wrong type."""
    if name == "CPPN_weights_path":
        if not isinstance(value, (str, os.PathLike)):
            raise ValueError(f"option CPPN_weights_path must be a path (got {type(value).__name__})")
        return os.fspath(value)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.generic)):
        kind = "an integer" if name in _INT_OPTIONS else "a number"
        raise ValueError(f"option {name} must be {kind} (got {value!r})")
    value = value.item() if isinstance(value, np.generic) else value
    # repr keeps every digit of a float; the env checks ranges and integrality.
    return repr(int(value)) if isinstance(value, numbers.Integral) else repr(float(value))


def _task_values(name, value):
    """A task value (number, sequence or numpy array) as a list of floats."""
    if isinstance(value, (numbers.Real, np.generic)) and np.ndim(value) == 0:
        return [float(value)]
    array = np.asarray(value, dtype=np.float64)
    if array.ndim != 1:
        raise ValueError(f"task parameter {name} must be a number or a 1-D sequence")
    return [float(v) for v in array]


class TmaEnv:
    """One TeachMyAgent environment; see the module docstring."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 50}

    def __init__(
        self,
        env_id=STUMP_TRACKS,
        agent_body_type="old_classic_bipedal",
        movable_creepers=False,
        lidars_type=None,
        water_clip=20.0,
        max_episode_steps=2000,
        render_mode="rgb_array",
        **options,
    ):
        """``options``: the reference's body options (motors_torque; nb_of_bodies for the
        millipede; nb_pairs_of_legs for the spider; nb_steps_under_water for walkers and
        climbers; nb_steps_outside_water for the fish) and Parkour options (CPPN_weights_path,
        input_CPPN_dim, ceiling_offset, ceiling_clip_offset). None keeps the default."""
        unknown = sorted(k for k in options if k not in OPTIONS)
        if unknown:
            accepted = ", ".join(
                ("movable_creepers", "lidars_type", "water_clip", "max_episode_steps",
                 "render_mode") + OPTIONS)
            raise ValueError(
                f"unknown TeachMyAgent option '{unknown[0]}' (expected one of: {accepted})")
        pairs = [(k, _option_text(k, v)) for k, v in options.items() if v is not None]
        if env_id not in ENV_IDS:
            raise ValueError(f"unknown env id '{env_id}' (expected one of {', '.join(ENV_IDS)})")
        if lidars_type is not None and lidars_type not in LIDAR_TYPES:
            raise ValueError(f"unknown lidars_type '{lidars_type}' (expected down, up or full)")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"unknown render_mode '{render_mode}' (expected 'rgb_array' or None)")
        self._env = _cradle.TmaEnv(
            env_id,
            agent_body_type,
            lidars_type or "",
            bool(movable_creepers),
            float(water_clip),
            int(max_episode_steps),
            pairs,
        )
        self.env_id = env_id
        self.render_mode = render_mode
        self.agent_body_type = agent_body_type
        self.action_space = spaces.make_box(-1.0, 1.0, (self._env.action_size,), np.float32)
        # float32 as the reference's observation space (values computed in float64, rounded once).
        self.observation_space = spaces.make_box(
            -np.inf, np.inf, (self._env.observation_size,), np.float32
        )

    @property
    def body_type(self):
        """walker, climber, swimmer or amphibian."""
        return self._env.body_type

    def set_environment(self, **task):
        """Sets the task of the next reset(). Stump Tracks: stump_height, obstacle_spacing, and
        the optional stump_width=(mean, std), stump_rot=(mean, std) (radians), roughness.
        Parkour: input_vector (input_CPPN_dim values, 3 by default), water_level, creepers_width, creepers_height,
        creepers_spacing, terrain_cppn_scale. None leaves a parameter at its default."""
        params = [(k, _task_values(k, v)) for k, v in task.items() if v is not None]
        self._env.set_environment(params)

    def reset(self, *, seed=None, options=None):
        if options:
            self.set_environment(**options)
        return self._env.reset(seed), {}

    def step(self, action):
        action = np.asarray(action, dtype=np.float64).ravel()
        obs, reward, terminated, truncated, success = self._env.step(action)
        return obs, reward, terminated, truncated, {"success": success}

    def render(self, width=600, height=400, lidars=True):
        """An RGB frame of the scene (camera on the head)."""
        return self._env.render(width, height, lidars)

    def terrain(self):
        """(x, ground, ceiling, water_y) of the current terrain (ceiling empty in Stump Tracks)."""
        xs, ground, ceiling, water_y = self._env.terrain()
        return np.asarray(xs), np.asarray(ground), np.asarray(ceiling), water_y

    def head_position(self):
        return self._env.head_position()

    def close(self):
        pass


def make(env_id, **kwargs):
    """As the reference's gym.make(env_id, agent_body_type=..., ...): a TmaEnv."""
    return TmaEnv(env_id, **kwargs)


class OldGymEnv:
    """The reference's Gym API over a TmaEnv: reset() -> obs, step() -> (obs, r, done, info)."""

    def __init__(self, env):
        self.env = env
        self.action_space = env.action_space
        self.observation_space = env.observation_space

    def set_environment(self, **task):
        self.env.set_environment(**task)

    def reset(self):
        return self.env.reset()[0]

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        return obs, reward, terminated or truncated, info

    def render(self, mode="rgb_array"):
        return self.env.render()

    def close(self):
        self.env.close()


gym = types.SimpleNamespace(make=lambda env_id, **kwargs: OldGymEnv(make(env_id, **kwargs)))



def __getattr__(name):
    """`from cradle.tma import analysis`: the campaign analysis (python/cradle/tma_analysis.py),
    imported on first use so the envs do not pull in pandas and matplotlib."""
    if name == "analysis":
        from . import tma_analysis

        sys.modules[__name__ + ".analysis"] = tma_analysis
        return tma_analysis
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
