"""A trained policy of any run, by its folder: cradle.load_policy(run_folder) gives a Policy whose
predict(obs) returns the action for an observation dict as the run's env returns it::

    policy = cradle.load_policy("results/tma/stump-tracks:old_classic_bipedal")
    env = cradle.make(policy.env_id)
    obs, info = env.reset(seed=1000)
    policy.reset()
    while True:
        obs, reward, terminated, truncated, info = env.step(policy.predict(obs))
        if terminated or truncated:
            break

The actions are those `cradle evaluate --run` takes (the same C++ learner and checkpoint).
"""

import os

from . import _cradle, spaces


class Policy:
    """A run's trained policy (see load_policy).

    Attributes: env_id (the registered id the run trained on; None for a BabyBench config's
    run), family, algorithm, seed (the run's), checkpoint (the file), steps (env steps it was
    trained for), deterministic, observation_space and action_space (the env's).
    """

    def __init__(self, core, deterministic):
        self._core = core
        self.deterministic = deterministic
        self.env_id = core.env or None
        self.family = core.family
        self.algorithm = core.algorithm
        self.seed = core.seed
        self.checkpoint = core.checkpoint
        self.steps = core.steps
        self.observation_space = spaces.from_core_dict(core.observation_space)
        self.action_space = spaces.from_core_box(core.action_space)

    def predict(self, obs):
        """The action (a float64 array) for one observation dict as the env returns it."""
        return self._core.act(obs)

    __call__ = predict  # usable as cradle.evaluate(policy=...)'s fn(obs) -> action

    def reset(self):
        """Starts a new episode: call it after each env.reset() (a policy with memory, such as
        SaMI's context learners, forgets the last episode)."""
        self._core.new_episode()

    def __repr__(self):
        what = self.env_id or "a BabyBench config"
        return (f"<cradle.Policy {self.algorithm} on {what}, {os.path.basename(self.checkpoint)}, "
                f"{'mean' if self.deterministic else 'sampled'} actions>")


def load_run_policy(run_folder, checkpoint="final", deterministic=True):
    """The policy of a run folder (what cradle.train / `cradle train` wrote: run.json and
    checkpoints/): checkpoint is "final", "latest", "step_<n>" or a .ckpt path."""
    if not isinstance(checkpoint, (str, os.PathLike)):
        raise ValueError(f"checkpoint must be final, latest, step_<n> or a .ckpt path, not "
                         f"{checkpoint!r}")
    if not isinstance(deterministic, bool):
        raise ValueError(f"deterministic must be True or False, not {deterministic!r}")
    core = _cradle.RunPolicy(os.fspath(run_folder), os.fspath(checkpoint), not deterministic)
    return Policy(core, deterministic)
