#include "learn/intrinsic/reward.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <utility>

#include "core/error.h"
#include "learn/intrinsic/body_part_novelty.h"
#include "learn/intrinsic/disagreement.h"
#include "learn/intrinsic/episode_coverage.h"
#include "learn/intrinsic/gaze_alignment.h"
#include "learn/intrinsic/hand_visibility.h"
#include "learn/intrinsic/icm.h"
#include "learn/intrinsic/regard_count.h"
#include "learn/intrinsic/rnd.h"
#include "learn/intrinsic/saliency.h"
#include "learn/intrinsic/touch_count.h"

namespace cradle::learn::intrinsic {
namespace {

using Factory = std::function<std::unique_ptr<IntrinsicReward>(double scale)>;

template <typename Reward>
Factory factory() {
  return [](double scale) { return std::make_unique<Reward>(scale); };
}

// The registry, in the order intrinsic_names() lists it.
const std::vector<std::pair<std::string, Factory>>& registry() {
  static const std::vector<std::pair<std::string, Factory>> entries = {
      {"touch_count", factory<TouchCount>()},
      {"saliency", factory<Saliency>()},
      {"body_part_novelty", factory<BodyPartNovelty>()},
      {"episode_coverage", factory<EpisodeCoverage>()},
      {"hand_visibility", factory<HandVisibility>()},
      {"regard_count", factory<RegardCount>()},
      {"gaze_alignment", factory<GazeAlignment>()},
      {"rnd", factory<Rnd>()},
      {"icm", factory<Icm>()},
      {"disagreement", factory<Disagreement>()},
  };
  return entries;
}

std::string known_names() {
  std::string list;
  for (const std::string& name : intrinsic_names()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

std::string_view trim(std::string_view s) {
  const size_t first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

}  // namespace

std::vector<std::string> intrinsic_names() {
  std::vector<std::string> names;
  for (const auto& entry : registry()) names.push_back(entry.first);
  return names;
}

std::unique_ptr<IntrinsicReward> make_intrinsic(std::string_view name, double scale) {
  for (const auto& [known, make] : registry()) {
    if (known == name) return make(scale);
  }
  throw UserError("unknown intrinsic reward '" + std::string(name) + "' (known: " + known_names() +
                  ")");
}

FunctionReward::FunctionReward(std::string name, Function fn, double scale)
    : IntrinsicReward(scale), name_(std::move(name)), fn_(std::move(fn)) {}

void FunctionReward::compute(const VecEnv& env, std::span<const double> actions,
                             std::span<double> rewards) {
  const int n = env.num_envs();
  const size_t dim = n > 0 ? actions.size() / n : 0;
  for (int i = 0; i < n; ++i) {
    rewards[i] += scale() * fn_(env.env_id(i), env.observation(i), actions.subspan(i * dim, dim),
                                env.info(i));
  }
}

void Composite::add(std::unique_ptr<IntrinsicReward> term) {
  for (const auto& t : terms_) {
    if (t->name() == term->name()) {
      throw UserError("intrinsic reward '" + std::string(term->name()) + "' given twice");
    }
  }
  terms_.push_back(std::move(term));
  last_.emplace_back();
}

std::string Composite::describe() const {
  std::string out;
  for (const auto& t : terms_) {
    char weight[32];
    const auto end = std::to_chars(weight, weight + sizeof(weight), t->scale()).ptr;
    // Appended piece by piece: GCC 12 at -O3 takes `"" + string` for an oversized copy.
    if (!out.empty()) out += ',';
    out += std::string(t->name()) + ":" + std::string(weight, end);
  }
  return out;
}

void Composite::bind(const VecEnv& env) {
  for (size_t k = 0; k < terms_.size(); ++k) {
    terms_[k]->bind(env);
    last_[k].assign(env.num_envs(), 0);
  }
}

void Composite::reset(const VecEnv& env) {
  for (const auto& t : terms_) t->reset(env);
}

void Composite::compute(const VecEnv& env, std::span<const double> actions,
                        std::span<double> rewards) {
  for (size_t k = 0; k < terms_.size(); ++k) {
    last_[k].assign(env.num_envs(), 0);
    terms_[k]->compute(env, actions, last_[k]);
    for (int i = 0; i < env.num_envs(); ++i) rewards[i] += scale() * last_[k][i];
  }
}

void Composite::update() {
  for (const auto& t : terms_) t->update();
}

void Composite::save(const std::filesystem::path& dir) const {
  for (const auto& t : terms_) t->save(dir);
}

void Composite::load(const std::filesystem::path& dir) {
  for (const auto& t : terms_) t->load(dir);
}

std::unique_ptr<Composite> parse_intrinsic(std::string_view spec) {
  auto composite = std::make_unique<Composite>();
  while (!trim(spec).empty()) {
    const size_t comma = spec.find(',');
    const std::string_view item = trim(spec.substr(0, comma));
    spec = comma == std::string_view::npos ? std::string_view() : spec.substr(comma + 1);
    const size_t colon = item.find(':');
    const std::string_view name = trim(item.substr(0, colon));
    double weight = 1;
    if (colon != std::string_view::npos) {
      const std::string_view text = trim(item.substr(colon + 1));
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), weight);
      if (text.empty() || ec != std::errc() || end != text.data() + text.size() ||
          !std::isfinite(weight)) {
        throw UserError("intrinsic reward '" + std::string(name) + "': weight '" +
                        std::string(text) + "' is not a number (expected name[:weight],...)");
      }
    }
    composite->add(make_intrinsic(name, weight));
  }
  return composite;
}

namespace detail {

int key_index(const VecEnv& env, std::string_view key) {
  const auto& entries = env.observation_space().entries;
  for (int k = 0; k < static_cast<int>(entries.size()); ++k) {
    if (entries[k].first == key) return k;
  }
  return -1;
}

void EpisodeStarts::record_flags(const VecEnv& env) {
  const auto terminated = env.terminated();
  const auto truncated = env.truncated();
  for (int i = 0; i < env.num_envs(); ++i) starts_[env.env_id(i)] = terminated[i] || truncated[i];
}

}  // namespace detail

}  // namespace cradle::learn::intrinsic
