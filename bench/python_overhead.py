"""Python overhead benchmark: µs per env step of the C++ loop (a bound loop over the same actions,
no Python per step) vs the Python loop over env.step(), and vector-env throughput from Python
(cradle.VectorEnv.step, batched numpy copies) vs the C++ vector loop.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [--steps 3000] [--envs 2]
"""

import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
try:
    import cradle
except ImportError:
    sys.path.insert(0, os.path.join(ROOT, "build", "python"))
    import cradle


def python_loop(env, actions):
    start = time.perf_counter()
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        if terminated or truncated:
            env.reset()
    return time.perf_counter() - start


def vector_loop(vec, actions):
    start = time.perf_counter()
    for a in actions:
        vec.step(a)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default=os.path.join(ROOT, "configs", "config_selftouch.yml"))
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--envs", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    config = cradle.config_dict(args.config)
    rng = np.random.default_rng(0)

    # Single env: the same actions through the C++ loop and through Python, alternating; best of
    # the repeats (the machine is shared).
    results = {}
    for copy in (True, False):
        env = cradle.make_env(config, training=False, copy_observations=copy)
        low, high = env.action_space.low, env.action_space.high
        actions = rng.uniform(low, high, (args.steps, low.size))
        cpp, py = [], []
        for _ in range(args.repeats):
            env.reset(seed=0)
            cpp.append(env._core.bench(actions) / args.steps)
            env.reset(seed=0)
            py.append(python_loop(env, actions) / args.steps)
        results[copy] = (min(cpp), min(py))
        env.close()
    for copy, (cpp, py) in results.items():
        mode = "fresh arrays (default)" if copy else "views (copy_observations=False)"
        print(f"single env, {mode}: C++ {cpp * 1e6:8.2f} µs/step, Python {py * 1e6:8.2f} µs/step, "
              f"overhead {(py - cpp) * 1e6:6.2f} µs/step")

    # Vector env: C++ vector steps vs cradle.VectorEnv.step (which also copies the batch).
    vec = cradle.VectorEnv(config, num_envs=args.envs, threads=args.envs)
    low, high = vec.single_action_space.low, vec.single_action_space.high
    actions = rng.uniform(low, high, (args.steps, args.envs, low.size))
    cpp, py = [], []
    for _ in range(args.repeats):
        vec.reset(seed=0)
        cpp.append(vec._core.bench(actions))
        vec.reset(seed=0)
        py.append(vector_loop(vec, actions))
    cpp_sps = args.steps * args.envs / min(cpp)
    py_sps = args.steps * args.envs / min(py)
    print(f"vector env ({args.envs} envs, {vec.threads} threads): C++ {cpp_sps:8.0f} steps/s, "
          f"Python {py_sps:8.0f} steps/s, Python/C++ {py_sps / cpp_sps:.3f}")
    vec.close()


if __name__ == "__main__":
    main()
