// Vision: cameras rendered headless through MuJoCo's renderer. Inline models check colour, row
// order, motion, odd sizes and threads; the composed hand-regard scene checks binocular parallax,
// hand regard and that view culling leaves every pixel as MuJoCo draws it.
#include "senses/vision.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/config.h"
#include "core/error.h"
#include "scene/compose.h"
#include "senses/gl_context.h"

extern char** environ;

namespace cradle::senses {
namespace {

using Image = std::vector<std::uint8_t>;

// Two eye cameras looking along +x (image right = -y, up = +z) at a red box on a slide joint,
// with a green bar in the upper part of the view. Emissive materials: exact colours, no lights.
constexpr const char* kBoxes = R"(
<mujoco>
  <visual><headlight active="0"/></visual>
  <asset>
    <material name="red" rgba="1 0 0 1" emission="1" specular="0"/>
    <material name="green" rgba="0 1 0 1" emission="1" specular="0"/>
  </asset>
  <worldbody>
    <camera name="eye_left" pos="0 0.03 0" xyaxes="0 -1 0 0 0 1" fovy="45"/>
    <camera name="eye_right" pos="0 -0.03 0" xyaxes="0 -1 0 0 0 1" fovy="45"/>
    <body name="box" pos="1 0 0">
      <joint name="slide" type="slide" axis="0 1 0"/>
      <geom type="box" size="0.1 0.2 0.2" material="red"/>
    </body>
    <geom type="box" pos="1 0 0.33" size="0.05 0.3 0.05" material="green"/>
  </worldbody>
</mujoco>)";

scene::ModelPtr boxes_model() { return scene::compile_scene({.xml = kBoxes}); }

struct Rgb {
  int r, g, b;
};
Rgb pixel(const Image& img, int width, int row, int col) {
  const std::uint8_t* p = &img[(static_cast<size_t>(row) * width + col) * 3];
  return {p[0], p[1], p[2]};
}
bool red(Rgb c) { return c.r > 200 && c.g < 60 && c.b < 60; }
bool green(Rgb c) { return c.g > 200 && c.r < 60 && c.b < 60; }

// Fraction of pixels whose largest channel difference exceeds `tolerance`.
double changed(const Image& a, const Image& b, int tolerance = 30) {
  int n = 0;
  for (size_t p = 0; p < a.size(); p += 3) {
    int diff = 0;
    for (int c = 0; c < 3; ++c) diff = std::max(diff, std::abs(a[p + c] - b[p + c]));
    n += diff > tolerance;
  }
  return 3.0 * n / a.size();
}

// Number of distinct colours: a uniform image has one.
size_t colours(const Image& img) {
  std::vector<std::uint32_t> all;
  for (size_t p = 0; p < img.size(); p += 3) {
    all.push_back(img[p] << 16 | img[p + 1] << 8 | img[p + 2]);
  }
  std::sort(all.begin(), all.end());
  return std::unique(all.begin(), all.end()) - all.begin();
}

// Checks the boxes view of a w x h image: red centre, green top band, black bottom corner.
void expect_boxes_view(const Image& img, int w, int h) {
  EXPECT_TRUE(red(pixel(img, w, h / 2, w / 2)));
  const Rgb top = pixel(img, w, h * 5 / 64, w / 2);
  EXPECT_TRUE(green(top)) << top.r << " " << top.g << " " << top.b;
  EXPECT_FALSE(green(pixel(img, w, h - 1 - h * 5 / 64, w / 2)));
  const Rgb corner = pixel(img, w, h - 1, 0);
  EXPECT_LT(corner.r + corner.g + corner.b, 30);
}

TEST(Vision, EyesSpaceIsUint8ResByResBy3) {
  const Box space = Eyes::space_for(64);
  EXPECT_EQ(space.shape, (std::vector<int>{64, 64, 3}));
  EXPECT_EQ(space.dtype, DType::kUInt8);
  EXPECT_EQ(space.low.front(), 0);
  EXPECT_EQ(space.high.back(), 255);
}

TEST(Vision, RedBoxInTheCentreGreenBarInTheTopRows) {
  auto model = boxes_model();
  mjData* d = mj_makeData(model.get());
  mj_forward(model.get(), d);
  Eyes eyes(model.get(), 64);
  EXPECT_EQ(eyes.space(), Eyes::space_for(64));
  Image left(64 * 64 * 3), right(64 * 64 * 3);
  eyes.render(model.get(), d, left, right);
  expect_boxes_view(left, 64, 64);
  expect_boxes_view(right, 64, 64);
  mj_deleteData(d);
}

TEST(Vision, OddSizesAndSingleCameras) {
  auto model = boxes_model();
  mjData* d = mj_makeData(model.get());
  mj_forward(model.get(), d);
  CameraRenderer renderer(model.get(), 90, 70);
  for (auto [w, h] : {std::pair{50, 30}, std::pair{37, 70}, std::pair{90, 64}}) {
    Image img(static_cast<size_t>(w) * h * 3);
    renderer.render(model.get(), d, 0, w, h, img);
    expect_boxes_view(img, w, h);
  }
  Image small(10 * 10 * 3);
  EXPECT_THROW(renderer.render(model.get(), d, 0, 91, 10, small), std::invalid_argument);
  EXPECT_THROW(renderer.render(model.get(), d, 2, 10, 10, small), std::invalid_argument);
  EXPECT_THROW(renderer.render(model.get(), d, 0, 10, 9, small), std::invalid_argument);
  mj_deleteData(d);
}

TEST(Vision, ImageFollowsAMovingObjectAndLeavesTheStateAlone) {
  auto model = boxes_model();
  const mjModel* m = model.get();
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  Eyes eyes(m, 64);
  Image left0(64 * 64 * 3), right0(left0.size()), left(left0.size()), right(left0.size());
  eyes.render(m, d, left0, right0);

  d->qpos[0] = 0.3;  // slide along +y: to the left of the image
  mj_forward(m, d);
  const std::vector<mjtNum> qpos(d->qpos, d->qpos + m->nq), xpos(d->xpos, d->xpos + 3 * m->nbody);
  const mjtNum time = d->time;
  eyes.render(m, d, left, right);
  EXPECT_GT(changed(left0, left), 0.1);
  EXPECT_GT(changed(right0, right), 0.1);
  EXPECT_TRUE(red(pixel(left, 64, 32, 8)));
  EXPECT_FALSE(red(pixel(left, 64, 32, 56)));
  EXPECT_EQ(std::vector<mjtNum>(d->qpos, d->qpos + m->nq), qpos);
  EXPECT_EQ(std::vector<mjtNum>(d->xpos, d->xpos + 3 * m->nbody), xpos);
  EXPECT_EQ(d->time, time);
  mj_deleteData(d);
}

TEST(Vision, PairMatchesSingleRenders) {
  auto model = boxes_model();
  mjData* d = mj_makeData(model.get());
  d->qpos[0] = 0.12;
  mj_forward(model.get(), d);
  Eyes eyes(model.get(), 48, RenderQuality::model());
  CameraRenderer single(model.get(), 48, 48, RenderQuality::model());
  Image left(48 * 48 * 3), right(left.size()), one(left.size());
  eyes.render(model.get(), d, left, right);
  single.render(model.get(), d, 0, 48, 48, one);
  EXPECT_EQ(one, left);
  single.render(model.get(), d, 1, 48, 48, one);
  EXPECT_EQ(one, right);
  EXPECT_NE(left, right);  // the eyes sit 6 cm apart
  mj_deleteData(d);
}

TEST(Vision, EyesOnSeveralThreads) {
  auto model = boxes_model();
  const mjModel* m = model.get();
  auto check = [m](Eyes& eyes) {
    mjData* d = mj_makeData(m);
    mj_forward(m, d);
    Image left(64 * 64 * 3), right(left.size());
    for (int i = 0; i < 3; ++i) {
      eyes.render(m, d, left, right);
      expect_boxes_view(left, 64, 64);
      expect_boxes_view(right, 64, 64);
    }
    mj_deleteData(d);
  };
  // Two envs on this thread, interleaved; a third built and used on its own thread; the first
  // one then handed to another thread and back.
  Eyes a(m, 64), b(m, 64);
  check(a);
  check(b);
  check(a);
  std::thread worker([&] {
    Eyes c(m, 64);
    check(c);
  });
  worker.join();
  std::thread([&] { check(a); }).join();
  check(a);
}

// What crashed hand-regard training in libOSMesa: envs rendering on pool threads while
// another thread builds and frees contexts (the evaluation env, its video renderer). Every image
// must stay exact and nothing may crash.
TEST(Vision, ContextsComeAndGoWhileOtherThreadsRender) {
  auto model = boxes_model();
  const mjModel* m = model.get();
  std::atomic<bool> stop{false};
  std::atomic<int> renders{0}, wrong{0};
  auto render_loop = [&] {
    Eyes eyes(m, 64);
    mjData* d = mj_makeData(m);
    mj_forward(m, d);
    Image left(64 * 64 * 3), right(left.size());
    while (!stop.load()) {
      eyes.render(m, d, left, right);
      wrong += !red(pixel(left, 64, 32, 32)) || !green(pixel(right, 64, 6, 32));
      ++renders;
    }
    mj_deleteData(d);
  };
  std::thread a(render_loop), b(render_loop);
  // Contexts of two sizes built, used and freed here meanwhile.
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  Image image(96 * 96 * 3);
  for (int i = 0; i < 2; ++i) {
    CameraRenderer video(m, 96, 96, RenderQuality::model());
    video.render(m, d, 0, 96, 96, image);
    EXPECT_TRUE(red(pixel(image, 96, 48, 48)));
    Eyes eyes(m, 64);
  }
  stop = true;
  a.join();
  b.join();
  mj_deleteData(d);
  EXPECT_GT(renders.load(), 8);
  EXPECT_EQ(wrong.load(), 0);
}

TEST(Vision, UnknownBackendIsAOneLineUserError) {
  const char* old = std::getenv("CRADLE_GL");
  const std::optional<std::string> saved = old ? std::optional<std::string>(old) : std::nullopt;
  setenv("CRADLE_GL", "bogus", 1);
  try {
    GlContext::create(64, 64);
    ADD_FAILURE() << "no error for CRADLE_GL=bogus";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos);
    EXPECT_NE(message.find("bogus"), std::string::npos);
    EXPECT_NE(message.find("egl or osmesa"), std::string::npos);
  }
  auto model = boxes_model();
  EXPECT_THROW(Eyes(model.get(), 64), UserError);
  if (saved) {
    setenv("CRADLE_GL", saved->c_str(), 1);
  } else {
    unsetenv("CRADLE_GL");
  }
  EXPECT_EQ(gl_backend_from_name("egl"), GlBackend::kEgl);
  EXPECT_EQ(gl_backend_from_name("osmesa"), GlBackend::kOsmesa);
  EXPECT_EQ(gl_backend_from_name("glx"), std::nullopt);
}

