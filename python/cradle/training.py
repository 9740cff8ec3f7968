"""Training, evaluation and training logs from Python, on the C++ learners and evaluation."""

import inspect
import json
import numbers
import os
import pickle

from . import _cradle
from .env import load_config
from .policy import load_run_policy

# Per behaviour, the keys of a reference training.pkl entry, in the reference's order.
_REFERENCE_KEYS = {
    "self_touch": ["right_hand_touches", "left_hand_touches", "steps"],
    "hand_regard": [
        "right_eye_right_hand",
        "right_eye_left_hand",
        "left_eye_right_hand",
        "left_eye_left_hand",
        "steps",
    ],
    "none": ["steps"],
}
# Cradle's extra keys in training.jsonl (kept with extras=True).
_EXTRA_KEYS = ["right_eye_either_hand", "left_eye_either_hand", "physics_overflow",
               "physics_diverged", "score", "wall_time"]


def _wants_full_call(fn):
    """True when fn takes (obs, action, info); False when it takes only (obs)."""
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return True
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    if any(p.kind == p.VAR_POSITIONAL for p in params):
        return True
    return len(positional) >= 3


def _split_intrinsic(intrinsic):
    """(C++ spec "name:w,...", [(callable, weight, full call)]) from the intrinsic list."""
    if intrinsic is None:
        return "", []
    if isinstance(intrinsic, str) or callable(intrinsic):
        intrinsic = [intrinsic]
    names, terms = [], []
    for item in intrinsic:
        weight = 1.0
        if isinstance(item, tuple):
            if len(item) != 2:
                raise ValueError(f"intrinsic term {item!r}: expected (name or callable, weight)")
            item, weight = item
        if isinstance(item, str):
            names.append(item if weight == 1.0 else f"{item}:{float(weight)!r}")
        elif callable(item):
            terms.append((item, float(weight), _wants_full_call(item)))
        else:
            raise ValueError(f"intrinsic term {item!r}: expected a reward name or a callable")
    return ",".join(names), terms


