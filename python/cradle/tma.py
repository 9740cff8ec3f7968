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

import json
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
    """A task value (a real number, a 1-D sequence or numpy array of them) as a list of floats;
    ValueError naming the parameter for anything else (bools, strings, complex, nested)."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        array = None
    if array is None or array.dtype.kind not in "iuf" or array.ndim > 1:
        raise ValueError(f"task parameter {name} must be a real number or a 1-D sequence of real "
                         f"numbers (got {_short(value)})")
    return [float(v) for v in np.atleast_1d(array.astype(np.float64))]


def _is_text(value, text):
    """value == text for a str value (an array would compare element by element)."""
    return isinstance(value, str) and value == text


def _short(value):
    """A value for a one-line error message."""
    text = repr(value).replace("\n", " ")
    return text if len(text) <= 60 else text[:57] + "..."


def _integer(name, value, low, high=None):
    """An int argument in [low, high] or a one-line ValueError naming it (bools refused)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) or not (
            low <= value and (high is None or value <= high)):
        bound = f"from {low} to {high}" if high is not None else f">= {low}"
        raise ValueError(f"{name} must be an integer {bound} (got {_short(value)})")
    return int(value)


def _flag(name, value):
    """A bool argument (True, False, or numpy's) or a one-line ValueError naming it."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False (got {_short(value)})")
    return bool(value)


def _number(name, value):
    """A finite real argument or a one-line ValueError naming it."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) or not (
            np.isfinite(float(value))):
        raise ValueError(f"{name} must be a finite real number (got {_short(value)})")
    return float(value)


def real_action(action, size):
    """``action`` as a float64 vector of ``size`` finite values, or a one-line ValueError saying
    which of shape, dtype (real) and finiteness it breaks."""
    try:
        array = np.asarray(action)
    except (TypeError, ValueError):
        array = np.asarray(None)
    if array.dtype.kind not in "iuf":
        raise ValueError(f"action has dtype {array.dtype} (expected real numbers)")
    if array.shape != (size,):
        raise ValueError(
            f"action has shape {array.shape} (expected {size} values, shape ({size},))")
    array = array.astype(np.float64)
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise ValueError(f"action {bad[0]} is {array[bad[0]]} (expected finite values)")
    return array


_SEED_MAX = 2**64 - 1


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
        if not isinstance(env_id, str) or env_id not in ENV_IDS:
            raise ValueError(
                f"unknown env id {_short(env_id)} (expected one of {', '.join(ENV_IDS)})")
        if not isinstance(agent_body_type, str):  # the env names the embodiments for other names
            raise ValueError("agent_body_type must be an embodiment name, one of tma.embodiments() "
                             f"(got {_short(agent_body_type)})")
        if lidars_type is not None and (not isinstance(lidars_type, str)
                                        or lidars_type not in LIDAR_TYPES):
            raise ValueError(
                f"unknown lidars_type {_short(lidars_type)} (expected down, up or full)")
        if render_mode is not None and not _is_text(render_mode, "rgb_array"):
            raise ValueError(
                f"unknown render_mode {_short(render_mode)} (expected 'rgb_array' or None)")
        self._env = _cradle.TmaEnv(
            env_id,
            agent_body_type,
            lidars_type or "",
            _flag("movable_creepers", movable_creepers),
            _number("water_clip", water_clip),
            _integer("max_episode_steps", max_episode_steps, 1, 2**31 - 1),
            pairs,
        )
        self._needs_reset = True
        self.env_id = env_id
        self.render_mode = render_mode
        self.agent_body_type = agent_body_type
        self.action_space = spaces.make_box(-1.0, 1.0, (self._env.action_size,), np.float32)
        # float32 as the reference's observation space (values computed in float64, rounded once).
        self.observation_space = spaces.make_box(
            -np.inf, np.inf, (self._env.observation_size,), np.float32
        )

    def _live(self, method):
        """The C++ env, or a one-line ValueError once close() released it."""
        if self._env is None:
            raise ValueError(f"{method}: the env is closed (make a new one)")
        return self._env

    @property
    def body_type(self):
        """walker, climber, swimmer or amphibian."""
        return self._live("body_type").body_type

    def set_environment(self, **task):
        """Sets the task of the next reset(). Stump Tracks: stump_height, obstacle_spacing, and
        the optional stump_width=(mean, std), stump_rot=(mean, std) (radians), roughness.
        Parkour: input_vector (input_CPPN_dim values, 3 by default), water_level,
        creepers_width, creepers_height, creepers_spacing, terrain_cppn_scale. None leaves a
        parameter at its default. A value that is not a real number or 1-D sequence of them, an
        unknown name or a value out of range is a one-line ValueError naming the parameter."""
        env = self._live("set_environment")
        params = [(k, _task_values(k, v)) for k, v in task.items() if v is not None]
        env.set_environment(params)

    def reset(self, *, seed=None, options=None):
        """``seed``: an integer from 0 to 2^64 - 1 or None. ``options``: a dict of the task
        parameters set_environment takes (they stay set for later resets); any other key is a
        ValueError."""
        env = self._live("reset")
        if seed is not None:
            seed = _integer("seed", seed, 0, _SEED_MAX)
        if options is not None:
            if not isinstance(options, dict) or not all(isinstance(k, str) for k in options):
                raise ValueError("reset options must be a dict of task parameters as "
                                 f"set_environment takes (got {_short(options)})")
            self.set_environment(**options)
        obs = env.reset(seed)
        self._needs_reset = False
        return obs, {}

    def step(self, action):
        """``action``: action_space.shape real, finite values (anything else is a one-line
        ValueError). As in the reference, which clips the motor commands to [-1, 1], values
        outside [-1, 1] are clipped."""
        env = self._live("step")
        if self._needs_reset:
            raise ValueError("step: call reset() before the first step")
        action = real_action(action, env.action_size)
        obs, reward, terminated, truncated, success = env.step(action)
        return obs, reward, terminated, truncated, {"success": success}

    def render(self, width=600, height=400, lidars=True):
        """An RGB frame of the scene (camera on the head); width and height from 16 to 4096."""
        env = self._live("render")
        return env.render(_integer("width", width, 16, 4096),
                          _integer("height", height, 16, 4096), _flag("lidars", lidars))

    def terrain(self):
        """(x, ground, ceiling, water_y) of the current terrain (ceiling empty in Stump Tracks)."""
        xs, ground, ceiling, water_y = self._live("terrain").terrain()
        return np.asarray(xs), np.asarray(ground), np.asarray(ceiling), water_y

    def head_position(self):
        return self._live("head_position").head_position()

    def close(self):
        """Releases the env; later calls raise ValueError. Closing twice is fine."""
        self._env = None


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
        if not _is_text(mode, "rgb_array"):
            raise ValueError(f"render mode {_short(mode)} is not supported (expected 'rgb_array')")
        return self.env.render()

    def close(self):
        self.env.close()


