"""cradle.tma.run: `cradle tma run` from Python, the same run folder as the CLI's."""

import json
import os
import subprocess

import pytest
from conftest import cradle_binary

from cradle import tma

TINY = {"learning_starts": 300, "batch_size": 32, "pi_layers": [16], "qf_layers": [16]}


def _progress(run):
    with open(os.path.join(run, "progress.csv")) as f:
        return [line.split(",") for line in f.read().splitlines()[1:]]


def test_a_python_run_is_the_cli_run(tmp_path):
    # The same student run from Python and from the CLI: the same run.json record (but the
    # folder), the same evaluations (the columns that do not measure time).
    py_run = tmp_path / "py"
    r = tma.run(student="sac", teacher="Random", steps=1000, test_every=500, nb_test_episodes=2,
                seed=3, hyperparameters=TINY, out=str(py_run), motors_torque=80)
    assert r["run"] == str(py_run)
    assert r["env_steps"] == 1000 and r["evaluations"] == 3  # at 0, 500 and 1000 steps
    # The result is summary.json's record, and the run folder.
    summary = json.loads((py_run / "summary.json").read_text())
    assert list(r) == list(summary) + ["run"]
    assert {k: r[k] for k in ("env_steps", "episodes", "evaluations", "pct_mastered")} == \
        {k: summary[k] for k in ("env_steps", "episodes", "evaluations", "pct_mastered")}
    cli_run = tmp_path / "cli"
    subprocess.run([cradle_binary(), "tma", "run", "--student", "sac", "--teacher", "Random", "--steps",
                    "1000", "--test_every", "500", "--nb_test_episodes", "2", "--seed", "3",
                    "--hp", "learning_starts=300", "--hp", "batch_size=32", "--hp",
                    "pi_layers=16", "--hp", "qf_layers=16", "--motors_torque", "80",
                    "--no-progress", "--out", str(cli_run)], check=True, capture_output=True)
    py_json = json.loads((py_run / "run.json").read_text())
    cli_json = json.loads((cli_run / "run.json").read_text())
    for run in (py_json, cli_json):
        run["arguments"].pop("out")
    assert py_json["arguments"] == cli_json["arguments"]
    assert py_json["arguments"]["env_options"] == {"motors_torque": "80"}
    assert py_json["hyperparameters"] == cli_json["hyperparameters"]
    # evaluation, env_steps, episodes, then (after wall_s and sps) the test returns
    kept = [0, 1, 2, 5, 6, 7, 8]
    assert [[row[c] for c in kept] for row in _progress(py_run)] == \
        [[row[c] for c in kept] for row in _progress(cli_run)]
    assert (py_run / "test_returns.csv").read_text() == (cli_run / "test_returns.csv").read_text()


def test_a_finished_run_resumes_and_is_not_replaced(tmp_path):
    out = str(tmp_path / "run")
    args = dict(teacher="Random", steps=600, test_every=300, nb_test_episodes=2,
                hyperparameters=TINY, out=out)
    tma.run(**args)
    before = (tmp_path / "run" / "progress.csv").read_text()
    with pytest.raises(ValueError, match="holds a run .*: give --resume"):
        tma.run(**args)
    assert (tmp_path / "run" / "progress.csv").read_text() == before
    args["steps"] = 900
    r = tma.run(resume=True, **args)
    assert r["env_steps"] == 900 and len(_progress(out)) == 4  # 0, 300, 600, 900


@pytest.mark.parametrize("kwargs, says", [
    ({"steps": 0}, "steps must be an integer from 1"),
    ({"student": "dqn"}, "--student 'dqn' (expected sac or ppo)"),
    ({"teacher": "Oracle"}, "Oracle"),
    ({"hyperparameters": ["batch_size", 4]}, "hyperparameters must be a dict"),
    ({"teacher_params": {"x": object()}}, "teacher_params"),
    ({"motors_torque": "strong"}, "option motors_torque must be a number"),
    ({"wings": 2}, "unknown option wings"),
    ({"embodiment": "dragon"}, "dragon"),
    ({"seed": -1}, "seed must be an integer"),
])
def test_bad_inputs_are_value_errors(tmp_path, kwargs, says):
    with pytest.raises(ValueError, match=says.replace("(", r"\(").replace(")", r"\)")):
        tma.run(steps=kwargs.pop("steps", 300), out=str(tmp_path / "bad"), **kwargs)
    assert not (tmp_path / "bad" / "run.json").exists()
