"""TeachMyAgent campaign analysis: the paper's figures, statistical tests and tables.

    python3 -m cradle.tma_analysis RESULTS [--out DIR] [--baseline LABEL]   # or `cradle tma analyze`

    from cradle.tma import analysis                  # the same module
    runs = analysis.load_results("tma_results")      # one Run per run folder
    analysis.analyze("tma_results", "figures")       # every figure + summary.md / summary.csv

RESULTS is the tree of ``cradle tma campaign launch`` (docs/tma_campaigns.md): run folders holding
``progress.csv`` (one row per evaluation), ``test_returns.csv``, ``test_set.csv``, ``run.json``,
``logs/teacher.jsonl`` and the launcher's ``launch.json`` (campaign, experiment, seed, arguments).
A run is labelled by its campaign (one teacher and its parameters); the baseline is the campaign
whose teacher is Random unless ``--baseline`` names another. Needs only numpy, scipy, pandas and
matplotlib (Debian's), so it also runs as a plain script without the compiled extension.
"""

import argparse
import io
import json
import math
import os
import sys
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

MASTERED = "pct_mastered"
EK_LEVELS = ("none", "low", "high")
TEST_EVERY_N_EVALS = 10  # Welch tests against the baseline every 10 evaluations (the paper's)


# ---- statistics ---------------------------------------------------------------------------------


def welch(a, b):
    """Welch's unequal-variance t-test of samples a and b: (t, degrees of freedom, two-sided p).

    t = (mean a - mean b) / sqrt(s_a^2/n_a + s_b^2/n_b) with sample variances (ddof 1), and the
    Welch-Satterthwaite degrees of freedom. Fewer than 2 values on a side, or no spread on either,
    gives nan (no test)."""
    from scipy import special

    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.size < 2 or b.size < 2:
        return math.nan, math.nan, math.nan
    va = a.var(ddof=1) / a.size
    vb = b.var(ddof=1) / b.size
    if va + vb == 0:
        return math.nan, math.nan, math.nan
    t = (a.mean() - b.mean()) / math.sqrt(va + vb)
    df = (va + vb) ** 2 / (va**2 / (a.size - 1) + vb**2 / (b.size - 1))
    # Two-sided tail of Student's t: 2 * P(T > |t|) = 2 * (1 - stdtr(df, |t|)).
    p = 2.0 * special.stdtr(df, -abs(t))
    return float(t), float(df), float(p)


def mean_se(values):
    """Per-column mean and standard error (sample std, ddof 1, / sqrt(n)) of a seeds x points
    array; one seed gives a zero-width band."""
    values = np.asarray(values, dtype=np.float64)
    mean = values.mean(axis=0)
    if values.shape[0] < 2:
        return mean, np.zeros_like(mean)
    return mean, values.std(axis=0, ddof=1) / math.sqrt(values.shape[0])


# ---- loading ------------------------------------------------------------------------------------


@dataclass
class Run:
    """One run folder and what the analysis groups it by."""

    path: str
    label: str  # campaign (teacher + its parameters)
    teacher: str
    experiment: str  # criterion_1..5, parkour, upper_baseline, or the experiment name
    ek: str
    embodiment: str
    student: str
    seed: int
    progress: pd.DataFrame
    run_json: dict = field(default_factory=dict)
    test_returns: pd.DataFrame = None  # None without the file (or rows)
    test_set: pd.DataFrame = None

    @property
    def final(self):
        """% mastered at the last evaluation."""
        return float(self.progress[MASTERED].iloc[-1])


def _arg(args, key):
    """The value after --key in an argument list (None when absent)."""
    for flag in ("--" + key, "--" + key.replace("_", "-")):
        if flag in args:
            i = args.index(flag)
            if i + 1 < len(args) and not args[i + 1].startswith("--"):
                return args[i + 1]
    return None


class AnalysisInputError(ValueError):
    """A results tree the analysis cannot read: one line naming the file and what was expected."""


# The columns the analysis reads from each of a run's tables.
PROGRESS_COLUMNS = ("env_steps", "mean_test_return", MASTERED, "mean_train_return")
TEST_RETURNS_COLUMNS = ("evaluation", "task_index", "mastered")
TEST_SET_COLUMNS = ("task_index",)


def _read_text(path, expected):
    """A run file's text; None when it does not exist. A folder, an unreadable file or one that
    is not UTF-8 text raises AnalysisInputError."""
    if not os.path.lexists(path):
        return None
    if not os.path.isfile(path):
        kind = "a folder" if os.path.isdir(path) else "not a regular file"
        raise AnalysisInputError(f"{path} is {kind}; expected {expected}")
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except OSError as e:
        raise AnalysisInputError(
            f"cannot read {path} ({e.strerror}); expected {expected}") from None
    except UnicodeDecodeError:
        raise AnalysisInputError(f"{path} is not text; expected {expected}") from None


