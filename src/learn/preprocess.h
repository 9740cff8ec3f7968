// Observation preprocessing: a Dict observation becomes one float vector (every non-image key
// flattened and concatenated, in observation order) plus one uint8 image per eye, batched over
// envs into tensors the networks read.
//
// - Touch pooling (default for the "touch" key): the skin's ~17,000 values become one number per
//   MIMo geom with sensors, the summed force magnitude over that geom's sensors (a few dozen
//   values); pool_touch = false keeps the raw skin.
// - Normalisation (default on): the vector is standardised with a running mean and variance over
//   every observation seen in training, then clipped (as SB3's VecNormalize with
//   norm_obs=True, norm_reward=False). The statistics are saved with the model. Images are only
//   scaled to [0, 1], by the networks.
#pragma once

#include <torch/torch.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/spaces.h"
#include "envs/env.h"
#include "learn/hyperparams.h"

namespace cradle::learn {

class VecEnv;
class GradSync;

struct ObservationConfig {
  bool normalize_observations = true;  // running mean/std normalisation (VecNormalize norm_obs)
  double clip_observations = 10.0;     // clip after normalising (VecNormalize clip_obs)
  bool pool_touch = true;              // touch pooled per geom instead of the raw skin
  bool policy_images = true;           // false: the networks never see image keys (rewards may)
  void bind(Hyperparameters& table);
  // Throws UserError when a checkpoint's config text (Hyperparameters::to_text) holds other
  // observation settings: its networks would read differently scaled inputs.
  void check_matches(const std::string& checkpoint_config) const;
};

// The layout env(0) publishes for its "touch" observation (null: none, or no envs).
const envs::ObservationLayout* find_touch(const VecEnv& env);

// Sums the force magnitude of each geom's sensors: one output per geom with at least one sensor
// (the layout's "geom" grouping), in ascending geom id. A sensor's magnitude is |value| with one
// value per sensor (the normal function) and the Euclidean norm of its 3 values otherwise.
class TouchPooling {
 public:
  // Throws UserError when the layout has no "geom" grouping.
  explicit TouchPooling(const envs::ObservationLayout& skin);
  int size() const { return static_cast<int>(geoms_.size()); }
  int input_size() const { return sensors_ * values_per_sensor_; }
  const std::vector<int>& geoms() const { return geoms_; }  // geom id of each output
  // raw: input_size() values (the touch observation); out: size() values.
  void pool(std::span<const float> raw, std::span<float> out) const;

 private:
  // Sensors [begin, end) all feed output `output` (a geom's sensors are contiguous).
  struct Run {
    int begin, end, output;
  };
  int values_per_sensor_;
  int sensors_ = 0;
  std::vector<int> geoms_;
  std::vector<Run> runs_;
};

// Running mean and variance of vectors, merged batch by batch (Chan et al.'s parallel update),
// in double precision. Starts at mean 0, variance 1 with a pseudo-count of epsilon (SB3's
// RunningMeanStd(epsilon=1e-4)).
class RunningMeanStd {
 public:
  static constexpr double kInitialCount = 1e-4;
  explicit RunningMeanStd(int size = 0);
  int size() const { return static_cast<int>(mean_.size()); }
  // batch: rows x size() values, row-major.
  void update(std::span<const float> batch, int rows);
  // out = clip((in - mean) / sqrt(var + kVarianceEpsilon), -clip, clip), element-wise over rows.
  void normalize(std::span<const float> in, std::span<float> out, double clip) const;
  static constexpr double kVarianceEpsilon = 1e-8;  // VecNormalize epsilon

  const std::vector<double>& mean() const { return mean_; }
  const std::vector<double>& var() const { return var_; }
  double count() const { return count_; }
  void set(std::vector<double> mean, std::vector<double> var, double count);
  // Data-parallel: every rank's observations since the last merge added to the statistics of
  // the last merge (which every rank shares), so every rank ends with the statistics of all the
  // ranks' observations. Nothing without a sync or alone.
  void merge(GradSync* sync);