// Runs in a child process (a process keeps one GL backend for life): renders the boxes through
// EGL and prints a verdict line for the parent test below.
TEST(VisionEglChild, RendersThroughEgl) {
  if (!std::getenv("CRADLE_VISION_EGL_CHILD")) GTEST_SKIP() << "runs only as a child process";
  auto model = boxes_model();
  mjData* d = mj_makeData(model.get());
  mj_forward(model.get(), d);
  try {
    Eyes eyes(model.get(), 64);
    ASSERT_EQ(eyes.renderer().context().backend(), GlBackend::kEgl);
    Image left(64 * 64 * 3), right(left.size());
    eyes.render(model.get(), d, left, right);
    expect_boxes_view(left, 64, 64);
    EXPECT_THROW(GlContext::create(GlBackend::kOsmesa, 8, 8), UserError);
    std::cout << "EGL OK: " << eyes.renderer().context().description() << std::endl;
  } catch (const UserError& e) {
    std::cout << "EGL UNAVAILABLE: " << e.what() << std::endl;
  }
  mj_deleteData(d);
}

TEST(Vision, EglBackendRendersOrSaysWhyNot) {
  int out[2];
  ASSERT_EQ(pipe(out), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, out[0]);
  std::vector<std::string> env = {"CRADLE_GL=egl", "CRADLE_VISION_EGL_CHILD=1"};
  for (char** e = environ; *e; ++e) {
    if (std::strncmp(*e, "CRADLE_GL=", 10) != 0) env.emplace_back(*e);
  }
  std::vector<char*> envp;
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  const std::string exe = std::filesystem::read_symlink("/proc/self/exe");
  std::string filter = "--gtest_filter=VisionEglChild.RendersThroughEgl";
  char* argv[] = {const_cast<char*>(exe.c_str()), filter.data(), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv, envp.data()), 0);
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  std::string output;
  char buf[4096];
  for (ssize_t n; (n = read(out[0], buf, sizeof buf)) > 0;) output.append(buf, n);
  close(out[0]);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  const size_t ok = output.find("EGL OK: ");
  const size_t no = output.find("EGL UNAVAILABLE: ");
  if (no != std::string::npos) {
    GTEST_SKIP() << output.substr(no, output.find('\n', no) - no);
  }
  ASSERT_NE(ok, std::string::npos) << output;
  std::cout << output.substr(ok, output.find('\n', ok) - ok) << "\n";
}

