#!/usr/bin/python3
"""SaCCM's gradient step in PyTorch (Debian's python3-torch), the side-by-side of
bench/sami_update_bench.cc: the same networks (actor and twin critics 512-512-512, LSTM 128 without
biases -> ReLU -> Linear 6, target copies), the same batch shapes, SAC with contexts and the
weighted SaNCE step of the `half` sampler. Prints gradient steps/s per setting and thread count
(the median of --rounds rounds, the settings alternating within each round).

    /usr/bin/python3 bench/sami_update_torch.py [--iterations 5] [--threads 1 2] [--rounds 1]
"""
import argparse
import os

# One OpenBLAS thread, as Cradle runs it (src/apps/main.cc): otherwise OpenBLAS under PyTorch takes
# a second core whatever --threads says, and the one-thread comparison is not one thread.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import torch
import torch.nn as nn
import torch.nn.functional as F

from side_by_side import TwinCritics, alternate, medians, mlp, squashed_sample, time_steps


class Encoder(nn.Module):
    def __init__(self, inp, hidden=128, ctx=6):
        super().__init__()
        self.lstm = nn.LSTM(inp, hidden, bias=False)
        self.head = nn.Linear(hidden, ctx)

    def forward(self, x):  # [T, B, in]
        return self.head(F.relu(self.lstm(x)[0]))


class Actor(nn.Module):
    def __init__(self, inp, act, layers):
        super().__init__()
        self.latent = mlp(inp, layers[:-1], layers[-1])
        self.mean = nn.Linear(layers[-1], act)
        self.log_std = nn.Linear(layers[-1], act)

    def sample(self, x):
        h = F.relu(self.latent(x))
        return squashed_sample(self.mean(h), self.log_std(h))


def sance(q, kp, kn, mp, mn, tau=0.1):
    def emb(x, m):
        return F.normalize((x * m.unsqueeze(2)).reshape(-1, x.size(2)), dim=1)
    q, kp, kn = emb(q, mp), emb(kp, mp), emb(kn, mn)
    return -F.logsigmoid(q @ kp.t() / tau).mean() - F.logsigmoid(-(q @ kn.t()) / tau).mean()


