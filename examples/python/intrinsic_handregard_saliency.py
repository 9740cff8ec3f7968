"""Hand regard with a visual-saliency intrinsic reward (the reference's
examples/intrinsic_handregard_saliency.py): r = sal(eye_left) + sal(eye_right), where sal(I) is
the L2 norm of the Laplacian of the grey image divided by H x W. The reference convolves with
scipy.ndimage (mode "reflect"); numpy's "symmetric" padding is the same boundary rule."""

import numpy as np

from _common import cradle, parse_args, train_ppo

GREY = np.array([0.2989, 0.5870, 0.1140])


def saliency(image):
    grey = image @ GREY
    p = np.pad(grey, 1, mode="symmetric")
    laplacian = 4 * p[1:-1, 1:-1] - p[:-2, 1:-1] - p[2:, 1:-1] - p[1:-1, :-2] - p[1:-1, 2:]
    return float(np.linalg.norm(laplacian) / grey.size)


def compute_intrinsic_reward(obs):
    return saliency(obs["eye_left"]) + saliency(obs["eye_right"])


class Wrapper(cradle.Wrapper):
    def step(self, action):
        obs, extrinsic_reward, terminated, truncated, info = self.env.step(action)
        return obs, compute_intrinsic_reward(obs) + extrinsic_reward, terminated, truncated, info


def main():
    args = parse_args("Visual-saliency intrinsic reward, hand regard",
                      "configs/config_handregard.yml")
    train_ppo(args.config, Wrapper, compute_intrinsic_reward, args.train_for)


if __name__ == "__main__":
    main()