def _read_json(path):
    """A run's launch.json / run.json as a dict ({} when it does not exist)."""
    expected = "a JSON object written by `cradle tma run` or the campaign launcher"
    text = _read_text(path, expected)
    if text is None:
        return {}
    try:
        value = json.loads(text)
    except ValueError:
        raise AnalysisInputError(f"{path} is not valid JSON (cut short or edited?); "
                                 f"expected {expected}") from None
    if not isinstance(value, dict):
        raise AnalysisInputError(f"{path} is not a JSON object; expected {expected}")
    return value


def read_table(path, columns):
    """A run's CSV table (progress.csv, test_returns.csv, test_set.csv) as a DataFrame: None when
    the file does not exist or holds no rows yet. Every row must be complete (as many cells as
    the header, the last line ended) and every cell a number or empty (NaN), and `columns` must
    be in the header; otherwise AnalysisInputError names the file, the line and the column."""
    name = os.path.basename(path)
    expected = f"the {name} of `cradle tma run`"
    text = _read_text(path, expected)
    if text is None:
        return None
    lines = text.split("\n")
    if lines[-1] != "":
        raise AnalysisInputError(f"{path} is truncated: its last line has no end; expected "
                                 "complete rows (a run still writing it, or a cut copy?)")
    rows = [(number, line) for number, line in enumerate(lines[:-1], 1) if line.strip()]
    if len(rows) < 2:
        return None  # no rows yet (an empty file or the header alone)
    header = rows[0][1].split(",")
    missing = [c for c in columns if c not in header]
    if missing:
        raise AnalysisInputError(f"{path} has no column {missing[0]}; expected {expected} "
                                 f"(columns {', '.join(columns)}, ...)")
    for number, line in rows[1:]:
        cells = line.split(",")
        if len(cells) != len(header):
            raise AnalysisInputError(
                f"{path} line {number} has {len(cells)} cells, the header {len(header)}; "
                "expected complete rows (cut short or edited?)")
        for column, cell in zip(header, cells):
            if cell.strip() == "":
                continue
            try:
                float(cell)
            except ValueError:
                raise AnalysisInputError(
                    f"{path} line {number}, column {column}: {cell!r} is not a number; "
                    "expected numbers (or empty cells)") from None
    return pd.read_csv(io.StringIO(text))


def load_run(path):
    """One run folder -> Run (None when it has no progress.csv rows yet). A progress.csv,
    test_returns.csv, test_set.csv, run.json or launch.json that is there but unreadable,
    truncated or not numeric raises AnalysisInputError naming it."""
    progress = read_table(os.path.join(path, "progress.csv"), PROGRESS_COLUMNS)
    if progress is None:
        return None
    test_returns = read_table(os.path.join(path, "test_returns.csv"), TEST_RETURNS_COLUMNS)
    test_set = read_table(os.path.join(path, "test_set.csv"), TEST_SET_COLUMNS)
    launch = _read_json(os.path.join(path, "launch.json"))
    run_json = _read_json(os.path.join(path, "run.json"))
    args = launch.get("args", [])
    # run.json: the parsed values at the top, the command line's under "arguments".
    given = run_json.get("arguments") if isinstance(run_json.get("arguments"), dict) else {}
    aliases = {"allow_expert_knowledge": ("allow_expert_knowledge", "expert_knowledge")}

    def value(key, default):
        v = _arg(args, key)
        for name in aliases.get(key, (key,)):
            for source in (run_json, given):
                if v is None and isinstance(source.get(name), (str, int, float)):
                    v = source.get(name)
        return str(v) if v is not None else default

    teacher = value("teacher", "unknown")
    name = os.path.basename(os.path.normpath(path))
    seed = launch.get("seed", run_json.get("seed", given.get("seed")))
    try:
        seed = -1 if seed is None else int(seed)
        if isinstance(seed, bool):
            raise TypeError
    except (TypeError, ValueError):
        raise AnalysisInputError(f"{path}: the seed in launch.json / run.json is {seed!r}; "
                                 "expected an integer") from None
    ek = value("allow_expert_knowledge", "none")
    ek = {"no": "none", "minimal": "low", "maximal": "high", "original": "high"}.get(ek, ek)
    return Run(
        path=path,
        label=launch.get("campaign") or teacher,
        teacher=teacher,
        experiment=launch.get("experiment") or value("exp_name", name),
        ek=ek,
        embodiment=value("embodiment", "old_classic_bipedal"),
        student=value("student", "sac"),
        seed=seed,
        progress=progress,
        run_json=run_json,
        test_returns=test_returns,
        test_set=test_set,
    )


