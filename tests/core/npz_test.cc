// Tests for the .npz writer and reader: round trips of every dtype, numpy loading our files (and
// us loading numpy's), argument errors, atomic writes and malformed input.
#include "core/npz.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"

namespace cradle {
namespace {

namespace fs = std::filesystem;
using Shape = std::vector<std::size_t>;

// A fresh folder per test, removed afterwards.
class NpzTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("cradle_npz_test_" + std::to_string(::getpid())) /
           (std::string(info->test_suite_name()) + "." + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }
  fs::path dir_;
};

std::string read_all(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_all(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary) << bytes;
}

// Runs a shell command, returning its stdout and exit status.
std::string run(const std::string& command, int& status) {
  std::string out;
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) {
    status = -1;
    return out;
  }
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, n);
  status = ::pclose(pipe);
  return out;
}

constexpr char kPython[] = "/usr/bin/python3";

bool have_numpy() {
  if (!fs::exists(kPython)) return false;
  int status = 0;
  run(std::string(kPython) + " -c 'import numpy' 2>/dev/null", status);
  return status == 0;
}

// Writes one array of each dtype (2-D, 3-D, 0-d and empty ones too) and reads them back.
void round_trip(const fs::path& file, bool compress) {
  std::vector<double> f8 = {1.5, -2.25, 3.0, 1e300, -0.0, 6.0};
  std::vector<float> f4 = {0.5f, -1.0f, 3.25f, 7.0f};
  std::vector<std::int32_t> i4 = {-2147483647 - 1, 0, 7, 2147483647};
  std::vector<std::int64_t> i8 = {-(std::int64_t{1} << 62), 1, 42};
  std::vector<std::uint8_t> u1(2 * 2 * 3);
  for (std::size_t i = 0; i < u1.size(); ++i) u1[i] = static_cast<std::uint8_t>(i * 21);
  std::vector<double> zeros(1000, 0.0);  // compresses well
  {
    NpzWriter w(file, compress);
    w.add("f8", f8, {2, 3});
    w.add("f4", f4, {4});
    w.add("i4", i4, {2, 2});
    w.add("i8", i8, {3});
    w.add("u1", u1, {2, 2, 3});
    w.add("scalar", std::span<const double>(f8.data(), 1), {});
    w.add("empty", std::span<const double>(), {0});
    w.add("empty2d", std::span<const std::int32_t>(), {0, 5});
    w.add("zeros", zeros, {10, 100});
    w.close();
  }
  auto arrays = read_npz(file);
  ASSERT_EQ(arrays.size(), 9u);
  EXPECT_EQ(arrays["f8"].descr, "<f8");
  EXPECT_EQ(arrays["f8"].shape, (Shape{2, 3}));
  EXPECT_EQ(arrays["f8"].values<double>(), f8);
  EXPECT_EQ(arrays["f4"].descr, "<f4");
  EXPECT_EQ(arrays["f4"].values<float>(), f4);
  EXPECT_EQ(arrays["i4"].descr, "<i4");
  EXPECT_EQ(arrays["i4"].shape, (Shape{2, 2}));
  EXPECT_EQ(arrays["i4"].values<std::int32_t>(), i4);
  EXPECT_EQ(arrays["i8"].descr, "<i8");
  EXPECT_EQ(arrays["i8"].values<std::int64_t>(), i8);
  EXPECT_EQ(arrays["u1"].descr, "|u1");
  EXPECT_EQ(arrays["u1"].shape, (Shape{2, 2, 3}));
  EXPECT_EQ(arrays["u1"].values<std::uint8_t>(), u1);
  EXPECT_EQ(arrays["scalar"].shape, Shape{});
  EXPECT_EQ(arrays["scalar"].values<double>(), std::vector<double>{1.5});
  EXPECT_EQ(arrays["empty"].shape, Shape{0});
  EXPECT_TRUE(arrays["empty"].bytes.empty());
  EXPECT_EQ(arrays["empty2d"].descr, "<i4");
  EXPECT_EQ(arrays["empty2d"].shape, (Shape{0, 5}));
  EXPECT_EQ(arrays["empty2d"].count(), 0u);
  EXPECT_EQ(arrays["zeros"].values<double>(), zeros);
  EXPECT_THROW(arrays["f8"].values<float>(), std::invalid_argument);
}

TEST_F(NpzTest, RoundTripsEveryDtypeCompressed) { round_trip(dir_ / "c.npz", true); }

TEST_F(NpzTest, RoundTripsEveryDtypeStored) { round_trip(dir_ / "s.npz", false); }

TEST_F(NpzTest, CompressionShrinksAndOutputIsDeterministic) {
  std::vector<double> zeros(10000, 0.0);
  for (bool compress : {true, false}) {
    for (const char* name : {"a.npz", "b.npz"}) {
      NpzWriter w(dir_ / (std::string(compress ? "c" : "s") + name), compress);
      w.add("zeros", zeros, {100, 100});
      w.add_strings("s", {"x", "yy"});
    }
  }
  EXPECT_LT(fs::file_size(dir_ / "ca.npz"), 2000u);
  EXPECT_GT(fs::file_size(dir_ / "sa.npz"), 80000u);
  EXPECT_EQ(read_all(dir_ / "ca.npz"), read_all(dir_ / "cb.npz"));
  EXPECT_EQ(read_all(dir_ / "sa.npz"), read_all(dir_ / "sb.npz"));
}

