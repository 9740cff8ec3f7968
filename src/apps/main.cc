// `cradle`: the command-line entry point. User errors print one line and exit 1; nothing a user
// types may crash the program.
#include <dlfcn.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "apps/commands.h"
#include "apps/interrupt.h"
#include "core/error.h"
#include "core/resources.h"

int main(int argc, char** argv) {
  // Mesa's software rasterizer spawns its own threads by default; at eye resolutions they only
  // slow rendering down, most of all when several envs render in parallel. A user's own
  // setting wins. Mesa reads it once, so it is set before any GL context exists.
  setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);
  // Likewise OpenBLAS (under LibTorch): its threads slow the small networks by ~30% while the env
  // workers keep the cores busy. It reads its variable when loaded, so it is told directly.
  if (!std::getenv("OPENBLAS_NUM_THREADS")) {
    using SetThreads = void (*)(int);
    if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) {
      set(1);
    }
  }
  CLI::App app{"Cradle: the BabyBench infant benchmark (MIMo in MuJoCo), in C++."};
  // --version also names the data files this program uses: its installed copy's or the source
  // tree's.
  const auto& installed = cradle::installed_resources();
  const std::string data =
      installed ? installed->string() : std::string(CRADLE_SOURCE_DIR) + " (source tree)";
  app.set_version_flag("--version", std::string(CRADLE_VERSION) + "\ndata files: " + data);
  app.require_subcommand(1);
  cradle::apps::register_envs(app);
  cradle::apps::register_build_scene(app);
  cradle::apps::register_model_info(app);
  cradle::apps::register_bench(app);
  cradle::apps::register_random(app);
  cradle::apps::register_evaluate(app);
  cradle::apps::register_test_installation(app);
  cradle::apps::register_train(app);
  cradle::apps::register_illustrate(app);
  cradle::apps::register_tma(app);
  cradle::apps::register_tma_campaign(*app.get_subcommand("tma"));
  cradle::apps::register_sami(app);
  cradle::apps::register_launch(app);
  cradle::apps::register_soak(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print and succeed; a flag error is one line and exit 1.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::string message = e.what();
    for (char& ch : message) ch = ch == '\n' ? ' ' : ch;
    std::fprintf(stderr, "cradle: error: %s (see --help)\n", message.c_str());
    return 1;
  } catch (const cradle::apps::Stopped&) {
    return cradle::apps::kStoppedStatus;
  } catch (const cradle::UserError& e) {
    std::fprintf(stderr, "cradle: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cradle: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
