#include "learn/intrinsic/body_part_novelty.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"

namespace cradle::learn::intrinsic {
namespace {

std::filesystem::path state_file(const std::filesystem::path& dir) {
  return dir / "intrinsic_body_part_novelty.json";
}

void add_count(std::vector<long>& counts, int geom) {
  if (geom < 0) return;
  if (geom >= static_cast<int>(counts.size())) counts.resize(geom + 1, 0);
  ++counts[geom];
}

}  // namespace

BodyPartNovelty::BodyPartNovelty(double scale, Options options)
    : IntrinsicReward(scale), options_(options) {
  if (!(options_.balance >= 0 && options_.balance <= 1)) {
    throw UserError("body_part_novelty: balance must lie in [0, 1]");
  }
}

double BodyPartNovelty::hand_weight(int hand) const {
  const double own = distinct_[hand], other = distinct_[1 - hand];
  return (1 - options_.balance) + options_.balance * 2 * (1 + other) / (2 + own + other);
}

void BodyPartNovelty::bind(const VecEnv& env) {
  const int n = env.num_envs();
  seen_.assign(n, {0, 0});
  starts_.assign(n, true);
  const char* touches[2] = {"right_hand_touches", "left_hand_touches"};
  const char* contacts[2] = {"right_hand_contacts", "left_hand_contacts"};
  for (int h = 0; h < 2; ++h) {
    touches_slot_[h] = n > 0 ? env.info(0).find(touches[h]) : -1;
    contacts_slot_[h] = n > 0 ? env.info(0).find(contacts[h]) : -1;
  }
  onsets_ = options_.onset_weight > 0 && contacts_slot_[0] >= 0 && contacts_slot_[1] >= 0;
  in_contact_.assign(onsets_ ? 2 * n : 0, {});
  now_.assign(onsets_ ? 2 : 0, {});
}

void BodyPartNovelty::start_episode(int id) {
  seen_[id] = {0, 0};
  if (!onsets_) return;
  for (int h = 0; h < 2; ++h) {
    std::fill(in_contact_[2 * id + h].begin(), in_contact_[2 * id + h].end(), 0);
  }
}

void BodyPartNovelty::reset(const VecEnv& env) {
  if (static_cast<int>(seen_.size()) != env.num_envs()) bind(env);
  events_.clear();
  for (int i = 0; i < env.num_envs(); ++i) {
    start_episode(env.env_id(i));
    if (onsets_) collect_onsets(env, i, env.env_id(i));
  }
  events_.clear();  // contacts present at the start are no onsets
  starts_.assign(env.num_envs(), false);
}

void BodyPartNovelty::collect_onsets(const VecEnv& env, int i, int id) {
  const envs::Info& info = env.info(i);
  for (int h = 0; h < 2; ++h) {
    std::vector<std::uint8_t>& before = in_contact_[2 * id + h];
    std::vector<std::uint8_t>& now = now_[h];
    std::fill(now.begin(), now.end(), 0);
    for (int g : info.list(contacts_slot_[h])) {
      if (g >= static_cast<int>(now.size())) now.resize(g + 1, 0);
      now[g] = 1;
    }
    // Both sized to the largest geom id seen (absent ids are not in contact).
    if (before.size() < now.size()) before.resize(now.size(), 0);
    if (now.size() < before.size()) now.resize(before.size(), 0);
    for (size_t g = 0; g < before.size(); ++g) {
      if (now[g] && !before[g]) events_.push_back({h, static_cast<int>(g), true});
    }
    before.swap(now);
  }
}

void BodyPartNovelty::compute(const VecEnv& env, std::span<const double>,
                              std::span<double> rewards) {
  if (seen_.empty()) bind(env);
  events_.clear();
  event_env_.clear();
  for (int i = 0; i < env.num_envs(); ++i) {
    const int id = env.env_id(i);
    const size_t before = events_.size();
    if (starts_[id]) start_episode(id);
    if (onsets_) {
      collect_onsets(env, i, id);
      if (starts_[id]) events_.resize(before);  // a new episode's first contacts are no onsets
    }
    const envs::Info& info = env.info(i);
    for (int h = 0; h < 2; ++h) {
      if (touches_slot_[h] < 0) continue;
      const std::span<const int> list = info.list(touches_slot_[h]);
      if (list.size() < seen_[id][h]) seen_[id][h] = 0;  // reset behind our back
      for (size_t k = seen_[id][h]; k < list.size(); ++k) events_.push_back({h, list[k], false});
      seen_[id][h] = list.size();
    }
    event_env_.resize(events_.size(), i);
  }

  // Bonuses from the counts before this step ...
  const double weight[2] = {hand_weight(0), hand_weight(1)};
  for (size_t e = 0; e < events_.size(); ++e) {
    const Event& event = events_[e];
    const double bonus =
        event.onset ? options_.onset_weight / std::sqrt(1.0 + count(onset_[event.hand], event.geom))
                    : 1.0 / std::sqrt(1.0 + count(first_[event.hand], event.geom));
    rewards[event_env_[e]] += scale() * weight[event.hand] * bonus;
  }
  // ... then the counts take this step in.
  for (const Event& event : events_) {
    if (event.onset) {
      add_count(onset_[event.hand], event.geom);
    } else {
      add_count(first_[event.hand], event.geom);
      if (first_[event.hand][event.geom] == 1) ++distinct_[event.hand];
    }
  }
  starts_.record_flags(env);
}

void BodyPartNovelty::save(const std::filesystem::path& dir) const {
  const nlohmann::json state = {{"first", first_}, {"onset", onset_}};
  std::ofstream out(state_file(dir));
  out << state.dump() << "\n";
  if (!out) throw UserError("cannot write " + state_file(dir).string());
}

void BodyPartNovelty::load(const std::filesystem::path& dir) {
  std::ifstream in(state_file(dir));
  if (!in) throw UserError("cannot read " + state_file(dir).string());
  try {
    const nlohmann::json state = nlohmann::json::parse(in);
    state.at("first").get_to(first_);
    state.at("onset").get_to(onset_);
  } catch (const nlohmann::json::exception& e) {
    throw UserError("malformed " + state_file(dir).string() + ": " + e.what());
  }
  for (int h = 0; h < 2; ++h) {
    distinct_[h] = 0;
    for (long n : first_[h]) distinct_[h] += n > 0;
  }
}

}  // namespace cradle::learn::intrinsic
