"""Self-touch with a touch-count intrinsic reward (the reference's
examples/intrinsic_selftouch_count.py): r = fraction of the flattened touch vector above 1e-6."""

import numpy as np

from _common import cradle, parse_args, train_ppo


def compute_intrinsic_reward(obs):
    touch = obs["touch"]
    return float(np.sum(touch > 1e-6) / len(touch))


class Wrapper(cradle.Wrapper):
    def step(self, action):
        obs, extrinsic_reward, terminated, truncated, info = self.env.step(action)
        return obs, compute_intrinsic_reward(obs) + extrinsic_reward, terminated, truncated, info


def main():
    args = parse_args("Touch-count intrinsic reward, self-touch", "configs/config_selftouch.yml")
    train_ppo(args.config, Wrapper, compute_intrinsic_reward, args.train_for)


if __name__ == "__main__":
    main()
