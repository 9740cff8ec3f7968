"""cradle.tma: TeachMyAgent's environments from Python, and the CPPN terrain against numpy."""

import pathlib

import numpy as np
import pytest

from cradle import tma

ROOT = pathlib.Path(__file__).resolve().parents[2]
WEIGHTS = ROOT / "data" / "teachmyagent" / "ground_ceiling_cppn.f32"
TERRAIN_STEP = 14 / 30
TERRAIN_HEIGHT = 400 / 30 / 4


def numpy_cppn(input_vector):
    """An independent evaluation of the terrain CPPN (float64) from the weight file."""
    w = np.fromfile(WEIGHTS, dtype="<f4").astype(np.float64)
    shapes = [(4, 64), (64, 64), (64, 64), (64, 64), (64, 2)]
    layers, offset = [], 0
    for rows, cols in shapes:
        layers.append(w[offset : offset + rows * cols].reshape(rows, cols))
        offset += rows * cols
    assert offset == w.size
    x = np.arange(200) / 199.0
    h = np.concatenate([x[:, None], np.tile(np.asarray(input_vector, float), (200, 1))], axis=1)
    h = np.tanh(h @ layers[0])
    h = np.logaddexp(0.0, h @ layers[1])
    h = np.tanh(h @ layers[2])
    h = np.logaddexp(0.0, h @ layers[3])
    return h @ layers[4]


@pytest.mark.parametrize(
    "input_vector", [(0.0, 0.0, 0.0), (-0.35, 0.6, -0.1), (0.05, 1.0, 0.3), (-1.0, 1.0, -1.0)]
)
def test_cppn_terrain_matches_numpy(input_vector):
    env = tma.make(tma.PARKOUR, agent_body_type="old_classic_bipedal")
    env.set_environment(input_vector=np.array(input_vector), water_level=0.0)
    env.reset(seed=0)
    xs, ground, ceiling, _ = env.terrain()
    y = numpy_cppn(input_vector) / 10.0
    want_ground = y[:, 0] - y[0, 0] + TERRAIN_HEIGHT
    want_ceiling = np.maximum(y[:, 1] - y[0, 1] + TERRAIN_HEIGHT + 20.0, want_ground)
    assert len(xs) == 220
    np.testing.assert_allclose(ground[20:], want_ground, atol=2e-4)
    np.testing.assert_allclose(ceiling[20:], want_ceiling, atol=2e-4)
    np.testing.assert_allclose(xs, np.arange(220) * TERRAIN_STEP, atol=1e-9)


def test_seed_example_runs_with_the_old_gym_api():
    from cradle.tma import gym

    env = gym.make("parametric-continuous-parkour-v0", agent_body_type="fish", movable_creepers=True)
    env.set_environment(input_vector=np.zeros(3), water_level=0.1)
    env.reset()
    for _ in range(30):
        _, _, d, _ = env.step(env.action_space.sample())
        frame = env.render()
    assert frame.shape == (400, 600, 3) and frame.dtype == np.uint8
    assert isinstance(d, bool)


@pytest.mark.parametrize(
    "body, stump, parkour, actions",
    [
        ("old_classic_bipedal", 24, 36, 4),
        ("spider", 42, 54, 12),
        ("climbing_profile_chimpanzee", 42, 54, 12),
        ("fish", 26, 38, 4),
    ],
)
def test_spaces(body, stump, parkour, actions):
    s = tma.make(tma.STUMP_TRACKS, agent_body_type=body)
    p = tma.make(tma.PARKOUR, agent_body_type=body)
    assert s.observation_space.shape == (stump,) and p.observation_space.shape == (parkour,)
    assert s.action_space.shape == (actions,) and p.action_space.shape == (actions,)
    obs, info = p.reset(seed=0)
    assert obs.shape == (parkour,) and info == {}


def test_gymnasium_shaped_step_and_determinism():
    runs = []
    for _ in range(2):
        env = tma.make(tma.STUMP_TRACKS, agent_body_type="small_bipedal")
        env.set_environment(stump_height=1.0, obstacle_spacing=3.0)
        obs, _ = env.reset(seed=11)
        rng = np.random.default_rng(0)
        trace = [obs]
        for _ in range(100):
            obs, reward, terminated, truncated, info = env.step(rng.uniform(-1, 1, 4))
            assert set(info) == {"success"} and isinstance(info["success"], bool)
            trace.append(np.append(obs, reward))
            if terminated or truncated:
                break
        runs.append(np.concatenate(trace))
    np.testing.assert_array_equal(runs[0], runs[1])


