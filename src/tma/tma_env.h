// TeachMyAgent's two parametric environments, Gymnasium-shaped: a spec (observation and action
// sizes), set_environment(...) before reset() to pick the task, reset(seed) and step(action).
//   parametric-continuous-stump-tracks-v0: obs = 4 head + motor state + 10 lidars;
//   parametric-continuous-parkour-v0:      obs = 6 head + motor state + 10 lidars + 10 codes.
// Each reset builds a fresh Box2D world, so a seed and a task give bitwise-identical episodes.
#pragma once

#include <box2d/box2d.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "tma/agent.h"
#include "tma/contacts.h"
#include "tma/cppn.h"
#include "tma/lidar.h"
#include "tma/terrain.h"
#include "tma/water.h"

namespace cradle::tma {

enum class EnvId { kStumpTracks, kParkour };
// Accepts the reference ids and the short names "stump-tracks" and "parkour".
EnvId parse_env_id(std::string_view name);
std::string_view env_id_name(EnvId id);

struct TmaOptions {
  EnvId env = EnvId::kStumpTracks;
  std::string body = "old_classic_bipedal";
  std::string lidars;             // "down", "up" or "full"; empty: by body kind (Parkour)
  bool movable_creepers = false;  // Parkour
  double water_clip = 20;         // Parkour: max push force per component
  int max_episode_steps = kMaxEpisodeSteps;
  // The reference bodies' constructor arguments; unset keeps the body's own default. A body that
  // has no such argument refuses it (the reference raises a TypeError).
  std::optional<double> motors_torque;        // every body: max motor torque at |action| = 1
  std::optional<int> nb_of_bodies;            // millipede: segments, one pair of legs each (4)
  std::optional<int> nb_pairs_of_legs;        // spider (2)
  std::optional<int> nb_steps_under_water;    // walkers, climbers: steps before drowning (600)
  std::optional<int> nb_steps_outside_water;  // fish: steps before stranding (600)
  // Parkour's terrain: a user's CPPN weights (Cradle's raw float32 file, or the reference's
  // TensorFlow checkpoint prefix; empty: the shipped weights), the CPPN's input dimension (the
  // task's input_vector size), and the ceiling's start height above the ground and its least
  // height above the ground, both in CPPN units (divided by the task's terrain_cppn_scale).
  std::string cppn_weights_path;
  int input_cppn_dim = 3;
  double ceiling_offset = 200;
  double ceiling_clip_offset = 0;
};

// Sets one option of TmaOptions by its reference name (motors_torque, nb_of_bodies,
// nb_pairs_of_legs, nb_steps_under_water, nb_steps_outside_water, CPPN_weights_path,
// input_CPPN_dim, ceiling_offset, ceiling_clip_offset, lidars_type, water_clip,
// movable_creepers) from its text. Throws cradle::UserError naming the option and what it takes
// for a malformed value, and listing the options for an unknown name. Whether the body and env
// take it is checked when the env is built.
void set_option(TmaOptions& options, std::string_view name, std::string_view value);
const std::vector<std::string>& option_names();

struct TmaStep {
  double reward = 0;
  bool terminated = false;
  bool truncated = false;
  bool success = false;  // episode return so far > 230
};

// One task parameter as the CLI and Python pass it: a name and its values.
using TaskParam = std::pair<std::string, std::vector<double>>;

class TmaEnv {
 public:
  // Throws cradle::UserError for an unknown body or lidar type, or an option the body or env does
  // not take. `cppn` may be shared by many envs; when null, Parkour loads
  // options.cppn_weights_path (or the shipped weights).
  explicit TmaEnv(const TmaOptions& options, std::shared_ptr<const Cppn> cppn = nullptr);
  ~TmaEnv();
  TmaEnv(const TmaEnv&) = delete;
  TmaEnv& operator=(const TmaEnv&) = delete;

  const TmaOptions& options() const { return options_; }
  // Parkour's CPPN (null on Stump Tracks), to share with more envs of the same options.
  const std::shared_ptr<const Cppn>& cppn() const { return cppn_; }
  int observation_size() const { return static_cast<int>(obs_.size()); }
  int action_size() const { return action_size_; }

  // The task of the next reset(). Unknown names, wrong counts, NaN or out-of-range values throw
  // cradle::UserError; names not given keep their defaults (see StumpTask / ParkourTask).
  void set_environment(const std::vector<TaskParam>& params);
  void set_stump_task(const StumpTask& task);
  void set_parkour_task(const ParkourTask& task);
  const StumpTask& stump_task() const { return stump_task_; }
  const ParkourTask& parkour_task() const { return parkour_task_; }

  // A seed reseeds the env's generator; without one its stream continues.
  std::span<const double> reset(std::optional<std::uint64_t> seed = std::nullopt);
  // Throws cradle::UserError for a wrong action size or a non-finite component.
  TmaStep step(std::span<const double> action);
  std::span<const double> observation() const { return obs_; }
  double episode_return() const { return episode_return_; }
  int episode_steps() const { return steps_; }

  // Inspection (renderer, tests, benchmarks).
  b2World& world() { return *world_; }
  const b2World& world() const { return *world_; }
  const Agent& agent() const { return agent_; }
  Agent& agent() { return agent_; }
  const Scene& scene() const { return scene_; }
  const std::array<LidarReading, kLidars>& lidars() const { return lidars_; }
  LidarType lidar_type() const { return lidar_type_; }
  bool dead() const { return dead_; }
  int steps_under_water() const { return under_water_; }
  int steps_outside_water() const { return outside_water_; }
  double finish_x() const;
  // The spawn point of the agent (before a body's own offset), unrounded: every part is placed
  // from it and rounded to Box2D's floats only at the end, as the reference does.
  WorldPoint spawn() const;

 private:
  // Refuses options the body or env does not take; sets the water limits.
  void check_body_options();
  TmaStep step_raw(const double* action);
  void cast_and_observe(bool dead);

  TmaOptions options_;
  const Embodiment* body_ = nullptr;
  std::shared_ptr<const Cppn> cppn_;
  StumpTask stump_task_;
  ParkourTask parkour_task_;
  LidarType lidar_type_ = LidarType::kDown;
  double startpad_ = kStartpad;
  int action_size_ = 0;
  Rng rng_;

  std::unique_ptr<b2World> world_;
  ContactListener listener_;
  TerrainTags tags_;
  Scene scene_;
  Agent agent_;
  std::array<LidarReading, kLidars> lidars_{};
  WaterParams water_;

  std::vector<double> obs_, action_;
  std::optional<double> prev_shaping_;
  double episode_return_ = 0;
  int steps_ = 0;
  int under_water_ = 0, outside_water_ = 0;
  bool dead_ = false;
  // Steps the agent may stay under / out of water before it is dead (none: it never dies).
  std::optional<int> under_water_limit_, outside_water_limit_;
};

}  // namespace cradle::tma
