"""Curriculum teachers (TeachMyAgent's ACL methods), run in C++, driven from a Python loop.

    import cradle.teach
    teacher = cradle.teach.make_teacher("ALP-GMM", mins=[0, 0], maxs=[3, 6], seed=1,
                                        fit_rate=150, random_task_ratio=0.05)
    for episode in range(1000):
        task = teacher.sample_task()            # float32 array, inside [mins, maxs]
        ret, success = play_one_episode(task)   # your env and student
        teacher.episodic_update(task, ret, success)
    teacher.dump()                              # the teacher's book-keeping as a dict

Names: teacher_names(). Keyword arguments are the reference's teacher kwargs (docs/teach.md); an
unknown one, or one of the wrong type, raises ValueError naming it.
"""

import json
import numbers

import numpy as np

from . import _cradle

__all__ = ["Teacher", "make_teacher", "teacher_names"]


def teacher_names():
    """The valid teacher names, in the reference's order."""
    return list(_cradle.teacher_names())


def _plain(value, key):
    # numpy scalars and arrays to JSON-able Python values.
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v, key) for v in value]
    if value is None or isinstance(value, (bool, numbers.Number, str)):
        return value
    raise ValueError(f"make_teacher: parameter {key!r} is a {type(value).__name__}; "
                     "expected a number, bool, string, list or None")


def _dist(value, what):
    # (mean, variance) or {"mean": ..., "variance": ...}; None stays None.
    if value is None:
        return None
    if isinstance(value, dict):
        if set(value) != {"mean", "variance"}:
            raise ValueError(f"make_teacher: {what} has keys {sorted(value)}; "
                             "expected mean and variance")
        value = (value["mean"], value["variance"])
    if len(value) != 2:
        raise ValueError(f"make_teacher: {what} expected (mean, variance)")
    return ([float(v) for v in np.ravel(value[0])], [float(v) for v in np.ravel(value[1])])


class Teacher:
    """A teacher over flat float task vectors in the box [mins, maxs] (hooks of TeachMyAgent's
    AbstractTeacher)."""

    def __init__(self, core):
        self._core = core

    @property
    def name(self):
        return self._core.name

    @property
    def dims(self):
        return self._core.dims

    def sample_task(self):
        """The task of the next training episode (float32 array)."""
        return self._core.sample_task()

    def non_exploratory_task_sampling(self):
        """A task with no exploration noise (curriculum snapshots)."""
        return self._core.non_exploratory_task_sampling()

    def is_non_exploratory_task_sampling_available(self):
        return self._core.is_non_exploratory_task_sampling_available()

    def record_initial_state(self, task, s0):
        """After each reset (only Self-Paced uses it)."""
        self._core.record_initial_state(_floats(task), _floats(s0))

    def step_update(self, s, a, r, s_next, done):
        """After each env step (only Self-Paced uses it)."""
        self._core.step_update(_floats(s), _floats(a), float(r), _floats(s_next), bool(done))

    def episodic_update(self, task, ret, success):
        """At the end of each training episode played on `task`."""
        self._core.episodic_update(_floats(task), float(ret), bool(success))

    def set_value_estimator(self, fn):
        """fn((n, state_dim) float32 array) -> n values: the student's V(s) (Self-Paced)."""
        self._core.set_value_estimator(fn)

    def dump(self):
        """The teacher's book-keeping as a dict."""
        return json.loads(self._core.dump_json())

    def __repr__(self):
        return f"<cradle.teach.Teacher {self.name} dims={self.dims}>"


def _floats(x):
    return [float(v) for v in np.ravel(np.asarray(x, dtype=np.float64))]


def make_teacher(name, mins, maxs, seed=0, expert_knowledge="none", initial_dist=None,
                 target_dist=None, reward_bounds=(-100.0, 100.0), scale_reward=False, **params):
    """Builds a teacher by name (see teacher_names()).

    Args:
      name: e.g. "ALP-GMM", "Self-Paced", "GoalGAN".
      mins, maxs: the task box, one value per dimension.
      seed: the teacher's seed (same seed, same curriculum).
      expert_knowledge: "none" (or "no"), "low" or "high" (TeachMyAgent's levels; ADR, GoalGAN and
        Setter-Solver refuse "none").
      initial_dist, target_dist: (mean, variance) of a diagonal Gaussian: the env's easy region
        and Self-Paced's target, used at "high".
      reward_bounds, scale_reward: the env's return bounds, when the teacher sees scaled returns.
      **params: the teacher's kwargs by the reference's names (fit_rate=150, ...).
    """
    if not isinstance(name, str):
        raise ValueError(f"make_teacher: name must be a string, got {type(name).__name__}")
    if not isinstance(expert_knowledge, str):
        raise ValueError("make_teacher: expert_knowledge must be 'none', 'low' or 'high'")
    if len(reward_bounds) != 2:
        raise ValueError("make_teacher: reward_bounds expected (lb, ub)")
    plain = {key: _plain(value, key) for key, value in params.items()}
    core = _cradle.make_teacher(
        name, [float(v) for v in np.ravel(mins)], [float(v) for v in np.ravel(maxs)], int(seed),
        expert_knowledge, json.dumps(plain), _dist(initial_dist, "initial_dist"),
        _dist(target_dist, "target_dist"), float(reward_bounds[0]), float(reward_bounds[1]),
        bool(scale_reward))
    return Teacher(core)
