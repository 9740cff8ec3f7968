"""Every env id of the registry from Python: cradle.make over every listed id, the vector of any
id against single envs, unknown ids, the Gymnasium ids (against a stand-in module) and reset
options reaching the env."""

import re

import numpy as np
import pytest

import cradle

# One id per family, and the references' names.
EXAMPLES = ["babybench/selftouch", "mimo/reach", "tma/parkour:fish", "sami/CrippleAnt:moderate"]


def same_bits(a, b):
    """Bitwise equality of two arrays (NaN equals NaN of the same bits)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def check_observation(obs, space):
    """obs is a dict of numpy arrays with the space's keys, shapes and dtypes."""
    assert list(obs) == list(space.spaces)
    for key, value in obs.items():
        assert isinstance(value, np.ndarray), key
        assert value.shape == space[key].shape and value.dtype == space[key].dtype, key


def test_specs_list_every_family_and_resolve_aliases():
    specs = cradle.env_specs()
    ids = cradle.env_ids()
    assert ids == [s.id for s in specs] and len(set(ids)) == len(ids)
    assert {s.family for s in specs} == {"babybench", "mimo", "tma", "sami"}
    assert set(EXAMPLES) <= set(ids)
    for spec in specs:
        assert spec.max_episode_steps >= 0
        for name, (low, high) in spec.task_parameters.items():
            assert isinstance(name, str) and low <= high
        for alias in spec.aliases:
            assert cradle.env_spec(alias).id == spec.id
        assert cradle.env_spec(cradle.gymnasium_id(spec.id)).id == spec.id
    assert cradle.env_spec("MIMoReach-v0").id == "mimo/reach"
    assert cradle.env_spec("sami/CrippleAnt").id == "sami/CrippleAnt:train"
    assert cradle.env_spec("BabyBench-SelfTouch").id == "babybench/selftouch"
    assert "stump_height" in cradle.env_spec("tma/stump-tracks:old_classic_bipedal").task_parameters
    assert cradle.env_spec("sami/CrippleAnt:moderate").task_parameters == {"mass": (0.05, 3.0)}


# 100 random steps of every listed id (71 ids, about 25 s on two cores; the MIMo envs with eyes
# take 3-4 s each, the BabyBench ones 1-1.5 s).
@pytest.mark.parametrize("env_id", cradle.env_ids())
def test_every_id_makes_resets_and_steps(env_id, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # BabyBench's relative save_dir, should anything write there
    env = cradle.make(env_id)
    spec = cradle.env_spec(env_id)
    expected = cradle.BabyBenchEnv if spec.family == "babybench" else cradle.RegistryEnv
    assert isinstance(env, expected)
    obs, info = env.reset(seed=0)
    check_observation(obs, env.observation_space)
    assert isinstance(info, dict)
    env.action_space.seed(0)
    for _ in range(100):
        action = env.action_space.sample()
        obs, reward, terminated, truncated, info = env.step(action)
        assert np.isfinite(reward) and isinstance(info, dict)
        if terminated or truncated:
            obs, info = env.reset()
    check_observation(obs, env.observation_space)
    env.close()


def test_make_resolves_aliases_and_gymnasium_ids():
    for env_id in ("MIMoReach-v0", "cradle/mimo-reach-v0", "cradle/MIMoReach-v0", "mimo/reach"):
        env = cradle.make(env_id, seed=3)
        assert env.spec_id == "mimo/reach" and env.family == "mimo"
        assert env.max_episode_steps == 1000
        env.close()
    env = cradle.make("cradle/tma-parkour.fish-v0")
    assert env.spec_id == "tma/parkour:fish" and env.family == "tma"
    assert set(env.task_parameters) >= {"water_level", "input_vector_0"}
    # The old BabyBench names still take config keys.
    env = cradle.make("BabyBench-SelfTouch", touch_active=False, vision_active=False)
    assert isinstance(env, cradle.BabyBenchEnv) and "touch" not in env.observation_space.spaces
    env = cradle.make("babybench/selftouch", max_episode_steps=7)
    assert env.max_episode_steps == 7


def test_single_env_api():
    env = cradle.make("mimo/reach")
    obs1, _ = env.reset(seed=5)
    obs2, _ = env.reset(seed=5)
    assert same_bits(obs1["observation"], obs2["observation"])  # a seed gives the same start
    assert env.model.nu == env.action_space.shape[0] and env.data.qpos.shape == (env.model.nq,)
    assert not env.data.qpos.flags.writeable
    assert env.task() is None and env.score() is None
    assert env.render() is None  # render_mode None
    with pytest.raises(ValueError, match="action has shape"):
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match="finite"):
        env.step(np.full(env.action_space.shape, np.nan))
    env.close()
    env.close()
    with pytest.raises(ValueError, match="closed"):
        env.reset()
    tma = cradle.make("tma/stump-tracks:old_classic_bipedal", render_mode="rgb_array",
                      motors_torque=100)
    tma.reset(seed=0)
    frame = tma.render()
    assert frame.shape == (400, 600, 3) and frame.dtype == np.uint8
    assert tma.render(width=64, height=32).shape == (32, 64, 3)
    with pytest.raises(AttributeError, match="Box2D"):
        tma.model  # noqa: B018
    sami = cradle.make("sami/PandaPush", render_mode="rgb_array")
    sami.reset(seed=0)
    assert sami.render().shape == (240, 320, 3)
    assert sami.model.nbody > 1 and sami.data.qpos.shape == (sami.model.nq,)
    with pytest.raises(ValueError, match="not one"):
        cradle.make("mimo/reach", colour="red")
    with pytest.raises(ValueError, match="render_mode"):
        cradle.make("mimo/reach", render_mode="human")


