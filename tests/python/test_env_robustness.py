"""The TMA and SaMI Python envs refuse nonsense with a one-line ValueError naming the argument,
never crash, hang or accept it silently; valid calls still work."""

import numpy as np
import pytest

from cradle import sami, tma

ST = tma.STUMP_TRACKS


def tma_env(reset=True):
    env = tma.make(ST)
    if reset:
        env.reset(seed=0)
    return env


def sami_env(reset=True):
    env = sami.make("Hopper")
    if reset:
        env.reset(seed=0)
    return env


def closed(make):
    env = make()
    env.close()
    return env


# (case, call, text the message must hold)
CASES = [
    ("tma body None", lambda: tma.make(ST, agent_body_type=None), "agent_body_type"),
    ("tma body unknown", lambda: tma.make(ST, agent_body_type="snake"), "snake"),
    ("tma env id 3", lambda: tma.make(3), "env id"),
    ("tma steps str", lambda: tma.make(ST, max_episode_steps="10"), "max_episode_steps"),
    ("tma steps float", lambda: tma.make(ST, max_episode_steps=1.5), "max_episode_steps"),
    ("tma steps bool", lambda: tma.make(ST, max_episode_steps=True), "max_episode_steps"),
    ("tma steps 0", lambda: tma.make(ST, max_episode_steps=0), "max_episode_steps"),
    ("tma steps huge", lambda: tma.make(ST, max_episode_steps=2**40), "max_episode_steps"),
    ("tma water_clip str", lambda: tma.make(ST, water_clip="a"), "water_clip"),
    ("tma water_clip nan", lambda: tma.make(ST, water_clip=float("nan")), "water_clip"),
    ("tma creepers str", lambda: tma.make(tma.PARKOUR, movable_creepers="no"), "movable_creepers"),
    ("tma lidars list", lambda: tma.make(ST, lidars_type=["up"]), "lidars_type"),
    ("tma option str", lambda: tma.make(ST, motors_torque="a"), "motors_torque"),
    ("tma unknown option", lambda: tma.make(ST, foo=1), "foo"),
    ("tma stump bool", lambda: tma_env(False).set_environment(stump_height=True), "stump_height"),
    ("tma stump str", lambda: tma_env(False).set_environment(stump_height="a"), "stump_height"),
    ("tma stump complex", lambda: tma_env(False).set_environment(stump_height=1j), "stump_height"),
    ("tma stump 2-D", lambda: tma_env(False).set_environment(stump_height=[[1.0]]),
     "stump_height"),
    ("tma stump nan", lambda: tma_env(False).set_environment(stump_height=np.nan), "stump_height"),
    ("tma stump 1e300", lambda: tma_env(False).set_environment(stump_height=1e300),
     "stump_height = 1e+300 is out of range"),
    ("tma unknown task", lambda: tma_env(False).set_environment(foo=1.0), "foo"),
    ("tma step before reset", lambda: tma_env(False).step(np.zeros(4)), "reset"),
    ("tma action 2-D", lambda: tma_env().step(np.zeros((2, 2))), "shape"),
    ("tma action complex", lambda: tma_env().step(np.zeros(4) + 1j), "real"),
    ("tma action str", lambda: tma_env().step("abcd"), "real"),
    ("tma action None", lambda: tma_env().step(None), "real"),
    ("tma action ragged", lambda: tma_env().step([1.0, [2.0]]), "real"),
    ("tma action length", lambda: tma_env().step(np.zeros(3)), "shape"),
    ("tma action nan", lambda: tma_env().step([0, 0, np.nan, 0]), "action 2 is nan"),
    ("tma action inf", lambda: tma_env().step([np.inf, 0, 0, 0]), "finite"),
    ("tma reset options", lambda: tma_env().reset(options={"foo": 1.0}), "foo"),
    ("tma reset options list", lambda: tma_env().reset(options=[1]), "options"),
    ("tma reset options bool", lambda: tma_env().reset(options={"stump_height": True}),
     "stump_height"),
    ("tma seed -1", lambda: tma_env().reset(seed=-1), "seed"),
    ("tma seed 2^64", lambda: tma_env().reset(seed=2**64), "seed"),
    ("tma seed str", lambda: tma_env().reset(seed="1"), "seed"),
    ("tma seed float", lambda: tma_env().reset(seed=1.0), "seed"),
    ("tma render width str", lambda: tma_env().render(width="a"), "width"),
    ("tma render height 0", lambda: tma_env().render(height=0), "height"),
    ("tma render lidars str", lambda: tma_env().render(lidars="no"), "lidars"),
    ("tma step after close", lambda: closed(tma_env).step(np.zeros(4)), "closed"),
    ("tma reset after close", lambda: closed(tma_env).reset(), "closed"),
    ("tma render after close", lambda: closed(tma_env).render(), "closed"),
    ("tma set_environment after close",
     lambda: closed(tma_env).set_environment(stump_height=1.0), "closed"),
    ("tma terrain after close", lambda: closed(tma_env).terrain(), "closed"),
    ("sami name None", lambda: sami.make(None), "name"),
    ("sami name unknown", lambda: sami.make("Nope"), "Nope"),
    ("sami split int", lambda: sami.make("Hopper", split=3), "split"),
    ("sami seed str", lambda: sami.make("Hopper", seed="a"), "seed"),
    ("sami seed bool", lambda: sami.make("Hopper", seed=True), "seed"),
    ("sami seed 2^64", lambda: sami.make("Hopper", seed=2**64), "seed"),
    ("sami contact_forces str", lambda: sami.make("Hopper", contact_forces="yes"),
     "contact_forces"),
    ("sami render_mode", lambda: sami.make("Hopper", render_mode="human"), "render_mode"),
    ("tma render_mode array", lambda: tma.make(ST, render_mode=np.zeros(2)), "render_mode"),
    ("sami render_mode array", lambda: sami.make("Hopper", render_mode=np.zeros(2)),
     "render_mode"),
    ("sami step before reset", lambda: sami_env(False).step(np.zeros(3)), "reset"),
    ("tma old gym render human", lambda: tma.gym.make(ST).render(mode="human"), "human"),
    ("sami action nan", lambda: sami_env().step([0, np.nan, 0]), "action 1 is nan"),
    ("sami action inf", lambda: sami_env().step([0, 0, -np.inf]), "finite"),
    ("sami action 2-D", lambda: sami_env().step(np.zeros((1, 3))), "shape"),
    ("sami action length", lambda: sami_env().step(np.zeros(2)), "shape"),
    ("sami action complex", lambda: sami_env().step(np.zeros(3) + 1j), "real"),
    ("sami action str", lambda: sami_env().step("abc"), "real"),
    ("sami action object", lambda: sami_env().step([0, None, 0]), "real"),
    ("sami action 1e300", lambda: sami_env().step([0, 1e300, 0]), "action 1 is 1e+300"),
    ("sami reset options", lambda: sami_env().reset(options={"mass": 2.0}), "mass"),
    ("sami reset options list", lambda: sami_env().reset(options=["mass"]), "options"),
    ("sami reset seed -1", lambda: sami_env().reset(seed=-1), "seed"),
    ("sami reset seed float", lambda: sami_env().reset(seed=0.5), "seed"),
    ("sami render width str", lambda: sami_env().render(width="a"), "width"),
    ("sami render height huge", lambda: sami_env().render(height=10**6), "height"),
    ("sami step after close", lambda: closed(sami_env).step(np.zeros(3)), "closed"),
    ("sami reset after close", lambda: closed(sami_env).reset(), "closed"),
    ("sami model after close", lambda: closed(sami_env).model, "closed"),
    ("sami data after close", lambda: closed(sami_env).data, "closed"),
]


