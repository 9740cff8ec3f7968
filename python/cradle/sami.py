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
import os

import numpy as np

from . import _cradle
from . import spaces
from .env import _EnvBase

ENV_NAMES = tuple(_cradle.sami_env_names())
# The largest action magnitude step() takes.
_MAX_ACTION = 1e6


def _is_text(value, text):
    """value == text for a str value (an array would compare element by element)."""
    return isinstance(value, str) and value == text


def _short(value):
    """A value for a one-line error message."""
    text = repr(value).replace("\n", " ")
    return text if len(text) <= 60 else text[:57] + "..."


def _integer(name, value, low, high):
    """An int argument in [low, high] or a one-line ValueError naming it (bools refused)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) or not (
            low <= value <= high):
        raise ValueError(f"{name} must be an integer from {low} to {high} (got {_short(value)})")
    return int(value)


def _seed(seed):
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, numbers.Integral) or not (
            0 <= seed < 2**64):
        raise ValueError(f"seed must be a non-negative integer below 2^64, not {_short(seed)}")
    return int(seed)


def _flag(name, value):
    """A bool argument (True, False, or numpy's) or a one-line ValueError naming it."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False (got {_short(value)})")
    return bool(value)


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
        if render_mode is not None and not _is_text(render_mode, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', not {_short(render_mode)}")
        if not isinstance(name, str):
            raise ValueError(f"name must be one of {', '.join(ENV_NAMES)} (got {_short(name)})")
        if not isinstance(split, (str, os.PathLike)):
            raise ValueError("split must be train, moderate, extreme or a path to a .yml file "
                             f"(got {_short(split)})")
        split = os.fspath(split)
        seed = _seed(seed)
        contact_forces = _flag("contact_forces", contact_forces)
        self._core = _cradle.SamiEnv(name, split, seed, contact_forces)
        self._needs_reset = True
        self.name = self._core.name
        self.split = split
        self.render_mode = render_mode
        self.action_space = spaces.from_core_box(self._core.action_space)
        self._low = np.asarray(self.action_space.low, dtype=np.float64)
        self._high = np.asarray(self.action_space.high, dtype=np.float64)
        self.observation_space = spaces.from_core_dict(self._core.observation_space)
        self.max_episode_steps = self._core.horizon
        self.dt = self._core.dt
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": round(1.0 / self.dt)}

    def _live(self, method):
        """The C++ env, or a one-line ValueError once close() released it."""
        if self._core is None:
            raise ValueError(f"{method}: the env is closed (make a new one)")
        return self._core

    def reset(self, *, seed=None, options=None):
        """``seed``: an integer from 0 to 2^64 - 1 or None. SaMI envs take no reset options (the
        split draws each episode's hidden parameters): ``options`` must be None or empty."""
        core = self._live("reset")
        if seed is not None:
            seed = _seed(seed)
        if options is not None and (not isinstance(options, dict) or options):
            keys = ", ".join(map(str, options)) if isinstance(options, dict) else _short(options)
            raise ValueError(f"reset options {keys} are not supported (SaMI envs take no reset "
                             "options; the split draws the hidden parameters)")
        result = core.reset(seed)
        self._needs_reset = False
        return result

    def step(self, action):
        """``action``: action_space.shape real, finite values of magnitude at most 1e6 (anything
        else is a one-line ValueError). As in the reference, an action outside the action space is
        passed on as it is: PandaPush clips it to [-1, 1], and the locomotion envs let MuJoCo clamp
        the controls to their ctrlrange while the control cost is charged on the action given (so
        a policy that overshoots pays for it, as it did in SaMI's runs)."""
        core = self._live("step")
        if self._needs_reset:
            raise ValueError("step: call reset() before the first step")
        try:
            array = np.asarray(action)
        except (TypeError, ValueError):
            array = np.asarray(None)
        if array.dtype.kind not in "iuf":
            raise ValueError(
                f"action has dtype {array.dtype} (expected real numbers)")
        if array.shape != self._low.shape:
            raise ValueError(f"action has shape {array.shape} (expected {self._low.size} values, "
                             f"shape {self._low.shape})")
        array = array.astype(np.float64)
        bad = np.flatnonzero(~np.isfinite(array))
        if bad.size:
            raise ValueError(f"action {bad[0]} is {array[bad[0]]} (expected finite values)")
        # No policy outputs such values; the reference's control cost would overflow on them.
        bad = np.flatnonzero(np.abs(array) > _MAX_ACTION)
        if bad.size:
            raise ValueError(f"action {bad[0]} is {array[bad[0]]:.6g} (expected a magnitude of "
                             f"at most {_MAX_ACTION:g})")
        return core.step(array)

    @property
    def model(self):
        """Read-only numpy views of the env's MuJoCo model: this episode's hidden parameters
        (body_mass, dof_damping, geom_size, geom_friction, pair_friction, ...), with the sizes
        and body/joint/geom/actuator names."""
        return self._live("model").model

    @property
    def data(self):
        """Read-only numpy views of the env's mjData (qpos, qvel, xpos, ...); they follow the env."""
        return self._live("data").data

    def render(self, width=320, height=240):
        """An RGB frame (height, width, 3), width and height from 16 to 4096; None unless
        render_mode is "rgb_array"."""
        core = self._live("render")
        width = _integer("width", width, 16, 4096)
        height = _integer("height", height, 16, 4096)
        if self.render_mode != "rgb_array":
            return None
        return core.render(width, height)

    def close(self):
        """Releases the env (views from model and data stay readable); later calls raise
        ValueError. Closing twice is fine."""
        self._core = None

    def __repr__(self):
        return f"<SamiEnv {self.name} split={self.split}>"


def make(name, split="train", seed=0, **kwargs):
    """A SaMI env by name, e.g. make("CrippleHalfCheetah", split="moderate")."""
    return SamiEnv(name, split=split, seed=seed, **kwargs)


METHODS = ("TESAC", "CCM", "SaTESAC", "SaCCM", "SaCCMAll")


def train(env=None, method=None, seed=0, steps_per_env=0, hyperparameters=None,
          out="", resume=False, checkpoint_every=100_000, progress_bar=False):
    """`cradle sami train` from Python: trains a SaMI method on the env's training task sets.

    env and method default to PandaPush and SaCCM; resume=True with out continues that run's env
    and method (an env or method given must be the run's, else ValueError). steps_per_env=0 takes
    SaMI's budget (500k per env; PandaPush 1M). hyperparameters: a dict of overrides
    ({"batch_size": 32}). The run folder is `cradle train --env`'s (run.json, logs/progress.csv,
    checkpoints/). Returns a dict: run, steps, updates, sps, gradient_steps_per_s, last_return,
    checkpoint (checkpoints/final.ckpt). Bad inputs raise ValueError (one line).
    """
    continues = bool(resume) and bool(str(out))
    env = ("" if continues else "PandaPush") if env is None else env
    method = ("" if continues else "SaCCM") if method is None else method
    hp = {str(k): str(v).lower() if isinstance(v, bool) else
          ",".join(str(x) for x in v) if isinstance(v, (list, tuple)) else str(v)
          for k, v in (hyperparameters or {}).items()}
    return _cradle.sami_train(str(env), str(method), int(seed), int(steps_per_env), hp, str(out),
                              bool(resume), int(checkpoint_every), bool(progress_bar))


def evaluate(run, split="train", episodes=10, video=False, seed=12345):
    """`cradle sami evaluate` from Python: per task cell success rate, return and skill mix.

    Writes eval_<split>.json / .csv and contexts_<split>.csv into the run folder and returns the
    same numbers as a dict (cells: a list of dicts).
    """
    return _cradle.sami_evaluate(str(run), str(split), int(episodes), bool(video), int(seed))


def table(runs, out=""):
    """`cradle sami table`: the paper's Table 1/2 layout (markdown) over evaluated runs."""
    return _cradle.sami_table([str(r) for r in runs], str(out))


def plot_contexts(csv, png, title=None):
    """Draws a contexts_<split>.csv (written by evaluate) as two scatter plots of its 2-D PCA.

    Panda push: coloured by task cell (friction, mass) and by the episode's skill (push, roll,
    pick-and-place). Locomotion, which has no skill labels: by the crippled joints each episode
    drew and by its mass factor. Needs matplotlib."""
    import csv as csv_module

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(csv, newline="") as f:
        rows = list(csv_module.DictReader(f))
    if not rows:
        raise ValueError(f"{csv}: no contexts")
    x = np.array([float(r["pc1"]) for r in rows])
    y = np.array([float(r["pc2"]) for r in rows])
    has_skills = any(r["episode_skill"] != "none" for r in rows)
    panels = (("cell", "task"), ("episode_skill", "skill")) if has_skills else (
        ("crippled", "crippled joints"), ("mass", "mass factor"))
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, (key, name) in zip(axes, panels):
        labels = sorted({r[key] for r in rows})
        colours = plt.cm.tab20 if len(labels) > 10 else plt.cm.tab10
        for i, label in enumerate(labels):
            mask = np.array([r[key] == label for r in rows])
            ax.scatter(x[mask], y[mask], s=4, alpha=0.6, label=label,
                       color=colours(i % colours.N))
        ax.set_title(f"contexts by {name}")
        ax.set_xlabel("PC 1")
        ax.set_ylabel("PC 2")
        ax.legend(fontsize=6, markerscale=3, ncol=2 if len(labels) > 10 else 1)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png
