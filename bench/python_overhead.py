"""Python overhead benchmark: µs per env step of the C++ loop (a bound loop over the same actions,
no Python per step) vs the Python loop over env.step(), and vector-env throughput from Python
(cradle.VectorEnv.step, batched numpy copies) vs the C++ vector loop.

Physics time varies by more than the overhead on a shared machine, so the overhead is also
measured within each run: loop wall time minus the time spent inside the C++ env's steps (its
own profile), Python loop minus C++ loop.

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


def per_step_overhead(env, actions):
    """Per step: wall time of env.step() from Python minus the C++ env's own time for that step.
    The median is robust to the preemptions of a shared machine (most steps see none)."""
    core = env._core
    out = np.empty(len(actions))
    for i, a in enumerate(actions):
        p0 = core.profile_seconds
        t0 = time.perf_counter()
        obs, reward, terminated, truncated, info = env.step(a)
        t1 = time.perf_counter()
        out[i] = (t1 - t0) - (core.profile_seconds - p0)
        if terminated or truncated:
            env.reset()
    return out


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
        cpp, py, cpp_out, py_out, cpp_cpu, py_cpu = [], [], [], [], [], []
        for _ in range(args.repeats):
            env.reset(seed=0)
            env._core.clear_profile()
            cpu = time.process_time()
            wall = env._core.bench(actions)
            cpp_cpu.append((time.process_time() - cpu) / args.steps)
            cpp.append(wall / args.steps)
            cpp_out.append((wall - env._core.profile_seconds) / args.steps)
            env.reset(seed=0)
            env._core.clear_profile()
            cpu = time.process_time()
            wall = python_loop(env, actions)
            py_cpu.append((time.process_time() - cpu) / args.steps)
            py.append(wall / args.steps)
            py_out.append((wall - env._core.profile_seconds) / args.steps)
        env.reset(seed=0)
        each = per_step_overhead(env, actions)
        results[copy] = (min(cpp), min(py), np.median(cpp_out), np.median(py_out), each,
                         min(cpp_cpu), min(py_cpu))
        env.close()
    for copy, (cpp, py, cpp_out, py_out, each, cpp_cpu, py_cpu) in results.items():
        mode = "fresh arrays (default)" if copy else "views (copy_observations=False)"
        print(f"single env, {mode}: C++ loop {cpp * 1e6:7.1f} µs/step, Python loop "
              f"{py * 1e6:7.1f} µs/step (best of {args.repeats}); outside the env step: C++ "
              f"{cpp_out * 1e6:5.2f}, Python {py_out * 1e6:5.2f} -> overhead "
              f"{(py_out - cpp_out) * 1e6:5.2f} µs/step (median)")
        print(f"  CPU time (not counting waits for a core): C++ loop {cpp_cpu * 1e6:.1f}, Python "
              f"loop {py_cpu * 1e6:.1f} µs/step -> {(py_cpu - cpp_cpu) * 1e6:.2f} µs/step")
        print(f"  per step, Python env.step() minus the C++ step inside it: median "
              f"{np.median(each) * 1e6:.2f} µs, 10th-90th percentile "
              f"{np.percentile(each, 10) * 1e6:.2f}"
              f"-{np.percentile(each, 90) * 1e6:.2f} µs")

    # Vector env: C++ vector steps vs cradle.VectorEnv.step (which also copies the batch), in
    # alternating blocks so that both see the same machine load; median of the block ratios.
    for threads in sorted({1, args.envs}):
        vec = cradle.VectorEnv(config, num_envs=args.envs, threads=threads)
        low, high = vec.single_action_space.low, vec.single_action_space.high
        block = 200
        actions = rng.uniform(low, high, (block, args.envs, low.size))
        vec.reset(seed=0)
        cpp, py, cpp_cpu, py_cpu, inside = [], [], [], [], []
        for _ in range(max(1, args.steps // block)):
            cpu = time.process_time()
            cpp.append(vec._core.bench(actions))
            cpp_cpu.append(time.process_time() - cpu)
            cpu = time.process_time()
            vec._core.clear_stepping()
            py.append(vector_loop(vec, actions))
            inside.append(vec._core.stepping_seconds)
            py_cpu.append(time.process_time() - cpu)
        cpp, py, inside = np.array(cpp), np.array(py), np.array(inside)
        steps = block * args.envs
        print(f"vector env ({args.envs} envs, {vec.threads} threads, {len(cpp)} blocks of {block} "
              f"steps): C++ {steps / np.median(cpp):6.0f} env steps/s, Python "
              f"{steps / np.median(py):6.0f} env steps/s; Python/C++ throughput "
              f"{np.median(cpp / py):.3f} "
              f"(median of blocks); {(np.median(py) - np.median(cpp)) / block * 1e6:.1f} µs more "
              f"per vector step; CPU time Python/C++ {np.sum(py_cpu) / np.sum(cpp_cpu):.3f}")
        print(f"  within the Python loop: time inside the C++ vector step / loop time "
              f"{np.median(inside / py):.4f} (median of blocks); outside it "
              f"{np.median(py - inside) / block * 1e6:.1f} µs per vector step")
        vec.close()


if __name__ == "__main__":
    main()