def load_results(root):
    """Every run folder under root (folders holding progress.csv), sorted by label, experiment,
    seed."""
    runs = []

    def unreadable(error):
        raise AnalysisInputError(f"cannot read the folder {error.filename} ({error.strerror})")

    for dirpath, dirnames, filenames in os.walk(root, onerror=unreadable):
        dirnames.sort()
        # A progress.csv that is a folder is listed under dirnames: read_table refuses it.
        if "progress.csv" in filenames or "progress.csv" in dirnames:
            run = load_run(dirpath)
            if run is not None:
                runs.append(run)
            # A run's own folders (logs/ holds every run's per-report progress.csv) are no runs.
            dirnames[:] = []
    runs.sort(key=lambda r: (r.label, r.experiment, r.ek, r.embodiment, r.student, r.seed))
    return runs


def find_baseline(runs, baseline=None):
    """The baseline label: `baseline` when given (it must exist), else the Random campaign."""
    labels = sorted({r.label for r in runs})
    if baseline is not None:
        if baseline not in labels:
            raise ValueError(f"baseline {baseline!r} is not a campaign of the results ({labels})")
        return baseline
    randoms = sorted({r.label for r in runs if r.teacher.lower() == "random"})
    return randoms[0] if randoms else None


def _curves(runs, column=MASTERED):
    """seeds x evaluations array of a column (cut to the shortest run) and its env steps."""
    n = min(len(r.progress) for r in runs)
    values = np.stack([r.progress[column].to_numpy(np.float64)[:n] for r in runs])
    steps = runs[0].progress["env_steps"].to_numpy(np.float64)[:n]
    return values, steps


def _baseline_runs(runs, baseline, experiment, ek=None, embodiment=None):
    """The baseline's runs of one cell; its EK-none runs stand for every EK (as in the paper)."""
    base = [r for r in runs if r.label == baseline and r.experiment == experiment]
    if embodiment is not None:
        base = [r for r in base if r.embodiment == embodiment]
    if ek is not None:
        same = [r for r in base if r.ek == ek]
        base = same or [r for r in base if r.ek == "none"]
    return base


# ---- figures ------------------------------------------------------------------------------------


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _colors(labels):
    plt = _plt()
    cmap = plt.get_cmap("tab10")
    return {label: cmap(i % 10) for i, label in enumerate(sorted(labels))}


def plot_curves(runs, baseline, title, file, column=MASTERED, ylabel="% mastered test tasks"):
    """Mean curve per label with standard-error shading; stars where Welch's p < 0.05 against the
    baseline, every 10 evaluations. Returns the rows of the Welch tests."""
    plt = _plt()
    labels = sorted({r.label for r in runs})
    colors = _colors(labels)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    base_values = None
    if baseline in labels:
        base_values, _ = _curves([r for r in runs if r.label == baseline], column)
    tests = []
    top = 0.0
    for label in labels:
        values, steps = _curves([r for r in runs if r.label == label], column)
        mean, se = mean_se(values)
        x = steps / 1e6
        ax.plot(x, mean, color=colors[label], label=f"{label} ({values.shape[0]} seeds)")
        ax.fill_between(x, mean - se, mean + se, color=colors[label], alpha=0.25)
        top = max(top, float(np.max(mean + se)))
        if base_values is None or label == baseline:
            continue
        n = min(values.shape[1], base_values.shape[1])
        # Evaluations 10, 20, ... and the last one.
        for k in sorted(set(range(TEST_EVERY_N_EVALS, n, TEST_EVERY_N_EVALS)) | {n - 1}):
            t, df, p = welch(values[:, k], base_values[:, k])
            tests.append(
                {"label": label, "evaluation": k, "env_steps": steps[k], "t": t, "df": df, "p": p,
                 "mean": values[:, k].mean(), "baseline_mean": base_values[:, k].mean()}
            )
    # Stars above the curves where the test is significant.
    star_y = top * 1.05 + 1
    for i, row in enumerate(tests):
        if row["p"] < 0.05:
            ax.plot(row["env_steps"] / 1e6, star_y + i % 3, marker="*", color=colors[row["label"]])
    ax.set_title(title)
    ax.set_xlabel("environment steps (millions)")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(file, dpi=100)
    plt.close(fig)
    return tests


