"""A curriculum teacher written in Python drives a C++ training run: cradle.train(teacher=obj)
hands every env reset's task to the object's sample_task() and every finished episode to its
episodic_update(); a wrong object, a wrong task or an exception inside the teacher stops the run
with one clear Python exception (docs/curricula.md, "A teacher of your own, in Python")."""

import json
import threading

import pytest

import cradle

ENV = "tma/stump-tracks:old_classic_bipedal"
PPO = {"n_steps": 64, "batch_size": 64, "n_epochs": 1}
SPACE = "params:\n  stump_height: [0, 3]\n  obstacle_spacing: [0, 6]\n"


@pytest.fixture
def space(tmp_path):
    path = tmp_path / "space.yml"
    path.write_text(SPACE)
    return path


def run(space, save_dir, teacher, steps=3000):
    return cradle.train(env=ENV, algo="ppo", steps=steps, envs=2, hyperparameters=PPO,
                        task_space=space, teacher=teacher, save_dir=save_dir, progress_bar=False)


def longest_decreasing(values):
    best = []
    for i, v in enumerate(values):
        best.append(1 + max([best[j] for j in range(i) if values[j] > v], default=0))
    return max(best, default=0)


class Counting:
    """Hands out task k = (k % 24 / 8, k // 24 % 48 / 8): distinct, exact in float32, in bounds."""

    def __init__(self):
        self.handed, self.updates, self.threads = [], [], set()

    def sample_task(self):
        self.threads.add(threading.get_ident())
        k = len(self.handed)
        task = [(k % 24) * 0.125, (k // 24 % 48) * 0.125]
        self.handed.append(task)
        return task

    def episodic_update(self, task, episode_return, success):
        self.updates.append((list(map(float, task)), episode_return, success))

    def dump(self):
        return {"handed": len(self.handed), "teacher": "not Cradle's key"}


def test_a_python_teacher_drives_a_teachmyagent_run(tmp_path, space):
    teacher = Counting()
    run(space, tmp_path / "run", teacher)
    with open(tmp_path / "run" / "logs" / "teacher.jsonl") as f:
        lines = [json.loads(line) for line in f]
    episodes = [e for e in lines if e["kind"] == "train"]
    assert len(episodes) >= 2
    # The controller books an episode when it ends, in the order episodes end (the two envs'
    # interleave): the same calls, in the same order, as the teacher's episodic_update.
    assert [e["task"] for e in episodes] == [u[0] for u in teacher.updates]
    assert [e["return"] for e in episodes] == pytest.approx([u[1] for u in teacher.updates],
                                                            rel=1e-12, abs=1e-12)
    assert [e["success"] for e in episodes] == [u[2] for u in teacher.updates]
    # Every booked task was handed out by the teacher, once; what was handed out and not booked
    # is the episode each env was playing when the run ended.
    booked = [tuple(e["task"]) for e in episodes]
    assert len(set(booked)) == len(booked)
    assert set(booked) <= {tuple(t) for t in teacher.handed}
    assert len(teacher.handed) - len(booked) <= 2
    # Each env plays its tasks in the order the teacher handed them out, so the booked order is
    # two increasing runs of hand-out indices merged: no decreasing subsequence of 3.
    order = {tuple(t): i for i, t in enumerate(teacher.handed)}
    assert longest_decreasing([order[t] for t in booked]) <= 2
    # The dump line: Cradle's keys (the class name, the bounds), then the teacher's own.
    dump = lines[-1]
    assert dump["kind"] == "dump"
    assert dump["teacher"] == {"teacher": "Counting", "mins": [0, 0], "maxs": [3, 6],
                               "handed": len(teacher.handed)}


class NoUpdate:
    def sample_task(self):
        return [1.0, 1.0]


def test_a_missing_method_is_a_value_error_before_anything_is_written(tmp_path, space):
    with pytest.raises(ValueError, match=r"has no method episodic_update\(task, episode_return, "
                                         r"success\)"):
        run(space, tmp_path / "run", NoUpdate())
    with pytest.raises(ValueError, match=r"has no method sample_task\(\)"):
        run(space, tmp_path / "run", object())
    assert not (tmp_path / "run").exists()


class Failing(Counting):
    """Raises in sample_task after `after` tasks, or in episodic_update after `updates` updates."""

    def __init__(self, after=None, updates=None):
        super().__init__()
        self.after, self.max_updates = after, updates

    def sample_task(self):
        if self.after is not None and len(self.handed) >= self.after:
            raise ZeroDivisionError("the teacher gave up")
        return super().sample_task()

    def episodic_update(self, task, episode_return, success):
        if self.max_updates is not None and len(self.updates) >= self.max_updates:
            raise KeyError("no such task")
        super().episodic_update(task, episode_return, success)


@pytest.mark.parametrize("teacher, message, cause", [
    (Failing(after=0), r"teacher Failing\.sample_task\(\) raised ZeroDivisionError: the teacher "
                       r"gave up", ZeroDivisionError),
    (Failing(updates=2), r"teacher Failing\.episodic_update\(\) raised KeyError: 'no such task'",
     KeyError),
])
def test_an_exception_inside_the_teacher_stops_the_run(tmp_path, space, teacher, message, cause):
    with pytest.raises(RuntimeError, match=message) as raised:
        run(space, tmp_path / "run", teacher, steps=20_000)
    assert isinstance(raised.value.__cause__, cause)
    assert "\n" not in str(raised.value)
    # Later envs stop too: the run ended at the failing call, not at its step budget.
    assert len(teacher.handed) < 100


class Fixed:
    def __init__(self, task):
        self.task = task

    def sample_task(self):
        return self.task

    def episodic_update(self, task, episode_return, success):
        pass


@pytest.mark.parametrize("task, message", [
    ([1.0, 6.5], r"sample_task\(\) returned obstacle_spacing = 6\.5, outside its bounds \[0, 6\]"),
    ([-0.5, 1.0], r"stump_height = -0\.5, outside its bounds \[0, 3\]"),
    ([1.0, float("nan")], r"obstacle_spacing = nan; expected a number in \[0, 6\]"),
    ([1.0, 2.0, 3.0], r"returned \[1\.0, 2\.0, 3\.0\]; expected a sequence of 2 numbers "
                      r"\(stump_height, obstacle_spacing\)"),
    ("ab", r"returned 'ab'; expected a sequence of 2 numbers"),
])
def test_a_task_outside_the_task_space_is_a_value_error(tmp_path, space, task, message):
    with pytest.raises(ValueError, match=message) as raised:
        run(space, tmp_path / "run", Fixed(task), steps=256)
    assert "\n" not in str(raised.value)


class BadDump(Fixed):
    def dump(self):
        return {"seen": {1, 2}}


def test_a_dump_that_is_not_json_is_a_value_error(tmp_path, space):
    with pytest.raises(ValueError, match=r"teacher BadDump: dump\(\) returned a dict that is not "
                                         r"JSON \(.*set.*\)"):
        run(space, tmp_path / "run", BadDump([1.0, 2.0]), steps=256)


def test_resume_replays_the_booked_episodes_into_the_teacher(tmp_path, space):
    run(space, tmp_path / "run", Counting())
    with open(tmp_path / "run" / "logs" / "teacher.jsonl") as f:
        booked = [e for e in map(json.loads, f) if e["kind"] == "train"]
    fresh = Counting()
    cradle.train(env=ENV, algo="ppo", steps=4096, envs=2, hyperparameters=PPO, task_space=space,
                 teacher=fresh, save_dir=tmp_path / "run", progress_bar=False, resume=True)
    # One sample_task() (discarded) and one episodic_update() per booked episode, then the run.
    assert [u[0] for u in fresh.updates[:len(booked)]] == [e["task"] for e in booked]
    assert [u[1] for u in fresh.updates[:len(booked)]] == pytest.approx(
        [e["return"] for e in booked], rel=1e-12, abs=1e-12)
    assert len(fresh.handed) > len(booked)


def test_without_a_task_space_the_teacher_sets_every_parameter_the_env_declares(tmp_path):
    # Stump Tracks declares stump_height [0, 3] and obstacle_spacing [0, 6]: the same box as the
    # file's, so the Python teacher's tasks fit it.
    teacher = Counting()
    cradle.train(env=ENV, algo="ppo", steps=3000, envs=2, hyperparameters=PPO, teacher=teacher,
                 save_dir=tmp_path / "run", progress_bar=False)
    with open(tmp_path / "run" / "logs" / "teacher.jsonl") as f:
        lines = [json.loads(line) for line in f]
    assert lines[-1]["teacher"]["mins"] == [0, 0]
    assert lines[-1]["teacher"]["maxs"] == [3, 6]
    assert len([e for e in lines if e["kind"] == "train"]) == len(teacher.updates) >= 2
    # An env without task parameters is a ValueError naming it, and nothing is written.
    with pytest.raises(ValueError, match="mimo/standup has no task parameters"):
        cradle.train(env="mimo/standup", algo="ppo", steps=64, teacher="Random",
                     save_dir=tmp_path / "standup", progress_bar=False)
    assert not (tmp_path / "standup").exists()
