"""cradle.tma_analysis: Welch's test against scipy and a hand computation, standard-error bands
against a hand computation, and every figure and table from a synthetic 2-teacher x 2-seed tree.
Runs without the compiled extension (ctest: tma_analysis_tests)."""

import json
import math
import os
import pathlib
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python" / "cradle"))
import tma_analysis as ta  # noqa: E402


def student_t_tail(t, df, n=20000):
    """P(T > t) for Student's t by Simpson's rule on the density, with x = t + u / (1 - u)."""
    c = math.exp(math.lgamma((df + 1) / 2) - math.lgamma(df / 2)) / math.sqrt(df * math.pi)
    total = 0.0
    h = 1.0 / n
    for i in range(n + 1):
        u = min(i * h, 1 - 1e-12)
        x = t + u / (1 - u)
        f = c * (1 + x * x / df) ** (-(df + 1) / 2) / (1 - u) ** 2
        total += f * (1 if i in (0, n) else 4 if i % 2 else 2)
    return total * h / 3


def test_welch_matches_a_hand_computation():
    # a: mean 2.5, s^2 5/3; b: mean 6, s^2 10. s^2/n: 5/12 and 2.
    t, df, p = ta.welch([1, 2, 3, 4], [2, 4, 6, 8, 10])
    se2 = 5 / 12 + 2
    assert t == pytest.approx(-3.5 / math.sqrt(se2), rel=1e-12)
    assert df == pytest.approx(se2**2 / ((5 / 12) ** 2 / 3 + 2**2 / 4), rel=1e-12)
    assert t == pytest.approx(-2.2514363, abs=1e-6)
    assert df == pytest.approx(5.52076, abs=1e-4)
    assert p == pytest.approx(2 * student_t_tail(abs(t), df), abs=1e-6)


def test_welch_matches_scipy_on_known_numbers():
    from scipy import stats

    # Welch's classic example (unequal variances, n 15 and 15): t -2.46, df 24.99, p 0.021.
    a = [27.5, 21.0, 19.0, 23.6, 17.0, 17.9, 16.9, 20.1, 21.9, 22.6, 23.1, 19.6, 19.0, 21.7, 21.4]
    b = [27.1, 22.0, 20.8, 23.4, 23.4, 23.5, 25.8, 22.0, 24.8, 20.2, 21.9, 22.1, 22.9, 20.5, 24.4]
    t, df, p = ta.welch(a, b)
    ref = stats.ttest_ind(a, b, equal_var=False)
    assert t == pytest.approx(ref.statistic, rel=1e-12)
    assert p == pytest.approx(ref.pvalue, rel=1e-9)
    assert (round(t, 2), round(df, 2), round(p, 3)) == (-2.46, 24.99, 0.021)
    rng = np.random.default_rng(3)
    for _ in range(20):
        x, y = rng.normal(0, 1, 7), rng.normal(0.5, 3, 11)
        ref = stats.ttest_ind(x, y, equal_var=False)
        assert ta.welch(x, y)[0] == pytest.approx(ref.statistic, rel=1e-10)
        assert ta.welch(x, y)[2] == pytest.approx(ref.pvalue, rel=1e-8)


def test_welch_without_spread_or_samples_is_no_test():
    assert all(math.isnan(v) for v in ta.welch([1, 1], [1, 1]))
    assert all(math.isnan(v) for v in ta.welch([1], [1, 2, 3]))


def test_standard_error_bands_match_a_hand_computation():
    # Columns: (0, 2, 4) -> mean 2, sample std 2; (10, 14, 18) -> mean 14, sample std 4.
    mean, se = ta.mean_se([[0, 10], [2, 14], [4, 18]])
    np.testing.assert_allclose(mean, [2, 14])
    np.testing.assert_allclose(se, [2 / math.sqrt(3), 4 / math.sqrt(3)])
    mean, se = ta.mean_se([[5, 7]])
    np.testing.assert_allclose(se, [0, 0])


