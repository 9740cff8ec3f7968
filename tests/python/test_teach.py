"""cradle.teach: the curriculum teachers from a Python student loop."""

import numpy as np
import pytest

import cradle.teach


def fake_episode(task):
    # Easy when the first coordinate is small: (return, success).
    ret = 200.0 * (1.0 - task[0] / 3.0)
    return ret, ret > 150.0


def test_names():
    assert cradle.teach.teacher_names() == [
        "Random", "ADR", "ALP-GMM", "Covar-GMM", "RIAC", "Self-Paced", "GoalGAN", "Setter-Solver"]


def test_alp_gmm_student_loop_and_book_keeping():
    teacher = cradle.teach.make_teacher("ALP-GMM", mins=[0, 0], maxs=[3, 6], seed=1,
                                        fit_rate=50, potential_ks=np.arange(2, 5),
                                        random_task_ratio=0.05)
    assert teacher.name == "alp_gmm" and teacher.dims == 2
    assert not teacher.is_non_exploratory_task_sampling_available()
    for _ in range(120):
        task = teacher.sample_task()
        assert task.dtype == np.float32 and task.shape == (2,)
        assert 0 <= task[0] <= 3 and 0 <= task[1] <= 6
        ret, success = fake_episode(task)
        teacher.episodic_update(task, ret, success)
    assert teacher.is_non_exploratory_task_sampling_available()
    snapshot = teacher.non_exploratory_task_sampling()
    assert snapshot.dtype == np.float32 and snapshot.shape == (2,)
    dump = teacher.dump()
    assert dump["episodes"] == 120 and dump["fits"] == 2
    assert len(dump["task_origins"]) == 120


def test_same_seed_same_curriculum():
    a = cradle.teach.make_teacher("RIAC", [0, 0], [1, 1], seed=5)
    b = cradle.teach.make_teacher("RIAC", [0, 0], [1, 1], seed=5)
    for _ in range(50):
        ta, tb = a.sample_task(), b.sample_task()
        np.testing.assert_array_equal(ta, tb)
        a.episodic_update(ta, float(ta[0]), False)
        b.episodic_update(tb, float(tb[0]), False)


def test_self_paced_step_hooks_and_value_estimator():
    teacher = cradle.teach.make_teacher(
        "Self-Paced", [0, 0], [1, 1], seed=2, expert_knowledge="high",
        initial_dist=([0.2, 0.2], [0.01, 0.01]), update_frequency=100, update_offset=0, zeta=0.5)
    seen = []

    def value(states):
        seen.append(states.shape)
        return 10.0 * (1.0 - np.hypot(states[:, 0] - 0.5, states[:, 1] - 0.5))

    teacher.set_value_estimator(value)
    for _ in range(50):
        task = teacher.sample_task()
        teacher.record_initial_state(task, task)
        for step in range(10):
            teacher.step_update(task, np.zeros(1), 1.0, task, step == 9)
        teacher.episodic_update(task, 10.0, True)
    dump = teacher.dump()
    assert dump["iterations"] == 5 and seen and seen[0][1] == 2
    assert dump["history"][-1]["kl"] < dump["history"][0]["kl"]


def test_errors_are_one_line_value_errors():
    with pytest.raises(ValueError, match="unknown teacher 'alp-gmm'"):
        cradle.teach.make_teacher("alp-gmm", [0], [1])
    with pytest.raises(ValueError, match="unknown parameter 'fit_rat'"):
        cradle.teach.make_teacher("ALP-GMM", [0], [1], fit_rat=10)
    with pytest.raises(ValueError, match="expected an integer"):
        cradle.teach.make_teacher("ALP-GMM", [0], [1], fit_rate=1.5)
    with pytest.raises(ValueError, match="expert knowledge none"):
        cradle.teach.make_teacher("ADR", [0], [1], expert_knowledge="none")
    with pytest.raises(ValueError, match="expected none"):
        cradle.teach.make_teacher("ADR", [0], [1], expert_knowledge="maximal")
    with pytest.raises(ValueError, match="mins but"):
        cradle.teach.make_teacher("Random", [0, 0], [1])


# Small settings so that every teacher fits or trains within a few dozen episodes.
SMALL = {
    "ALP-GMM": dict(fit_rate=10, potential_ks=[2, 3]),
    "Covar-GMM": dict(fit_rate=10, potential_ks=[2, 3]),
    "RIAC": dict(max_region_size=10),
    "GoalGAN": dict(update_size=8, n_rollouts=1, train_iterations=2),
    "Setter-Solver": dict(update_frequency=8, setter_hidden_size=8),
    "Self-Paced": dict(update_frequency=10, update_offset=0),
}