def plot_pairwise(runs, title, file):
    """Grid of Welch p-values of the final % mastered, row label vs column label; green where
    the row is significantly better, red where worse."""
    plt = _plt()
    labels = sorted({r.label for r in runs})
    finals = {label: [r.final for r in runs if r.label == label] for label in labels}
    n = len(labels)
    color = np.ones((n, n, 3))
    fig, ax = plt.subplots(figsize=(1.2 * n + 2.5, 1.0 * n + 1.5))
    rows = []
    for i, a in enumerate(labels):
        for j, b in enumerate(labels):
            if i == j:
                color[i, j] = (0.85, 0.85, 0.85)
                continue
            t, _, p = welch(finals[a], finals[b])
            rows.append({"row": a, "column": b, "t": t, "p": p})
            if p < 0.05:
                color[i, j] = (0.55, 0.85, 0.55) if t > 0 else (0.9, 0.55, 0.55)
            text = "n/a" if math.isnan(p) else f"p={p:.3f}"
            ax.text(j, i, text, ha="center", va="center", fontsize=8)
    ax.imshow(color)
    ax.set_xticks(range(n), labels, rotation=30, ha="right")
    ax.set_yticks(range(n), labels)
    ax.set_title(title + "\n(row vs column, Welch test of final % mastered)", fontsize=9)
    fig.tight_layout()
    fig.savefig(file, dpi=100)
    plt.close(fig)
    return rows


def skill_table(runs, baseline):
    """Per criterion x EK x label: mean final % mastered, the baseline's, the ratio and Welch's p.
    Criteria are the experiments named criterion_*."""
    criteria = sorted({r.experiment for r in runs if r.experiment.startswith("criterion")})
    rows = []
    for crit in criteria:
        for ek in EK_LEVELS:
            base = [r.final for r in _baseline_runs(runs, baseline, crit, ek)]
            for label in sorted({r.label for r in runs if r.label != baseline}):
                mine = [r.final for r in runs if r.label == label and r.experiment == crit
                        and r.ek == ek]
                if not mine or not base:
                    continue
                t, _, p = welch(mine, base)
                ratio = np.mean(mine) / np.mean(base) if np.mean(base) > 0 else math.nan
                rows.append({"criterion": crit, "ek": ek, "label": label, "seeds": len(mine),
                             "mean": np.mean(mine), "baseline_mean": np.mean(base),
                             "ratio": ratio, "p": p,
                             "star": bool(p < 0.05 and np.mean(mine) > np.mean(base))})
    return pd.DataFrame(rows)


def plot_skill_radar(table, file):
    """One radar per EK level: axes = criteria, one polygon per label of ratio to the baseline
    (1 = the baseline); a star marks Welch p < 0.05 where the label beats the baseline."""
    plt = _plt()
    levels = [ek for ek in EK_LEVELS if ek in set(table["ek"])]
    criteria = sorted(set(table["criterion"]))
    colors = _colors(set(table["label"]))
    fig, axes = plt.subplots(1, len(levels), subplot_kw={"projection": "polar"},
                             figsize=(4.2 * len(levels), 4.4), squeeze=False)
    angles = np.linspace(0, 2 * np.pi, len(criteria), endpoint=False)
    for ax, ek in zip(axes[0], levels):
        for label in sorted(set(table["label"])):
            sub = table[(table["ek"] == ek) & (table["label"] == label)].set_index("criterion")
            r = np.array([sub["ratio"].get(c, np.nan) for c in criteria], dtype=np.float64)
            r_closed = np.append(np.nan_to_num(r), np.nan_to_num(r[:1]))
            ax.plot(np.append(angles, angles[:1]), r_closed, color=colors[label], label=label)
            for a, c, v in zip(angles, criteria, r):
                if c in sub.index and bool(sub["star"].get(c)):
                    ax.plot(a, v, marker="*", markersize=12, color=colors[label])
        ax.plot(np.linspace(0, 2 * np.pi, 100), np.ones(100), "k--", linewidth=0.8)
        ax.set_xticks(angles, [c.replace("criterion_", "C") for c in criteria])
        ax.set_title(f"{ek} expert knowledge", fontsize=10)
    axes[0][0].legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.2, -0.2))
    fig.suptitle("final % mastered / baseline's (dashed: baseline)", fontsize=10)
    fig.tight_layout()
    fig.savefig(file, dpi=100)
    plt.close(fig)


def plot_skill_bars(table, file):
    """Bars of ratio to the baseline per criterion x EK cell, one bar per label, stars as above."""
    plt = _plt()
    cells = sorted({(c, ek) for c, ek in zip(table["criterion"], table["ek"])},
                   key=lambda ce: (ce[0], EK_LEVELS.index(ce[1]) if ce[1] in EK_LEVELS else 9))
    labels = sorted(set(table["label"]))
    colors = _colors(labels)
    width = 0.8 / max(1, len(labels))
    fig, ax = plt.subplots(figsize=(max(6, 0.9 * len(cells) + 2), 4))
    for i, label in enumerate(labels):
        for k, (c, ek) in enumerate(cells):
            row = table[(table["criterion"] == c) & (table["ek"] == ek) & (table["label"] == label)]
            if row.empty:
                continue
            v = float(np.nan_to_num(row["ratio"].iloc[0]))
            x = k + (i - (len(labels) - 1) / 2) * width
            ax.bar(x, v, width, color=colors[label], label=label if k == 0 else None)
            if bool(row["star"].iloc[0]):
                ax.text(x, v, "*", ha="center", va="bottom", fontsize=14)
    ax.axhline(1.0, color="k", linestyle="--", linewidth=0.8)
    ax.set_xticks(range(len(cells)), [f"{c.replace('criterion_', 'C')}\n{ek}" for c, ek in cells])
    ax.set_ylabel("final % mastered / baseline's")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(file, dpi=100)
    plt.close(fig)


