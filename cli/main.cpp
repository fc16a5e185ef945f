// flatmarch: render flat surfaces by ray marching, and measure renderers against the truth.
#include <algorithm>
#include <cstdio>
#include <exception>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "scene/load.hpp"

int main(int argc, char** argv) {
  using namespace flatmarch;
  CLI::App app{
      "flatmarch renders flat surfaces (translation surfaces, unfolded polyhedra, mirror rooms,\n"
      "translation prisms) as rooms you walk through, by ray marching, and measures every\n"
      "renderer against an exact oracle. Scenes are JSON files (see scenes/ and DESIGN.md).\n",
      "flatmarch"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every subcommand");
  cli::add_inspect(app);
  cli::add_render(app);
  cli::add_trace(app);
  cli::add_backends(app);
  cli::add_plan(app);
  cli::add_gallery(app);
  cli::add_import_peer(app);
  cli::add_shader(app);
  cli::add_export_web(app);
  cli::add_view(app);
  cli::add_conform(app);
  cli::add_merge(app);
  cli::add_report(app);
  cli::add_select(app);
  cli::add_sweep(app);
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
  } catch (const cli::UsageError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const cli::ConformanceFailure& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  } catch (const cli::UnavailableError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
