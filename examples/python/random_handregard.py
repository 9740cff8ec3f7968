"""Hand regard with a random policy (the reference's examples/random_handregard.py): trains for
--train_for steps in training mode, so save_dir gets scene.xml and logs/training.jsonl, then
prints the training score."""

from _common import cradle, parse_args


def main():
    args = parse_args("Random policy, hand regard", "configs/config_handregard.yml")
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


if __name__ == "__main__":
    main()