def _teacher_records(path):
    """logs/teacher.jsonl (teacher.jsonl in runs of earlier versions) -> (training tasks with env
    steps, dumps with env steps); empty without the file. A line that is not a JSON record of
    `cradle tma run` raises AnalysisInputError."""
    tasks, steps, dumps = [], [], []
    file = os.path.join(path, "logs", "teacher.jsonl")
    if not os.path.exists(file) and os.path.exists(os.path.join(path, "teacher.jsonl")):
        file = os.path.join(path, "teacher.jsonl")
    text = _read_text(file, "the teacher.jsonl of `cradle tma run`") or ""
    for number, line in enumerate(text.split("\n"), 1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
            if rec.get("kind") == "train":
                task, step = [float(x) for x in rec["task"]], float(rec["env_steps"])
                if tasks and len(task) != len(tasks[0]):
                    raise ValueError
                tasks.append(task)
                steps.append(step)
            elif rec.get("kind") == "dump":
                float(rec["env_steps"])
                dumps.append(rec)
        except (ValueError, KeyError, TypeError, AttributeError):
            raise AnalysisInputError(f"{file} line {number} is not a teacher record (cut short or "
                                     "edited?); expected one JSON object per line") from None
    return np.asarray(tasks, dtype=np.float64), np.asarray(steps, dtype=np.float64), dumps


def _bounds(run):
    b = run.run_json.get("bounds") or run.run_json.get("params") or {}
    names = b.get("names") or []
    mins = b.get("mins") or []
    maxs = b.get("maxs") or []
    return list(names), list(mins), list(maxs)


def _draw_dump(ax, teacher):
    """GMM ellipses, ADR box or RIAC regions of one dump, over the first two dimensions."""
    from matplotlib import patches

    for comp in teacher.get("components", []):
        mean = comp["mean"]
        cov = comp.get("covariance") or comp.get("cov")
        if cov is not None:
            c = np.asarray(cov, dtype=np.float64)
            c = np.diag(c) if c.ndim == 1 else c
            vals, vecs = np.linalg.eigh(c[:2, :2])
            angle = math.degrees(math.atan2(vecs[1, 1], vecs[0, 1]))
            w, h = 2 * 2 * np.sqrt(np.maximum(vals[::-1], 0))  # 2 std
            ax.add_patch(patches.Ellipse(mean[:2], w, h, angle=angle, fill=False, color="C3",
                                         alpha=min(1.0, 0.3 + comp.get("weight", 0.5))))
        else:
            ax.plot(mean[0], mean[1], "o", color="C3", markersize=4 + 20 * comp.get("weight", 0))
    if "cur_min" in teacher and "cur_max" in teacher:
        lo, hi = teacher["cur_min"], teacher["cur_max"]
        ax.add_patch(patches.Rectangle((lo[0], lo[1]), hi[0] - lo[0], hi[1] - lo[1], fill=False,
                                       color="C2", linewidth=2))
    for region in teacher.get("regions", []):
        if not region.get("leaf", True):
            continue
        lo, hi = region["lo"], region["hi"]
        ax.add_patch(patches.Rectangle((lo[0], lo[1]), hi[0] - lo[0], hi[1] - lo[1], fill=False,
                                       color="C1", linewidth=0.8))


def plot_curriculum(run, file, panels=4, records=None):
    """Tasks the teacher sampled in each quarter of training over the first two task dimensions,
    with the teacher's state at the end of that quarter (GMM ellipses, ADR box, RIAC regions).
    records: the run's _teacher_records when already read. Returns False when the run has no
    training tasks."""
    tasks, steps, dumps = records if records is not None else _teacher_records(run.path)
    if tasks.ndim != 2 or len(tasks) == 0:
        return False
    plt = _plt()
    names, mins, maxs = _bounds(run)
    end = steps.max()
    fig, axes = plt.subplots(1, panels, figsize=(3.3 * panels, 3.3), squeeze=False)
    for k, ax in enumerate(axes[0]):
        lo, hi = end * k / panels, end * (k + 1) / panels
        pick = (steps > lo) & (steps <= hi) if k else (steps <= hi)
        ax.scatter(tasks[pick, 0], tasks[pick, 1] if tasks.shape[1] > 1 else np.zeros(pick.sum()),
                   s=4, alpha=0.5, color="C0")
        before = [d for d in dumps if d["env_steps"] <= hi]
        if before:
            _draw_dump(ax, before[-1].get("teacher", {}))
        if len(mins) >= 2:
            ax.set_xlim(mins[0], maxs[0])
            ax.set_ylim(mins[1], maxs[1])
        if len(names) >= 2:
            ax.set_xlabel(names[0])
            ax.set_ylabel(names[1])
        ax.set_title(f"{lo / 1e6:.3g}-{hi / 1e6:.3g} M steps", fontsize=9)
    fig.suptitle(f"{run.label} {run.experiment} seed {run.seed}: sampled tasks", fontsize=10)
    fig.tight_layout()
    fig.savefig(file, dpi=100)
    plt.close(fig)
    return True


def plot_test_heatmap(runs, file):
    """Fraction of seeds that master each test task at the final evaluation, over the first two
    test-set dimensions. Returns False without test files."""
    test_set, mastered = None, []
    for run in runs:
        ts, tr = run.test_set, run.test_returns
        if ts is None or tr is None:
            continue
        last = tr[tr["evaluation"] == tr["evaluation"].max()].sort_values("task_index")
        test_set = ts.sort_values("task_index")
        mastered.append(last["mastered"].to_numpy(np.float64))
    if test_set is None or not mastered or len(test_set.columns) < 2:
        return False
    n = min(len(m) for m in mastered)
    frac = np.mean([m[:n] for m in mastered], axis=0)
    cols = [c for c in test_set.columns if c != "task_index"]
    x = test_set[cols[0]].to_numpy()[:n]
    y = test_set[cols[1]].to_numpy()[:n] if len(cols) > 1 else np.zeros(n)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5, 4))
    sc = ax.scatter(x, y, c=frac, cmap="viridis", vmin=0, vmax=1, marker="s", s=120)
    fig.colorbar(sc, ax=ax, label=f"fraction of {len(mastered)} seeds mastering")
    ax.set_xlabel(cols[0])
    ax.set_ylabel(cols[1] if len(cols) > 1 else "")
    r = runs[0]
    ax.set_title(f"{r.label} {r.experiment}: test set, final evaluation", fontsize=9)
    fig.tight_layout()
    fig.savefig(file, dpi=100)
    plt.close(fig)
    return True