class Setup:
    def __init__(self, envs, batch, horizon, obs, act, cap=64, per_env=16):
        self.envs, self.batch, self.t, self.obs, self.act, self.cap = envs, batch, horizon + 1, obs, act, cap
        n = envs * cap
        self.o = torch.randn(n, self.t, obs)
        self.a = torch.rand(n, self.t, act) * 2 - 1
        self.a[:, -1] = 0
        self.r = torch.zeros(n, self.t)
        self.len = torch.full((n,), horizon, dtype=torch.long)
        self.ret = torch.zeros(n, dtype=torch.float64)
        for e in range(envs):
            for k in range(per_env):
                self.r[e * cap + k, :horizon] = k % 7
                self.ret[e * cap + k] = k % 7
        self.per_env = per_env
        ctx = 6
        self.enc, self.enc_t = Encoder(obs + act), Encoder(obs + act)
        self.enc_t.load_state_dict(self.enc.state_dict())
        self.w = nn.Linear(ctx, ctx, bias=False)
        self.actor = Actor(obs + ctx, act, [512, 512, 512])
        self.critic = TwinCritics(obs + ctx, act, [512] * 3)
        self.critic_t = TwinCritics(obs + ctx, act, [512] * 3)
        self.critic_t.load_state_dict(self.critic.state_dict())
        for p in list(self.enc_t.parameters()) + list(self.critic_t.parameters()):
            p.requires_grad_(False)
        self.log_alpha = torch.zeros(1, requires_grad=True)
        lr = 1e-3
        self.opt_enc = torch.optim.Adam(list(self.enc.parameters()) + list(self.w.parameters()), lr)
        self.opt_actor = torch.optim.Adam(self.actor.parameters(), lr)
        self.opt_critic = torch.optim.Adam(self.critic.parameters(), lr)
        self.opt_alpha = torch.optim.Adam([self.log_alpha], lr)

    def even(self, count):
        out = []
        for e in range(self.envs):
            n = count // self.envs + (1 if e < count % self.envs else 0)
            out.append(e * self.cap + torch.randint(self.per_env, (n,)))
        return torch.cat(out)

    def gather(self, idx):
        o, a, r, ln = self.o[idx], self.a[idx], self.r[idx], self.len[idx]
        prev = torch.zeros_like(a)
        prev[:, 1:] = a[:, :-1]
        x = torch.cat([prev, o], 2).transpose(0, 1).contiguous()
        valid = (torch.arange(self.t).unsqueeze(0) < ln.unsqueeze(1)).float()
        return o, a, r, ln, x, valid

    def update(self):
        gamma, tau = 0.95, 0.05
        o, a, r, ln, x, valid = self.gather(self.even(self.batch))
        c = self.enc(x)
        with torch.no_grad():
            cn = self.enc_t(x)
        rows = valid.t()[:-1].reshape(-1).nonzero().squeeze(1)
        ot = o.transpose(0, 1)

        def steps(z, b):
            return z[b:b + self.t - 1].reshape((self.t - 1) * z.size(1), -1)[rows]
        s = torch.cat([steps(ot, 0), steps(c, 0)], 1)
        sn = torch.cat([steps(ot, 1), steps(cn, 1)], 1)
        act = steps(a.transpose(0, 1), 0)
        rew = steps(r.t().unsqueeze(2), 0).squeeze(1)
        term = torch.zeros_like(rew)
        sd = s.detach()
        pi, logp = self.actor.sample(sd)
        alpha = self.log_alpha.detach().exp()
        alpha_loss = -(self.log_alpha * (logp.detach() - self.act)).mean()
        self.opt_alpha.zero_grad()
        alpha_loss.backward()
        self.opt_alpha.step()
        with torch.no_grad():
            an, logpn = self.actor.sample(sn)
            y = rew + gamma * (1 - term) * (self.critic_t(sn, an).min(0)[0] - alpha * logpn)
        q = self.critic(s, act)
        qloss = 0.5 * (q - y.unsqueeze(0)).square().mean(1).sum()
        self.opt_critic.zero_grad()
        self.opt_enc.zero_grad()
        qloss.backward()
        self.opt_critic.step()
        self.opt_enc.step()
        for p in self.critic.parameters():
            p.requires_grad_(False)
        aloss = (alpha * logp - self.critic(sd, pi).min(0)[0]).mean()
        self.opt_actor.zero_grad()
        aloss.backward()
        self.opt_actor.step()
        for p in self.critic.parameters():
            p.requires_grad_(True)
        with torch.no_grad():
            for pt, p in zip(self.critic_t.parameters(), self.critic.parameters()):
                pt.mul_(1 - tau).add_(p, alpha=tau)
        # SaCCM's `half` sampler: negatives the low half of an even batch; positives from one env
        # above the best negative.
        neg_n = min(max(int(self.batch * 0.5), 1), self.batch - 1)
        drawn = self.even(self.batch)
        drawn = drawn[torch.argsort(self.ret[drawn], descending=True, stable=True)]
        neg = drawn[-neg_n:]
        best = self.ret[neg[0]]
        pos = None
        for e in torch.randperm(self.envs).tolist():
            cand = torch.arange(e * self.cap, e * self.cap + self.per_env)
            cand = cand[self.ret[cand] > best]
            if len(cand) == 0:
                continue
            k = self.batch - neg_n
            pos = cand[torch.randperm(len(cand))[:k]] if len(cand) >= k else cand[torch.randint(len(cand), (k,))]
            break
        if pos is None:
            pos = drawn[:self.batch - neg_n]
        weight = min(max(0.01 * float(self.ret[pos].mean() - self.ret[neg].mean()), 0.0), 1.0)
        if weight > 0:
            _, _, _, lp, xp, _ = self.gather(pos)
            _, _, _, lneg, xn, _ = self.gather(neg)
            qz = self.enc(xp)
            with torch.no_grad():
                kp, kn = self.enc_t(xp), self.enc_t(xn)
            live = lambda ln: (torch.arange(self.t).unsqueeze(1) < (ln - 1).unsqueeze(0)).float()
            loss = weight * sance(qz, kp, kn, live(lp), live(lneg))
            self.opt_enc.zero_grad()
            loss.backward()
            self.opt_enc.step()
        with torch.no_grad():
            for pt, p in zip(self.enc_t.parameters(), self.enc.parameters()):
                pt.mul_(1 - tau).add_(p, alpha=tau)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--iterations", type=int, default=5)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--rounds", type=int, default=1, help="alternations of all the settings")
    args = ap.parse_args()
    torch.manual_seed(0)
    print(f"torch {torch.__version__}")
    settings = [("panda_256x50", (6, 256, 50, 25, 4)), ("mujoco_16x1000", (4, 16, 1000, 18, 6))]

    def measure(name, setup, threads):
        def run():
            torch.set_num_threads(threads)
            rate = time_steps(Setup(*setup).update, warmup=1, iterations=args.iterations)
            return {f"{name}/threads:{threads}": rate}
        return run

    table = alternate(args.rounds, [measure(name, setup, threads) for name, setup in settings
                                    for threads in args.threads])
    for key, runs in table.items():
        rate, cpu = medians(runs)
        print(f"{key}  {1000 / rate:.0f} ms/step  {rate:.3f} gradient steps/s  cpu {cpu:.0f} ms/step")


if __name__ == "__main__":
    main()
