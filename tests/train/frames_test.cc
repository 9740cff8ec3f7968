// Evaluation video frames: layout, panel choice per behaviour, the touch map's colours, the
// anaglyph's channels and determinism, on the reference configs. Frames are also written as PNG
// to /tmp/cradle_frames/ for looking at.
#include "train/frames.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <vector>

#include "core/config.h"
#include "core/image.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "envs/self_touch.h"

namespace cradle::train {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr int kH = FrameComposer::kHeight, kW = FrameComposer::kWidth;
constexpr int kPanel = FrameComposer::kPanel, kCorner = FrameComposer::kCorner;

Config reference(const char* name) {
  return load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / name);
}

// A w x h block of an RGB image of width `width`, from (row, col).
Bytes crop(const Bytes& image, int width, int row, int col, int w, int h) {
  Bytes out(static_cast<size_t>(w) * h * 3);
  for (int r = 0; r < h; ++r) {
    std::copy_n(image.begin() + (static_cast<size_t>(row + r) * width + col) * 3, w * 3,
                out.begin() + static_cast<size_t>(r) * w * 3);
  }
  return out;
}
Bytes up_panel(const Bytes& frame) { return crop(frame, kW, 0, kCorner, kPanel, kPanel); }
Bytes down_panel(const Bytes& frame) { return crop(frame, kW, kPanel, kCorner, kPanel, kPanel); }
Bytes left_view(const Bytes& frame) { return crop(frame, kW, 0, 0, kCorner, kCorner); }

bool uniform(const Bytes& image) {
  for (size_t i = 3; i < image.size(); ++i) {
    if (image[i] != image[i % 3]) return false;
  }
  return true;
}

void save(const Bytes& rgb, int w, int h, const char* name) {
  write_png(model::Image{w, h, rgb}, std::filesystem::path("/tmp/cradle_frames") / name);
}

// Steps the env with zero actions.
void rest(envs::BabyBenchEnv& env, int steps) {
  const std::vector<double> zero(env.action_space().size(), 0.0);
  for (int i = 0; i < steps; ++i) env.step(zero);
}

// Milliseconds per compose, over a few frames.
double compose_ms(FrameComposer& composer, const envs::BabyBenchEnv& env, Bytes& frame) {
  constexpr int kFrames = 5;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kFrames; ++i) composer.compose(env, frame);
  const std::chrono::duration<double, std::milli> took = std::chrono::steady_clock::now() - start;
  return took.count() / kFrames;
}

// A separate renderer of one camera at the model's quality (the composer's default).
Bytes camera_view(const envs::BabyBenchEnv& env, const char* name, int size) {
  senses::CameraRenderer renderer(env.model(), kCorner, kCorner, senses::RenderQuality::model());
  Bytes out(static_cast<size_t>(size) * size * 3);
  renderer.render(env.model(), env.render_data(), mj_name2id(env.model(), mjOBJ_CAMERA, name), size,
                  size, out);
  return out;
}

TEST(FrameComposer, NoneUsesSide2AndTop) {
  Config config = reference("config_test_installation.yml");
  config.vision_active = false;
  envs::BabyBenchEnv env(envs::make_assets(config));
  env.reset(1);
  rest(env, 5);
  FrameComposer composer(env);
  EXPECT_EQ(composer.up(), FrameComposer::Panel::kSide2);
  EXPECT_EQ(composer.down(), FrameComposer::Panel::kTop);
  Bytes frame(static_cast<size_t>(kH) * kW * 3);
  composer.compose(env, frame);
  EXPECT_FALSE(uniform(left_view(frame)));
  EXPECT_FALSE(uniform(up_panel(frame)));
  EXPECT_FALSE(uniform(down_panel(frame)));
  EXPECT_EQ(left_view(frame), camera_view(env, "corner", kCorner));
  EXPECT_EQ(up_panel(frame), camera_view(env, "side2", kPanel));
  EXPECT_EQ(down_panel(frame), camera_view(env, "top", kPanel));
  // corner() alone is the frame's left view.
  Bytes corner(static_cast<size_t>(kCorner) * kCorner * 3);
  composer.corner(env, corner);
  EXPECT_EQ(corner, left_view(frame));
  std::cout << "none: " << compose_ms(composer, env, frame) << " ms per frame\n";
  save(frame, kW, kH, "none.png");
  save(corner, kCorner, kCorner, "corner.png");
}