@pytest.mark.parametrize("call,needle", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_is_a_one_line_value_error(call, needle):
    with pytest.raises(ValueError) as raised:
        call()
    message = str(raised.value)
    assert "\n" not in message and len(message) < 400
    assert needle in message


def test_tma_valid_calls_still_work():
    env = tma.make(ST, max_episode_steps=np.int64(50), water_clip=np.float32(10),
                   movable_creepers=np.bool_(False))
    env.set_environment(stump_height=np.float64(1.0), obstacle_spacing=2, stump_width=[1, 0.1])
    obs, info = env.reset(seed=np.uint64(2**64 - 1), options={"stump_height": 0.5})
    assert obs.shape == env.observation_space.shape and info == {}
    # Lists, float32 and int actions; out-of-range values are clipped as in the reference.
    for action in ([0.1, -0.2, 0.3, 0.0], np.ones(4, np.float32), np.zeros(4, int)):
        obs, reward, terminated, truncated, info = env.step(action)
        assert np.isfinite(reward) and "success" in info
    env.reset(seed=3)
    _, clipped, *_ = env.step(np.ones(4))
    env.reset(seed=3)
    _, huge, *_ = env.step(np.full(4, 1e300))
    assert huge == clipped
    env.reset(options={})
    assert env.render(width=64, height=48).shape == (48, 64, 3)
    env.close()
    env.close()  # closing twice is fine


def test_sami_valid_calls_still_work():
    env = sami.make("Hopper", seed=np.int32(1), contact_forces=np.bool_(False))
    obs, info = env.reset(seed=5, options={})
    assert set(obs) == set(env.observation_space.spaces)
    env.step([0.1, 0.2, 0.3])
    # An out-of-range action moves the body as the clamped one (MuJoCo clamps the controls), but
    # its control cost is the reference's, on the action given: 0.1 * sum(a^2) for Hopper.
    env.reset(seed=5)
    _, clamped_reward, *_ = env.step(np.ones(3))
    clamped_qpos = env.data.qpos.copy()
    env.reset(seed=5)
    _, reward, *_ = env.step(np.full(3, 10.0))
    np.testing.assert_array_equal(env.data.qpos, clamped_qpos)
    assert reward == pytest.approx(clamped_reward - 0.1 * 3 * (100.0 - 1.0), abs=1e-6)
    env.reset(seed=None, options=None)
    model = env.model
    env.close()
    assert model.body_mass.shape[0] == model.nbody  # views outlive the closed env
    env.close()


def test_old_gym_api_close():
    env = tma.gym.make(ST)
    env.reset()
    env.step(np.zeros(4))
    env.close()
    with pytest.raises(ValueError, match="closed"):
        env.step(np.zeros(4))


def test_a_training_log_is_never_replaced_silently(make_config):
    import os

    import cradle

    config = make_config("selftouch", max_episode_steps=3)
    env = cradle.make_env(config, training=True)
    env.reset(seed=0)
    for _ in range(4):
        env.step(np.zeros(env.action_space.shape))
    env.close()
    log = os.path.join(config["save_dir"], "logs", "training.jsonl")
    before = open(log).read()
    assert before
    with pytest.raises(ValueError, match="holds the training log of an earlier run") as err:
        cradle.make_env(config, training=True)
    assert "\n" not in str(err.value)
    assert open(log).read() == before  # nothing touched
    cradle.make_env(config, training=False).close()  # evaluation envs write no log
    cradle.make_env(config, training=True, overwrite=True).close()
