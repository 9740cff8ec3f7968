"""Every env of every family by one id (the list `cradle envs` prints), Gymnasium-shaped.

    import cradle
    env = cradle.make("tma/parkour:fish")     # or "mimo/reach", "sami/CrippleAnt:moderate", ...
    obs, info = env.reset(seed=0, options={"water_level": 0.5})
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

Ids: ``babybench/<config>``, ``mimo/<task>``, ``tma/<env>:<embodiment>`` and
``sami/<Env>[:<split>]``, plus the references' names as aliases (``BabyBench-SelfTouch``,
``MIMoReach-v0``, ``sami/CrippleAnt`` for its train split). ``cradle.make`` returns a
``BabyBenchEnv`` for BabyBench ids and a ``RegistryEnv`` for the other families.

Gymnasium ids: every listed id is registered as ``cradle/<id>-v0`` with ``/`` replaced by ``-``
and ``:`` by ``.`` (Gymnasium's ids allow one ``/`` and read ``:`` as a module name), e.g.
``cradle/tma-parkour.fish-v0``, ``cradle/sami-CrippleAnt.moderate-v0``, ``cradle/mimo-reach-v0``;
MIMo's envs also under their reference names (``cradle/MIMoReach-v0``).
"""

import numbers
import os

import numpy as np

from . import _cradle
from . import spaces
from .env import _EnvBase, _check_actions, _gymnasium

_SEED_MAX = 2**64 - 1


def gymnasium_id(env_id):
    """The Gymnasium id a listed id is registered under: "tma/parkour:fish" ->
    "cradle/tma-parkour.fish-v0"."""
    return "cradle/" + env_id.replace("/", "-").replace(":", ".") + "-v0"


def env_specs():
    """Every listed env, by family (babybench, mimo, tma, sami) then name, as EnvSpec objects:
    id, family, summary, max_episode_steps, task_parameters ({name: (low, high)}), aliases,
    natural_envs (SaMI: envs a vector needs for one of each training task set) and config
    (BabyBench: its YAML file)."""
    return list(_cradle.env_specs())


def env_ids():
    """Every listed id (aliases not included), as env_specs() orders them."""
    return [spec.id for spec in _cradle.env_specs()]


_gymnasium_names = None


def _gymnasium_names_to_ids():
    """Gymnasium id -> registry id, for every id register_gymnasium_envs registers."""
    global _gymnasium_names
    if _gymnasium_names is None:
        names = {}
        for spec in _cradle.env_specs():
            names[gymnasium_id(spec.id)] = spec.id
            if spec.family == "mimo":
                names.update({f"cradle/{alias}": spec.id for alias in spec.aliases})
        _gymnasium_names = names
    return _gymnasium_names


def env_spec(env_id):
    """The EnvSpec of an id, an alias, a Gymnasium id (cradle/...-v0) or a YAML path (a BabyBench
    config, or "sami/<Env>:<task sets>.yml"). An unknown id raises ValueError naming the closest
    listed ids."""
    if not isinstance(env_id, str):
        raise ValueError(f"env id must be a string such as 'mimo/reach', not {env_id!r}")
    name = _gymnasium_names_to_ids().get(env_id)
    if name is None:
        name = env_id[len("cradle/"):] if env_id.startswith("cradle/") else env_id
    try:
        return _cradle.env_spec(name)
    except ValueError as error:
        # An id the registry parses but its family refuses (an unknown TeachMyAgent env or body)
        # names what the family knows; add the closest listed ids. Config files' errors stay as
        # they are.
        if "closest" in str(error) or name.endswith((".yml", ".yaml")):
            raise
        closest = ", ".join(_cradle.close_env_ids(name))
        raise ValueError(f"{error}; closest listed ids: {closest}") from None


def _option_text(name, value):
    """A constructor option's value as the text the C++ family parses."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, str):
        return value
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    raise ValueError(f"env option {name} must be a string, a number or a bool (got {value!r})")


def option_texts(options):
    """Constructor options as {name: text} (None values dropped: the default is kept)."""
    return {name: _option_text(name, value) for name, value in options.items()
            if value is not None}


def _seed(seed):
    """A seed as an int in [0, 2^64 - 1], or a one-line ValueError."""
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, numbers.Integral) or not (
            0 <= seed <= _SEED_MAX):
        raise ValueError(f"seed must be an integer from 0 to 2**64 - 1, not {seed!r}")
    return int(seed)


def reset_options(options):
    """Reset options as {name: float}: a dict of task parameter names to real numbers; a 1-D
    sequence of numbers stands for name_0, name_1, ... (input_vector=[0, 0.5, 1]). ValueError for
    anything else; names and ranges are the env's to check."""
    if not isinstance(options, dict):
        raise ValueError(f"reset options must be a dict of task parameters, not {options!r}")
    out = {}
    for name, value in options.items():
        if not isinstance(name, str):
            raise ValueError(f"reset option name {name!r} is not a string")
        if isinstance(value, (list, tuple, np.ndarray)):
            values = np.asarray(value)
            if values.ndim != 1 or values.dtype.kind not in "iuf":
                raise ValueError(f"reset option {name} must be a number or a 1-D sequence of "
                                 f"numbers (got {value!r})")
            out.update({f"{name}_{i}": float(v) for i, v in enumerate(values)})
        elif isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
            raise ValueError(f"reset option {name} must be a real number (got {value!r})")
        else:
            out[name] = float(value)
    return out


