"""Stable-Baselines3 adapter: cradle.sb3.SB3VecEnv is an SB3 VecEnv over Cradle's C++ vector env,
so SB3 algorithms collect rollouts from N envs of any family stepped by C++ threads::

    from stable_baselines3 import PPO
    from cradle.sb3 import SB3VecEnv
    venv = SB3VecEnv("configs/config_selftouch.yml", num_envs=4)      # a BabyBench config
    venv = SB3VecEnv("tma/parkour:fish", num_envs=4)                  # or any env id
    PPO("MultiInputPolicy", venv).learn(100_000)

SB3 resets an env in the step that ends its episode and reports the last observation as
info["terminal_observation"]; the adapter uses the vector's same-step autoreset for that.
Importing this module without stable_baselines3 installed raises ImportError.
"""

import numpy as np
from stable_baselines3.common.vec_env import VecEnv as _SB3VecEnv

from .vector import VectorEnv, _registry_spec

# Keys of the vector infos that are not per-env info values.
_SKIP = ("final_obs", "final_info")


class SB3VecEnv(_SB3VecEnv):
    """num_envs envs of a BabyBench config or of any env id as an SB3 VecEnv, or an existing
    cradle.VectorEnv made with autoreset_mode="same_step".

    Args:
      env: a BabyBench config (dict, YAML path or parsed config), any listed env id
        ("tma/parkour:fish", "mimo/reach", "sami/CrippleAnt:moderate"), or a cradle.VectorEnv
        (then num_envs, threads, training and env_options come from it and must be left out).
      training: log every episode in the config's training log (BabyBench only; default: True
        for a BabyBench config or id, as make_env, False otherwise).
      seed: the seed of the first reset() when SB3 gives none (default 0; an existing vector's
        own generator when left out).
      env_options: an env id's constructor options, as cradle.VectorEnv's.
    """

    def __init__(self, env, num_envs=None, threads=None, training=None, seed=None,
                 env_options=None):
        if isinstance(env, VectorEnv):
            given = [name for name, value in (("num_envs", num_envs), ("threads", threads),
                                              ("training", training),
                                              ("env_options", env_options)) if value is not None]
            if given:
                raise ValueError(f"{', '.join(given)}: the vector is given, so these come from it "
                                 "(leave them out)")
            if env.closed:
                raise ValueError("the vector is closed; give an open cradle.VectorEnv")
            if getattr(env, "autoreset_mode", None) != "same_step":
                raise ValueError("SB3 resets an env in the step that ends its episode: make the "
                                 "vector with cradle.VectorEnv(..., autoreset_mode=\"same_step\")")
            self._vec = env
            self._next_seed = seed
        else:
            if isinstance(env, str):
                spec = _registry_spec(env)  # ValueError naming the closest ids for an unknown id
                babybench = spec is None or spec.family == "babybench"
            else:
                babybench = True
            if training is None:
                training = babybench
            self._vec = VectorEnv(env, 1 if num_envs is None else num_envs,
                                  threads=0 if threads is None else threads, training=training,
                                  seed=0 if seed is None else seed, autoreset_mode="same_step",
                                  env_options=env_options)
            self._next_seed = 0 if seed is None else seed
        self._actions = None
        super().__init__(self._vec.num_envs, self._vec.single_observation_space,
                         self._vec.single_action_space)

    def _infos(self, infos, dones, truncated, terminated):
        out = []
        for i in range(self.num_envs):
            if dones is not None and dones[i]:
                info = dict(infos["final_info"][i])
                info["terminal_observation"] = infos["final_obs"][i]
                info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
            else:
                info = {
                    k: v[i] for k, v in infos.items() if not k.startswith("_") and k not in _SKIP
                }
            out.append(info)
        return out

    def reset(self):
        # SB3 >= 2.2 keeps the seeds given to seed() in _seeds until the next reset.
        seeds = getattr(self, "_seeds", None)
        seed = seeds[0] if seeds and seeds[0] is not None else self._next_seed
        self._next_seed = None
        obs, infos = self._vec.reset(seed=seed)
        if hasattr(self, "_reset_seeds"):
            self._reset_seeds()
        self.reset_infos = self._infos(infos, None, None, None)
        return obs

    def step_async(self, actions):
        self._actions = np.asarray(actions, dtype=np.float64).reshape(self.num_envs, -1)

    def step_wait(self):
        obs, rewards, terminated, truncated, infos = self._vec.step(self._actions)
        dones = terminated | truncated
        return obs, rewards.astype(np.float32), dones, self._infos(infos, dones, truncated,
                                                                    terminated)

    def close(self):
        self._vec.close()

    def get_images(self):
        raise NotImplementedError("SB3VecEnv does not render; use cradle.make_env(render_mode=...)")

    def _indices(self, indices):
        if indices is None:
            return range(self.num_envs)
        if isinstance(indices, int):
            return [indices]
        return indices

    def get_attr(self, attr_name, indices=None):
        if attr_name == "render_modes":
            value = ["rgb_array"]
        elif attr_name == "render_mode":
            value = None
        else:
            value = getattr(self._vec, attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(self, attr_name, value, indices=None):
        setattr(self._vec, attr_name, value)

    def env_method(self, method_name, *method_args, indices=None, **method_kwargs):
        method = getattr(self._vec, method_name)
        return [method(*method_args, **method_kwargs) for _ in self._indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False for _ in self._indices(indices)]
