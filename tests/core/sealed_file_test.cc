// Tests for sealed files: round trips, every truncation and byte flip refused with one line, and
// write errors (a file-size limit, a full tmpfs) leaving the previous file intact and no temp.
#include "core/sealed_file.h"

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"

namespace cradle {
namespace {

namespace fs = std::filesystem;

class SealedFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("cradle_sealed_test_" + std::to_string(::getpid())) /
           info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }
  fs::path dir_;
};

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

// The error of reading `file`, or "" when it reads.
std::string read_error(const fs::path& file) {
  try {
    read_sealed(file, "checkpoint");
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

Sections sample() {
  std::string binary;
  for (int i = 0; i < 300; ++i) binary += static_cast<char>(i * 7);
  return {{"learner", binary}, {"run", R"({"steps":128})"}, {"empty", ""}};
}

TEST_F(SealedFileTest, RoundTripsSectionsAndIsByteIdentical) {
  write_sealed(dir_ / "a", sample());
  write_sealed(dir_ / "b", sample());
  EXPECT_EQ(read_sealed(dir_ / "a", "checkpoint"), sample());
  EXPECT_EQ(read_text(dir_ / "a"), read_text(dir_ / "b"));
  EXPECT_FALSE(fs::exists(dir_ / "a.tmp"));
  EXPECT_EQ(crc32_of("123456789"), 0xCBF43926u);  // the CRC-32 check value
}

// Every truncation and every single-byte flip is refused with one line.
TEST_F(SealedFileTest, EveryTruncationAndByteFlipIsOneLineError) {
  write_sealed(dir_ / "good", sample());
  const std::string good = read_text(dir_ / "good");
  const fs::path bad = dir_ / "bad";
  for (size_t n = 0; n < good.size(); ++n) {
    write_text(bad, good.substr(0, n));
    const std::string error = read_error(bad);
    ASSERT_FALSE(error.empty()) << "truncated to " << n << " bytes was accepted";
    ASSERT_EQ(error.find('\n'), std::string::npos) << error;
  }
  for (size_t at = 0; at < good.size(); ++at) {
    for (const unsigned char mask : {0x01, 0x80, 0xff}) {
      std::string flipped = good;
      flipped[at] = static_cast<char>(flipped[at] ^ mask);
      write_text(bad, flipped);
      const std::string error = read_error(bad);
      ASSERT_FALSE(error.empty()) << "flip at " << at << " was accepted";
      ASSERT_EQ(error.find('\n'), std::string::npos) << error;
    }
  }
  write_text(bad, good + "x");
  EXPECT_NE(read_error(bad), "");
  EXPECT_NE(read_error(dir_ / "missing"), "");
  EXPECT_NE(read_error(dir_), "");  // a folder
}

// A write that fails part-way (here: the file-size limit, EFBIG) is one line; the earlier file
// stays and the temp file is gone. Run in a child so the limit stays there.
TEST_F(SealedFileTest, WriteErrorKeepsPreviousFileAndRemovesTemp) {
  write_sealed(dir_ / "ckpt", sample());
  const std::string before = read_text(dir_ / "ckpt");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{.rlim_cur = 4096, .rlim_max = 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      write_sealed(dir_ / "ckpt", {{"learner", std::string(100000, 'x')}});
    } catch (const UserError& e) {
      const std::string message = e.what();
      ::_exit(message.find('\n') == std::string::npos &&
                      message.find("cannot write") != std::string::npos
                  ? 0
                  : 2);
    }
    ::_exit(1);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(read_text(dir_ / "ckpt"), before);
  EXPECT_FALSE(fs::exists(dir_ / "ckpt.tmp"));
  EXPECT_THROW(write_sealed("/proc/cradle_no_such_dir/ckpt", {}), UserError);
}

// A full disk (a 64 KiB tmpfs, where this process may mount one): same guarantees, ENOSPC.
TEST_F(SealedFileTest, FullTmpfsKeepsPreviousFile) {
  const fs::path mnt = dir_ / "tmpfs";
  fs::create_directories(mnt);
  if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=64k") != 0) {
    GTEST_SKIP() << "cannot mount a tmpfs here (not root or no CAP_SYS_ADMIN)";
  }
  struct Unmount {
    const fs::path& path;
    ~Unmount() { ::umount2(path.c_str(), MNT_DETACH); }
  } unmount{mnt};
  write_sealed(mnt / "ckpt", {{"learner", std::string(20000, 'a')}});
  const std::string before = read_text(mnt / "ckpt");
  try {
    write_sealed(mnt / "ckpt", {{"learner", std::string(60000, 'b')}});
    ADD_FAILURE() << "a write past the tmpfs size succeeded";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text(mnt / "ckpt"), before);
  EXPECT_FALSE(fs::exists(mnt / "ckpt.tmp"));
}

}  // namespace
}  // namespace cradle
