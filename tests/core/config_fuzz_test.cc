// Property test over config mutations: every mutated config (wrong types, out-of-range and
// non-finite numbers, unknown enums and keys, broken YAML syntax, random byte edits) either
// parses or is refused with one UserError line, in bounded time; the mutations known to be
// invalid are all refused. Prints the run's figures (cases, clear errors, crashes, hangs).
#include <gtest/gtest.h>
#include <time.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/error.h"

namespace cradle {
namespace {

struct Figures {
  int cases = 0, errors = 0, accepted = 0, crashes = 0, hangs = 0;
  double max_ms = 0;
};

// This thread's CPU time in ms: a runaway parse shows in it, while waiting for a core on a loaded
// machine does not (a wall-clock bound failed there for no fault of the parser).
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

// Parses one mutated text; records the outcome. Returns true when refused with a clear line.
bool run_case(const std::string& text, Figures& f, std::string& what) {
  ++f.cases;
  const double start = thread_cpu_ms();
  bool refused = false;
  try {
    parse_config(text, "fuzz.yml");
    ++f.accepted;
  } catch (const UserError& e) {
    what = e.what();
    const bool one_line = !what.empty() && what.find('\n') == std::string::npos;
    if (one_line) {
      ++f.errors;
      refused = true;
    } else {
      ++f.crashes;
      ADD_FAILURE() << "multi-line error for:\n" << text << "\n-> " << what;
    }
  } catch (const std::exception& e) {
    ++f.crashes;
    ADD_FAILURE() << "internal exception " << e.what() << " for:\n" << text;
  }
  const double ms = thread_cpu_ms() - start;
  f.max_ms = std::max(f.max_ms, ms);
  if (ms > 1000) {
    ++f.hangs;
    ADD_FAILURE() << "took " << ms << " ms for:\n" << text;
  }
  return refused;
}

// The default config's YAML with `key`'s value replaced.
std::string with_value(const std::string& base, const std::string& key, const std::string& value) {
  const size_t at = base.find("\n" + key + ": ");
  const size_t start = at == std::string::npos ? 0 : at + 1;
  const size_t colon = base.find(": ", start) + 2;
  const size_t end = base.find('\n', colon);
  return base.substr(0, colon) + value + base.substr(end);
}

TEST(ConfigFuzz, EveryMutationParsesOrIsOneLineError) {
  const std::string base = to_yaml(default_config());
  ASSERT_NO_THROW(parse_config(base, "base.yml"));
  Figures f;
  std::string what;

  // Values no key accepts (save_dir, a free string, excepted): all refused.
  const std::vector<std::string> never = {"[1, 2]", "{a: 1}", "",      "~",
                                          ".nan",   ".inf",   "-.inf", "1e999",
                                          "-1e999", "[",      "{",     "\"unterminated"};
  // Values some keys accept: parse or one line.
  const std::vector<std::string> maybe = {"abc",
                                          "\"quoted\"",
                                          "'1'",
                                          "0x10",
                                          "1_000",
                                          "99999999999999999999",
                                          "-99999999999999999999",
                                          "1.5",
                                          "-1",
                                          "0",
                                          "1",
                                          "2147483648",
                                          "-2147483649",
                                          "True",
                                          "yes",
                                          "1e-300",
                                          "1e300",
                                          "0.001",
                                          "2147483647",
                                          "100000000",
                                          "-0",
                                          "+1",
                                          "1.",
                                          ".5",
                                          "1e5",
                                          "nan",
                                          "inf",
                                          "null",
                                          "NULL",
                                          "\x01\x02",
                                          "\xff\xfe",
                                          "self_touch",
                                          "crib",
                                          "muscle",
                                          "normal",
                                          "nearest",
                                          "0.25",
                                          "0.2",
                                          "101",
                                          "4097",
                                          "15"};
  for (const std::string& key : config_keys()) {
    for (const std::string& value : never) {
      const bool refused = run_case(with_value(base, key, value), f, what);
      // save_dir takes any non-empty scalar text.
      if (key != "save_dir" || value.empty() || value == "~" || value[0] == '[' ||
          value[0] == '{') {
        EXPECT_TRUE(refused) << key << ": " << value << " accepted";
      }
    }
    for (const std::string& value : maybe) run_case(with_value(base, key, value), f, what);
  }

  // Unknown and repeated keys, non-mapping documents: refused.
  for (const std::string& text :
       {base + "no_such_key: 1\n", base + "max_episode_steps: 5\n", std::string("[1, 2, 3]\n"),
        std::string("42\n"), std::string("just text\n"), base + "---\n" + base,
        std::string("? [a]\n: 1\n"), base + "act_hands: False\nact_arms: False\n"}) {
    EXPECT_TRUE(run_case(text, f, what)) << text;
  }
  // Every act_* off: no actuated joints.
  std::string off = base;
  for (const std::string& key : config_keys()) {
    if (key.starts_with("act_")) off = with_value(off, key, "False");
  }
  EXPECT_TRUE(run_case(off, f, what));
  EXPECT_NE(what.find("no actuated joints"), std::string::npos) << what;

  // Random byte edits of the base text (syntax): parse or one line.
  std::mt19937_64 rng(2026);
  const std::string alphabet = ":-[]{}'\"#&*!|>%@`,?\t\n abcxyz0123456789.\\";
  for (int k = 0; k < 2000; ++k) {
    std::string text = base;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const size_t at = rng() % text.size();
      switch (rng() % 4) {
        case 0:
          text.erase(at, 1 + rng() % 8);
          break;
        case 1:
          text.insert(at, 1, alphabet[rng() % alphabet.size()]);
          break;
        case 2:
          text[at] = alphabet[rng() % alphabet.size()];
          break;
        default:
          text = text.substr(0, at);  // truncation
          break;
      }
      if (text.empty()) text = "x";
    }
    run_case(text, f, what);
  }
  std::printf(
      "config fuzz: %d cases, %d one-line errors, %d accepted, %d crashes, %d hangs (> 1 CPU s), "
      "slowest %.1f ms\n",
      f.cases, f.errors, f.accepted, f.crashes, f.hangs, f.max_ms);
  EXPECT_EQ(f.crashes, 0);
  EXPECT_EQ(f.hangs, 0);
}

}  // namespace
}  // namespace cradle