def train(
    config=None,
    algo="ppo",
    intrinsic=None,
    steps=100_000,
    envs=2,
    threads=0,
    async_batch=0,
    seed=0,
    resume=False,
    randomize_start=False,
    checkpoint_every=100_000,
    hyperparameters=None,
    eval_episodes=2,
    eval_duration=1000,
    eval_render=True,
    compare_random=False,
    progress_bar=True,
    *,
    env=None,
    save_dir=None,
    task_space=None,
    teacher=None,
    overwrite=False,
    procs=0,
    reset_every=0,
):
    """Trains a policy with Cradle's C++ learners, exactly as `cradle train` does (same options,
    same outputs under save_dir: training log, logs/progress.csv, checkpoints/, plots/, the
    evaluation of the trained policy).

    config: a BabyBench config (dict or YAML path); or env: any env id of cradle.env_ids() (a
      BabyBench id trains its config; the others train by id into save_dir, default
      results/<id>, with logs/progress.csv, checkpoints/ and plots/). algo: any learner of
      `cradle train --help` (ppo, a2c, sac, td3, ddpg, tesac, ccm, satesac, saccm, saccm_all).
    task_space / teacher: a curriculum (a task-space YAML whose teacher sets the env's task
      parameters before every reset; teacher overrides the file's), as --task-space / --teacher.
      A teacher without task_space sets every task parameter the env declares.
      teacher may also be a Python object with sample_task() and episodic_update(task,
      episode_return, success), optionally dump() and non_exploratory_task_sampling()
      (docs/curricula.md, "A teacher of your own, in Python"): a missing method or a task outside
      the task space is a ValueError; an exception the teacher raises stops the run as a
      RuntimeError with its message (the teacher's exception as its __cause__).
    save_dir: the run folder (overrides the config's). A folder that already holds a run is
      refused (ValueError) unless resume=True continues it or overwrite=True replaces it.

    intrinsic: a list of reward terms, each a registered name ("touch_count", "saliency",
      "body_part_novelty", "rnd", "icm", "disagreement", "hand_visibility"; "name:weight" also
      works), a Python callable, or a (name or callable, weight) pair; [] trains on the env reward
      (0 for BabyBench) only. Default: body_part_novelty for BabyBench configs, none for an env
      id. A callable is called once per env and vector step as fn(obs) or
      fn(obs, action, info) and returns a float; obs holds read-only views of the env's buffers,
      valid only during the call (copy what you keep). The C++ loop takes the GIL once per vector
      step for these calls; their cost is the Python calls themselves (about a microsecond each
      plus the callable's own time, next to an env step of about 0.4 ms).
    hyperparameters: {name: value} overrides of the algorithm's hyperparameters (as --hp).
    async_batch: K > 0 collects PPO/A2C rollouts asynchronously in batches of the first K of the
      envs to finish (as --async-batch; 1 <= K < envs); 0: lock-step.
    procs: P > 0 runs the envs in P worker processes (as --procs; envs a multiple of P), each with
      its own GL contexts, so envs that render draw in parallel; the same run as with threads.
    reset_every: N > 0 replaces the learner by a fresh one (networks, optimiser, buffer) every N
      env steps, the run's step count going on (as --reset-every); 0: never.

    Returns a dict: run (the run folder), steps, seconds, steps_per_second, training_score,
    checkpoint, evaluation (the evaluation report, a dict) and random_evaluation. Ctrl-C stops training with a
    KeyboardInterrupt.
    """
    if (config is None) == (env is None):
        raise ValueError("give config (a BabyBench config) or env (an env id), not "
                         + ("both" if config is not None else "neither"))
    if env is not None and not isinstance(env, str):
        raise ValueError(f"env must be an env id (a str), not {type(env).__name__}")
    if intrinsic is None:
        intrinsic = ("body_part_novelty",) if config is not None else ()
    spec, terms = _split_intrinsic(intrinsic)
    if not isinstance(procs, numbers.Integral) or isinstance(procs, bool) or procs < 0:
        raise ValueError(f"procs must be a non-negative integer (0: threads), not {procs!r}")
    if (not isinstance(reset_every, numbers.Integral) or isinstance(reset_every, bool)
            or reset_every < 0):
        raise ValueError(f"reset_every must be a non-negative integer (0: never), not "
                         f"{reset_every!r}")
    hp = {str(k): str(v) for k, v in (hyperparameters or {}).items()}
    base = load_config(config) if config is not None else _cradle.default_config()
    result = _cradle.train(
        base, algo, spec, int(steps), int(envs), int(threads), int(async_batch),
        int(seed), bool(resume), bool(randomize_start), int(checkpoint_every), hp,
        int(eval_episodes), int(eval_duration), bool(eval_render), bool(compare_random),
        bool(progress_bar), terms, env=env or "",
        save_dir=os.fspath(save_dir) if save_dir is not None else "",
        task_space=os.fspath(task_space) if task_space is not None else "",
        teacher="" if teacher is None else teacher, overwrite=bool(overwrite), procs=int(procs),
        reset_every=int(reset_every),
    )
    for key in ("evaluation", "random_evaluation"):
        if result[key] is not None:
            result[key] = json.loads(result[key])
    return result


def load_policy(run_folder, checkpoint="final", deterministic=True, *, stochastic=None):
    """A trained policy.

    load_policy(run_folder, checkpoint="final", deterministic=True): the policy of a run folder
    of any family (cradle.train(env=...) or `cradle train`, which write run.json and
    checkpoints/), a cradle.Policy with predict(obs) -> action and reset(); checkpoint is "final",
    "latest", "step_<n>" or a .ckpt path; deterministic=False samples the actions from the
    policy's distribution by the checkpoint's own generator.

    load_policy(config, checkpoint, stochastic=False): a BabyBench config and a checkpoint path,
    for evaluate(config, policy=...): its mean action, or with stochastic=True actions sampled
    from its distribution.
    """
    folder = isinstance(run_folder, (str, os.PathLike)) and os.path.isdir(run_folder)
    if folder:
        if stochastic is not None:
            raise ValueError("stochastic is for a BabyBench config's checkpoint; a run folder's "
                             "policy takes deterministic=False instead")
        return load_run_policy(run_folder, checkpoint, deterministic)
    if isinstance(run_folder, (str, os.PathLike)) and not os.path.exists(run_folder):
        raise FileNotFoundError(f"'{os.fspath(run_folder)}' does not exist; expected a run folder "
                                "(it holds run.json) or a BabyBench config")
    if checkpoint == "final":
        raise ValueError("a BabyBench config needs the checkpoint file: load_policy(config, "
                         "'results/.../checkpoints/final.ckpt'), or give the run folder instead")
    if not isinstance(checkpoint, (str, os.PathLike)):
        raise ValueError(f"checkpoint must be a .ckpt path, not {checkpoint!r}")
    sampled = (not deterministic) if stochastic is None else bool(stochastic)
    return _cradle.load_policy(load_config(run_folder), os.fspath(checkpoint), sampled)