# ---- tables and the whole analysis --------------------------------------------------------------


def summary_table(runs, baseline):
    """Mean ± std final % mastered per experiment, EK and label, with Welch's p vs the baseline."""
    rows = []
    keys = sorted({(r.experiment, r.ek, r.label) for r in runs})
    for experiment, ek, label in keys:
        finals = [r.final for r in runs if (r.experiment, r.ek, r.label) == (experiment, ek, label)]
        base = [r.final for r in _baseline_runs(runs, baseline, experiment, ek)]
        p = welch(finals, base)[2] if label != baseline and base else math.nan
        rows.append({"experiment": experiment, "ek": ek, "label": label, "seeds": len(finals),
                     "final_mean": float(np.mean(finals)),
                     "final_std": float(np.std(finals, ddof=1)) if len(finals) > 1 else 0.0,
                     "p_vs_baseline": p})
    return pd.DataFrame(rows)


def _markdown(table):
    lines = ["| experiment | EK | campaign | seeds | final % mastered | Welch p vs baseline |",
             "|---|---|---|---|---|---|"]
    for _, r in table.iterrows():
        p = "" if math.isnan(r["p_vs_baseline"]) else f"{r['p_vs_baseline']:.3g}"
        lines.append(f"| {r['experiment']} | {r['ek']} | {r['label']} | {r['seeds']} | "
                     f"{r['final_mean']:.1f} ± {r['final_std']:.1f} | {p} |")
    return "\n".join(lines) + "\n"


def _safe(text):
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in str(text))