TEST_F(NpzTest, RoundTripsStrings) {
  std::vector<std::string> values = {"{\"step\": 1}", "", "abc", "\xc3\xa9t\xc3\xa9"};
  {
    NpzWriter w(dir_ / "s.npz");
    w.add_strings("info", values);
    w.add_strings("none", {});
    w.add_strings("blank", {"", ""});
  }  // the destructor writes
  auto arrays = read_npz(dir_ / "s.npz");
  EXPECT_EQ(arrays["info"].descr, "|S11");
  EXPECT_EQ(arrays["info"].shape, Shape{4});
  EXPECT_EQ(arrays["info"].strings(), values);
  EXPECT_EQ(arrays["none"].descr, "|S1");
  EXPECT_EQ(arrays["none"].shape, Shape{0});
  EXPECT_TRUE(arrays["none"].strings().empty());
  EXPECT_EQ(arrays["blank"].strings(), (std::vector<std::string>{"", ""}));
  EXPECT_THROW(arrays["info"].values<std::uint8_t>(), std::invalid_argument);
}

TEST_F(NpzTest, RejectsBadArguments) {
  NpzWriter w(dir_ / "bad.npz");
  std::vector<double> six(6);
  EXPECT_THROW(w.add("x", six, {2, 2}), std::invalid_argument);
  EXPECT_THROW(w.add("x", six, {}), std::invalid_argument);
  EXPECT_THROW(w.add("", six, {6}), std::invalid_argument);
  EXPECT_THROW(w.add("x", six, Shape(33, 1)), std::invalid_argument);
  w.add("x", six, {3, 2});
  EXPECT_THROW(w.add("x", six, {6}), std::invalid_argument);
  EXPECT_THROW(w.add_strings("x", {"a"}), std::invalid_argument);
  w.close();
  w.close();  // idempotent
  EXPECT_THROW(w.add("y", six, {6}), std::invalid_argument);
  EXPECT_EQ(read_npz(dir_ / "bad.npz").size(), 1u);
}

TEST_F(NpzTest, WritesAnEmptyArchiveAndCreatesFolders) {
  NpzWriter(dir_ / "a" / "b" / "empty.npz").close();
  EXPECT_TRUE(read_npz(dir_ / "a" / "b" / "empty.npz").empty());
}

TEST_F(NpzTest, ReplacesAnExistingFile) {
  write_all(dir_ / "old.npz", "not a zip");
  {
    NpzWriter w(dir_ / "old.npz");
    w.add("x", std::vector<std::int64_t>{5}, {1});
  }
  EXPECT_EQ(read_npz(dir_ / "old.npz")["x"].values<std::int64_t>(), std::vector<std::int64_t>{5});
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(NpzTest, FailedCloseThrowsAndLeavesNoFile) {
  std::vector<double> data(100, 1.0);
  // The parent "folder" is a regular file, so neither folder nor temp file can be made.
  write_all(dir_ / "plain", "x");
  NpzWriter blocked(dir_ / "plain" / "out.npz");
  blocked.add("x", data, {100});
  try {
    blocked.close();
    FAIL() << "close() did not throw";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("out.npz"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
  blocked.close();  // closed even after a failure: does nothing

  // The target is a folder: the temp file is written, the rename fails and the temp is removed.
  fs::create_directory(dir_ / "taken.npz");
  NpzWriter taken(dir_ / "taken.npz");
  taken.add("x", data, {10, 10});
  EXPECT_THROW(taken.close(), UserError);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"plain", "taken.npz"}));
  EXPECT_TRUE(fs::is_empty(dir_ / "taken.npz"));

  // The destructor swallows the same failure.
  EXPECT_NO_THROW({
    NpzWriter quiet(dir_ / "plain" / "quiet.npz");
    quiet.add("x", data, {100});
  });
}

TEST_F(NpzTest, RejectsBadFiles) {
  EXPECT_THROW(read_npz(dir_ / "missing.npz"), UserError);
  write_all(dir_ / "garbage.npz", std::string(100, 'g'));
  EXPECT_THROW(read_npz(dir_ / "garbage.npz"), UserError);

  std::vector<std::int32_t> data(1000);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::int32_t>(i * i);
  for (bool compress : {true, false}) {
    fs::path good = dir_ / "good.npz";
    {
      NpzWriter w(good, compress);
      w.add("x", data, {1000});
    }
    std::string bytes = read_all(good);
    write_all(dir_ / "cut.npz", bytes.substr(0, bytes.size() / 2));
    EXPECT_THROW(read_npz(dir_ / "cut.npz"), UserError);
    std::string flipped = bytes;
    flipped[200] = static_cast<char>(flipped[200] ^ 0x40);  // inside the payload
    write_all(dir_ / "flipped.npz", flipped);
    try {
      read_npz(dir_ / "flipped.npz");
      FAIL() << "a corrupted payload was accepted";
    } catch (const UserError& e) {
      EXPECT_NE(std::string(e.what()).find("flipped.npz"), std::string::npos) << e.what();
    }
  }
}