# The vector of an id against single envs built as its envs are (env i: seed env_seed(seed, i),
# vector index i), stepping the same actions: bitwise equal observations and rewards. PandaPush
# truncates after 50 steps, so its 60 steps cover an autoreset.
@pytest.mark.parametrize("env_id, steps", [("mimo/reach", 50), ("tma/parkour:fish", 50),
                                           ("sami/CrippleAnt:train", 50),
                                           ("sami/PandaPush:train", 60)])
def test_vector_matches_single_envs(env_id, steps):
    seed, n = 11, 2
    vec = cradle.VectorEnv(env_id, n, threads=2, seed=seed)
    assert vec.family == cradle.env_spec(env_id).family and vec.spec_id == env_id
    seeds = [cradle.VectorEnv.env_seed(seed, i) for i in range(n)]
    singles = [cradle.make(env_id, seed=s, vector_index=i) for i, s in enumerate(seeds)]
    obs, infos = vec.reset(seed=seed)
    assert list(infos["steps"]) == [0] * n
    for i, env in enumerate(singles):
        single_obs, _ = env.reset(seed=seeds[i])
        for key, value in single_obs.items():
            assert same_bits(obs[key][i], value), key
    rng = np.random.default_rng(0)
    low = np.asarray(vec.single_action_space.low, dtype=np.float64)
    high = np.asarray(vec.single_action_space.high, dtype=np.float64)
    ended, autoresets = [False] * n, 0
    for _ in range(steps):
        actions = rng.uniform(low, high, size=(n,) + low.shape)
        obs, rewards, terminated, truncated, infos = vec.step(actions)
        for i, env in enumerate(singles):
            if ended[i]:  # next-step autoreset: the env's stream continues
                single_obs, _ = env.reset()
                reward, term, trunc = 0.0, False, False
                autoresets += 1
            else:
                single_obs, reward, term, trunc, _ = env.step(actions[i])
            ended[i] = term or trunc
            for key, value in single_obs.items():
                assert same_bits(obs[key][i], value), key
            assert same_bits(rewards[i], np.float64(reward))
            assert (terminated[i], truncated[i]) == (term, trunc)
    if env_id.startswith("sami/PandaPush"):
        assert autoresets == n
    vec.close()
    for env in singles:
        env.close()


def test_vector_of_an_id_in_worker_processes_steps_as_threads():
    import numpy as np
    env_id = "tma/stump-tracks:old_classic_bipedal"
    procs = cradle.VectorEnv(env_id, 4, seed=3, procs=2)
    threads = cradle.VectorEnv(env_id, 4, seed=3, threads=2)
    assert (procs.procs, threads.procs) == (2, 0)
    obs_p, _ = procs.reset(seed=4)
    obs_t, _ = threads.reset(seed=4)
    rng = np.random.default_rng(0)
    ended = 0
    for _ in range(200):
        for key in obs_t:
            np.testing.assert_array_equal(obs_p[key], obs_t[key])
        action = rng.uniform(-1, 1, size=procs.action_space.shape)
        obs_p, rew_p, term_p, trunc_p, _ = procs.step(action)
        obs_t, rew_t, term_t, trunc_t, _ = threads.step(action)
        np.testing.assert_array_equal(rew_p, rew_t)
        np.testing.assert_array_equal(term_p, term_t)
        np.testing.assert_array_equal(trunc_p, trunc_t)
        ended += int(np.sum(term_p | trunc_p))
    assert ended > 0  # random walkers fall: the autoreset is compared too
    procs.close()
    threads.close()


def test_vector_of_an_id_options_and_errors():
    vec = cradle.VectorEnv("tma/stump-tracks:old_classic_bipedal", 2, seed=1,
                           autoreset_mode="same_step", env_options={"motors_torque": 100})
    obs, _ = vec.reset(seed=2, options={"stump_height": 1.5})
    assert obs["observation"].shape == (2,) + vec.single_observation_space["observation"].shape
    with pytest.raises(ValueError, match="stump_height"):
        vec.reset(options={"stump_height": 99.0})  # outside the env's [-3, 9]
    with pytest.raises(ValueError, match="training"):
        cradle.VectorEnv("mimo/reach", 2, training=True)
    with pytest.raises(ValueError, match="do not split evenly over 2 processes"):
        cradle.VectorEnv("mimo/reach", 3, procs=2)
    with pytest.raises(ValueError, match="closest"):
        cradle.VectorEnv("mimo/reech", 2)
    for threads in (-5, 1.5, True, "2"):
        with pytest.raises(ValueError, match="threads must be a non-negative integer"):
            cradle.VectorEnv("mimo/reach", 2, threads=threads)
    # A BabyBench id makes the config's vector.
    vec = cradle.VectorEnv("BabyBench-SelfTouch", 2)
    assert vec.family == "babybench" and vec.single_action_space.shape == (30,)


