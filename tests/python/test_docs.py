"""The user's guide as tests: every ```sh / ```bash and ```python block of README.md and
docs/python.md runs, with its budgets cut, and must exit 0 and write what the text says.

How a block runs:
- in a fresh temporary folder holding `configs/` (copies of the repository's configs, with
  `max_episode_steps` cut, see CONFIG_CUTS), links to the repository's `examples/` and `bench/`,
  `build/cradle` (the CLI named by $CRADLE_BINARY, as ctest sets it) and `build/python` (the
  package on $PYTHONPATH), so `build/cradle ...` and `export PYTHONPATH=$PWD/build/python` work
  as written;
- a shell block as one `bash -euo pipefail` script, a Python block as one `python3` script
  (the interpreter running pytest), after the substitutions of SUBSTITUTIONS;
- afterwards every path named by a `<!-- docs-test: expect PATH, PATH -->` comment right before
  the block must exist (a glob; relative to the temporary folder).

A block preceded by `<!-- docs-test: skip (reason) -->` is not run (reported as skipped); such
comments stand on the line right before the block (or before its `expect` comment).
"""

import glob
import os
import pathlib
import re
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

from conftest import ROOT, cradle_binary

DOCS = ["README.md", "docs/python.md"]

# (pattern, replacement, why): applied in order to every block before it runs.
SUBSTITUTIONS = [
    (r"--steps \d[\d_]*", "--steps 256", "training and bench budgets (cradle train/bench/launch)"),
    (r"--eval-episodes [1-9]\d*", "--eval-episodes 1 --no-eval-video",
     "evaluation after training: one episode, no video (a filmed episode takes about a minute)"),
    (r"eval_episodes=\d+", "eval_episodes=1, eval_render=False", "the same from Python"),
    (r"--episodes \d+", "--episodes 1", "evaluation / random episodes: one"),
    (r"--train_for \d+", "--train_for 256", "illustrate and the Python examples: 256 steps"),
    (r"--test_for \d+", "--test_for 100", "illustrate's test: 100 steps"),
    (r"--nb_env_steps [\d.]+", "--nb_env_steps 0.0004", "tma run: 400 env steps"),
    (r"--test_every \d+", "--test_every 200 --nb_test_episodes 2",
     "tma run: two test tasks every 200 steps"),
    (r"--steps-per-env \d+", "--steps-per-env 200", "sami train: 200 steps per training env"),
    (r"range\(\d[\d_]*\)", "range(50)", "Python loops over steps or episodes: 50"),
    (r"steps=\d[\d_]*", "steps=2048", "cradle.train(steps=...): one rollout"),
]
# Config keys cut in the temporary folder's copies of configs/*.yml.
CONFIG_CUTS = [(r"(?m)^max_episode_steps: *\d+", "max_episode_steps: 60")]
BLOCK_TIMEOUT = 240  # seconds per block

FENCE = re.compile(r"^```(\w*)\s*$")
COMMENT = re.compile(r"^<!--\s*docs-test:\s*(skip|expect)\b(.*?)-->\s*$")


def extract(doc):
    """Blocks of one markdown file: (id, language, code, skip reason or None, expected paths)."""
    lines = (ROOT / doc).read_text().splitlines()
    blocks, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        lang, start = m.group(1), i
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        code = "\n".join(lines[i + 1:j]) + "\n"
        skip, expect = None, []
        k = start - 1
        while k >= 0 and COMMENT.match(lines[k]):
            kind, rest = COMMENT.match(lines[k]).groups()
            if kind == "skip":
                skip = rest.strip(" ()") or "marked skip"
            else:
                expect += [p.strip() for p in rest.split(",") if p.strip()]
            k -= 1
        if lang in ("sh", "bash", "python"):
            blocks.append((f"{doc}:{start + 1}", lang, code, skip, expect))
        i = j + 1
    return blocks


BLOCKS = [b for doc in DOCS for b in extract(doc)]


def cut(code):
    for pattern, replacement, _ in SUBSTITUTIONS:
        code = re.sub(pattern, replacement, code)
    return code