gym = types.SimpleNamespace(make=lambda env_id, **kwargs: OldGymEnv(make(env_id, **kwargs)))


def _text(name, value):
    if not isinstance(value, (str, os.PathLike)):
        raise ValueError(f"{name} must be a string (got {_short(value)})")
    return os.fspath(value)


def run(env="stump-tracks", embodiment="old_classic_bipedal", student="sac", teacher="ALP-GMM",
        steps=20_000_000, test_every=500_000, nb_test_episodes=100, seed=0,
        expert_knowledge="high", test_set="", hyperparameters=None, teacher_params=None,
        reset_frequency=0, shuffle_dimensions=False, scale_reward=False,
        keep_periodical_task_samples=0, exp_name="test", out="", resume=False, overwrite=False,
        progress_bar=False, **env_options):
    """`cradle tma run` from Python: a student (sac or ppo, the reference presets) trained with a
    teacher on TeachMyAgent's benchmark env, evaluated on the test set every test_every env steps.

    The same run folder, checks and resume as the CLI (docs/tma_run.md); env_options are the
    body and Parkour options (``motors_torque=...``); hyperparameters and teacher_params are
    dicts (a teacher value as JSON-able data). out defaults to tma_runs/<exp_name>/<exp_name>_s<seed>.
    Returns the run's summary.json as a dict (env_steps, episodes, evaluations, wall_s,
    env_steps_per_s, gradient_steps, teacher_s, pct_mastered, ...; None where there is no value,
    e.g. PPO's gradient steps) and its folder as "run". Bad inputs raise ValueError (one line).
    """
    a = _cradle.TmaRunArguments()
    a.exp_name, a.env = _text("exp_name", exp_name), _text("env", env)
    a.body, a.student = _text("embodiment", embodiment), _text("student", student)
    a.teacher, a.expert_knowledge = _text("teacher", teacher), _text("expert_knowledge",
                                                                      expert_knowledge)
    a.test_set, a.out = _text("test_set", test_set), _text("out", out)
    a.steps = _integer("steps", steps, 1, 1_000_000_000)
    a.test_every = _integer("test_every", test_every, 1)
    a.nb_test_episodes = _integer("nb_test_episodes", nb_test_episodes, 1, 2**31 - 1)
    a.seed = _integer("seed", seed, 0, 2**64 - 1)
    a.reset_frequency = _integer("reset_frequency", reset_frequency, 0)
    a.keep_periodical_task_samples = _integer("keep_periodical_task_samples",
                                              keep_periodical_task_samples, 0)
    a.shuffle_dimensions = _flag("shuffle_dimensions", shuffle_dimensions)
    a.scale_reward = _flag("scale_reward", scale_reward)
    a.resume, a.overwrite = _flag("resume", resume), _flag("overwrite", overwrite)
    a.progress_bar = _flag("progress_bar", progress_bar)
    for name, value in (("hyperparameters", hyperparameters), ("teacher_params", teacher_params)):
        if value is not None and not isinstance(value, dict):
            raise ValueError(f"{name} must be a dict (got {_short(value)})")
    def hp_text(v):  # as `--hp name=value` spells it: lists comma-separated, bools lower-case
        if isinstance(v, bool):
            return str(v).lower()
        return ",".join(map(str, v)) if isinstance(v, (list, tuple)) else str(v)
    a.hp = [f"{k}={hp_text(v)}" for k, v in (hyperparameters or {}).items()]
    try:
        a.teacher_params = [f"{k}={json.dumps(v)}" for k, v in (teacher_params or {}).items()]
    except TypeError as e:
        raise ValueError(f"teacher_params: {e}") from None
    unknown = sorted(set(env_options) - set(OPTIONS))
    if unknown:
        raise ValueError(f"unknown option {unknown[0]} (expected one of {', '.join(OPTIONS)})")
    a.env_options = {k: _option_text(k, v) for k, v in env_options.items()}
    return _cradle.tma_run(a)



def __getattr__(name):
    """`from cradle.tma import analysis`: the campaign analysis (python/cradle/tma_analysis.py),
    imported on first use so the envs do not pull in pandas and matplotlib."""
    if name == "analysis":
        from . import tma_analysis

        sys.modules[__name__ + ".analysis"] = tma_analysis
        return tma_analysis
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