def analyze(root, out=None, baseline=None, log=print):
    """Every figure and table of a results tree into `out` (default root/analysis); returns the
    list of files written."""
    out = out or os.path.join(root, "analysis")
    if not os.path.isdir(root):
        raise AnalysisInputError(f"{root} is not a folder; expected the results tree of "
                                 "`cradle tma campaign launch`")
    runs = load_results(root)
    if not runs:
        raise AnalysisInputError(f"no run folder with a progress.csv under {root}; expected the "
                                 "results tree of `cradle tma campaign launch`")
    baseline = find_baseline(runs, baseline)
    # Every input is read before the first file is written: the curricula pictured (the first
    # seed of each label, experiment and embodiment) too.
    curricula = {}
    for experiment in sorted({r.experiment for r in runs}):
        for label in sorted({r.label for r in runs if r.experiment == experiment}):
            mine = [r for r in runs if r.experiment == experiment and r.label == label]
            for body in sorted({r.embodiment for r in mine}):
                first = [r for r in mine if r.embodiment == body][0]
                curricula[first.path] = _teacher_records(first.path)
    os.makedirs(out, exist_ok=True)
    written = []

    def path(name):
        written.append(os.path.join(out, name))
        return written[-1]

    welch_rows, pair_rows = [], []
    for experiment in sorted({r.experiment for r in runs}):
        exp_runs = [r for r in runs if r.experiment == experiment]
        for ek in sorted({r.ek for r in exp_runs}):
            # The baseline's EK-none runs stand for every EK level.
            cell = [r for r in exp_runs if r.ek == ek and r.label != baseline]
            cell += _baseline_runs(exp_runs, baseline, experiment, ek)
            tag = f"{_safe(experiment)}_{ek}"
            tests = plot_curves(cell, baseline, f"{experiment}, {ek} EK", path(f"curves_{tag}.png"))
            welch_rows += [dict(t, experiment=experiment, ek=ek, embodiment="all") for t in tests]
            # Mean test return: what moves before any task is mastered (short budgets).
            plot_curves(cell, baseline, f"{experiment}, {ek} EK: mean test return",
                        path(f"test_return_{tag}.png"), column="mean_test_return",
                        ylabel="mean test return")
            plot_curves(cell, baseline, f"{experiment}, {ek} EK: training return",
                        path(f"train_return_{tag}.png"), column="mean_train_return",
                        ylabel="mean training return")
            if len({r.label for r in cell}) > 1:
                pair_rows += [dict(p, experiment=experiment, ek=ek) for p in
                              plot_pairwise(cell, f"{experiment}, {ek} EK",
                                            path(f"pairwise_{tag}.png"))]
            bodies = sorted({r.embodiment for r in cell})
            if len(bodies) > 1:
                for body in bodies:
                    sub = [r for r in cell if r.embodiment == body]
                    tests = plot_curves(sub, baseline, f"{experiment}, {ek} EK, {body}",
                                        path(f"curves_{tag}_{_safe(body)}.png"))
                    welch_rows += [dict(t, experiment=experiment, ek=ek, embodiment=body)
                                   for t in tests]
        # Curriculum pictures (first seed of each label) and test-set heat maps.
        for label in sorted({r.label for r in exp_runs}):
            mine = [r for r in exp_runs if r.label == label]
            for body in sorted({r.embodiment for r in mine}):
                group = [r for r in mine if r.embodiment == body]
                tag = f"{_safe(label)}_{_safe(experiment)}_{_safe(body)}"
                name = f"curriculum_{tag}.png"
                if plot_curriculum(group[0], os.path.join(out, name),
                                   records=curricula.get(group[0].path)):
                    written.append(os.path.join(out, name))
                name = f"testset_{tag}.png"
                if plot_test_heatmap(group, os.path.join(out, name)):
                    written.append(os.path.join(out, name))

    skills = skill_table(runs, baseline) if baseline else pd.DataFrame()
    if not skills.empty:
        skills.to_csv(path("skill_ratios.csv"), index=False)
        plot_skill_radar(skills, path("skill_radar.png"))
        plot_skill_bars(skills, path("skill_bars.png"))
    else:
        log("no criterion_* experiment with a baseline: no radar / bar charts")
    pd.DataFrame(welch_rows).to_csv(path("welch_tests.csv"), index=False)
    pd.DataFrame(pair_rows).to_csv(path("pairwise.csv"), index=False)
    summary = summary_table(runs, baseline)
    summary.to_csv(path("summary.csv"), index=False)
    with open(path("summary.md"), "w") as f:
        f.write(f"Baseline: {baseline}. {len(runs)} runs under {root}.\n\n" + _markdown(summary))
    log(f"{len(runs)} runs, baseline {baseline}: {len(written)} files in {out}")
    return written


# ---- synthetic results (tests, notebooks) -------------------------------------------------------


