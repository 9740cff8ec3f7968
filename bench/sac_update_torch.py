#!/usr/bin/python3
"""SAC's gradient step in PyTorch (Debian's python3-torch), the side-by-side of
bench/sac_update_bench.cc at the self-touch sizes: observation = the self-touch env's pooled
vector, action 44, actor and twin critics 256-256 ReLU, batch 256, SB3's SAC defaults (Adam 3e-4,
learned temperature, tau 0.005). One gradient step: sample 256 transitions from a replay of 512,
normalise the observations (running mean/std, clip 10), the temperature, critic and actor Adam
steps, the Polyak update, and the losses read out (.item()) as both loggers do.

Critics two ways: `separate` (two MLPs, SB3's ContinuousCritic) and `fused` (one weight
[2, in, out] per layer and baddbmm, as Cradle's). With --cradle-bench the C++ benchmark runs in the
same go, alternating with the Python timings, and the ratio is printed (its obs_dim is used):

    /usr/bin/python3 bench/sac_update_torch.py --cradle-bench build/cradle_bench [--rounds 3]
"""
import argparse
import json
import math
import os
import subprocess

# One OpenBLAS thread, as Cradle runs it (src/apps/main.cc): otherwise OpenBLAS under PyTorch takes
# a second core whatever --threads says, and the one-thread comparison is not one thread.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import torch
import torch.nn as nn
import torch.nn.functional as F

from side_by_side import TwinCritics, alternate, medians, squashed_sample, time_steps

ACTIONS, HIDDEN, BATCH, REPLAY = 44, 256, 256, 512


class Actor(nn.Module):
    def __init__(self, obs):
        super().__init__()
        self.latent = nn.Sequential(nn.Linear(obs, HIDDEN), nn.ReLU(), nn.Linear(HIDDEN, HIDDEN),
                                    nn.ReLU())
        self.mean = nn.Linear(HIDDEN, ACTIONS)
        self.log_std = nn.Linear(HIDDEN, ACTIONS)

    def sample(self, s):
        h = self.latent(s)
        return squashed_sample(self.mean(h), self.log_std(h))


def separate_critics(obs):
    return TwinCritics(obs, ACTIONS, [HIDDEN, HIDDEN])


class FusedCritics(nn.Module):
    def __init__(self, obs):
        super().__init__()
        sizes = [obs + ACTIONS, HIDDEN, HIDDEN, 1]
        self.w = nn.ParameterList()
        self.b = nn.ParameterList()
        for i, o in zip(sizes[:-1], sizes[1:]):
            bound = 1 / math.sqrt(i)
            self.w.append(nn.Parameter(torch.empty(2, i, o).uniform_(-bound, bound)))
            self.b.append(nn.Parameter(torch.empty(2, 1, o).uniform_(-bound, bound)))

    def forward(self, s, a):
        x = torch.cat([s, a], 1)
        h = x.unsqueeze(0).expand(2, x.shape[0], x.shape[1])
        for k, (w, b) in enumerate(zip(self.w, self.b)):
            h = torch.baddbmm(b, h, w)
            if k + 1 < len(self.w):
                h = F.relu(h)
        return h.squeeze(2)


