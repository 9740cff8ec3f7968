// Tests for JSON-lines logs: append across reopenings, crash-truncated last lines, errors.
#include "core/jsonl.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"

namespace cradle {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A fresh folder per test, removed afterwards.
class JsonlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("cradle_jsonl_test_" + std::to_string(::getpid())) /
           info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }
  fs::path dir_;
};

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST_F(JsonlTest, AppendsAcrossReopenings) {
  fs::path file = dir_ / "logs" / "deep" / "log.jsonl";
  {
    JsonlWriter log(file);
    log.write({{"step", 0}, {"reward", 0.5}});
    log.write({{"step", 1}, {"text", "a\nb"}});
    log.flush();
    EXPECT_EQ(read_jsonl(file).size(), 2u);  // visible after flush, before closing
    log.write(json::array({1, 2, 3}));
    log.flush(/*sync=*/true);
  }
  {
    JsonlWriter log(file, /*append=*/true);
    log.write({{"step", 2}});
    log.write(42);
  }
  std::vector<json> entries = read_jsonl(file);
  ASSERT_EQ(entries.size(), 5u);
  EXPECT_EQ(entries[0]["reward"], 0.5);
  EXPECT_EQ(entries[1]["text"], "a\nb");
  EXPECT_EQ(entries[2], json::array({1, 2, 3}));
  EXPECT_EQ(entries[3]["step"], 2);
  EXPECT_EQ(entries[4], 42);
  EXPECT_EQ(read_text(file).back(), '\n');
}

TEST_F(JsonlTest, TruncatesWhenNotAppending) {
  fs::path file = dir_ / "log.jsonl";
  JsonlWriter(file).write({{"old", true}});
  JsonlWriter(file, /*append=*/false).write({{"new", true}});
  std::vector<json> entries = read_jsonl(file);
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_TRUE(entries[0].contains("new"));
}

TEST_F(JsonlTest, IgnoresATruncatedLastLine) {
  fs::path file = dir_ / "log.jsonl";
  write_text(file, "{\"a\": 1}\n\n{\"b\": 2}\n{\"c\": [1, 2");
  std::vector<json> entries = read_jsonl(file);
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[1]["b"], 2);
}

TEST_F(JsonlTest, AppendingCutsAPartialLine) {
  fs::path file = dir_ / "log.jsonl";
  std::string partial = "{\"c\": \"" + std::string(10000, 'x');  // longer than one scan block
  write_text(file, "{\"a\": 1}\n" + partial);
  JsonlWriter(file).write({{"d", 4}});
  EXPECT_EQ(read_text(file), "{\"a\": 1}\n{\"d\":4}\n");

  write_text(file, partial);  // no complete line at all
  JsonlWriter(file).write({{"d", 4}});
  EXPECT_EQ(read_text(file), "{\"d\":4}\n");
}

TEST_F(JsonlTest, AppendingKeepsAValidUnterminatedLine) {
  fs::path file = dir_ / "log.jsonl";
  write_text(file, "{\"a\": 1}\n{\"b\": 2}");
  EXPECT_EQ(read_jsonl(file).size(), 2u);
  JsonlWriter(file).write({{"c", 3}});
  std::vector<json> entries = read_jsonl(file);
  ASSERT_EQ(entries.size(), 3u);
  EXPECT_EQ(entries[1]["b"], 2);
  EXPECT_EQ(entries[2]["c"], 3);
}

TEST_F(JsonlTest, MalformedMiddleLineNamesFileAndLine) {
  fs::path file = dir_ / "bad.jsonl";
  write_text(file, "{\"a\": 1}\n{oops}\n{\"b\": 2}\n");
  try {
    read_jsonl(file);
    FAIL() << "a malformed line was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.jsonl:2:"), std::string::npos) << e.what();
  }
}

TEST_F(JsonlTest, ReportsFilesItCannotUse) {
  EXPECT_THROW(read_jsonl(dir_ / "missing.jsonl"), UserError);
  write_text(dir_ / "plain", "x");
  EXPECT_THROW(JsonlWriter(dir_ / "plain" / "log.jsonl"), UserError);
  EXPECT_THROW(JsonlWriter{dir_}, UserError);  // a folder
}

TEST_F(JsonlTest, ReplacesInvalidUtf8) {
  fs::path file = dir_ / "log.jsonl";
  JsonlWriter(file).write({{"s", std::string("a\xff")}});
  EXPECT_EQ(read_jsonl(file)[0]["s"], "a\xef\xbf\xbd");
}

}  // namespace
}  // namespace cradle
