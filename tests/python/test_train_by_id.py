"""cradle.train over env ids of every family: the same run as `cradle train --env`, returning the
run folder; curricula over an env's task parameters; a finished run is never replaced silently."""

import csv
import json
import os

import pytest

import cradle

PPO = {"n_steps": 64, "batch_size": 64, "n_epochs": 1}


def rows(run):
    with open(os.path.join(run, "logs", "progress.csv")) as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("env", ["mimo/reach", "tma/stump-tracks:old_classic_bipedal",
                                 "sami/CrippleHalfCheetah:moderate"])
def test_train_by_id_on_every_family(tmp_path, env):
    run = tmp_path / "run"
    result = cradle.train(env=env, steps=1024, envs=2, hyperparameters=PPO, save_dir=run,
                          progress_bar=False)
    assert result["run"] == str(run)
    assert result["steps"] == 1024
    assert os.path.exists(result["checkpoint"])
    assert [int(r["global_step"]) for r in rows(run)] == [128 * k for k in range(1, 9)]
    # The trained policy's whole episodes, from seeds apart from training's.
    evaluation = json.loads((run / "evaluation.json").read_text())
    assert [e["seed"] for e in evaluation["episodes"]] == [1000, 1001]
    assert evaluation["mean_return"] == pytest.approx(
        sum(e["return"] for e in evaluation["episodes"]) / 2)
    assert json.loads((run / "run.json").read_text())["env"] == cradle.env_spec(env).id


def test_worker_processes_train_the_run_of_threads(tmp_path):
    runs = {}
    for procs in (0, 2):
        run = tmp_path / f"procs{procs}"
        cradle.train(env="tma/stump-tracks:old_classic_bipedal", steps=1024, envs=2,
                     hyperparameters=PPO, save_dir=run, progress_bar=False, eval_episodes=1,
                     procs=procs)
        runs[procs] = run
    timing = {"time", "charts/SPS", "perf/collect_seconds", "perf/update_seconds"}
    strip = lambda run: [{k: v for k, v in r.items() if k not in timing} for r in rows(run)]
    assert strip(runs[2]) == strip(runs[0])
    assert (runs[2] / "checkpoints" / "final.ckpt").read_bytes() == \
        (runs[0] / "checkpoints" / "final.ckpt").read_bytes()
    with pytest.raises(ValueError, match="procs must be a non-negative integer"):
        cradle.train(env="mimo/reach", save_dir=tmp_path / "x", procs=-1)
    with pytest.raises(ValueError, match="give --envs a multiple of --procs"):
        cradle.train(env="mimo/reach", envs=3, save_dir=tmp_path / "y", procs=2)


def test_a_teacher_drives_a_teachmyagent_run(tmp_path):
    space = tmp_path / "space.yml"
    space.write_text("teacher: Random\nparams:\n  stump_height: [0.5, 1.5]\n"
                     "  obstacle_spacing: [2.0, 4.0]\n")
    run = tmp_path / "run"
    cradle.train(env="tma/stump-tracks:old_classic_bipedal", steps=3000, envs=2,
                 hyperparameters=PPO, task_space=space, save_dir=run, progress_bar=False)
    with open(run / "logs" / "teacher.jsonl") as f:
        episodes = [e for e in map(json.loads, f) if e["kind"] == "train"]
    assert episodes
    for e in episodes:
        height, spacing = e["task"]
        assert 0.5 <= height <= 1.5 and 2.0 <= spacing <= 4.0


def test_a_finished_run_is_refused_unless_resumed_or_overwritten(tmp_path):
    run = tmp_path / "run"
    cradle.train(env="sami/Hopper", steps=128, envs=1, hyperparameters=PPO, save_dir=run,
                 progress_bar=False)
    before = (run / "logs" / "progress.csv").read_text()
    with pytest.raises(ValueError, match="--overwrite"):
        cradle.train(env="sami/Hopper", steps=128, envs=1, hyperparameters=PPO, save_dir=run,
                     progress_bar=False, seed=3)
    assert (run / "logs" / "progress.csv").read_text() == before
    resumed = cradle.train(env="sami/Hopper", steps=256, envs=1, hyperparameters=PPO, save_dir=run,
                           progress_bar=False, resume=True)
    assert resumed["steps"] == 256
    cradle.train(env="sami/Hopper", steps=128, envs=1, hyperparameters=PPO, save_dir=run,
                 progress_bar=False, seed=3, overwrite=True)
    assert len(rows(run)) == 2


def test_reset_every_starts_fresh_learners_as_the_cli_does(tmp_path):
    run = tmp_path / "run"
    result = cradle.train(env="mimo/reach", steps=256, envs=1, hyperparameters=PPO, save_dir=run,
                          progress_bar=False, eval_episodes=0, reset_every=128,
                          checkpoint_every=128)
    assert result["steps"] == 256
    assert [int(r["global_step"]) for r in rows(run)] == [64, 128, 192, 256]
    assert json.loads((run / "run.json").read_text())["reset_every"] == 128
    assert b'"learner_resets":1' in (run / "checkpoints" / "final.ckpt").read_bytes()
    for bad in (-1, 1.5, True, "128"):
        with pytest.raises(ValueError, match="reset_every"):
            cradle.train(env="mimo/reach", save_dir=tmp_path / "bad", reset_every=bad)
    assert not (tmp_path / "bad").exists()


def test_wrong_arguments_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="config .* or env"):
        cradle.train()
    with pytest.raises(ValueError, match="closest"):
        cradle.train(env="mimo/rech", save_dir=tmp_path / "x")
    with pytest.raises(ValueError):
        cradle.train(env="mimo/reach", algo="dqn", save_dir=tmp_path / "y")
    assert not (tmp_path / "x").exists()