def workspace(tmp):
    """The temporary folder a block runs in (see the module's docstring)."""
    (tmp / "configs").mkdir()
    for config in (ROOT / "configs").glob("*.yml"):
        text = config.read_text()
        for pattern, replacement in CONFIG_CUTS:
            text = re.sub(pattern, replacement, text)
        (tmp / "configs" / config.name).write_text(text)
    if (ROOT / "configs" / "curricula").is_dir():
        shutil.copytree(ROOT / "configs" / "curricula", tmp / "configs" / "curricula")
    for name in ("examples", "bench", "data"):
        (tmp / name).symlink_to(ROOT / name)
    (tmp / "build").mkdir()
    (tmp / "build" / "cradle").symlink_to(os.path.abspath(cradle_binary()))
    package = next((p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                    if p and (pathlib.Path(p) / "cradle").is_dir()), str(ROOT / "build" / "python"))
    (tmp / "build" / "python").symlink_to(os.path.abspath(package))


def test_docs_have_runnable_blocks():
    ran = [b[0] for b in BLOCKS if b[3] is None]
    skipped = [(b[0], b[3]) for b in BLOCKS if b[3] is not None]
    print(f"\ndocs blocks: {len(ran)} run, {len(skipped)} skipped: {skipped}")
    assert len(ran) >= 10, ran
    for block_id, _, _, skip, expect in BLOCKS:
        assert skip is None or not expect, f"{block_id}: skipped but expects outputs"


def subcommands(*words):
    """The subcommand names `cradle WORDS... --help` lists: the entries of every heading but
    Options and Positionals (`cradle --help` groups them: Envs, Train, ...)."""
    text = subprocess.run([cradle_binary(), *words, "--help"], capture_output=True, text=True,
                          check=True).stdout
    names, heading = [], None
    for line in text.splitlines():
        if re.match(r"^\S.*:$", line):
            heading = line[:-1]
        elif heading not in (None, "Options", "Positionals") and re.match(r"^  \S", line):
            names.append(line.split()[0])
    return names


def test_cli_reference_has_every_subcommand():
    """docs/cli.md has a row for every subcommand the CLI lists, nested ones included."""
    reference = (ROOT / "docs" / "cli.md").read_text()
    missing, level = [], [[]]
    with ThreadPoolExecutor(4) as pool:
        while level:
            paths = [words + [name] for words in level for name in subcommands(*words)]
            nested = list(pool.map(lambda path: subcommands(*path), paths))
            level = [path for path, names in zip(paths, nested) if names]
            missing += [" ".join(path) for path, names in zip(paths, nested)
                        if not names and f"`cradle {' '.join(path)}" not in reference]
    assert not missing, f"docs/cli.md lacks rows for: {missing}"


@pytest.mark.parametrize("block_id,lang,code,skip,expect", BLOCKS, ids=[b[0] for b in BLOCKS])
def test_docs_block(block_id, lang, code, skip, expect, tmp_path):
    if skip is not None:
        pytest.skip(skip)
    workspace(tmp_path)
    code = cut(code)
    env = dict(os.environ, OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    if lang == "python":
        script = tmp_path / "block.py"
        script.write_text(code)
        command = [sys.executable, str(script)]
    else:
        script = tmp_path / "block.sh"
        script.write_text(code)
        command = ["bash", "-euo", "pipefail", str(script)]
    start = time.monotonic()
    result = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=BLOCK_TIMEOUT)
    took = time.monotonic() - start
    assert result.returncode == 0, (
        f"{block_id} exited {result.returncode} after {took:.0f} s\n--- block as run:\n{code}"
        f"--- stdout (end):\n{result.stdout[-3000:]}\n--- stderr (end):\n{result.stderr[-3000:]}")
    missing = [p for p in expect if not glob.glob(str(tmp_path / p))]
    assert not missing, f"{block_id}: ran ({took:.0f} s) but did not write {missing}"
    print(f"\n{block_id}: {took:.1f} s")