class Sac:
    def __init__(self, obs, fused):
        critic = FusedCritics if fused else separate_critics
        self.actor, self.critic, self.target = Actor(obs), critic(obs), critic(obs)
        self.target.load_state_dict(self.critic.state_dict())
        self.log_alpha = torch.zeros(1, requires_grad=True)
        self.actor_opt = torch.optim.Adam(self.actor.parameters(), lr=3e-4)
        self.critic_opt = torch.optim.Adam(self.critic.parameters(), lr=3e-4)
        self.alpha_opt = torch.optim.Adam([self.log_alpha], lr=3e-4)
        self.target_entropy = -float(ACTIONS)
        # The replay and the normaliser's statistics.
        self.obs = torch.randn(REPLAY, obs)
        self.next_obs = torch.randn(REPLAY, obs)
        self.act = torch.rand(REPLAY, ACTIONS) * 2 - 1
        self.rew = torch.randn(REPLAY)
        self.term = (torch.rand(REPLAY) < 0.01).to(torch.uint8)
        self.mean, self.var = torch.randn(obs).double(), torch.rand(obs).double() + 0.5

    def normalize(self, x):
        z = (x.double() - self.mean) / torch.sqrt(self.var + 1e-8)
        return z.clamp(-10, 10).float()

    def step(self):
        i = torch.randint(0, REPLAY, (BATCH,))
        s, s2 = self.normalize(self.obs[i]), self.normalize(self.next_obs[i])
        a, r, d = self.act[i], self.rew[i], self.term[i].float()
        pi, log_pi = self.actor.sample(s)
        alpha = self.log_alpha.detach().exp()
        alpha_loss = -(self.log_alpha * (log_pi.detach() + self.target_entropy)).mean()
        self.alpha_opt.zero_grad()
        alpha_loss.backward()
        self.alpha_opt.step()
        with torch.no_grad():
            a2, log_pi2 = self.actor.sample(s2)
            q2 = self.target(s2, a2).min(0).values - alpha * log_pi2
            y = r + 0.99 * (1 - d) * q2
        q = self.critic(s, a)
        q_losses = (q - y.unsqueeze(0)).square().mean(1)
        qf_loss = 0.5 * q_losses.sum()
        self.critic_opt.zero_grad()
        qf_loss.backward()
        self.critic_opt.step()
        for p in self.critic.parameters():
            p.requires_grad_(False)
        actor_loss = (alpha * log_pi - self.critic(s, pi).min(0).values).mean()
        self.actor_opt.zero_grad()
        actor_loss.backward()
        self.actor_opt.step()
        for p in self.critic.parameters():
            p.requires_grad_(True)
        with torch.no_grad():
            for t, o in zip(self.target.parameters(), self.critic.parameters()):
                t.mul_(0.995).add_(o, alpha=0.005)
        for v in (qf_loss, q_losses[0], q[0].mean(), actor_loss, alpha, alpha_loss):
            v.item()


def python_rate(obs, fused, threads, seconds):
    torch.set_num_threads(threads)
    return time_steps(Sac(obs, fused).step, warmup=3, seconds=seconds)


def cradle_rates(binary, seconds):
    """{threads: (gradient steps/s, CPU ms per step, obs_dim)} from one run of the C++ benchmark
    (its CPU time is the timing thread's: a lower bound with 2 threads)."""
    out = subprocess.run([binary, "--benchmark_filter=BM_SacGradientStep",
                          "--benchmark_format=json", f"--benchmark_min_time={seconds}"],
                         check=True, capture_output=True, text=True).stdout
    rates = {}
    for b in json.loads(out)["benchmarks"]:
        threads = int(b["name"].split("threads:")[1].split("/")[0])
        rates[threads] = (b["gradient_steps_per_s"], b["cpu_time"], int(b["obs_dim"]))
    return rates


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--obs-dim", type=int, default=0,
                    help="observation size (default: the C++ benchmark's, else 500)")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--seconds", type=float, default=3.0, help="timing per measurement")
    ap.add_argument("--rounds", type=int, default=3, help="alternations C++ / Python")
    ap.add_argument("--cradle-bench", default="", help="build/cradle_bench: time it in the same go")
    args = ap.parse_args()
    obs = [args.obs_dim]  # the C++ benchmark's obs_dim when not given, else 500

    def cradle():
        rates = {}
        for threads, (rate, cpu, dim) in cradle_rates(args.cradle_bench, args.seconds).items():
            rates[("cradle (fused)", threads)] = (rate, cpu)
            obs[0] = obs[0] or dim
        return rates

    def python():
        obs[0] = obs[0] or 500
        return {("torch fused" if fused else "torch separate (SB3)", threads):
                python_rate(obs[0], fused, threads, args.seconds)
                for threads in args.threads for fused in (False, True)}

    table = alternate(args.rounds, [cradle, python] if args.cradle_bench else [python])
    print(f"SAC gradient step, obs {obs[0]}, action {ACTIONS}, 256-256, batch {BATCH}: "
          f"median of {args.rounds} rounds; wall and CPU time per step (CPU: robust to a loaded "
          f"machine)")
    for (who, threads), runs in sorted(table.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        rate, cpu = medians(runs)
        line = (f"  threads {threads}  {who:22s} {rate:7.1f}/s  wall {1000 / rate:7.2f} ms  "
                f"cpu {cpu:7.2f} ms")
        base = table.get(("torch separate (SB3)", threads))
        if base and who != "torch separate (SB3)":
            base_rate, base_cpu = medians(base)
            line += (f"  speed x{rate / base_rate:.2f}, cpu x{base_cpu / cpu:.2f} of torch "
                     f"separate")
        print(line)


if __name__ == "__main__":
    main()