 private:
  std::vector<double> mean_, var_;
  double count_ = kInitialCount;
  std::vector<double> merged_mean_, merged_var_;  // at the last merge (or set)
  double merged_count_ = kInitialCount;
  std::vector<double> sums_;                    // scratch of merge
  std::vector<double> batch_mean_, batch_var_;  // scratch
};

// Sizes of a preprocessed observation.
struct ObsShape {
  int vector_size = 0;                     // floats in the concatenated vector
  std::vector<std::array<int, 3>> images;  // (height, width, channels) of each image key
  friend bool operator==(const ObsShape&, const ObsShape&) = default;
};

// A batch of preprocessed observations: vector [B, vector_size] float32 and one
// [B, height, width, channels] uint8 tensor per image key.
struct ObsBatch {
  torch::Tensor vector;
  std::vector<torch::Tensor> images;

  static ObsBatch zeros(const ObsShape& shape, long rows);
  long rows() const { return vector.size(0); }
  // Rows `index` (a 1-D int64 tensor) of every tensor.
  ObsBatch select(const torch::Tensor& index) const;
  // Rows [begin, end) as views.
  ObsBatch slice(long begin, long end) const;
  // Copies `source` (same shapes) into rows [begin, begin + source.rows()).
  void assign(long begin, const ObsBatch& source);
};

// Dict observation -> ObsBatch rows, with touch pooling and normalisation. Keys: uint8 boxes of
// rank 3 are images (height, width, channels); "touch" is pooled when pool_touch is set; every
// other key is flattened into the vector.
class ObservationPipeline {
 public:
  // `touch` (the skin's layout) is required when pooling a space that has a "touch" key
  // (UserError otherwise).
  ObservationPipeline(const DictSpace& space, const ObservationConfig& config,
                      const envs::ObservationLayout* touch);
  const ObsShape& shape() const { return shape_; }
  const ObservationConfig& config() const { return config_; }
  // Writes env i's observation into row i of `out` (env.num_envs() rows). With update_stats the
  // normaliser first takes in these observations (training).
  void process(const VecEnv& env, bool update_stats, ObsBatch& out);
  // One observation into row 0 of `out`, without updating the statistics (acting, evaluation).
  void process(const envs::ObservationBuffers& observation, ObsBatch& out);
  // As process(env, ...), but `out` gets the vectors before normalisation (replay buffers keep
  // raw observations and normalise them when sampled, with the statistics of that time).
  void process_raw(const VecEnv& env, bool update_stats, ObsBatch& out);
  // Normalises raw vectors ([rows, vector_size] float32, contiguous) into `out` (same shape);
  // a copy when normalisation is off.
  void normalize(const torch::Tensor& raw, torch::Tensor& out) const;
  // The same with given statistics (a copy of normalizer(), taken while a collector thread
  // updates the pipeline's own).
  void normalize(const torch::Tensor& raw, torch::Tensor& out, const RunningMeanStd& stats) const;
  // The vector before normalisation (pooled touch included), for tests and intrinsic rewards.
  void raw_vector(const envs::ObservationBuffers& observation, std::span<float> out) const;

  const RunningMeanStd& normalizer() const { return normalizer_; }
  // Merges the normaliser's statistics over a data-parallel run's ranks (RunningMeanStd::merge).
  void merge_statistics(GradSync* sync) {
    if (config_.normalize_observations) normalizer_.merge(sync);
  }
  void save(torch::serialize::OutputArchive& archive) const;
  void load(torch::serialize::InputArchive& archive);

 private:
  struct Segment {
    int key = 0;  // index in the observation
    DType dtype = DType::kFloat64;
    int offset = 0;  // in the vector
    int size = 0;
    bool pooled = false;
  };
  void gather(const VecEnv& env, ObsBatch& out);  // raw vectors into raw_, images into out
  void finish(int rows, bool update_stats, ObsBatch& out);

  ObservationConfig config_;
  ObsShape shape_;
  std::vector<Segment> segments_;
  std::vector<int> image_keys_;
  std::vector<int> image_bytes_;
  std::unique_ptr<TouchPooling> pooling_;
  RunningMeanStd normalizer_;
  std::vector<float> raw_;  // rows x vector_size scratch
};

}  // namespace cradle::learn