def small_teacher(name):
    return cradle.teach.make_teacher(name, [0, 0], [3, 6], seed=1, expert_knowledge="low",
                                     **SMALL.get(name, {}))


def play(teacher, episodes):
    teacher.set_value_estimator(lambda states: np.ones(len(states), dtype=np.float32))
    for e in range(episodes):
        task = teacher.sample_task()
        assert np.all(np.isfinite(task)) and 0 <= task[0] <= 3 and 0 <= task[1] <= 6
        teacher.record_initial_state(task, task)
        teacher.step_update(task, [0.0], 1.0, task, True)
        teacher.episodic_update(task, 200.0 if task[0] < 1 else 10.0 * (e % 3), task[0] < 1)


@pytest.mark.parametrize("name", cradle.teach.teacher_names())
def test_every_teacher_refuses_bad_episodes_and_keeps_working(name):
    teacher = small_teacher(name)
    for _ in range(3):
        for ret in [np.nan, np.inf, -np.inf, 1e170, -1e300, 2e15]:
            with pytest.raises(ValueError, match=r"^teacher: episode return is .*; expected a finite"):
                teacher.episodic_update([1.0, 2.0], ret, True)
        for task in [[], [1.0], [1.0, 2.0, 3.0], [np.nan, 2.0], np.array([1.0, np.inf]),
                     [-np.inf, 0.0], [1.0, 1e300]]:
            with pytest.raises(ValueError, match=r"^teacher: episode task"):
                teacher.episodic_update(task, 1.0, False)
        play(teacher, 20)
    with pytest.raises(ValueError, match="initial-state task has 1 values"):
        teacher.record_initial_state([1.0], [0.0])
    with pytest.raises(ValueError, match="step reward is nan"):
        teacher.step_update([0.0], [0.0], np.nan, [0.0], False)
    assert np.all(np.isfinite(teacher.non_exploratory_task_sampling()))
    assert isinstance(teacher.dump(), dict)


def test_alp_gmm_fuzz_case_is_a_value_error_not_a_crash():
    # The fuzzer's crash: non-finite and huge returns and a NaN task, then sampling and dump().
    teacher = cradle.teach.make_teacher("ALP-GMM", [0, 0], [3, 6], seed=1, expert_knowledge="low",
                                        fit_rate=10)
    for n in range(40):
        task = teacher.sample_task()
        for bad in [np.nan, np.inf, 1e170]:
            with pytest.raises(ValueError):
                teacher.episodic_update(task, bad, False)
        with pytest.raises(ValueError):
            teacher.episodic_update([np.nan, task[1]], 1.0, False)
        teacher.episodic_update(task, float(n % 7), False)
    dump = teacher.dump()
    assert dump["episodes"] == 40 and dump["fits"] == 4 and dump["failed_fits"] == 0
    assert all(np.all(np.isfinite(c["mean"])) for c in dump["components"])


def test_gmm_teachers_stay_finite_at_the_return_bound():
    for name in ["ALP-GMM", "Covar-GMM"]:
        teacher = small_teacher(name)
        for n in range(100):
            task = teacher.sample_task()
            assert np.all(np.isfinite(task)) and 0 <= task[0] <= 3 and 0 <= task[1] <= 6
            teacher.episodic_update(task, (-1) ** n * 1e15 * task[0] / 3, False)
        assert teacher.dump()["fits"] == 10


def self_paced_until_update(estimator):
    teacher = small_teacher("Self-Paced")
    teacher.set_value_estimator(estimator)
    for _ in range(10):
        task = teacher.sample_task()
        teacher.record_initial_state(task, task)
        teacher.step_update(task, [0.0], 1.0, task, True)
    return teacher


def test_self_paced_refuses_a_misbehaving_value_estimator():
    with pytest.raises(ValueError, match="returned 9 values for 10 states"):
        self_paced_until_update(lambda states: np.ones(len(states) - 1))
    with pytest.raises(ValueError, match="returned 20 values for 10 states"):
        self_paced_until_update(lambda states: np.ones((len(states), 2)))
    with pytest.raises(ValueError, match="value 0 is nan"):
        self_paced_until_update(lambda states: np.full(len(states), np.nan))

    class Broken(Exception):
        pass

    def raises(states):
        raise Broken("student not ready")

    with pytest.raises(Broken, match="student not ready"):
        self_paced_until_update(raises)
    with pytest.raises(ValueError, match="no value estimator"):
        self_paced_until_update(None)