// Writes a trajectory-like file and checks what numpy.load makes of it.
void check_numpy_loads(const fs::path& file, bool compress) {
  std::vector<double> qpos(1000 * 54);
  double qpos_sum = 0;
  for (std::size_t i = 0; i < qpos.size(); ++i) {
    qpos[i] = static_cast<double>(i % 7) * 0.25 - 0.5;  // exact sums in any order
    qpos_sum += qpos[i];
  }
  std::vector<std::uint8_t> image(8 * 8 * 3);
  long image_sum = 0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    image[i] = static_cast<std::uint8_t>((i * 37) % 256);
    image_sum += image[i];
  }
  std::vector<std::int32_t> steps = {0, 1, 2, -3, 100000};
  std::vector<float> reward = {0.5f, 0.25f};
  std::vector<std::int64_t> big = {std::int64_t{1} << 40, 1};
  {
    NpzWriter w(file, compress);
    w.add("qpos", qpos, {1000, 54});
    w.add("image", image, {8, 8, 3});
    w.add("steps", steps, {5});
    w.add("reward", reward, {2, 1});
    w.add("big", big, {2});
    w.add_strings("info", {"{\"a\": 1}", "", "xyz"});
  }
  const fs::path script = file.parent_path() / "load.py";
  std::ofstream(script) << "import json, sys\n"
                           "import numpy as np\n"
                           "with np.load(sys.argv[1], allow_pickle=False) as d:\n"
                           "    for k in sorted(d.files):\n"
                           "        a = d[k]\n"
                           "        if a.dtype.kind == 'S':\n"
                           "            v = json.dumps([s.decode() for s in a.tolist()])\n"
                           "        else:\n"
                           "            v = repr(a.sum().item())\n"
                           "        print(k, a.dtype.str, tuple(a.shape), v)\n"
                           "    print('last', repr(d['qpos'][999, 53].item()))\n";
  int status = 0;
  std::string out =
      run(std::string(kPython) + " " + script.string() + " " + file.string() + " 2>&1", status);
  ASSERT_EQ(status, 0) << out;
  char expected[1024];
  std::snprintf(expected, sizeof expected,
                "big <i8 (2,) %lld\n"
                "image |u1 (8, 8, 3) %ld\n"
                "info |S8 (3,) [\"{\\\"a\\\": 1}\", \"\", \"xyz\"]\n"
                "qpos <f8 (1000, 54) %.2f\n"
                "reward <f4 (2, 1) 0.75\n"
                "steps <i4 (5,) 100000\n"
                "last %.2f\n",
                static_cast<long long>(big[0] + big[1]), image_sum, qpos_sum, qpos.back());
  EXPECT_EQ(out, expected);
}

TEST_F(NpzTest, NumpyLoadsCompressed) {
  if (!have_numpy()) GTEST_SKIP() << "no /usr/bin/python3 with numpy";
  check_numpy_loads(dir_ / "c.npz", true);
}

TEST_F(NpzTest, NumpyLoadsStored) {
  if (!have_numpy()) GTEST_SKIP() << "no /usr/bin/python3 with numpy";
  check_numpy_loads(dir_ / "s.npz", false);
}

TEST_F(NpzTest, ReadsFilesNumpyWrote) {
  if (!have_numpy()) GTEST_SKIP() << "no /usr/bin/python3 with numpy";
  for (const char* save : {"savez", "savez_compressed"}) {
    fs::path file = dir_ / (std::string(save) + ".npz");
    int status = 0;
    std::string out =
        run(std::string(kPython) + " -c \"import numpy as np; np." + save + "('" + file.string() +
                "', a=np.arange(6.0).reshape(2, 3), b=np.array([b'hi', b'']), "
                "c=np.zeros((0, 4), np.uint8), d=np.int32(7))\" 2>&1",
            status);
    ASSERT_EQ(status, 0) << out;
    auto arrays = read_npz(file);
    ASSERT_EQ(arrays.size(), 4u) << save;
    EXPECT_EQ(arrays["a"].shape, (Shape{2, 3}));
    EXPECT_EQ(arrays["a"].values<double>(), (std::vector<double>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(arrays["b"].descr, "|S2");
    EXPECT_EQ(arrays["b"].strings(), (std::vector<std::string>{"hi", ""}));
    EXPECT_EQ(arrays["c"].descr, "|u1");
    EXPECT_EQ(arrays["c"].shape, (Shape{0, 4}));
    EXPECT_EQ(arrays["d"].shape, Shape{});
    EXPECT_EQ(arrays["d"].values<std::int32_t>(), std::vector<std::int32_t>{7});
  }
}

}  // namespace
}  // namespace cradle