TEST(FrameComposer, WrongSizesThrow) {
  Config config = reference("config_selftouch.yml");
  config.vision_active = false;
  envs::BabyBenchEnv env(envs::make_assets(config));
  env.reset(1);
  FrameComposer composer(env);
  Bytes small(100);
  EXPECT_THROW(composer.compose(env, small), std::invalid_argument);
  EXPECT_THROW(composer.corner(env, small), std::invalid_argument);
}

// Red: an active sensor's marker; grey: an idle sensor's (equal channels, darker than white).
bool reddish(const std::uint8_t* p) { return p[0] > p[1] + 40 && p[1] == p[2]; }
bool grayish(const std::uint8_t* p) { return p[0] == p[1] && p[1] == p[2] && p[0] < 250; }
bool yellowish(const std::uint8_t* p) { return p[0] > p[2] + 60 && std::abs(p[0] - p[1]) < 8; }
int count(const Bytes& image, bool (*test)(const std::uint8_t*)) {
  int n = 0;
  for (size_t i = 0; i < image.size(); i += 3) n += test(&image[i]);
  return n;
}

TEST(FrameComposer, SelfTouchMapShowsActiveSensors) {
  Config config = reference("config_selftouch.yml");
  config.vision_active = false;
  envs::BabyBenchEnv env(envs::make_assets(config));
  env.reset(3);
  rest(env, 20);  // lying on the mattress: back and head sensors press
  FrameComposer composer(env);
  EXPECT_EQ(composer.up(), FrameComposer::Panel::kTouches);
  EXPECT_EQ(composer.down(), FrameComposer::Panel::kTop);
  Bytes frame(static_cast<size_t>(kH) * kW * 3);
  composer.compose(env, frame);
  const Bytes map = up_panel(frame);
  EXPECT_FALSE(uniform(left_view(frame)));
  EXPECT_FALSE(uniform(map));
  EXPECT_EQ(down_panel(frame), camera_view(env, "top", kPanel));
  EXPECT_GT(count(map, reddish), 50);
  EXPECT_GT(count(map, grayish), 500);
  // The background stays white: MIMo fits in the panel with room around him.
  EXPECT_EQ(map[0], 255);
  EXPECT_EQ(map[map.size() - 1], 255);
  // Deterministic: the same state composes to the same bytes.
  Bytes again(frame.size());
  composer.compose(env, again);
  EXPECT_EQ(frame, again);
  std::cout << "self_touch: " << compose_ms(composer, env, frame) << " ms per frame\n";
  save(frame, kW, kH, "self_touch.png");
}

// Random actions until a hand touches MIMo's body: yellow contact markers show.
TEST(FrameComposer, SelfTouchMapShowsHandContacts) {
  Config config = reference("config_selftouch.yml");
  config.vision_active = false;
  envs::BabyBenchEnv env(envs::make_assets(config));
  env.reset(5);
  const auto& task = dynamic_cast<const envs::SelfTouch&>(env.task());
  std::vector<char> hand(env.model()->ngeom, 0), mimo(env.model()->ngeom, 0);
  for (int h = 0; h < 2; ++h) {
    for (int g : task.hand_geoms(h)) hand[g] = 1;
  }
  for (int g : task.mimo_geoms()) mimo[g] = 1;
  auto touching = [&] {
    const mjData* d = env.data();
    for (int i = 0; i < d->ncon; ++i) {
      const int a = d->contact[i].geom1, b = d->contact[i].geom2;
      if ((hand[a] && mimo[b]) || (hand[b] && mimo[a])) return true;
    }
    return false;
  };
  Rng rng(11);
  std::vector<double> action(env.action_space().size());
  bool found = false;
  for (int step = 0; step < 2000 && !found; ++step) {
    for (size_t i = 0; i < action.size(); ++i) {
      action[i] = rng.uniform(env.action_space().low[i], env.action_space().high[i]);
    }
    env.step(action);
    found = touching();
  }
  ASSERT_TRUE(found) << "no hand contact in 2000 random steps";
  FrameComposer composer(env);
  Bytes frame(static_cast<size_t>(kH) * kW * 3);
  composer.compose(env, frame);
  EXPECT_GT(count(up_panel(frame), yellowish), 10);
  save(frame, kW, kH, "self_touch_contact.png");
}

