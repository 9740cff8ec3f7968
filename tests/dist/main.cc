// dist_test's main: the GoogleTest suite, or (CRADLE_DIST_WORKER set) one rank of a test's run.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "core/error.h"
#include "workers.h"

int main(int argc, char** argv) {
  if (const char* worker = std::getenv("CRADLE_DIST_WORKER")) {
    try {
      return cradle::test::run_worker(worker);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "worker error: %s\n", e.what());
      return 1;
    }
  }
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
