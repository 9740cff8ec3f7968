"""The reference's intrinsic-motivation template (examples/intrinsic_motivation_wrapper.py): a
Wrapper whose reward is compute_intrinsic_reward(obs) plus the env's extrinsic reward, trained
with PPO. Fill compute_intrinsic_reward in with your own idea."""

from _common import cradle, parse_args, train_ppo


def compute_intrinsic_reward(obs):
    """Placeholder, as in the reference: replace with your intrinsic reward."""
    return 0.0


class Wrapper(cradle.Wrapper):  # gymnasium.Wrapper when Gymnasium is installed
    def __init__(self, env):
        super().__init__(env)

    def compute_intrinsic_reward(self, obs):
        return compute_intrinsic_reward(obs)

    def step(self, action):
        obs, extrinsic_reward, terminated, truncated, info = self.env.step(action)
        intrinsic_reward = self.compute_intrinsic_reward(obs)
        total_reward = intrinsic_reward + extrinsic_reward
        return obs, total_reward, terminated, truncated, info

    def reset(self, **kwargs):
        return self.env.reset(**kwargs)


def main():
    args = parse_args("Intrinsic-motivation wrapper template", "configs/config_selftouch.yml")
    train_ppo(args.config, Wrapper, compute_intrinsic_reward, args.train_for)


if __name__ == "__main__":
    main()