// Without touch the map still draws (MIMo's geoms as faint discs) instead of failing.
TEST(FrameComposer, SelfTouchMapWithoutTouch) {
  Config config = reference("config_selftouch.yml");
  config.vision_active = false;
  config.touch_active = false;
  envs::BabyBenchEnv env(envs::make_assets(config));
  env.reset(3);
  ASSERT_EQ(env.touch(), nullptr);
  FrameComposer composer(env);
  Bytes frame(static_cast<size_t>(kH) * kW * 3);
  composer.compose(env, frame);
  const Bytes map = up_panel(frame);
  EXPECT_GT(count(map, grayish), 200);
  EXPECT_EQ(count(map, reddish), 0);
  save(frame, kW, kH, "self_touch_no_touch.png");
}

TEST(FrameComposer, HandRegardAnaglyph) {
  envs::BabyBenchEnv env(envs::make_assets(reference("config_handregard.yml")));
  env.reset(2);
  rest(env, 5);
  FrameComposer composer(env);
  EXPECT_EQ(composer.up(), FrameComposer::Panel::kBinocular);
  EXPECT_EQ(composer.down(), FrameComposer::Panel::kTop);
  Bytes frame(static_cast<size_t>(kH) * kW * 3);
  composer.compose(env, frame);
  const Bytes stereo = up_panel(frame);
  EXPECT_FALSE(uniform(left_view(frame)));
  EXPECT_FALSE(uniform(stereo));
  EXPECT_EQ(down_panel(frame), camera_view(env, "top", kPanel));
  // Green and blue both carry the right eye; red differs from them where the eyes differ.
  // The eyes as the composer draws them: one pass, one read-back.
  senses::CameraRenderer renderer(env.model(), kCorner, kCorner, senses::RenderQuality::model());
  Bytes left(static_cast<size_t>(kPanel) * kPanel * 3), right(left.size());
  renderer.render_pair(
      env.model(), env.render_data(), mj_name2id(env.model(), mjOBJ_CAMERA, "eye_left"),
      mj_name2id(env.model(), mjOBJ_CAMERA, "eye_right"), kPanel, kPanel, left, right);
  auto gray = [](const Bytes& img, size_t i) {
    return static_cast<int>(0.2989 * img[i] + 0.5870 * img[i + 1] + 0.1140 * img[i + 2]);
  };
  int differ = 0;
  for (size_t i = 0; i < stereo.size(); i += 3) {
    ASSERT_EQ(stereo[i + 1], stereo[i + 2]) << "pixel " << i / 3;
    EXPECT_EQ(stereo[i], gray(left, i));
    EXPECT_EQ(stereo[i + 1], gray(right, i));
    if (gray(left, i) != gray(right, i)) {
      ++differ;
      EXPECT_NE(stereo[i], stereo[i + 1]);
    }
  }
  EXPECT_GT(differ, 1000);  // the eyes see the scene from 2 different places
  Bytes again(frame.size());
  composer.compose(env, again);
  EXPECT_EQ(frame, again);
  std::cout << "hand_regard: " << compose_ms(composer, env, frame) << " ms per frame\n";
  save(frame, kW, kH, "hand_regard.png");
}

}  // namespace
}  // namespace cradle::train
