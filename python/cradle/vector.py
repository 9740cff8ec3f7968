"""cradle.VectorEnv: N envs stepped together by C++ threads (a BabyBench config's, or any listed
env id's), with Gymnasium 1.x vector semantics: batched numpy observations (num_envs, ...),
reward/terminated/truncated arrays, infos as a dict of arrays with "_key" masks, and next-step
autoreset (an env whose episode ended in one step() is reset by the next, which reports reward 0
and the new episode's first observation).

Every step returns fresh arrays. The envs share what their family compiles once (a model, a
CPPN); env i is seeded with env_seed(seed, i), the i-th seed derived from reset(seed=...), so a
seed gives the same batches for any number of threads.
"""

import numbers
import os

import numpy as np

from . import _cradle
from . import spaces
from . import registry
from .env import _check_actions, _gymnasium, load_config

if _gymnasium is not None:
    import gymnasium.vector as _gym_vector

    _VectorBase = _gym_vector.VectorEnv
    _NEXT_STEP = getattr(_gym_vector, "AutoresetMode", None)
    _NEXT_STEP = _NEXT_STEP.NEXT_STEP if _NEXT_STEP is not None else "next_step"
    _SAME_STEP = getattr(_gym_vector, "AutoresetMode", None)
    _SAME_STEP = _SAME_STEP.SAME_STEP if _SAME_STEP is not None else "same_step"
else:
    _VectorBase = object
    _NEXT_STEP, _SAME_STEP = "next_step", "same_step"


def _registry_spec(config):
    """The EnvSpec of an env id given as VectorEnv's first argument; None for a config (a dict, a
    parsed config, or a path: an existing file or a name ending in .yml / .yaml)."""
    if not isinstance(config, str) or os.path.exists(config) or config.endswith((".yml", ".yaml")):
        return None
    return registry.env_spec(config)


class VectorEnv(_VectorBase):
    """num_envs envs of one BabyBench config or env id on a C++ thread pool (or, BabyBench, in
    worker processes).

    Args:
      config: a BabyBench config (dict, YAML path or parsed config) or any listed env id
        ("tma/parkour:fish", "mimo/reach", "sami/CrippleAnt:moderate", "BabyBench-SelfTouch").
      num_envs: number of envs.
      threads: pool participants (0: one per env, at most the cores; 1: the calling thread only).
      procs: 0 (threads), or run the envs in that many worker processes (num_envs a multiple of
        it), so that envs which render draw in parallel. Make such a vector before anything in
        this process renders. BabyBench only.
      training: prepare save_dir and log every episode of every env in one training log
        (BabyBench only).
      seed: seed used by reset() without a seed (and of the seeds it draws afterwards); env i is
        built with env_seed(seed, i) and index i (SaMI: env i draws its tasks from training set
        i mod the number of sets).
      autoreset_mode: "next_step" (Gymnasium's default) or "same_step" (an ended env is reset in
        the same call; its last observation and info are in infos["final_obs"/"final_info"]).
      env_options: an env id's constructor options ({"motors_torque": 100}), as cradle.make's.
    """

    env_seed = staticmethod(_cradle.env_seed)

    def __init__(self, config, num_envs, threads=0, training=False, seed=0,
                 autoreset_mode="next_step", procs=0, env_options=None):
        if autoreset_mode not in ("next_step", "same_step"):
            raise ValueError("autoreset_mode must be 'next_step' or 'same_step'")
        if not isinstance(num_envs, numbers.Integral) or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, not {num_envs!r}")
        if not isinstance(threads, numbers.Integral) or isinstance(threads, bool) or threads < 0:
            raise ValueError(f"threads must be a non-negative integer (0: one per env, at most the "
                             f"cores), not {threads!r}")
        if not isinstance(procs, numbers.Integral) or procs < 0:
            raise ValueError(f"procs must be a non-negative integer, not {procs!r}")
        if not isinstance(seed, numbers.Integral) or isinstance(seed, bool) or not (
                0 <= seed <= 2**64 - 1):
            raise ValueError(f"seed must be an integer from 0 to 2**64 - 1, not {seed!r}")
        spec = _registry_spec(config)
        self.spec_id = spec.id if spec is not None else None
        self.family = spec.family if spec is not None else "babybench"
        if spec is not None and spec.family != "babybench":
            if training:
                raise ValueError(f"training=True is for BabyBench (env '{spec.id}' writes no "
                                 "training log)")
            self._config = None
            self._core = _cradle.VecEnv.for_id(spec.id, int(num_envs), int(threads), int(seed),
                                               autoreset_mode == "same_step",
                                               registry.option_texts(env_options or {}),
                                               int(procs))
        else:
            if env_options:
                raise ValueError("env_options are for env ids of the mimo, tma and sami families "
                                 "(a BabyBench config takes its keys)")
            if spec is not None:
                config = spec.config or _cradle.default_config()
            self._config = load_config(config)
            self._core = _cradle.VecEnv(self._config, int(num_envs), int(threads), bool(training),
                                        int(seed), autoreset_mode == "same_step", int(procs))
        self.num_envs = int(num_envs)
        self.autoreset_mode = autoreset_mode  # "next_step" or "same_step", as given
        self.single_observation_space = spaces.from_core_dict(self._core.observation_space)
        self.single_action_space = spaces.from_core_box(self._core.action_space)
        self.observation_space = spaces.batch_space(self.single_observation_space, self.num_envs)
        self.action_space = spaces.batch_space(self.single_action_space, self.num_envs)
        self.metadata = {
            "autoreset_mode": _NEXT_STEP if autoreset_mode == "next_step" else _SAME_STEP,
            "render_modes": [],
        }
        self.render_mode = None
        self.spec = None
        self.closed = False
        self._seeds = np.random.default_rng(seed)
        self._np_random = None

    @property
    def np_random(self):
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    @property
    def unwrapped(self):
        return self

    @property
    def threads(self):
        return self._core.threads

    @property
    def procs(self):
        """Worker processes (0: the envs run on threads)."""
        return self._core.procs

    def reset(self, *, seed=None, options=None):
        """Resets every env: (observations, infos). Env i gets env_seed(seed, i) (seed an int;
        None: the next seed of the vector's own generator). An env id's vector takes `options`,
        task parameters as reset options for every env (as RegistryEnv.reset's; they stay set for
        later resets); a BabyBench config's ignores them."""
        if self.closed:
            raise ValueError("reset() after close(): this vector is closed; make a new one")
        if options is not None and self._config is None:
            self._core.set_reset_options(registry.reset_options(options))
        if seed is None:
            seed = int(self._seeds.integers(2**63))
        elif not isinstance(seed, numbers.Integral) or seed < 0 or seed > 2**64 - 1:
            raise ValueError(f"seed must be a non-negative integer, not {seed!r}")
        else:
            self._np_random = np.random.default_rng(seed)
        return self._core.reset(int(seed))

    def step(self, actions):
        """actions: (num_envs, action dim). Returns (observations, rewards, terminated, truncated,
        infos); the C++ envs step in parallel with the GIL released."""
        if self.closed:
            raise ValueError("step() after close(): this vector is closed; make a new one")
        return self._core.step(_check_actions(actions, self.action_space.shape, "actions"))

    def render(self):
        return None

    def close(self, **kwargs):
        """Records the envs' last episodes in the training log (training mode)."""
        if not self.closed:
            self._core.close()
            self.closed = True

    def __repr__(self):
        if self._config is None:
            return f"<cradle.VectorEnv num_envs={self.num_envs} env={self.spec_id!r}>"
        return f"<cradle.VectorEnv num_envs={self.num_envs} behavior={self._config.behavior!r}>"
