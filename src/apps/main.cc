// `cradle`: the command-line entry point. User errors print one line and exit 1; nothing a user
// types may crash the program.
#include <dlfcn.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <string_view>

#include "apps/commands.h"
#include "apps/interrupt.h"
#include "core/error.h"
#include "core/resources.h"

namespace {

// --help as CLI11 writes it, less three oddities: a negatable flag's name shows no "{false}"
// ("--render,--no-render"), and neither a required option nor one whose default is an empty list
// shows a default ("=[]").
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_option_name(const CLI::Option* option, bool is_positional) const override {
    std::string name = CLI::Formatter::make_option_name(option, is_positional);
    for (const std::string_view value : {"{false}", "{true}"}) {
      for (size_t at; (at = name.find(value)) != std::string::npos;) name.erase(at, value.size());
    }
    return name;
  }
  std::string make_option_opts(const CLI::Option* option) const override {
    std::string opts = CLI::Formatter::make_option_opts(option);
    const std::string& value = option->get_default_str();
    if (value == "[]" || (option->get_required() && !value.empty())) {
      // " TYPE=VALUE": the default follows the type's label.
      const std::string shown = get_label(option->get_type_name()) + "=" + value;
      if (const size_t at = opts.find(shown); at != std::string::npos) {
        opts.erase(at + shown.size() - value.size() - 1, value.size() + 1);
      }
    }
    return opts;
  }
};

}  // namespace

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
  CLI::App app{
      "Cradle: a C++ platform for research on how embodied agents learn on their own. Four env\n"
      "families: BabyBench (MIMo, the infant model, in MuJoCo: self-touch and hand regard),\n"
      "MIMo's sample tasks (reach, stand up, self-body, catch), TeachMyAgent (Box2D walkers,\n"
      "teacher curricula) and SaMI (MuJoCo robots whose physics varies between tasks). Every env\n"
      "has one id: `cradle envs` lists them, `cradle train --env ID` trains on any of them.\n"};
  // --version also names the data files this program uses: its installed copy's or the source
  // tree's.
  const auto& installed = cradle::installed_resources();
  const std::string data =
      installed ? installed->string() : std::string(CRADLE_SOURCE_DIR) + " (source tree)";
  app.set_version_flag("--version", std::string(CRADLE_VERSION) + "\ndata files: " + data);
  app.require_subcommand(1);
  // Every option's --help shows its default, in one format; subcommands inherit both when
  // created after them.
  app.option_defaults()->always_capture_default();
  app.formatter(std::make_shared<HelpFormatter>());
  // --help lists the commands by what they are for; CLI11 shows the groups in the order of their
  // first registered command, hence the order below.
  const auto group = [&app](const char* name, const char* heading) {
    app.get_subcommand(name)->group(heading);
  };
  cradle::apps::register_envs(app);
  cradle::apps::register_random(app);
  cradle::apps::register_build_scene(app);
  cradle::apps::register_model_info(app);
  cradle::apps::register_test_installation(app);
  for (const char* name : {"envs", "random", "build-scene", "model-info", "test-installation"}) {
    group(name, "Envs");
  }
  cradle::apps::register_train(app);
  cradle::apps::register_illustrate(app);
  group("train", "Train");
  group("illustrate", "Train");
  cradle::apps::register_evaluate(app);
  group("evaluate", "Evaluate");
  cradle::apps::register_tma(app);
  cradle::apps::register_tma_campaign(*app.get_subcommand("tma"));
  cradle::apps::register_sami(app);
  group("tma", "Families (reference-compatible commands)");
  group("sami", "Families (reference-compatible commands)");
  cradle::apps::register_campaign(app);
  group("campaign", "Train");
  cradle::apps::register_bench(app);
  cradle::apps::register_soak(app);
  group("bench", "Benchmarks");
  group("soak", "Benchmarks");
  cradle::apps::register_launch(app);
  group("launch", "Distributed");
  // Set last: subcommands would inherit it.
  app.footer("Run `cradle COMMAND --help` for a command's options and their defaults.");
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