def test_bad_inputs_are_value_errors():
    with pytest.raises(ValueError, match="unknown embodiment 'snake'"):
        tma.make(tma.STUMP_TRACKS, agent_body_type="snake")
    with pytest.raises(ValueError, match="unknown env id"):
        tma.make("parametric-continuous-hexagon-v0")
    env = tma.make(tma.PARKOUR, agent_body_type="fish")
    with pytest.raises(ValueError, match="water_level"):
        env.set_environment(water_level=float("nan"))
    with pytest.raises(ValueError, match="input_vector takes 3 values"):
        env.set_environment(input_vector=[0.0, 0.1])
    with pytest.raises(ValueError, match="unknown Parkour task parameter 'stump_height'"):
        env.set_environment(stump_height=1.0)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="expected 4"):
        env.step(np.zeros(5))


def test_stump_tracks_optional_dimensions():
    """Roughness 0 keeps the ground flat, roughness > 0 makes it uneven; width and rotation are
    (mean, std) pairs; same seed and task give the same terrain."""
    env = tma.make(tma.STUMP_TRACKS, agent_body_type="old_classic_bipedal")
    env.set_environment(stump_height=1.0, obstacle_spacing=1.0, roughness=0)
    env.reset(seed=2)
    assert np.all(np.asarray(env.terrain()[1]) == TERRAIN_HEIGHT)
    task = dict(stump_height=1.0, obstacle_spacing=1.0, stump_width=[1.5, 0.2],
                stump_rot=np.array([0.3, 0.1]), roughness=3.0)
    env.set_environment(**task)
    env.reset(seed=2)
    xs, ground = np.asarray(env.terrain()[0]), np.asarray(env.terrain()[1])
    assert np.ptp(ground) > 0.05
    env.reset(seed=2)
    np.testing.assert_array_equal(np.asarray(env.terrain()[1]), ground)
    with pytest.raises(ValueError, match="stump_width takes 2 values"):
        env.set_environment(stump_width=1.0)
    with pytest.raises(ValueError, match="roughness"):
        env.set_environment(roughness=float("nan"))


@pytest.mark.parametrize("env_id, body", [(tma.STUMP_TRACKS, "spider"), (tma.PARKOUR, "fish")])
def test_observations_are_float32_of_the_float64_values(env_id, body):
    """The reference's observation space is float32: the env's float64 values rounded once."""
    env = tma.make(env_id, agent_body_type=body)
    assert env.observation_space.dtype == np.float32
    obs, _ = env.reset(seed=4)
    rng = np.random.default_rng(1)
    rounded = 0
    for _ in range(40):
        wide = env._env.observation_float64()
        assert obs.dtype == np.float32 and obs.shape == env.observation_space.shape
        np.testing.assert_array_equal(obs, wide.astype(np.float32))
        rounded += int(np.sum(obs.astype(np.float64) != wide))
        obs, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, env.action_space.shape))
        if terminated or truncated:
            obs, _ = env.reset()
    assert rounded > 0


def test_body_options_change_the_body():
    strong = tma.make(tma.PARKOUR, agent_body_type="classic_bipedal", motors_torque=250)
    assert strong._env.motors_torque == 250.0
    assert tma.make(tma.PARKOUR, agent_body_type="classic_bipedal")._env.motors_torque == 80.0
    millipede = tma.make(tma.STUMP_TRACKS, agent_body_type="millipede", nb_of_bodies=np.int64(6))
    assert millipede.action_space.shape == (24,)
    assert millipede.observation_space.shape == (4 + 10 + 60,)
    assert millipede._env.torque_penalty == pytest.approx(3.5e-4 / 6)
    spider = tma.make(tma.STUMP_TRACKS, agent_body_type="spider", nb_pairs_of_legs=3)
    assert spider.action_space.shape == (18,) and spider._env.body_parts == 19
    # None keeps the default, as the reference's run.py passes it.
    assert tma.make(tma.STUMP_TRACKS, agent_body_type="spider",
                    nb_pairs_of_legs=None).action_space.shape == (12,)


