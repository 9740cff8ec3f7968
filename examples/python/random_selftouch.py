"""Self-touch with a random policy (the reference's examples/random_selftouch.py): trains for
--train_for steps in training mode, so save_dir gets scene/scene.xml and logs/training.jsonl, then
prints the training score."""

from _common import run_random_policy

if __name__ == "__main__":
    run_random_policy("Random policy, self-touch", "configs/config_selftouch.yml")
