#!/usr/bin/env python3
"""Robustness sweep: bad flags, damaged run files and hostile campaign input on every surface.

Each case runs one `cradle` command (or a Python snippet) that a careless or hostile user could
type, and is classified by what happened:

  clear      exit 1, exactly one line `cradle: error: ...` (Python: one-line ValueError); or a
             damaged log kept whole beside a fresh one, with a line saying so
  unclear    exit 1 with more than one line, or a message that does not name the flag or file
  crash      exit status other than 0, 1 and 130, or killed by a signal ("internal error": 3)
  hang       still running after the timeout
  silent     exit 0 where the input was wrong
  data loss  a run folder changed by a command that was refused

Usage: scripts/fuzz-surfaces.py CRADLE [--quick] [--json FILE]
Prints one table (surface: tried / clear / unclear / crash / hang / silent / data loss) and the
cases that were not clear. Exit status 1 when any case was not clear.
"""

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile

TIMEOUT = 120
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the configs/ folder's parent


def folder_digest(path):
    """Hash of every file under path (names and bytes), to tell whether a command changed it."""
    h = hashlib.sha256()
    for root, dirs, files in sorted(os.walk(path)):
        dirs.sort()
        for name in sorted(files):
            full = os.path.join(root, name)
            h.update(os.path.relpath(full, path).encode())
            with open(full, "rb") as f:
                h.update(f.read())
        for name in dirs:
            h.update(("dir:" + os.path.relpath(os.path.join(root, name), path)).encode())
    return h.hexdigest()


class Sweep:
    def __init__(self, cradle, work):
        self.cradle = cradle
        self.work = work
        self.results = []  # (surface, case, verdict, detail)

    def run(self, surface, case, args, needle=None, folder=None, cwd=None):
        """Runs `cradle args`; the case expects a refusal naming `needle` (if given)."""
        before = folder_digest(folder) if folder else None
        try:
            p = subprocess.run([self.cradle] + args, capture_output=True, text=True,
                               timeout=TIMEOUT, cwd=cwd or self.work, errors="replace")
        except subprocess.TimeoutExpired:
            self.results.append((surface, case, "hang", f"still running after {TIMEOUT} s"))
            return
        out = (p.stdout + p.stderr).strip()
        lines = [l for l in out.splitlines() if l.strip()]
        if p.returncode == 0 and any("kept aside" in l or "kept as" in l for l in lines):
            # A log of other columns or cut short: kept whole beside a fresh one, with a line.
            verdict, detail = "clear", "kept aside: " + " / ".join(l for l in lines if "kept" in l)
        elif p.returncode == 0:
            verdict, detail = "silent", "exit 0"
        elif p.returncode == 1:
            error_lines = [l for l in lines if l.startswith("cradle: error: ")]
            if len(error_lines) == 1 and (needle is None or needle in error_lines[0]):
                verdict, detail = "clear", error_lines[0]
            else:
                verdict, detail = "unclear", " / ".join(lines[-3:])
        else:
            verdict, detail = "crash", f"exit {p.returncode}: " + " / ".join(lines[-2:])
        # A refused command must leave the folder as it was (one that went on changes it).
        if folder and p.returncode != 0 and folder_digest(folder) != before:
            verdict, detail = "data loss", "the run folder changed: " + detail
        self.results.append((surface, case, verdict, detail[:200]))

    def python(self, surface, case, code):
        """Runs a Python snippet that must raise a one-line ValueError."""
        snippet = ("import sys\ntry:\n" + "".join("    " + l + "\n" for l in code.splitlines()) +
                   "except ValueError as e:\n    m = str(e)\n"
                   "    print('VALUEERROR' if '\\n' not in m else 'MULTILINE', m)\n"
                   "    sys.exit(0)\nprint('ACCEPTED')\n")
        try:
            p = subprocess.run([sys.executable, "-c", snippet], capture_output=True, text=True,
                               timeout=TIMEOUT, cwd=self.work, errors="replace")
        except subprocess.TimeoutExpired:
            self.results.append((surface, case, "hang", f"still running after {TIMEOUT} s"))
            return
        out = p.stdout.strip()
        if p.returncode != 0:
            verdict = "crash"
            detail = (p.stderr.strip().splitlines() or ["?"])[-1]
        elif out.startswith("VALUEERROR"):
            verdict, detail = "clear", out
        elif out.startswith("MULTILINE"):
            verdict, detail = "unclear", out
        else:
            verdict, detail = "silent", out
        self.results.append((surface, case, verdict, detail[:200]))