class RegistryEnv(_EnvBase):
    """One env of any listed id, stepped in C++ (what cradle.make returns for the MIMo sample,
    TeachMyAgent and SaMI families).

    Args:
      env_id: an id, alias or Gymnasium id (see env_specs()).
      seed: seed of the env's generator until reset(seed=...) reseeds it.
      render_mode: None or "rgb_array" (render() then returns an RGB array).
      vector_index: None for a lone env, or the env's place i in a VectorEnv: with
        seed=VectorEnv.env_seed(s, i) the env is that vector's env i (SaMI: a lone env draws from
        every task set of the split, env i of a vector from set i mod the number of sets).
      **options: the family's constructor options, e.g. TeachMyAgent's motors_torque or
        nb_of_bodies, MIMo's actuation ("spring_damper" or "muscle"), SaMI's contact_forces.
        None keeps the default.
    """

    def __init__(self, env_id, seed=0, render_mode=None, vector_index=None, **options):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', not {render_mode!r}")
        spec = env_spec(env_id)
        if vector_index is None:
            index = -1
        elif isinstance(vector_index, (bool, np.bool_)) or not isinstance(
                vector_index, numbers.Integral) or vector_index < 0:
            raise ValueError(f"vector_index must be None or a non-negative integer, not "
                             f"{vector_index!r}")
        else:
            index = int(vector_index)
        self._core = _cradle.RegistryEnv(spec.id, _seed(seed), option_texts(options), index)
        self.env_spec = spec
        self.spec_id = spec.id
        self.family = spec.family
        self.max_episode_steps = spec.max_episode_steps
        self.render_mode = render_mode
        if render_mode is not None and not self._core.renders:
            raise NotImplementedError(f"env '{spec.id}' has no renderer here")
        self.action_space = spaces.from_core_box(self._core.action_space)
        self.observation_space = spaces.from_core_dict(self._core.observation_space)
        self.metadata = {"render_modes": ["rgb_array"] if self._core.renders else []}
        self._closed = False

    @property
    def task_parameters(self):
        """The reset options a teacher can set: {name: (low, high)}."""
        return self.env_spec.task_parameters

    def _live(self, method):
        if self._closed:
            raise ValueError(f"{method}() after close(): this env is closed; make a new one")
        return self._core

    def reset(self, *, seed=None, options=None):
        """Starts an episode: (observation, info). A seed reseeds the env's generator (and
        np_random); None continues its stream. ``options``: task parameters as reset options
        ({name: value}, see task_parameters); they stay set for later resets. An unknown name or a
        value out of range raises ValueError."""
        core = self._live("reset")
        if seed is not None:
            seed = _seed(seed)
        if options is not None:
            core.set_reset_options(reset_options(options))
        super().reset(seed=seed)
        return core.reset(seed)

    def step(self, action):
        """One env step: (observation, reward, terminated, truncated, info). The action is any
        array-like of action_space.shape (converted to float64); the GIL is released while C++
        steps. The env truncates at max_episode_steps itself."""
        core = self._live("step")
        return core.step(_check_actions(action, self.action_space.shape, "action"))

    def render(self, width=None, height=None):
        """An RGB array (height, width, 3) for render_mode="rgb_array", None otherwise. Sizes:
        MIMo's render size (500 x 500), TeachMyAgent's 600 x 400 and SaMI's 320 x 240 unless given
        (TeachMyAgent and SaMI, 16 to 4096 pixels)."""
        core = self._live("render")
        if not core.renders:
            raise NotImplementedError(f"env '{self.spec_id}' has no renderer here")
        if self.render_mode != "rgb_array":
            return None
        if (width is None) != (height is None):
            raise ValueError("render: give both width and height, or neither")
        if width is None:
            return core.render()
        for name, value in (("width", width), ("height", height)):
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
                raise ValueError(f"render {name} must be an integer, not {value!r}")
        return core.render(int(width), int(height))

    @property
    def model(self):
        """Read-only views of the MuJoCo model (the MIMo and SaMI families; SaMI's holds this
        episode's hidden parameters)."""
        model = self._live("model").model
        if model is None:
            raise AttributeError(f"env '{self.spec_id}' has no MuJoCo model (TeachMyAgent runs "
                                 "on Box2D)")
        return model

    @property
    def data(self):
        """Read-only views of the env's mjData (qpos, qvel, xpos, ...); they follow the env."""
        data = self._live("data").data
        if data is None:
            raise AttributeError(f"env '{self.spec_id}' has no MuJoCo data (TeachMyAgent runs on "
                                 "Box2D)")
        return data

    def task(self):
        """The current episode's task, named as the reset options: TeachMyAgent's terrain
        parameters, SaMI's hidden parameters. None for the families that do not read theirs
        back (MIMo, BabyBench)."""
        return self._live("task").task()

    def score(self):
        """The task's score of the episode so far (None when the task has none)."""
        return self._live("score").score()

    def close(self):
        """Ends the run (the env's last records); later calls raise ValueError. Closing twice is
        fine."""
        if not self._closed:
            self._core.close()
            self._closed = True

    def __repr__(self):
        return f"<RegistryEnv {self.spec_id}>"


def register_gymnasium_envs():
    """Registers every listed id with Gymnasium as gymnasium_id(id) (and MIMo's reference names as
    cradle/<name>), each made by cradle.make. Done on import when Gymnasium is installed."""
    if _gymnasium is None:
        return
    for name, env_id in _gymnasium_names_to_ids().items():
        if name not in _gymnasium.registry:
            _gymnasium.register(id=name, entry_point="cradle.env:make", kwargs={"env_id": env_id})