def evaluate(config, episodes=10, duration=1000, render=False, seed=0, policy=None,
             video_format="mp4", quiet=False, stochastic=False):
    """Runs the evaluation as `cradle evaluate`: prints the training-log score, runs `episodes`
    episodes of `duration` steps, writes trajectories/, evaluation.json and plots/ under save_dir,
    and returns the report as a dict. render=True also films every episode into videos/ (as
    `cradle evaluate --render`; a filmed frame costs 0.15-0.35 s, so it is off by default).

    policy: None (uniform random actions), a checkpoint path, a load_policy() result, or a
    callable fn(obs) -> action (fresh observation arrays; called with the GIL for each step).
    stochastic: with a checkpoint path, sample the policy's actions (SB3's predict() default)
    instead of taking its mean action; evaluation.json's policy_actions says which was used.
    """
    if stochastic and not isinstance(policy, (str, os.PathLike)):
        raise ValueError("stochastic=True needs policy to be a checkpoint path "
                         "(use load_policy(config, path, stochastic=True) otherwise)")
    if video_format not in ("mp4", "avi"):
        raise ValueError("video_format must be 'mp4' or 'avi'")
    if not isinstance(render, (bool, int)) or render not in (True, False):
        raise ValueError(f"render must be True or False, not {render!r}")
    if isinstance(policy, os.PathLike):
        policy = os.fspath(policy)
    report = _cradle.evaluate(load_config(config), int(episodes), int(duration), bool(render),
                              int(seed), "." + video_format, bool(quiet), policy,
                              bool(stochastic))
    return json.loads(report)


def _log_file(path):
    path = os.fspath(path)
    if os.path.isdir(path):
        for candidate in ("logs/training.jsonl", "training.jsonl", "logs/training.pkl",
                          "training.pkl"):
            if os.path.exists(os.path.join(path, candidate)):
                return os.path.join(path, candidate)
        raise FileNotFoundError(f"no training.jsonl or training.pkl under '{path}'")
    if not os.path.exists(path):
        raise FileNotFoundError(f"training log '{path}' does not exist")
    return path


def _is_count(value):
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def load_training_log(path, extras=False):
    """The reference's training.pkl structure (a list of dicts, one per recorded episode) from
    Cradle's logs/training.jsonl, a save_dir, or a reference training.pkl.

    Entries have the reference's keys in its order: self-touch {'right_hand_touches': [geom ids],
    'left_hand_touches': [...], 'steps': n}, hand regard the four eye-hand counts and 'steps',
    none {'steps': n}. extras=True keeps Cradle's additional keys ('score', 'wall_time',
    '*_either_hand'). The first entry is the 0-step one the first reset records, as in the
    reference.
    """
    file = _log_file(path)
    if file.endswith(".pkl"):
        with open(file, "rb") as f:
            return pickle.load(f)
    entries = []
    with open(file, encoding="utf-8") as f:
        lines = f.read().split("\n")
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            entry = json.loads(line)
        except json.JSONDecodeError:
            if number == len(lines):  # an unterminated last line (a crash mid-write)
                break
            raise ValueError(f"{file}:{number}: not a JSON line") from None
        # Valid JSON that is no entry (42, null, a list, wrong types) is refused with its line.
        if not isinstance(entry, dict) or not _is_count(entry.get("steps")):
            raise ValueError(f"{file}:{number}: expected an entry object with integer 'steps' >= 0")
        for key in ("right_hand_touches", "left_hand_touches"):
            if key in entry and not (isinstance(entry[key], list) and all(map(_is_count, entry[key]))):
                raise ValueError(f"{file}:{number}: '{key}' must be a list of geom ids (integers >= 0)")
        entries.append(entry)
    out = []
    for entry in entries:
        if "right_hand_touches" in entry:
            keys = _REFERENCE_KEYS["self_touch"]
        elif "right_eye_right_hand" in entry:
            keys = _REFERENCE_KEYS["hand_regard"]
        else:
            keys = _REFERENCE_KEYS["none"]
        ordered = {k: entry[k] for k in keys if k in entry}
        if extras:
            ordered.update({k: v for k, v in entry.items() if k not in ordered})
        out.append(ordered)
    return out


def training_score(log, behavior):
    """The reference's preliminary training score of a log (a load_training_log() list or a path):
    self-touch coverage over the last 10,000 episodes, hand regard the mean in-view fraction;
    None for behavior "none"."""
    if not isinstance(log, list):
        log = load_training_log(log)
    return _cradle.training_score(behavior, json.dumps(log))
