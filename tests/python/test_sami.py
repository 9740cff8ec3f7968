"""cradle.sami: the SaMI envs from Python."""

import numpy as np
import pytest

import cradle.sami


def test_panda_push_extreme_split_hides_cell_and_labels_skills():
    env = cradle.sami.make("PandaPush", split="extreme", seed=1)
    obs, info = env.reset(seed=3)
    assert set(obs) == {"observation", "achieved_goal", "desired_goal"}
    assert obs["observation"].shape == (19,) and obs["observation"].dtype == np.float32
    # Extreme cells: mass 30 or friction 30.
    assert info["cube_mass"] == 30 or info["friction"] == 30
    total = 0.0
    for _ in range(5):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        dist = np.linalg.norm(obs["achieved_goal"] - obs["desired_goal"])
        assert reward == pytest.approx(-dist, abs=1e-5)
        total += reward
        if terminated:
            break
    assert info["skill"] in ("push", "roll", "pick_and_place", "down")
    assert info["episode_skill"] in ("push", "roll", "pick_and_place")


def test_locomotion_seeded_runs_repeat_and_report_hidden_parameters():
    def run():
        env = cradle.sami.make("CrippleHalfCheetah", split="moderate")
        obs, info = env.reset(seed=7)
        rewards = [env.step(np.full(6, 0.5))[1] for _ in range(10)]
        return obs["observation"], rewards, info

    (obs_a, rew_a, info_a), (obs_b, rew_b, info_b) = run(), run()
    np.testing.assert_array_equal(obs_a, obs_b)
    assert rew_a == rew_b
    assert info_a["mass"] in (0.4, 0.5, 1.5, 1.6)
    assert len(info_a["crippled"]) == 1 and info_a["crippled"][0] in (0, 1, 2)
    assert obs_a.shape == (18,)


def test_bad_names_splits_and_actions_are_value_errors():
    with pytest.raises(ValueError, match="unknown SaMI env"):
        cradle.sami.make("Cheetah")
    with pytest.raises(ValueError, match="unknown split"):
        cradle.sami.make("Ant", split="hard")
    env = cradle.sami.make("Hopper")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="expected 3"):
        env.step(np.zeros(2))


@pytest.mark.parametrize("name", ["Hopper", "PandaPush"])
def test_non_finite_actions_are_refused_and_leave_the_state_alone(name):
    env = cradle.sami.make(name)
    obs, _ = env.reset(seed=3)
    size = env.action_space.shape[0]
    for value in (np.nan, np.inf, -np.inf):
        action = np.zeros(size)
        action[size - 1] = value
        with pytest.raises(ValueError) as raised:
            env.step(action)
        message = str(raised.value)
        assert "\n" not in message
        assert f"action {size - 1} is" in message and "expected finite values" in message
    # Nothing was stepped: the first finite step matches a fresh env's.
    fresh = cradle.sami.make(name)
    fresh.reset(seed=3)
    after, reward, *_ = env.step(np.zeros(size))
    expected, expected_reward, *_ = fresh.step(np.zeros(size))
    assert reward == expected_reward
    for key in expected:
        np.testing.assert_array_equal(after[key], expected[key])


def test_user_task_sets_from_yaml(tmp_path):
    path = tmp_path / "sets.yml"
    path.write_text("task_sets:\n  - mass: [2.0]\n    cripple: [[1]]\n")
    env = cradle.sami.make("CrippleWalker", split=str(path))
    _, info = env.reset(seed=0)
    assert info["mass"] == 2.0 and info["crippled"] == [1] and info["masked"]
    path.write_text("task_sets:\n  - damping: [2.0]\n")
    with pytest.raises(ValueError, match="does not vary damping"):
        cradle.sami.make("CrippleWalker", split=str(path))


@pytest.mark.parametrize("name", cradle.sami.ENV_NAMES)
def test_observations_are_float32_like_the_reference(name):
    env = cradle.sami.make(name)
    for key, space in env.observation_space.spaces.items():
        assert space.dtype == np.float32, key
    obs, _ = env.reset(seed=4)
    assert all(value.dtype == np.float32 for value in obs.values())
    obs, *_ = env.step(np.full(env.action_space.shape, 0.1))
    assert all(value.dtype == np.float32 for value in obs.values())
    assert env.observation_space.contains(obs)


def test_model_and_data_are_read_only_views_of_the_episode(tmp_path):
    path = tmp_path / "sets.yml"
    path.write_text("task_sets:\n  - mass: [2.0]\n    cripple: [[0]]\n")
    heavy = cradle.sami.make("CrippleAnt", split=str(path))
    heavy.reset(seed=0)
    path.write_text("task_sets:\n  - mass: [1.0]\n")
    plain = cradle.sami.make("CrippleAnt", split=str(path))
    plain.reset(seed=0)
    model, data = heavy.model, heavy.data
    assert model.nbody == plain.model.nbody and model.body_names[0] == "world"
    # The views show this episode's hidden parameters: every mass doubled, leg 0 shrunk.
    np.testing.assert_allclose(model.body_mass[1:], 2.0 * plain.model.body_mass[1:])
    shrunk = model.geom_size[:, 0] < plain.model.geom_size[:, 0]
    assert shrunk.sum() == 2
    np.testing.assert_allclose(model.geom_size[shrunk], 0.5 * plain.model.geom_size[shrunk])
    views = [model.body_mass, model.geom_size, model.dof_damping, model.actuator_gear,
             data.qpos, data.qvel, data.xpos, data.ctrl]
    for view in views:
        assert not view.flags.writeable
        with pytest.raises(ValueError):
            view[0] = 1.0
    # Data views follow the env and keep it alive.
    qpos = data.qpos
    before = qpos.copy()
    heavy.step(np.full(8, 0.5))
    assert not np.array_equal(qpos, before)
    assert heavy.data.time > 0
    del heavy, data, model
    import gc
    gc.collect()
    assert np.isfinite(qpos).all() and np.isfinite(views[0]).all()