def test_unknown_ids_name_the_closest():
    with pytest.raises(ValueError, match="unknown env id") as error:
        cradle.make("mimo/reech")
    assert "mimo/reach" in str(error.value)
    with pytest.raises(ValueError, match="closest") as error:
        cradle.make("tma/parkur:fish")
    assert "tma/parkour:fish" in str(error.value)
    with pytest.raises(ValueError, match="closest") as error:
        cradle.make("sami/CrippleAnt:hard")
    assert "sami/CrippleAnt" in str(error.value)
    with pytest.raises(ValueError, match="unknown env id"):
        cradle.make("BabyBench-Walk")
    with pytest.raises(ValueError, match="string"):
        cradle.make(42)


def test_reset_options_reach_the_env():
    tma = cradle.make("tma/stump-tracks:old_classic_bipedal")
    assert tma.task_parameters["stump_height"] == (0.0, 3.0)
    tma.reset(seed=0, options={"stump_height": 2.5, "obstacle_spacing": 4})
    assert tma.task()["stump_height"] == 2.5 and tma.task()["obstacle_spacing"] == 4.0
    tma.reset()  # the options stay set
    assert tma.task()["stump_height"] == 2.5
    # The spec lists the benchmark's task space; the env takes the reference's wider range.
    with pytest.raises(ValueError, match="stump_height"):
        tma.reset(options={"stump_height": 12.0})
    with pytest.raises(ValueError, match="water_level"):
        tma.reset(options={"water_level": 0.5})  # a Parkour parameter
    with pytest.raises(ValueError, match="real number"):
        tma.reset(options={"stump_height": "high"})
    parkour = cradle.make("tma/parkour:fish")
    parkour.reset(seed=0, options={"input_vector": [0.1, -0.2, 0.3], "water_level": 0.5})
    task = parkour.task()
    assert [task[f"input_vector_{i}"] for i in range(3)] == [0.1, -0.2, 0.3]
    assert task["water_level"] == 0.5

    sami = cradle.make("sami/CrippleAnt:moderate")
    _, info = sami.reset(seed=0, options={"mass": 2.0})
    assert info["mass"] == 2.0 and sami.task()["mass"] == 2.0
    _, info = sami.reset()
    assert info["mass"] == 2.0
    with pytest.raises(ValueError, match="out of range"):
        sami.reset(options={"mass": 50.0})
    with pytest.raises(ValueError, match="hidden parameter"):
        sami.reset(options={"damping": 1.0})  # CrippleAnt varies only the mass
    panda = cradle.make("sami/PandaPush:extreme")
    _, info = panda.reset(seed=0, options={"table_friction": 0.7, "cube_mass": 3.0})
    assert info["friction"] == 0.7 and info["cube_mass"] == 3.0


# The Gymnasium branch against conftest.py's stand-in: its registry, id grammar and make.
SCRIPT = '''
import gymnasium, numpy as np, cradle
assert cradle.HAS_GYMNASIUM
for spec in cradle.env_specs():
    name = cradle.gymnasium_id(spec.id)
    match = gymnasium.ENV_ID_RE.fullmatch(name)
    assert match and match["namespace"] == "cradle" and match["version"] == "0", name
    assert gymnasium.registry[name][1] == {"env_id": spec.id}, name
assert {"cradle/BabyBench-v0", "cradle/BabyBench-SelfTouch-v0", "cradle/MIMoReach-v0",
        "cradle/tma-parkour.fish-v0", "cradle/sami-CrippleAnt.moderate-v0",
        "cradle/mimo-bench-v2-v0", "cradle/babybench-selftouch-v0"} <= set(gymnasium.registry)
for name, spec_id in [("cradle/mimo-reach-v0", "mimo/reach"), ("cradle/MIMoReach-v0", "mimo/reach"),
                      ("cradle/tma-parkour.fish-v0", "tma/parkour:fish"),
                      ("cradle/sami-CrippleAnt.moderate-v0", "sami/CrippleAnt:moderate")]:
    env = gymnasium.make(name, seed=1)
    assert isinstance(env, cradle.RegistryEnv) and isinstance(env, gymnasium.Env), name
    assert env.spec_id == spec_id, name
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
    env.close()
env = gymnasium.make("cradle/babybench-selftouch-v0")
assert isinstance(env, cradle.BabyBenchEnv) and env.behavior == "self_touch"
print("ok")
'''


def test_gymnasium_ids(with_gymnasium):
    assert with_gymnasium(SCRIPT).strip() == "ok"


def test_without_gymnasium_ids_still_resolve():
    assert not re.search(r"[/:]", cradle.gymnasium_id("tma/parkour:fish")[len("cradle/"):])
    env = cradle.make("cradle/sami-CrippleAnt.moderate-v0")
    assert env.spec_id == "sami/CrippleAnt:moderate"