def test_outside_water_limit_kills_the_fish():
    env = tma.make(tma.PARKOUR, agent_body_type="fish", nb_steps_outside_water=3)
    env.set_environment(water_level=0.0)  # the fish starts (and stays) out of water
    env.reset(seed=0)
    dead = []
    for _ in range(6):
        obs, _, terminated, _, _ = env.step(np.ones(4))
        dead.append(obs[5])
        assert not terminated
    # After k steps the counter is k; the step that starts above 3 (the 5th) is dead.
    assert dead == [0, 0, 0, 0, 1, 1]


def test_ceiling_offsets_move_the_ceiling():
    env = tma.make(tma.PARKOUR, agent_body_type="classic_bipedal", ceiling_offset=120,
                   ceiling_clip_offset=10.0)
    env.set_environment(input_vector=np.zeros(3), water_level=0.0, terrain_cppn_scale=20)
    env.reset(seed=0)
    _, ground, ceiling, _ = env.terrain()
    assert ceiling[0] == pytest.approx(TERRAIN_HEIGHT + 120 / 20, abs=1e-12)
    assert np.all(ceiling >= ground + 10 / 20 - 1e-12)


def test_cppn_weights_path_and_input_dim(tmp_path):
    w = np.fromfile(WEIGHTS, dtype="<f4")
    w[-128:] *= 2  # the output layer: every output doubles
    w.tofile(tmp_path / "double.f32")
    plain = tma.make(tma.PARKOUR, agent_body_type="classic_bipedal")
    user = tma.make(tma.PARKOUR, agent_body_type="classic_bipedal",
                    CPPN_weights_path=tmp_path / "double.f32")
    for env in (plain, user):
        env.set_environment(input_vector=[-0.2, 0.8, 0.1], water_level=0.0)
        env.reset(seed=0)
    g0, g1 = plain.terrain()[1], user.terrain()[1]
    np.testing.assert_allclose(g1 - TERRAIN_HEIGHT, 2 * (g0 - TERRAIN_HEIGHT), atol=1e-9)
    # Two task inputs: a 3 x 64 first layer.
    rng = np.random.default_rng(0)
    rng.uniform(-1, 1, (3 + 3 * 64 + 2) * 64).astype("<f4").tofile(tmp_path / "two.f32")
    two = tma.make(tma.PARKOUR, agent_body_type="fish", CPPN_weights_path=str(tmp_path / "two.f32"),
                   input_CPPN_dim=2)
    two.set_environment(input_vector=[0.3, -0.3], water_level=1.0)
    two.reset(seed=0)
    with pytest.raises(ValueError, match="input_vector takes 2 values"):
        two.set_environment(input_vector=[0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="needs CPPN_weights_path"):
        tma.make(tma.PARKOUR, agent_body_type="fish", input_CPPN_dim=2)
    with pytest.raises(ValueError, match="not found"):
        tma.make(tma.PARKOUR, agent_body_type="fish", CPPN_weights_path=tmp_path / "missing.f32")
    (tmp_path / "bad.f32").write_bytes(b"\0" * 100)
    with pytest.raises(ValueError, match="has 100 bytes"):
        tma.make(tma.PARKOUR, agent_body_type="fish", CPPN_weights_path=tmp_path / "bad.f32")


def test_wrong_options_are_value_errors():
    with pytest.raises(ValueError, match=r"unknown TeachMyAgent option 'nb_legs' \(expected .*"
                                         r"nb_pairs_of_legs.*ceiling_clip_offset"):
        tma.make(tma.STUMP_TRACKS, agent_body_type="spider", nb_legs=3)
    with pytest.raises(ValueError, match="nb_of_bodies must be an integer"):
        tma.make(tma.STUMP_TRACKS, agent_body_type="millipede", nb_of_bodies="4")
    with pytest.raises(ValueError, match=r"nb_of_bodies = 2.5 \(expected an integer"):
        tma.make(tma.STUMP_TRACKS, agent_body_type="millipede", nb_of_bodies=2.5)
    with pytest.raises(ValueError, match="motors_torque must be a number"):
        tma.make(tma.STUMP_TRACKS, agent_body_type="spider", motors_torque=True)
    with pytest.raises(ValueError, match="does not apply to spider"):
        tma.make(tma.STUMP_TRACKS, agent_body_type="spider", nb_of_bodies=3)
    with pytest.raises(ValueError, match="nb_steps_outside_water does not apply"):
        tma.make(tma.PARKOUR, agent_body_type="classic_bipedal", nb_steps_outside_water=10)
    with pytest.raises(ValueError, match="Parkour only"):
        tma.make(tma.STUMP_TRACKS, agent_body_type="spider", ceiling_offset=100)