def write_synthetic_run(d, teacher, seed, strength=0.5, evaluations=21, test_tasks=16,
                        episodes_per_eval=8, launch=None):
    """One run folder in the format of `cradle tma run` (synthetic numbers): % mastered rises
    about `strength` x 100 % over the run; ALP-GMM-named teachers dump GMM components."""
    rng = np.random.default_rng([seed, sum(teacher.encode())])
    os.makedirs(d, exist_ok=True)
    grid = [(h, s) for h in np.linspace(0, 3, 4) for s in np.linspace(0, 6, 4)][:test_tasks]
    if launch is not None:
        with open(os.path.join(d, "launch.json"), "w") as f:
            json.dump(launch, f)
    with open(os.path.join(d, "run.json"), "w") as f:
        json.dump({"teacher": teacher, "seed": seed, "bounds": {
            "names": ["stump_height", "obstacle_spacing"], "mins": [0.0, 0.0],
            "maxs": [3.0, 6.0]}}, f)
    step = 1000
    rows, test_rows, teacher_rows, episode = [], [], [], 0
    for e in range(evaluations):
        p_master = min(0.95, strength * e / max(1, evaluations - 1) + rng.normal(0, 0.03))
        mastered = rng.random(len(grid)) < max(0.0, p_master)
        returns = np.where(mastered, 250.0, 100.0) + rng.normal(0, 5, len(grid))
        for k in range(len(grid)):
            test_rows.append((e, e * step, k, returns[k], int(returns[k] > 230)))
        rows.append((e, e * step, episode, e * 1.0, 1000.0, returns.mean(), returns.std(),
                     100.0 * np.mean(returns > 230), returns.mean() - 20))
        if e:
            for _ in range(episodes_per_eval):
                task = [rng.uniform(0, 3 * e / evaluations + 0.5), rng.uniform(0, 6)]
                teacher_rows.append({"kind": "train", "episode": episode, "env_steps": e * step,
                                     "task": task, "return": float(rng.normal(100, 50)),
                                     "length": 500, "success": False})
                episode += 1
        dump = {"teacher": teacher.lower(), "mins": [0, 0], "maxs": [3, 6]}
        if "GMM" in teacher and e:
            dump["components"] = [
                {"weight": 0.6, "mean": [1.0, 3.0, 0.1],
                 "covariance": [[0.2, 0.05, 0], [0.05, 0.5, 0], [0, 0, 0.01]]},
                {"weight": 0.4, "mean": [2.0, 1.5, 0.2], "covariance": [0.1, 0.3, 0.01]}]
        teacher_rows.append({"kind": "dump", "env_steps": e * step, "teacher": dump})
    pd.DataFrame(rows, columns=[
        "evaluation", "env_steps", "episodes", "wall_s", "sps", "mean_test_return",
        "std_test_return", MASTERED, "mean_train_return",
    ]).to_csv(os.path.join(d, "progress.csv"), index=False)
    pd.DataFrame(test_rows, columns=[
        "evaluation", "env_steps", "task_index", "return", "mastered",
    ]).to_csv(os.path.join(d, "test_returns.csv"), index=False)
    pd.DataFrame([(k, h, sp) for k, (h, sp) in enumerate(grid)], columns=[
        "task_index", "stump_height", "obstacle_spacing",
    ]).to_csv(os.path.join(d, "test_set.csv"), index=False)
    os.makedirs(os.path.join(d, "logs"), exist_ok=True)
    with open(os.path.join(d, "logs", "teacher.jsonl"), "w") as f:
        for rec in teacher_rows:
            f.write(json.dumps(rec) + "\n")


def make_synthetic_results(root, labels=(("Random", "Random"), ("ALP-GMM", "ALP-GMM")), seeds=2,
                           experiments=("criterion_1", "parkour"), **run_options):
    """A results tree as `cradle tma campaign launch` leaves it, with synthetic runs (tests,
    demos): each (campaign, teacher) of labels runs every experiment with `seeds` seeds; parkour
    runs split over two embodiments with distinct seeds. Later labels learn faster."""
    for li, (campaign, teacher) in enumerate(labels):
        for experiment in experiments:
            bodies = (["old_classic_bipedal", "fish"] if experiment == "parkour"
                      else ["old_classic_bipedal"])
            for bi, body in enumerate(bodies):
                for s in range(seeds):
                    seed = s + bi * seeds
                    name = f"{campaign}_{experiment}_{body}"
                    args = ["--env", "parkour" if experiment == "parkour" else "stump-tracks",
                            "--embodiment", body, "--student", "sac", "--teacher", teacher,
                            "--allow_expert_knowledge", "none"]
                    d = os.path.join(root, name, f"{name}_s{seed}")
                    write_synthetic_run(d, teacher, seed, strength=0.2 + 0.4 * li,
                                        launch={"campaign": campaign, "experiment": experiment,
                                                "name": name, "seed": seed, "args": args},
                                        **run_options)
                    with open(os.path.join(d, "finished"), "w") as f:
                        f.write("{}\n")
    return root


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="cradle tma analyze", description="Figures, Welch tests and tables of a TMA campaign")
    parser.add_argument("results", help="results tree of `cradle tma campaign launch`")
    parser.add_argument("--out", help="output folder (default RESULTS/analysis)")
    parser.add_argument("--baseline", help="campaign compared against (default: the Random one)")
    args = parser.parse_args(argv)
    try:
        analyze(args.results, args.out, args.baseline)
    except (ValueError, OSError) as e:
        # One line (`cradle tma analyze` passes it on as its own error message).
        message = " ".join(str(e).split())
        print(f"cradle: error: {message}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