# Damaged variants of a JSON object file: each key removed, each value of another type, and the
# whole file cut short, empty, binary garbage, a list, or a folder in its place.
def json_variants(text, keys=None):
    try:
        obj = json.loads(text)
    except ValueError:
        obj = None
    out = [("cut short", text[: len(text) // 2]), ("empty", ""),
           ("binary garbage", "\x00\x01\xff garbage"), ("a JSON list", "[]"), ("a folder", None)]
    if isinstance(obj, dict):
        for key in obj:
            if keys is not None and key not in keys:
                continue
            rest = {k: v for k, v in obj.items() if k != key}
            out.append((f"no {key}", json.dumps(rest)))
            for bad in ("x", -1, None, [1]):
                if obj[key] == bad or type(obj[key]) is type(bad):
                    continue
                changed = dict(obj)
                changed[key] = bad
                out.append((f"{key}={json.dumps(bad)}", json.dumps(changed)))
    return out


def damage(path, content):
    if os.path.isdir(path):
        shutil.rmtree(path)
    elif os.path.exists(path):
        os.remove(path)
    if content is None:
        os.makedirs(path)
    else:
        with open(path, "w", errors="surrogateescape") as f:
            f.write(content)


def damaged_runs(sweep, surface, base, files, command, quick):
    """For each file of a finished run (a path, or (path, the keys the command reads)), each
    damaged variant: the command must refuse it."""
    for entry in files:
        rel, keys = entry if isinstance(entry, tuple) else (entry, None)
        with open(os.path.join(base, rel), errors="replace") as f:
            text = f.read()
        variants = json_variants(text, keys) if rel.endswith(".json") else [
            ("cut short", text[: len(text) // 3]), ("empty", ""),
            ("binary garbage", "\x00\x01\xff garbage\n"), ("a folder", None)]
        if quick:
            variants = variants[:5]
        for name, content in variants:
            run = os.path.join(sweep.work, "case")
            shutil.rmtree(run, ignore_errors=True)
            shutil.copytree(base, run)
            damage(os.path.join(run, rel), content)
            sweep.run(surface, f"{rel}: {name}", command(run), os.path.basename(rel), folder=run)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cradle")
    parser.add_argument("--quick", action="store_true", help="fewer damaged-file variants")
    parser.add_argument("--json", help="also write the cases here")
    args = parser.parse_args()
    cradle = os.path.abspath(args.cradle)
    work = tempfile.mkdtemp(prefix="cradle_fuzz_")
    # The Python cases run from the work folder: the package path must not be relative.
    os.environ["PYTHONPATH"] = os.pathsep.join(
        os.path.abspath(p) for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p)
    s = Sweep(cradle, work)

    tiny_tma = ["tma", "run", "--test_every", "1000", "--nb_test_episodes", "2",
                "--hp", "learning_starts=300", "--hp", "batch_size=32", "--hp", "pi_layers=16",
                "--hp", "qf_layers=16", "--no-progress", "--seed", "3"]
    tiny_sami = ["sami", "train", "--hp", "learning_starts=1000", "--no-progress"]
    sami_env = ["--env", "CrippleHalfCheetah", "--algo", "tesac"]
    tiny_train = ["train", "--env", "mimo/reach", "--hp", "n_steps=64", "--hp", "batch_size=64",
                  "--eval-episodes", "0", "--no-progress", "--checkpoint-every", "128"]

    # --- TeachMyAgent CLI: flags.
    for case, extra, needle in [
        ("--steps 0", ["--steps", "0"], "--steps"),
        ("--steps -5", ["--steps", "-5"], "--steps"),
        ("--steps 1e12", ["--steps", "1e12"], "--steps"),
        ("--nb_env_steps 1e12", ["--nb_env_steps", "1e12"], "--nb_env_steps"),
        ("--nb_env_steps nan", ["--nb_env_steps", "nan"], "--nb_env_steps"),
        ("--nb_env_steps 20000", ["--nb_env_steps", "20000"], "--nb_env_steps"),
        ("--steps and --nb_env_steps", ["--steps", "10", "--nb_env_steps", "1"], "excludes"),
        ("--test_every 0", ["--test_every", "0", "--steps", "10"], "--test_every"),
        ("--test_every huge", ["--test_every", "99999999999999999999", "--steps", "10"],
         "--test_every"),
        ("--seed -1", ["--seed", "-1"], "--seed"),
        ("--seed 2^64", ["--seed", "18446744073709551616"], "--seed"),
        ("--seed 0x10", ["--seed", "0x10"], "--seed"),
        ("--algo dqn", ["--algo", "dqn", "--steps", "10"], "dqn"),
        ("--teacher Nope", ["--teacher", "Nope", "--steps", "10"], "Nope"),
        ("--teacher-param fit_rate=abc",
         ["--teacher", "ALP-GMM", "--teacher-param", "fit_rate=abc", "--steps", "10"], "fit_rate"),
        ("--teacher-param bogus=1",
         ["--teacher", "ALP-GMM", "--teacher-param", "bogus=1", "--steps", "10"], "bogus"),
        ("--hp pi_layers=", ["--hp", "pi_layers=", "--steps", "10"], "pi_layers"),
        ("--hp pi_layers=0", ["--hp", "pi_layers=0", "--steps", "10"], "pi_layers"),
        ("--hp pi_layers=abc", ["--hp", "pi_layers=abc", "--steps", "10"], "pi_layers"),
        ("--hp batch_size=0", ["--hp", "batch_size=0", "--steps", "10"], "batch_size"),
        ("--hp episode_train_freq=-1", ["--hp", "episode_train_freq=-1", "--steps", "10"],
         "episode_train_freq"),
        ("--hp twice", ["--hp", "tau=0.1", "--hp", "tau=0.2", "--steps", "10"], "tau"),
        ("--hp buffer_size=1e9", ["--hp", "buffer_size=1000000000", "--steps", "10"],
         "buffer_size"),
        ("--embodiment tripod", ["--embodiment", "tripod", "--steps", "10"], "tripod"),
        ("--test_set missing", ["--test_set", "no_such_set", "--steps", "10"], "no_such_set"),
        ("--allow_expert_knowledge some", ["--allow_expert_knowledge", "some", "--steps", "10"],
         "some"),
        ("--out /proc/x", ["--out", "/proc/cradle_x", "--steps", "10"], "/proc/cradle_x"),
        ("--out a file", ["--out", "/etc/hostname", "--steps", "10"], "/etc/hostname"),
        ("--resume without a run", ["--resume", "--out", os.path.join(work, "none"),
                                    "--steps", "10"], "--resume"),
        ("--resume and --overwrite", ["--resume", "--overwrite", "--steps", "10",
                                      "--out", os.path.join(work, "none")], "--resume"),
    ]:
        out = [] if "--out" in extra else ["--out", os.path.join(work, "tma_flags")]
        s.run("TMA CLI", "tma run " + case, tiny_tma + extra + out, needle)
        shutil.rmtree(os.path.join(work, "tma_flags"), ignore_errors=True)
    for case, cmd, needle in [
        ("tma random --steps 0", ["tma", "random", "--steps", "0"], "--steps"),
        ("tma random --seed -1", ["tma", "random", "--seed", "-1"], "--seed"),
        ("tma random --embodiment x", ["tma", "random", "--embodiment", "x"], "x"),
        ("tma random --png /proc/x.png", ["tma", "random", "--steps", "5", "--png",
                                          "/proc/cradle_x/a.png"], "/proc/cradle_x"),
        ("tma bench --steps -1", ["tma", "bench", "--steps", "-1"], "--steps"),
        ("tma video no run", ["tma", "video", "--run", os.path.join(work, "none"),
                              "--test-task", "0"], "none"),
    ]:
        s.run("TMA CLI", case, cmd, needle)

    # --- SaMI CLI: flags.
    for case, extra, needle in [
        ("--env Mars", ["--env", "Mars"], "Mars"),
        ("--algo sabogus", ["--algo", "sabogus"], "sabogus"),
        ("--steps 0", ["--steps", "0"], "--steps"),
        ("--steps-per-env -1", ["--steps-per-env", "-1"], "--steps-per-env"),
        ("--steps and --steps-per-env", ["--steps", "10", "--steps-per-env", "10"], "excludes"),
        ("--seed -1", ["--seed", "-1"], "--seed"),
        ("--hp buffer_size=1e9", ["--hp", "buffer_size=1000000000", "--steps", "30"],
         "buffer_size"),
        ("--hp net_arch=100000000", ["--hp", "net_arch=100000000", "--steps", "30"], "net_arch"),
        ("--hp lstm_hidden=65536", ["--hp", "lstm_hidden=65536", "--steps", "30"], "lstm_hidden"),
        ("--hp twice", ["--hp", "tau=0.1", "--hp", "tau=0.2", "--steps", "30"], "tau"),
        ("--out /proc/x", ["--out", "/proc/cradle_x", "--steps", "30"], "/proc/cradle_x"),
        ("--resume without a run", ["--resume", "--out", os.path.join(work, "none")], "run.json"),
    ]:
        env = [] if ("--env" in extra or "--algo" in extra) else sami_env
        if "--algo" in extra:
            env = ["--env", "CrippleHalfCheetah"]
        out = [] if "--out" in extra else ["--out", os.path.join(work, "sami_flags")]
        s.run("SaMI CLI", "sami train " + case, tiny_sami + env + extra + out, needle)
        shutil.rmtree(os.path.join(work, "sami_flags"), ignore_errors=True)
    for case, cmd, needle in [
        ("sami random --split a folder", ["sami", "random", "--env", "Hopper", "--split", work],
         work),
        ("sami random --episodes 0", ["sami", "random", "--env", "Hopper", "--episodes", "0"],
         "--episodes"),
        ("sami random --video /proc", ["sami", "random", "--env", "Hopper", "--episodes", "1",
                                       "--max-steps", "5", "--video", "/proc/cradle_x/a.mp4"],
         "/proc/cradle_x"),
        ("sami bench --env Mars", ["sami", "bench", "--env", "Mars"], "Mars"),
        ("sami table nothing", ["sami", "table", os.path.join(work, "none")], "none"),
    ]:
        s.run("SaMI CLI", case, cmd, needle)

    # --- Teachers and curricula (cradle train --task-space).
    curricula = {
        "unknown teacher:Nope": "teacher: Nope\nparams:\n  mass: [0.5, 2]\n",
        "bad bounds": "teacher: Random\nparams:\n  mass: [2, 0.5]\n",
        "nan bound": "teacher: Random\nparams:\n  mass: [.nan, 2]\n",
        "inf bound": "teacher: Random\nparams:\n  mass: [0, .inf]\n",
        "no params": "teacher: Random\n",
        "unknown key": "teacher: Random\nparams:\n  mass: [0.5, 2]\nwhat: 1\n",
        "bad teacher param:fit_rate": "teacher: ALP-GMM\nparams:\n  mass: [0.5, 2]\n"
                             "teacher_params: {fit_rate: abc}\n",
        "unknown parameter:gravity": "teacher: Random\nparams:\n  gravity: [0.5, 2]\n",
        "not YAML": "teacher: [unclosed\n",
        "expert knowledge": "teacher: Random\nparams:\n  mass: [0.5, 2]\nexpert_knowledge: some\n",
    }
    for case, text in curricula.items():
        # "case:needle" when the message names what is wrong rather than the file.
        case, _, needle = case.partition(":")
        path = os.path.join(work, "curriculum.yml")
        with open(path, "w") as f:
            f.write(text)
        s.run("teachers", "task space: " + case,
              tiny_train[:2] + ["sami/CrippleHalfCheetah:train"] + tiny_train[3:] +
              ["--steps", "64", "--task-space", path, "--out", os.path.join(work, "tsp")],
              needle or "curriculum.yml")
        shutil.rmtree(os.path.join(work, "tsp"), ignore_errors=True)

    # --- Campaigns.
    for case, cmd, needle in [
        ("generate --teacher with a shell", ["campaign", "generate", "c", "--kind", "tma",
                                             "--teacher", "ALP-GMM;touch${IFS}X"], "--teacher"),
        ("generate --teacher Nope", ["campaign", "generate", "c", "--kind", "tma", "--teacher",
                                     "Nope"], "Nope"),
        ("generate name ..", ["campaign", "generate", "..", "--kind", "tma", "--teacher",
                              "Random"], ".."),
        ("generate --steps nan", ["campaign", "generate", "c", "--kind", "tma", "--teacher",
                                  "Random", "--steps", "nan"], "--steps"),
        ("generate --kind bogus", ["campaign", "generate", "c", "--kind", "bogus"], "bogus"),
    ]:
        s.run("campaigns", case, cmd, needle)
    campaign_lines = {
        "2e9 seeds": "--seeds 2000000000 --name a --teacher Random\n",
        "name ..": "--seeds 1 --name .. --teacher Random\n",
        "owned --out": "--seeds 1 --name a --out x\n",
        "owned --overwrite": "--run sami --seeds 1 --name s --env Hopper --overwrite\n",
        "starred flag without value": "--seeds 1 --name a --*lr\n",
        "unknown kind": "--run bogus --seeds 1 --name a\n",
        "binary garbage": "\x00\x01\xff\n",
    }
    for case, text in campaign_lines.items():
        path = os.path.join(work, "campaign.txt")
        with open(path, "w", errors="surrogateescape") as f:
            f.write(text)
        s.run("campaigns", "launch --dry-run: " + case,
              ["campaign", "launch", path, "--local", "--dry-run", "--results",
               os.path.join(work, "results")], "campaign.txt")
    s.run("campaigns", "launch --sbatch with a newline",
          ["campaign", "launch", path, "--slurm", "--dry-run", "--sbatch", "--time=1\nrm -rf /"],
          "--sbatch")

    # --- Analysis of results trees.
    empty = os.path.join(work, "empty_results")
    os.makedirs(empty, exist_ok=True)
    s.run("analyze", "tma analyze: empty folder", ["tma", "analyze", empty], "empty_results")
    s.run("analyze", "campaign analyze: missing folder",
          ["campaign", "analyze", os.path.join(work, "none")], "none")

    # --- Run-state files of every family: a finished run, each file damaged, then --resume.
    tma_run = os.path.join(work, "tma_base")
    subprocess.run([cradle] + tiny_tma + ["--steps", "1000", "--out", tma_run], check=True,
                   capture_output=True)
    damaged_runs(s, "run files: tma run", tma_run,
                 [("run.json", ["arguments"]), "checkpoints/latest.ckpt", "logs/teacher.jsonl",
                  "progress.csv"],
                 lambda run: tiny_tma + ["--steps", "2000", "--out", run, "--resume"], args.quick)
    damaged_runs(s, "run files: tma video", tma_run, [("run.json", ["arguments"]), "test_set.csv"],
                 lambda run: ["tma", "video", "--run", run, "--test-task", "0", "--steps", "5",
                              "--out", os.path.join(work, "v.mp4")], args.quick)
    sami_run = os.path.join(work, "sami_base")
    subprocess.run([cradle] + tiny_sami + sami_env + ["--steps", "300", "--out", sami_run],
                   check=True, capture_output=True)
    s.run("SaMI CLI", "sami evaluate --split sideways",
          ["sami", "evaluate", "--run", sami_run, "--split", "sideways"], "sideways")
    sami_keys = ["env", "family", "algorithm", "seed", "steps", "envs", "hyperparameters"]
    damaged_runs(s, "run files: sami train", sami_run,
                 [("run.json", sami_keys), "checkpoints/latest.ckpt", "logs/progress.csv"],
                 lambda run: ["sami", "train", "--out", run, "--resume", "--steps", "600",
                              "--no-progress"], args.quick)
    damaged_runs(s, "run files: sami evaluate", sami_run,
                 [("run.json", sami_keys), "checkpoints/latest.ckpt"],
                 lambda run: ["sami", "evaluate", "--run", run, "--episodes", "1"], args.quick)
    train_run = os.path.join(work, "train_base")
    subprocess.run([cradle] + tiny_train + ["--steps", "256", "--out", train_run], check=True,
                   capture_output=True)
    damaged_runs(s, "run files: cradle train", train_run,
                 ["checkpoints/latest.ckpt", "logs/progress.csv"],
                 lambda run: tiny_train + ["--steps", "512", "--out", run, "--resume"], args.quick)
    damaged_runs(s, "run files: evaluate --run", train_run,
                 [("run.json", ["env", "family", "algorithm", "seed", "hyperparameters"]),
                  "checkpoints/final.ckpt"],
                 lambda run: ["evaluate", "--run", run, "--episodes", "1"], args.quick)
    # Finished runs are never replaced without --resume / --overwrite.
    for surface, cmd, run in [
        ("run files: tma run", tiny_tma + ["--steps", "1000"], tma_run),
        ("run files: sami train", tiny_sami + sami_env + ["--steps", "300"], sami_run),
        ("run files: cradle train", tiny_train + ["--steps", "256"], train_run),
    ]:
        s.run(surface, "a finished run, no --resume", cmd + ["--out", run], "--overwrite",
              folder=run)

    # --- Worker processes and the soak.
    soak_out = ["--out", os.path.join(work, "soak"), "--steps", "10"]
    for case, cmd, needle in [
        ("soak without an env", ["soak"] + soak_out, "--config"),
        ("soak --config and --env", ["soak", "--config", "configs/config_selftouch.yml",
                                      "--env", "mimo/reach"] + soak_out, "--env"),
        ("soak --env unknown", ["soak", "--env", "mimo/rech"] + soak_out, "mimo/rech"),
        ("soak --env babybench id", ["soak", "--env", "babybench/selftouch"] + soak_out,
         "--config"),
        ("soak --procs uneven", ["soak", "--env", "mimo/reach", "--envs", "3", "--procs", "2"]
         + soak_out, "--procs"),
        ("soak --procs 0", ["soak", "--env", "mimo/reach", "--procs", "0"] + soak_out, "--procs"),
        ("soak --out a file", ["soak", "--env", "mimo/reach", "--out", "/etc/hostname",
                               "--steps", "10"], "/etc/hostname"),
        ("train --env --procs uneven", tiny_train + ["--envs", "3", "--procs", "2", "--steps",
                                                     "64", "--out", os.path.join(work, "p")],
         "--procs"),
        ("train --procs and --async-batch", tiny_train + ["--envs", "4", "--procs", "2",
                                                          "--async-batch", "2", "--steps", "64",
                                                          "--out", os.path.join(work, "p")],
         "--async-batch"),
    ]:
        s.run("processes and soak", case, cmd, needle, cwd=ROOT)
        shutil.rmtree(os.path.join(work, "soak"), ignore_errors=True)
        shutil.rmtree(os.path.join(work, "p"), ignore_errors=True)

    # --- Python envs.
    py = [
        ("tma.make agent_body_type=None",
         "from cradle import tma\ntma.make('parametric-continuous-stump-tracks-v0', "
         "agent_body_type=None)"),
        ("tma max_episode_steps='10'",
         "from cradle import tma\ntma.make('parametric-continuous-stump-tracks-v0', "
         "agent_body_type='old_classic_bipedal', max_episode_steps='10')"),
        ("tma step before reset",
         "from cradle import tma\nimport numpy as np\ne = tma.make('parametric-continuous-"
         "stump-tracks-v0', agent_body_type='old_classic_bipedal')\ne.step(np.zeros(4))"),
        ("tma complex action",
         "from cradle import tma\nimport numpy as np\ne = tma.make('parametric-continuous-"
         "stump-tracks-v0', agent_body_type='old_classic_bipedal')\ne.reset()\n"
         "e.step(np.zeros(4, dtype=complex))"),
        ("sami 1e300 action",
         "import cradle, numpy as np\ne = cradle.sami.make('CrippleHalfCheetah')\ne.reset()\n"
         "e.step(np.full(6, 1e300))"),
        ("sami step after close",
         "import cradle, numpy as np\ne = cradle.sami.make('CrippleHalfCheetah')\ne.reset()\n"
         "e.close()\ne.step(np.zeros(6))"),
        ("VectorEnv threads=-5", "import cradle\ncradle.VectorEnv('mimo/reach', 2, threads=-5)"),
        ("make unknown id", "import cradle\ncradle.make('mimo/rech')"),
        ("train bad algo", "import cradle\ncradle.train(env='mimo/reach', algo='dqn', steps=10)"),
        ("train procs=-1", "import cradle\ncradle.train(env='mimo/reach', steps=10, procs=-1)"),
        ("train procs uneven",
         "import cradle\ncradle.train(env='mimo/reach', steps=10, envs=3, procs=2)"),
        ("VectorEnv id procs uneven", "import cradle\ncradle.VectorEnv('mimo/reach', 3, procs=2)"),
        ("render(-1, 10)",
         "import cradle\ne = cradle.make('mimo/reach', render_mode='rgb_array')\ne.reset()\n"
         "e.render(-1, 10)"),
    ]
    for case, code in py:
        s.python("Python", case, code)

    # The table.
    kinds = ["clear", "unclear", "crash", "hang", "silent", "data loss"]
    surfaces = []
    for r in s.results:
        if r[0] not in surfaces:
            surfaces.append(r[0])
    print("| surface | tried | " + " | ".join(kinds) + " |")
    print("|---|---|" + "---|" * len(kinds))
    totals = [0] * (len(kinds) + 1)
    for surface in surfaces:
        rows = [r for r in s.results if r[0] == surface]
        counts = [len(rows)] + [sum(r[2] == k for r in rows) for k in kinds]
        totals = [a + b for a, b in zip(totals, counts)]
        print(f"| {surface} | " + " | ".join(str(c) for c in counts) + " |")
    print("| all | " + " | ".join(str(c) for c in totals) + " |")
    bad = [r for r in s.results if r[2] != "clear"]
    if bad:
        print("\nNot clear:")
        for surface, case, verdict, detail in bad:
            print(f"- [{verdict}] {surface}: {case} -> {detail}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump([dict(zip(("surface", "case", "verdict", "detail"), r)) for r in s.results],
                      f, indent=1)
    shutil.rmtree(work, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
