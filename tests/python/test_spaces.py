"""Spaces from Python equal the C++ ones (the CLI's model-info) for the three reference configs."""

import json
import subprocess

import numpy as np
import pytest

import cradle
from cradle import spaces

from conftest import CONFIGS, cradle_binary


@pytest.mark.parametrize("name", sorted(CONFIGS))
def test_spaces_match_cli(name, make_config):
    info = json.loads(
        subprocess.run(
            [cradle_binary(), "model-info", "--config", str(CONFIGS[name]), "--json"],
            check=True, capture_output=True, text=True,
        ).stdout
    )
    env = cradle.make_env(make_config(name), training=False)
    obs_space = env.observation_space
    assert sorted(obs_space.spaces) == sorted(info["observation_sizes"])
    for key, size in info["observation_sizes"].items():
        assert int(np.prod(obs_space[key].shape)) == size, key
    assert env.action_space.shape == (info["action_dim"],)
    assert env.model.nu == info["action_dim"]
    # Reference dtypes: float64 proprioception/vestibular, float32 touch, uint8 images.
    expected = {"observation": np.float64, "vestibular": np.float64, "touch": np.float32,
                "eye_left": np.uint8, "eye_right": np.uint8}
    for key in obs_space.spaces:
        assert obs_space[key].dtype == expected[key], key
    if "eye_left" in obs_space.spaces:
        assert obs_space["eye_left"].shape == (64, 64, 3)
    # Spring-damper action bounds are the actuators' force ranges (float32, as the reference).
    assert env.action_space.dtype == np.float32
    forcerange = env.model.actuator_forcerange.astype(np.float32)
    np.testing.assert_array_equal(env.action_space.low, forcerange[:, 0])
    np.testing.assert_array_equal(env.action_space.high, forcerange[:, 1])
    obs, _ = env.reset(seed=0)
    assert obs_space.contains(obs)
    env.close()


def test_reference_counts(make_config):
    # The spec's verified numbers: self-touch 30 actuators, observation 264; hand regard 17 / 466.
    st = cradle.make_env(make_config("selftouch"), training=False)
    assert st.action_space.shape == (30,) and st.observation_space["observation"].shape == (264,)
    assert len(st.proprioception.joint_names) == 47
    assert st.model.actuator(0).name.startswith("act:")
    assert st.model.actuator(st.model.actuator(3).name).id == 3
    positions = st.touch.sensor_positions
    assert sum(len(p) for p in positions.values()) == st.touch.sensor_count
    assert st.touch.sensor_count * 3 == st.observation_space["touch"].shape[0]
    assert all(p.shape[1] == 3 for p in positions.values())
    with pytest.raises(IndexError):
        st.model.actuator(30)
    with pytest.raises(KeyError):
        st.model.joint("no_such_joint")
    hr = cradle.make_env(make_config("handregard"), training=False)
    assert hr.action_space.shape == (17,) and hr.observation_space["observation"].shape == (466,)
    assert hr.touch is None


def test_fallback_spaces():
    box = spaces.Box(-1.0, 2.0, (5,), np.float32, seed=3)
    a = box.sample()
    assert a.dtype == np.float32 and a.shape == (5,) and box.contains(a)
    assert np.array_equal(spaces.Box(-1.0, 2.0, (5,), np.float32, seed=3).sample(), a)
    assert not box.contains(np.full(5, 3.0, np.float32))
    assert not box.contains(np.zeros(4, np.float32))
    img = spaces.Box(0, 255, (4, 4, 3), np.uint8, seed=1)
    assert img.sample().dtype == np.uint8 and img.contains(img.sample())
    free = spaces.Box(-np.inf, np.inf, (3,), np.float64, seed=0)
    assert np.all(np.isfinite(free.sample())) and not free.is_bounded()
    d = spaces.Dict([("b", box), ("a", img)], seed=7)
    sample = d.sample()
    assert list(sample) == ["b", "a"] and d.contains(sample)
    d.seed(7)
    first = d.sample()["b"]
    again = spaces.Dict([("b", box), ("a", img)], seed=7)  # reseeds the shared sub-spaces
    assert np.array_equal(first, again.sample()["b"])
    assert not d.contains({"b": sample["b"]})
