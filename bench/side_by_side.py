"""What the PyTorch side-by-sides of Cradle's learner benchmarks share (bench/sac_update_torch.py,
bench/sami_update_torch.py): the networks both build the same way, the squashed-Gaussian sample of
SAC's actor, and the alternate-and-time loop (every measurement once per round, so that a change in
the machine's load falls on all of them alike, then the median over the rounds).
"""
import math
import statistics
import time

import torch
import torch.nn as nn
import torch.nn.functional as F


def mlp(inp, layers, out):
    """Linear layers of the sizes in `layers` with ReLU between them, then a linear head."""
    mods, last = [], inp
    for h in layers:
        mods += [nn.Linear(last, h), nn.ReLU()]
        last = h
    mods.append(nn.Linear(last, out))
    return nn.Sequential(*mods)


class TwinCritics(nn.Module):
    """Two separate Q MLPs on [state, action] (SB3's ContinuousCritic); forward gives [2, batch]."""

    def __init__(self, inp, act, layers):
        super().__init__()
        self.q = nn.ModuleList([mlp(inp + act, layers, 1) for _ in range(2)])

    def forward(self, s, a):
        x = torch.cat([s, a], 1)
        return torch.stack([q(x).squeeze(1) for q in self.q])


def squashed_sample(mean, log_std):
    """SAC's action: tanh of a Gaussian sample, with its log-probability (the tanh Jacobian in
    the stable form 2 (log 2 - u - softplus(-2u))), summed over the action dimensions."""
    log_std = log_std.clamp(-20, 2)
    eps = torch.randn_like(mean)
    u = mean + log_std.exp() * eps
    log_gauss = -0.5 * eps.square() - log_std - 0.5 * math.log(2 * math.pi)
    log_jac = 2 * (math.log(2) - u - F.softplus(-2 * u))
    return torch.tanh(u), (log_gauss - log_jac).sum(1)


def time_steps(step, warmup, iterations=0, seconds=0.0):
    """Runs `step` `warmup` times untimed, then `iterations` times (or for `seconds` when
    iterations is 0); returns (steps per wall second, CPU ms per step)."""
    for _ in range(warmup):
        step()
    steps, t0, c0 = 0, time.perf_counter(), time.process_time()
    while (steps < iterations) if iterations else (time.perf_counter() - t0 < seconds):
        step()
        steps += 1
    return steps / (time.perf_counter() - t0), 1000 * (time.process_time() - c0) / steps


def alternate(rounds, measurements):
    """Runs every measurement once per round, in turn. A measurement is a callable returning
    {key: (rate, cpu_ms)}; the answer is {key: [(rate, cpu_ms) per round]}."""
    table = {}
    for _ in range(rounds):
        for measure in measurements:
            for key, value in measure().items():
                table.setdefault(key, []).append(value)
    return table


def medians(runs):
    """(median rate, median CPU ms) of one key's [(rate, cpu_ms)] from alternate()."""
    return statistics.median(r for r, _ in runs), statistics.median(c for _, c in runs)