def test_every_figure_and_table_from_two_teachers_two_seeds(tmp_path):
    root = ta.make_synthetic_results(str(tmp_path / "results"), seeds=2,
                                     experiments=("criterion_1", "criterion_2", "parkour"),
                                     evaluations=21, test_tasks=16, episodes_per_eval=4)
    runs = ta.load_results(root)
    # 2 teachers x (2 criteria x 2 seeds + parkour 2 embodiments x 2 seeds).
    assert len(runs) == 16
    assert {r.label for r in runs} == {"Random", "ALP-GMM"}
    assert ta.find_baseline(runs) == "Random"
    out = tmp_path / "figures"
    written = ta.analyze(root, str(out), log=lambda *_: None)
    names = {os.path.basename(f) for f in written}
    expected = {
        "curves_criterion_1_none.png", "curves_parkour_none.png",
        "curves_parkour_none_fish.png", "curves_parkour_none_old_classic_bipedal.png",
        "train_return_parkour_none.png", "test_return_criterion_1_none.png",
        "pairwise_parkour_none.png",
        "skill_radar.png", "skill_bars.png", "skill_ratios.csv",
        "curriculum_ALP-GMM_criterion_1_old_classic_bipedal.png",
        "curriculum_Random_parkour_fish.png",
        "testset_ALP-GMM_parkour_fish.png", "testset_Random_criterion_2_old_classic_bipedal.png",
        "welch_tests.csv", "pairwise.csv", "summary.csv", "summary.md",
    }
    assert expected <= names
    for f in written:
        assert os.path.getsize(f) > 100, f
        if f.endswith(".png"):
            with open(f, "rb") as fh:
                assert fh.read(8) == b"\x89PNG\r\n\x1a\n"
    import pandas as pd

    summary = pd.read_csv(out / "summary.csv")
    row = summary[(summary.experiment == "parkour") & (summary.label == "ALP-GMM")].iloc[0]
    finals = [r.final for r in runs if r.label == "ALP-GMM" and r.experiment == "parkour"]
    assert row.seeds == 4
    assert row.final_mean == pytest.approx(np.mean(finals))
    assert row.final_std == pytest.approx(np.std(finals, ddof=1))
    base = [r.final for r in runs if r.label == "Random" and r.experiment == "parkour"]
    assert row.p_vs_baseline == pytest.approx(ta.welch(finals, base)[2])
    skills = pd.read_csv(out / "skill_ratios.csv")
    assert set(skills.criterion) == {"criterion_1", "criterion_2"}
    c1 = skills[skills.criterion == "criterion_1"].iloc[0]
    assert c1.ratio == pytest.approx(c1["mean"] / c1.baseline_mean)
    welch_rows = pd.read_csv(out / "welch_tests.csv")
    # Tests every 10 evaluations and at the last one: evaluations 10 and 20 of 21.
    assert sorted(set(welch_rows.evaluation)) == [10, 20]
    assert "| parkour | none | ALP-GMM | 4 |" in (out / "summary.md").read_text()


