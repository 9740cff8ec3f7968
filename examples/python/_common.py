"""Shared by the example scripts: the reference's flags, finding the package and the configs, and
PPO from Stable-Baselines3 when it is installed, Cradle's C++ PPO otherwise."""

import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

try:
    import cradle  # noqa: F401
except ImportError:  # run from a checkout without PYTHONPATH: use the build tree's package
    sys.path.insert(0, os.path.join(ROOT, "build", "python"))
    import cradle  # noqa: F401

try:
    import stable_baselines3
except ImportError:
    stable_baselines3 = None


def parse_args(description, default_config):
    """The reference examples' flags: --config and --train_for."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--config", default=default_config, type=str,
                        help="the configuration file to set up the environment")
    parser.add_argument("--train_for", default=10000, type=int,
                        help="total timesteps of training")
    args = parser.parse_args()
    # The reference runs from its repository root; configs/ here is found from anywhere.
    if not os.path.exists(args.config) and os.path.exists(os.path.join(ROOT, args.config)):
        args.config = os.path.join(ROOT, args.config)
    return args


def train_ppo(config, wrapper_class, reward_fn, train_for):
    """PPO for train_for steps on the intrinsic reward. With SB3: its PPO("MultiInputPolicy") with
    all defaults on the wrapped env (as the reference), model saved to <save_dir>/model.zip.
    Without SB3: Cradle's PPO (SB3's defaults, C++), reward_fn passed as a Python intrinsic
    reward, checkpoint under <save_dir>/checkpoints/."""
    save_dir = cradle.config_dict(config)["save_dir"]
    if stable_baselines3 is not None:
        env = wrapper_class(cradle.make_env(config, training=True))
        env.reset()
        model = stable_baselines3.PPO("MultiInputPolicy", env, verbose=1)
        model.learn(total_timesteps=train_for)
        model.save(os.path.join(save_dir, "model"))
        env.close()
        print(f"SB3 PPO model saved to {os.path.join(save_dir, 'model.zip')}")
        return
    print("stable_baselines3 is not installed: training with Cradle's PPO (C++)")
    # As the reference's scripts do, a rerun replaces the previous run in save_dir.
    result = cradle.train(config, algo="ppo", intrinsic=[reward_fn], steps=train_for, envs=1,
                          eval_episodes=0, overwrite=True)
    print(f"trained {result['steps']} steps at {result['steps_per_second']:.0f} steps/s; "
          f"checkpoint {result['checkpoint']}; training score {result['training_score']}")


def run_random_policy(description, default_config):
    """The reference's random baselines: a random policy for --train_for steps in training mode
    (save_dir gets scene/scene.xml and logs/training.jsonl), then the training score."""
    args = parse_args(description, default_config)
    env = cradle.make_env(args.config, training=True)
    env.reset()
    env.reset()  # as the reference: two zero-step entries in the log
    for _ in range(args.train_for):
        action = env.action_space.sample()
        obs, reward, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            env.reset()
    env.close()
    save_dir = cradle.config_dict(args.config)["save_dir"]
    log = cradle.load_training_log(save_dir)
    print(f"{len(log)} log entries; training score "
          f"{cradle.training_score(log, env.behavior):.4f}")
