// SaMI's context-SAC methods (TESAC, CCM, SaTESAC, SaCCM, SaCCMAll; learn/meta/context_sac.h) as
// ordinary learners (learn/learner.h), built by name in learn/registry.h: "tesac", "ccm",
// "satesac", "saccm", "saccm_all". They collect whole trajectories from any VecEnv with SaMI's
// loop, one trajectory ring per env slot (env i -> replay env i):
//
//   every learn() call: reset the envs (seed from the learner's generator); an open trajectory
//     is closed as truncated; every slot starts a trajectory at its first observation and a
//     zeroed context stream (the LSTM's (h, c) and the previous action)
//   while steps < total_steps:                                 (steps = vector steps x envs)
//     o = every float observation key of each env, concatenated in key order (float32 rows)
//     a = ContextSac.act(o, streams)                          (advances every stream, each step)
//     while steps < learning_starts x envs: a = uniform(-1, 1) (rng), taken as the streams'
//       previous actions
//     step the envs with low + (a + 1) (high - low) / 2; the reward hook may change the rewards
//     slot i reset by this step (next-step autoreset): no transition; stream i zeroed; its next
//       trajectory starts at the reported (first) observation
//     other slots: (a_i, r_i, o'_i) appended to trajectory i; on terminated or truncated it is
//       closed (o'_i is the final observation); at `horizon` steps it is closed as truncated and
//       stream i zeroed, and the episode goes on in a new trajectory from o'_i
//     once steps >= learning_starts x envs and every slot has a closed trajectory, every
//       train_freq vector steps: gradient_steps ContextSac updates (SAC on [o, c] + the method's
//       SaNCE step) on trajectories sampled from the rings with rng
//     every report_every vector steps and at the end: TrainStats
//
// On SaMI's envs (one per training task set, actions in [-1, 1]) this is SaMI's training loop but
// for one rule: SaMI's vector resets an env in the step that ends its episode, a VecEnv in the
// next step, so each reset costs a vector step and a ring gives up its oldest trajectory's slot at
// the new trajectory's first step rather than at the reset. Up to the first episode end the data
// and updates are those of SaMI's loop drawing from the same generators (ContextSac's seeded with
// the learner's seed, rng with seed ^ 0x5a4d49); the learning curves of both rules are compared in
// docs/fidelity.md. The envs' reset seeds come from the learner's own generator (seeded with the
// seed), which draws nothing else. `cradle sami train` runs these learners through `cradle
// train`'s path (train/sami/sami_experiment.h).
//
// Settings: SamiConfig (context_sac.h; defaults SaMI's MuJoCo ones, Panda's buffer_size,
// batch_size and contrast_batch_size of 1000, 256, 256 come as hyperparameters) plus:
//   horizon        longest trajectory stored (SaMI: the env's spec horizon; default 1000;
//                  `cradle train --env ID` presets it to the env's episode length)
//   report_every   vector steps between progress reports (default 1000; `cradle train --env
//                  ID`: the episode length)
// An unknown name or a bad value is a one-line UserError.
//
// Checkpoints hold everything: ContextSac's networks, optimisers and generator, the rings (so a
// loaded learner continues exactly as the saved one), rng, the env-seed generator and the
// counters, under the algorithm's name ("saccm"), so read_checkpoint_info names it for --resume.
//
// act() keeps one context stream: its calls are one episode's consecutive steps until
// new_episode(), a learn() or load() call, or `horizon` calls (the longest context the encoder is
// trained on). value() is NaN.
//
// Data-parallel (LearnerOptions::sync, `--distributed`): every rank starts from rank 0's networks,
// collects on its own envs into its own rings, and averages every gradient (temperature, critics
// with the encoder, actor, the contrastive step) before its optimiser steps; updates start when
// every rank holds a whole trajectory in every slot, and the contrastive step runs on every rank
// when any rank's batch gives it a weight. steps() counts every rank's env steps (as SAC's);
// learning_starts counts a rank's own. A resumed rank loads rank 0's checkpoint, rings included,
// and draws from generators of its own from there.
#pragma once

#include <memory>
#include <span>
#include <string_view>

#include "learn/hyperparams.h"
#include "learn/learner.h"

namespace cradle::learn::meta {

// The learner's settings besides SamiConfig's.
struct SamiLearnerConfig {
  int horizon = 1000;       // longest trajectory (SaMI: the env's horizon)
  int report_every = 1000;  // vector steps between progress reports
  void bind(Hyperparameters& table);
};

// "tesac", "ccm", "satesac", "saccm", "saccm_all", in this order.
std::span<const std::string_view> sami_learner_names();
// The same for messages: "tesac, ccm, satesac, saccm or saccm_all".
std::string sami_learner_list();
// ContextSac's method of a learner name ("saccm" -> "SaCCM"); "" for another name.
std::string_view sami_method(std::string_view algorithm);
// The learner name of a method ("SaCCM" -> "saccm"); UserError naming the methods for another.
std::string sami_learner_name(std::string_view method);

// Throws UserError for an unknown algorithm or hyperparameter, a bad value, an env with uint8
// (image) observation keys or no float ones, an action space without finite bounds, CCM on fewer
// than two envs, or a replay too large for the machine.
std::unique_ptr<Learner> make_sami_learner(std::string_view algorithm, VecEnv& env,
                                           const LearnerOptions& options);

// The context c_t the encoder inferred at the learner's last act() call (SamiConfig's
// context_size floats; empty before the first), for evaluations that record what the encoder
// infers (`cradle sami evaluate`). Valid until the next act(). UserError for another learner.
std::span<const float> last_context(const Learner& learner);

}  // namespace cradle::learn::meta
