// The flatmarch command line as a function, so that a test program can run it too (as a worker
// of its own supervised runs: reports/supervise.hpp).
#include <algorithm>
#include <cstdio>
#include <exception>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "reports/supervise.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

int run(int argc, char** argv, std::vector<std::string> self) {
  set_self_command(std::move(self), argc, argv);
  CLI::App app{
      "flatmarch renders flat surfaces (translation surfaces, unfolded polyhedra, mirror rooms,\n"
      "translation prisms) as rooms you walk through, by ray marching, and measures every\n"
      "renderer against an exact oracle. Scenes are JSON files (see scenes/ and DESIGN.md).\n",
      "flatmarch"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every subcommand");
  add_inspect(app);
  add_render(app);
  add_trace(app);
  add_backends(app);
  add_plan(app);
  add_gallery(app);
  add_import_peer(app);
  add_shader(app);
  add_export_web(app);
  add_view(app);
  add_conform(app);
  add_merge(app);
  add_report(app);
  add_select(app);
  add_sweep(app);
  add_history(app);
  // CLI11 would only say that a subcommand is required.
  const auto subcommands = app.get_subcommands([](const CLI::App*) { return true; });
  const auto known = [&](const char* name) {
    return std::any_of(subcommands.begin(), subcommands.end(),
                       [&](const CLI::App* c) { return c->check_name(name); });
  };
  if (argc > 1 && argv[1][0] != '-' && !known(argv[1])) {
    std::fprintf(stderr, "error: unknown command \"%s\"; run `flatmarch --help` for the commands\n",
                 argv[1]);
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr,
                 "error: %s\nRun `flatmarch --help` or `flatmarch COMMAND --help` for usage.\n",
                 e.what());
    return 2;
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const ConformanceFailure& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  } catch (const UnavailableError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 3;
  } catch (const reports::Interrupted& e) {
    return 128 + e.signal;  // 130 (SIGINT), 143 (SIGTERM): the command said how to resume
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace flatmarch::cli