def test_baseline_and_empty_tree_errors(tmp_path, capsys):
    root = ta.make_synthetic_results(str(tmp_path / "r"), seeds=2, experiments=("criterion_1",),
                                     evaluations=3, test_tasks=4, episodes_per_eval=1)
    runs = ta.load_results(root)
    assert ta.find_baseline(runs, "ALP-GMM") == "ALP-GMM"
    with pytest.raises(ValueError, match="baseline 'nope'"):
        ta.find_baseline(runs, "nope")
    os.makedirs(tmp_path / "empty")
    assert ta.main([str(tmp_path / "empty")]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("cradle: error: no run folder") and "\n" not in err


def test_unfinished_run_without_rows_is_left_out(tmp_path):
    root = ta.make_synthetic_results(str(tmp_path / "r"), seeds=2, experiments=("criterion_1",),
                                     evaluations=3, test_tasks=4, episodes_per_eval=1)
    d = tmp_path / "r" / "Random_criterion_1_old_classic_bipedal" / "new_s9"
    d.mkdir()
    (d / "progress.csv").write_text("evaluation,env_steps,pct_mastered\n")
    (d / "launch.json").write_text(json.dumps({"campaign": "Random"}))
    assert len(ta.load_results(root)) == 4


def test_package_alias_when_the_extension_is_built():
    try:
        from cradle.tma import analysis
    except ImportError:
        pytest.skip("the compiled extension is not on the path (PYTHONPATH=build/python)")
    assert analysis.welch is not None and hasattr(analysis, "analyze")


@pytest.mark.parametrize("name", ["tma_results_analysis", "tma_skill_comparison",
                                  "tma_curricula"])
def test_notebooks_run_on_a_small_tree(name, tmp_path, monkeypatch):
    """Every code cell of examples/<name>.ipynb runs (IPython's display stubbed where missing)."""
    import types

    root = ta.make_synthetic_results(str(tmp_path / "r"), seeds=2,
                                     experiments=("criterion_1", "parkour"), evaluations=11,
                                     test_tasks=4, episodes_per_eval=2)
    monkeypatch.setenv("RESULTS", root)
    monkeypatch.chdir(ROOT / "examples")
    shown = []
    display = types.ModuleType("IPython.display")
    display.Image = lambda f: f
    display.Markdown = lambda t: t
    display.display = lambda *items: shown.extend(items)
    ipython = types.ModuleType("IPython")
    ipython.get_ipython = lambda: None  # matplotlib asks when IPython is loaded
    monkeypatch.setitem(sys.modules, "IPython", ipython)
    monkeypatch.setitem(sys.modules, "IPython.display", display)
    with open(ROOT / "examples" / f"{name}.ipynb") as f:
        book = json.load(f)
    assert book["nbformat"] == 4
    scope = {}
    for cell in book["cells"]:
        assert not cell.get("outputs"), "notebooks are kept without outputs"
        if cell["cell_type"] == "code":
            exec("".join(cell["source"]), scope)
    images = [s for s in shown if isinstance(s, str) and s.endswith(".png")]
    assert images and all(os.path.getsize(i) > 100 for i in images)


def test_a_run_folder_without_launch_json_is_read_from_run_json(tmp_path):
    """`cradle tma run --out DIR` alone: labels come from run.json (parsed values at the top,
    the command line under "arguments")."""
    d = tmp_path / "alone_s7"
    ta.write_synthetic_run(str(d), "RIAC", 7, evaluations=3, test_tasks=4, episodes_per_eval=1)
    (d / "run.json").write_text(json.dumps({
        "arguments": {"env": "parkour", "embodiment": "fish", "exp_name": "alone"},
        "student": "sac", "teacher": "RIAC", "expert_knowledge": "low", "seed": 7,
        "bounds": {"names": ["a", "b"], "mins": [0, 0], "maxs": [1, 1]}}))
    run = ta.load_run(str(d))
    assert (run.label, run.teacher, run.ek, run.embodiment, run.seed, run.experiment) == (
        "RIAC", "RIAC", "low", "fish", 7, "alone")
    assert run.final == pytest.approx(float(run.progress["pct_mastered"].iloc[-1]))


def _first_run(root):
    """The first run folder of a synthetic tree (sorted), where the damage goes."""
    return sorted(p for p in pathlib.Path(root).glob("*/*") if (p / "progress.csv").exists())[0]


def _cut(path, keep=-15):
    data = path.read_bytes()
    path.write_bytes(data[:keep])


def _replace_cell(path, line, column, value):
    rows = path.read_text().split("\n")
    cells = rows[line - 1].split(",")
    cells[column] = value
    rows[line - 1] = ",".join(cells)
    path.write_text("\n".join(rows))


def _make_folder(path):
    path.unlink()
    path.mkdir()
    (path / "inside.txt").write_text("x\n")


# (file of the first run, damage, what the message says besides the file's path)
DAMAGE = {
    "progress_truncated": ("progress.csv", _cut, "is truncated"),
    "progress_short_row": ("progress.csv", lambda p: p.write_text(p.read_text() + "1,2\n"),
                           "has 2 cells, the header 9"),
    "progress_not_numeric": ("progress.csv", lambda p: _replace_cell(p, 3, 1, "abc"),
                             "line 3, column env_steps: 'abc' is not a number"),
    "progress_folder": ("progress.csv", _make_folder, "is a folder"),
    "progress_without_column": (
        "progress.csv", lambda p: p.write_text(p.read_text().replace("pct_mastered", "pct")),
        "has no column pct_mastered"),
    "test_returns_truncated": ("test_returns.csv", _cut, "is truncated"),
    "test_returns_not_numeric": ("test_returns.csv", lambda p: _replace_cell(p, 2, 4, "yes"),
                                 "line 2, column mastered: 'yes' is not a number"),
    "test_returns_folder": ("test_returns.csv", _make_folder, "is a folder"),
    "test_set_not_numeric": ("test_set.csv", lambda p: _replace_cell(p, 2, 1, "high"),
                             "'high' is not a number"),
    "run_json_cut": ("run.json", _cut, "is not valid JSON"),
    "launch_json_list": ("launch.json", lambda p: p.write_text("[1, 2]\n"),
                         "is not a JSON object"),
    "teacher_jsonl_cut": ("logs/teacher.jsonl", lambda p: _cut(p, 40),
                          "line 1 is not a teacher record"),
}


@pytest.mark.parametrize("case", sorted(DAMAGE))
def test_damaged_run_files_are_one_line_naming_the_file_and_write_nothing(tmp_path, capsys,
                                                                           case):
    root = ta.make_synthetic_results(str(tmp_path / "r"), seeds=2, experiments=("criterion_1",),
                                     evaluations=11, test_tasks=4, episodes_per_eval=2)
    name, damage, says = DAMAGE[case]
    file = _first_run(root) / name
    damage(file)
    out = tmp_path / "analysis"
    assert ta.main([root, "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("cradle: error: ") and err.count("\n") == 1, err
    assert str(file) in err and says in err, err
    assert not out.exists()


@pytest.mark.parametrize("case", ["empty", "not_a_campaign", "missing", "a_file"])
def test_a_folder_that_is_no_campaign_is_one_line(tmp_path, capsys, case):
    root = tmp_path / "r"
    if case != "missing":
        root.mkdir()
    if case == "not_a_campaign":
        (root / "notes.txt").write_text("hello\n")
        (root / "sub").mkdir()
    if case == "a_file":
        root.rmdir()
        root.write_text("x\n")
    out = tmp_path / "analysis"
    assert ta.main([str(root), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("cradle: error: ") and err.count("\n") == 1, err
    assert str(root) in err and "expected the results tree" in err, err
    assert not out.exists()
