"""cradle.sami.train / evaluate / table: a tiny SaCCM run on Panda push from Python."""

import os

import pytest

import cradle.sami

TINY = {"net_arch": [32, 32], "lstm_hidden": 16, "batch_size": 4, "contrast_batch_size": 4,
        "buffer_size": 8, "train_freq": 10, "gradient_steps": 2, "learning_starts": 60}


def test_train_evaluate_table_and_context_plot(tmp_path):
    run = tmp_path / "run"
    r = cradle.sami.train("PandaPush", "SaCCM", seed=3, steps_per_env=100,
                          hyperparameters=TINY, out=str(run))
    assert r["steps"] == 600 and r["updates"] > 0
    assert os.path.exists(r["checkpoint"])
    e = cradle.sami.evaluate(str(run), split="moderate", episodes=1)
    assert len(e["cells"]) == 6
    for cell in e["cells"]:
        assert cell["push"] + cell["roll"] + cell["pick_and_place"] == pytest.approx(1.0)
    text = cradle.sami.table([str(run)])
    assert "| SaCCM | 1 | – |" in text
    png = cradle.sami.plot_contexts(e["contexts"], str(tmp_path / "contexts.png"))
    assert os.path.getsize(png) > 1000


def test_bad_inputs_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="unknown method"):
        cradle.sami.train("PandaPush", "SaCCM2", out=str(tmp_path / "a"))
    with pytest.raises(ValueError, match="neg_ratio"):
        cradle.sami.train("PandaPush", "SaCCM", hyperparameters={"neg_ratio": 2},
                          out=str(tmp_path / "b"))
    # A missing run folder is a missing file (the module's FileNotFoundError), naming run.json.
    with pytest.raises(FileNotFoundError, match="missing/run.json does not exist"):
        cradle.sami.evaluate(str(tmp_path / "missing"))


def test_resume_keeps_the_runs_env_and_method_and_bad_run_json_names_the_key(tmp_path):
    run = tmp_path / "run"
    cradle.sami.train("PandaPush", "CCM", seed=3, steps_per_env=60, hyperparameters=TINY,
                      out=str(run))
    before = sorted(os.listdir(run))
    with pytest.raises(ValueError, match="is a run of --env PandaPush, not --env CrippleAnt"):
        cradle.sami.train("CrippleAnt", out=str(run), resume=True, steps_per_env=70)
    with pytest.raises(ValueError, match="is a run of --method CCM, not --method SaCCM"):
        cradle.sami.train(method="SaCCM", out=str(run), resume=True, steps_per_env=70)
    assert sorted(os.listdir(run)) == before
    # Left out, env and method are the run's.
    r = cradle.sami.train(out=str(run), resume=True, steps_per_env=70, hyperparameters=TINY)
    assert r["steps"] == 70 * 6
    text = (run / "run.json").read_text()
    (run / "run.json").write_text(text.replace('"seed": 3', '"seed": "x"'))
    with pytest.raises(ValueError, match='run.json: "seed" is "x"; expected an integer'):
        cradle.sami.evaluate(str(run), episodes=1)
