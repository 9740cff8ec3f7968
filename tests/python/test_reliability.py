"""Bad input from Python is a one-line ValueError: actions of another shape, strings, NaN, steps
after close(), malformed training-log lines, a config with no actuated joints."""

import json

import numpy as np
import pytest

import cradle


def one_line(excinfo):
    message = str(excinfo.value)
    assert message and "\n" not in message, message
    return message


def test_env_refuses_bad_actions_and_use_after_close(make_config):
    env = cradle.make_env(make_config("selftouch", vision_active=False), training=False)
    env.reset(seed=0)
    n = env.action_space.shape[0]
    for bad in (np.zeros((2, n)), np.zeros(n + 1), ["1.0"] * n, "1.0", None, [object()] * n):
        with pytest.raises(ValueError) as e:
            env.step(bad)
        one_line(e)
    for value in (np.nan, np.inf, -np.inf):
        action = np.zeros(n)
        action[3] = value
        with pytest.raises(ValueError) as e:
            env.step(action)
        assert "expected finite" in one_line(e)
    env.step(np.zeros(n))  # a good action still works after the refusals
    env.close()
    with pytest.raises(ValueError) as e:
        env.step(np.zeros(n))
    assert "close" in one_line(e)
    with pytest.raises(ValueError):
        env.reset(seed=2**64)


def test_vector_refuses_non_finite_actions_and_use_after_close(make_config):
    vec = cradle.VectorEnv(make_config("selftouch", vision_active=False), num_envs=2, threads=1)
    vec.reset(seed=0)
    actions = np.zeros(vec.action_space.shape)
    actions[1, 5] = np.nan
    with pytest.raises(ValueError) as e:
        vec.step(actions)
    one_line(e)
    with pytest.raises(ValueError) as e:
        vec.step(np.zeros((3, actions.shape[1])))
    one_line(e)
    vec.step(np.zeros(actions.shape))
    vec.close()
    with pytest.raises(ValueError) as e:
        vec.step(np.zeros(actions.shape))
    one_line(e)


def test_no_actuated_joints_is_refused(make_config):
    config = make_config("selftouch", vision_active=False)
    for key in list(config):
        if key.startswith("act_"):
            config[key] = False
    with pytest.raises(ValueError) as e:
        cradle.make_env(config, training=False)
    assert "no actuated joints" in one_line(e)


@pytest.mark.parametrize("line", ["42", "null", "[1,2,3]", '{"steps":"x"}',
                                  '{"steps":3,"right_hand_touches":["a"]}'])
def test_training_log_lines_that_are_no_entries(tmp_path, line):
    log = tmp_path / "training.jsonl"
    log.write_text(json.dumps({"steps": 0, "right_hand_touches": [], "left_hand_touches": []})
                   + "\n" + line + "\n")
    with pytest.raises(ValueError) as e:
        cradle.load_training_log(str(log))
    assert ":2:" in one_line(e)
    with pytest.raises(ValueError) as e:
        cradle.training_score([{"steps": 1}, json.loads(line)], "self_touch")
    one_line(e)
