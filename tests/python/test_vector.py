"""cradle.VectorEnv: batched arrays, Gymnasium next-step autoreset, same-step mode, determinism."""

import numpy as np
import pytest

import cradle


def test_batches_and_next_step_autoreset(make_config):
    vec = cradle.VectorEnv(make_config("selftouch", max_episode_steps=3), num_envs=2, threads=2)
    assert vec.action_space.shape == (2, 30)
    obs, infos = vec.reset(seed=4)
    assert obs["observation"].shape == (2, 264) and obs["touch"].dtype == np.float32
    assert list(infos["steps"]) == [0, 0] and infos["_steps"].all()
    actions = np.zeros((2, 30))
    for t in range(3):
        obs, rewards, terminated, truncated, infos = vec.step(actions)
        assert rewards.shape == (2,) and rewards.dtype == np.float64
        assert not terminated.any()
        assert truncated.all() == (t == 2)
        assert list(infos["steps"]) == [t, t]
    last = obs["observation"].copy()
    # Next step: both envs start their next episode instead of stepping.
    obs, rewards, terminated, truncated, infos = vec.step(actions)
    assert not truncated.any() and not terminated.any() and (rewards == 0).all()
    assert list(infos["steps"]) == [0, 0]
    assert [len(x) for x in infos["right_hand_touches"]] == [0, 0]
    assert not np.array_equal(obs["observation"], last)
    obs, _, _, truncated, infos = vec.step(actions)
    assert list(infos["steps"]) == [0, 0] and not truncated.any()
    vec.close()


def test_same_step_autoreset_and_thread_independence(make_config):
    config = make_config("selftouch", max_episode_steps=2)
    runs = []
    for threads, mode in ((1, "same_step"), (2, "same_step")):
        vec = cradle.VectorEnv(config, num_envs=3, threads=threads, autoreset_mode=mode)
        obs, _ = vec.reset(seed=11)
        rng = np.random.default_rng(0)
        seen = [obs["observation"].copy()]
        for t in range(3):
            space = vec.single_action_space
            actions = rng.uniform(space.low, space.high, (3, 30))
            obs, rewards, terminated, truncated, infos = vec.step(actions)
            seen.append(obs["observation"].copy())
            if t == 1:
                assert truncated.all() and infos["_final_obs"].all()
                assert infos["final_obs"][0]["observation"].shape == (264,)
                assert infos["final_info"][0]["steps"] == 1
                assert list(infos["steps"]) == [0, 0, 0]  # already the next episode
            else:
                assert not infos["_final_obs"].any()
        runs.append(seen)
        vec.close()
    for a, b in zip(*runs):
        np.testing.assert_array_equal(a, b)  # same seed, any number of threads: same batches


def test_vector_rejects_bad_input(make_config):
    vec = cradle.VectorEnv(make_config("selftouch"), num_envs=2)
    vec.reset(seed=0)
    with pytest.raises(ValueError, match=r"expected \(2, 30\)"):
        vec.step(np.zeros((2, 29)))
    with pytest.raises(ValueError):
        cradle.VectorEnv(make_config("selftouch"), num_envs=0)


def test_worker_processes_give_the_thread_vectors_batches(make_config):
    config = make_config("selftouch", max_episode_steps=4)
    runs = []
    for procs in (0, 2):
        vec = cradle.VectorEnv(config, num_envs=4, threads=2, procs=procs)
        assert vec.procs == procs
        obs, infos = vec.reset(seed=7)
        rng = np.random.default_rng(1)
        seen = [(obs, infos)]
        for _ in range(10):
            space = vec.single_action_space
            seen.append(vec.step(rng.uniform(space.low, space.high, (4, 30))))
        runs.append(seen)
        vec.close()
    for a, b in zip(*runs):
        for x, y in zip(a, b):
            if isinstance(x, dict):
                assert x.keys() == y.keys()
                for key in x:
                    if x[key].dtype == object:
                        assert [list(v) for v in x[key]] == [list(v) for v in y[key]]
                    else:
                        np.testing.assert_array_equal(x[key], y[key])
            else:
                np.testing.assert_array_equal(x, y)
    with pytest.raises(ValueError, match="3 envs do not split evenly over 2 processes"):
        cradle.VectorEnv(config, num_envs=3, procs=2)
