"""The env through Python: Gymnasium protocol, seeded determinism, buffers, truncation, errors."""

import subprocess

import numpy as np
import pytest

import cradle

from conftest import CONFIGS, cradle_binary


def rollout(env, seed, steps, action_seed=0):
    rng = np.random.default_rng(action_seed)
    low, high = env.action_space.low, env.action_space.high
    obs, info = env.reset(seed=seed)
    out = [obs]
    for _ in range(steps):
        obs, reward, terminated, truncated, info = env.step(rng.uniform(low, high))
        out.append(obs)
    return out, info


def test_seeded_determinism(make_config):
    config = make_config("selftouch")
    a = cradle.make_env(config, training=False)
    b = cradle.make_env(config, training=False, seed=99)  # construction seed is overridden
    ra, ia = rollout(a, seed=5, steps=30)
    rb, ib = rollout(b, seed=5, steps=30)
    for oa, ob in zip(ra, rb):
        for key in oa:
            np.testing.assert_array_equal(oa[key], ob[key])
    assert ia == ib
    # Another seed gives other random start actions, so another start state.
    rc, _ = rollout(a, seed=6, steps=0)
    assert not np.array_equal(rc[0]["observation"], ra[0]["observation"])
    assert a.np_random_seed == 6 if hasattr(a, "np_random_seed") else True


def test_step_protocol_and_truncation(make_config):
    env = cradle.make_env(make_config("selftouch", max_episode_steps=5), training=False)
    obs, info = env.reset(seed=0)
    assert set(obs) == {"observation", "touch", "vestibular"}
    # The reference's keys, plus Cradle's counts of MuJoCo size overflows and of diverged physics
    # (0 in normal episodes).
    assert info == {
        "right_hand_touches": [],
        "left_hand_touches": [],
        "steps": 0,
        "physics_overflow": 0,
        "physics_diverged": 0,
    }
    for t in range(5):
        obs, reward, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
        assert isinstance(reward, float) and reward == 0.0
        assert terminated is False
        assert truncated is (t == 4)
        assert info["steps"] == t  # the reference counts before incrementing
    assert env.unwrapped is env
    assert isinstance(env.np_random, np.random.Generator)
    with pytest.raises(ValueError, match=r"action has shape \(29,\), expected \(30,\)"):
        env.step(np.zeros(29))
    # float32 samples and lists are accepted (converted to float64).
    env.step(env.action_space.sample())
    env.step([0.0] * 30)


def test_copies_and_views(make_config):
    config = make_config("selftouch")
    env = cradle.make_env(config, training=False)
    obs0, _ = env.reset(seed=1)
    kept = obs0["observation"].copy()
    env.step(env.action_space.high)
    np.testing.assert_array_equal(obs0["observation"], kept)  # fresh arrays: untouched
    assert obs0["observation"].flags.writeable

    view_env = cradle.make_env(config, training=False, copy_observations=False)
    v0, _ = view_env.reset(seed=1)
    np.testing.assert_array_equal(v0["observation"], kept)
    assert not v0["observation"].flags.writeable
    v1, *_ = view_env.step(view_env.action_space.high)
    assert v1["observation"] is v0["observation"]  # the same buffer, now the new state
    assert not np.array_equal(v0["observation"], kept)
    del view_env  # views keep the C++ env alive
    assert np.isfinite(v1["observation"]).all()


def test_reference_attributes_follow_state(make_config):
    env = cradle.make_env(make_config("selftouch"), training=False)
    env.reset(seed=0)
    qpos = env.data.qpos
    t0 = env.data.time
    before = qpos.copy()
    env.step(env.action_space.high)
    assert env.data.time == pytest.approx(t0 + env.dt)
    assert not np.array_equal(qpos, before)  # a view of mjData
    outputs = env.touch.sensor_outputs
    touch = env.step(env.action_space.low)[0]["touch"]
    assert sum(o.size for o in outputs.values()) == touch.size


def test_render_rgb_array(make_config):
    env = cradle.make_env(make_config("selftouch", render_size=64), training=False,
                          render_mode="rgb_array")
    env.reset(seed=0)
    image = env.render()
    assert image.shape == (64, 64, 3) and image.dtype == np.uint8
    assert image.std() > 0  # a scene, not a blank buffer
    assert cradle.make_env(make_config("selftouch"), training=False).render() is None


def test_make_ids_and_overrides(tmp_path):
    env = cradle.make("BabyBench-SelfTouch", touch_active=False, save_dir=str(tmp_path))
    assert "touch" not in env.observation_space.spaces
    assert env.config["behavior"] == "self_touch" and env.config["scene"] == "crib"
    assert not (tmp_path / "scene").exists()  # make() does not train by default
    default = cradle.make("BabyBench", vision_active=False)
    assert default.action_space.shape == (44,)  # every actuator group of MIMo v1
    with pytest.raises(ValueError, match="unknown env id"):
        cradle.make("BabyBench-Walk")
    with pytest.raises(ValueError, match="unknown config key 'touch_sacle'"):
        cradle.make("BabyBench-SelfTouch", touch_sacle=2.0)


def test_bad_config_raises_value_error(tmp_path):
    with pytest.raises(ValueError) as error:
        cradle.make_env({"behavior": "walking"}, training=False)
    message = str(error.value)
    assert "\n" not in message and "behavior" in message and "walking" in message
    # From a file the message is exactly the CLI's one line.
    bad = tmp_path / "bad.yml"
    bad.write_text("behavior: self_touch\ntouch_scale: -1\n")
    cli = subprocess.run([cradle_binary(), "model-info", "--config", str(bad)],
                         capture_output=True, text=True)
    assert cli.returncode == 1
    with pytest.raises(ValueError) as error:
        cradle.make_env(str(bad), training=False)
    assert cli.stderr.strip() == "cradle: error: " + str(error.value)
    with pytest.raises(ValueError, match="vision_active"):
        cradle.make_env({"vision_active": 1}, training=False)  # booleans are real booleans
    with pytest.raises(FileNotFoundError):
        cradle.make_env(str(tmp_path / "missing.yml"))
    with pytest.raises(TypeError):
        cradle.make_env(42)
