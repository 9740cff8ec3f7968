// `cradle sami`: commands run and wrong input is a one-line error with exit status 1.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace {

struct Output {
  std::string text;
  int status = -1;
};

Output run(const std::string& args) {
  const std::string cmd = std::string(CRADLE_BINARY) + " " + args + " 2>&1";
  Output out;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof(buf), pipe)) out.text.append(buf, n);
  const int raw = pclose(pipe);
  out.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return out;
}

TEST(SamiCli, InfoAndRandomRun) {
  const Output info = run("sami info --env PandaPush");
  EXPECT_EQ(info.status, 0) << info.text;
  EXPECT_NE(info.text.find("cell friction 30, cube mass 30"), std::string::npos);
  const Output random =
      run("sami random --env CrippleAnt --split extreme --episodes 2 --max-steps 5 --seed 1");
  EXPECT_EQ(random.status, 0) << random.text;
  EXPECT_NE(random.text.find("episode 1: return"), std::string::npos);
}

TEST(SamiCli, WrongInputIsOneLineError) {
  for (const char* args : {"sami random --env Cheetah", "sami random --env Ant --split hard",
                           "sami bench --env Nope", "sami random --split missing.yml"}) {
    const Output out = run(args);
    EXPECT_EQ(out.status, 1) << args;
    EXPECT_EQ(out.text.rfind("cradle: error: ", 0), 0u) << out.text;
    EXPECT_EQ(out.text.find('\n'), out.text.size() - 1) << out.text;
  }
}

}  // namespace