// The composed hand-regard scene (MIMo v2 among the cubes), head tilted to look at the rug.
class HandRegardVision : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = new scene::ModelPtr(scene::compile_scene(scene::compose_scene(
        load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_handregard.yml"))));
  }
  static void TearDownTestSuite() {
    delete model_;
    model_ = nullptr;
  }

  void SetUp() override {
    m_ = model_->get();
    d_ = mj_makeData(m_);
    pose({});
  }
  void TearDown() override { mj_deleteData(d_); }

  // qpos0, head tilted 60 degrees down, the given joints set (degrees), then mj_forward.
  void pose(std::initializer_list<std::pair<const char*, double>> joints) {
    mju_copy(d_->qpos, m_->qpos0, m_->nq);
    d_->qpos[adr("robot:head_tilt")] = 60 * mjPI / 180;
    for (auto [name, degrees] : joints) d_->qpos[adr(name)] = degrees * mjPI / 180;
    mj_forward(m_, d_);
  }
  int adr(const char* joint) const {
    const int id = mj_name2id(m_, mjOBJ_JOINT, joint);
    EXPECT_GE(id, 0) << joint;
    return m_->jnt_qposadr[id];
  }

  static scene::ModelPtr* model_;
  const mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
};
scene::ModelPtr* HandRegardVision::model_ = nullptr;

TEST_F(HandRegardVision, BinocularViewsAndHandRegard) {
  Eyes eyes(m_, 64);
  Image left(64 * 64 * 3), right(left.size()), left_hand(left.size()), right_hand(left.size());
  eyes.render(m_, d_, left, right);
  EXPECT_GT(colours(left), 50u);
  EXPECT_GT(colours(right), 50u);
  // Parallax: the eyes see the same scene from 4.9 cm apart.
  EXPECT_GT(changed(left, right, 10), 0.01);
  EXPECT_LT(changed(left, right, 10), 0.5);

  // Right arm raised, elbow bent: the right hand fills the right eye's view.
  pose({{"robot:right_shoulder_ad_ab", -80}, {"robot:right_elbow", -100}});
  eyes.render(m_, d_, left_hand, right_hand);
  const double right_change = changed(right, right_hand);
  EXPECT_GT(right_change, 0.1);
  EXPECT_GT(right_change, changed(left, left_hand));
}

TEST_F(HandRegardVision, CullingLeavesEveryPixelAsMuJoCoDrawsIt) {
  pose({{"robot:right_shoulder_ad_ab", -80}, {"robot:right_elbow", -60}});
  const int eye = mj_name2id(m_, mjOBJ_CAMERA, "eye_right");
  const int corner = mj_name2id(m_, mjOBJ_CAMERA, "corner");
  CameraRenderer renderer(m_, 64, 64, RenderQuality::model());
  Image ours(64 * 64 * 3), plain(ours.size());

  // MuJoCo alone: every geom, the model's own quality and buffer.
  auto gl = GlContext::create(64, 64);
  gl->make_current();
  mjvScene scene;
  mjv_defaultScene(&scene);
  mjv_makeScene(m_, &scene, 1000);
  mjrContext con;
  mjr_defaultContext(&con);
  mjr_makeContext(m_, &con, mjFONTSCALE_50);
  mjr_setBuffer(mjFB_OFFSCREEN, &con);
  mjvOption option;
  mjv_defaultOption(&option);
  mjvCamera camera;
  mjv_defaultCamera(&camera);
  camera.type = mjCAMERA_FIXED;
  Image bottom_up(ours.size());
  for (int cam : {eye, corner}) {
    camera.fixedcamid = cam;
    gl->make_current();
    mjv_updateScene(m_, d_, &option, nullptr, &camera, mjCAT_ALL, &scene);
    mjr_render({0, 0, 64, 64}, &scene, &con);
    mjr_readPixels(bottom_up.data(), nullptr, {0, 0, 64, 64}, &con);
    for (int row = 0; row < 64; ++row) {
      std::memcpy(&plain[row * 64 * 3], &bottom_up[(63 - row) * 64 * 3], 64 * 3);
    }
    gl->release();
    renderer.render(m_, d_, cam, 64, 64, ours);
    EXPECT_EQ(ours, plain) << "camera " << cam;
  }
  gl->make_current();
  mjr_freeContext(&con);
  mjv_freeScene(&scene);
}

TEST_F(HandRegardVision, FastPathStaysCloseToTheModelQuality) {
  pose({{"robot:right_shoulder_ad_ab", -80}, {"robot:right_elbow", -60}});
  Eyes fast(m_, 64), reference(m_, 64, RenderQuality::model());
  Image fl(64 * 64 * 3), fr(fl.size()), rl(fl.size()), rr(fl.size());
  fast.render(m_, d_, fl, fr);
  reference.render(m_, d_, rl, rr);
  // Differences are edge anti-aliasing and tessellation: a few percent of the pixels.
  EXPECT_LT(changed(fl, rl, 16), 0.08);
  EXPECT_LT(changed(fr, rr, 16), 0.08);
}

}  // namespace
}  // namespace cradle::senses
