"""Stands in for `cradle tma run` in the campaign tests: reads --teacher, --seed, --out (and
--exp_name) and writes a synthetic run folder in the agreed format in well under a second.
Exits 3 when CRADLE_FAKE_FAIL_SEED equals the seed (a failing run)."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "python", "cradle"))
import tma_analysis  # noqa: E402


def value(args, flag):
    return args[args.index(flag) + 1]


def main(args):
    seed = int(value(args, "--seed"))
    if os.environ.get("CRADLE_FAKE_FAIL_SEED") == str(seed):
        print(f"fake run: seed {seed} fails on purpose")
        return 3
    teacher = value(args, "--teacher")
    tma_analysis.write_synthetic_run(value(args, "--out"), teacher, seed,
                                     strength=0.7 if teacher != "Random" else 0.2,
                                     evaluations=11, test_tasks=16, episodes_per_eval=4)
    print(f"fake run: {value(args, '--exp_name')} seed {seed} ({'--resume' in args and 'resumed' or 'new'})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
