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
