// `flatmarch select`: the backend, method and parameters `flatmarch report` chose for this
// machine, read back from its results.
#include <cstdio>
#include <filesystem>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "reports/report.hpp"
#include "scene/load.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;
using nlohmann::json;

void add_select(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "select",
      "Print the backend, method and parameters `flatmarch report` chose for this machine, from\n"
      "its results file: the fastest backend of those that passed every conformance case (when\n"
      "none did, the fastest with a method that passed on every scene), its fastest conforming\n"
      "method, and eps and offset per surface type from the sweep.");
  struct Options {
    std::string results = "reports/out/results.json", scene;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("RESULTS", o->results, "A results file of `flatmarch report`")
      ->capture_default_str();
  cmd->add_option("--scene", o->scene,
                  "A scene file: print only the parameters for its surface type");
  cmd->callback([o] {
    if (!fs::exists(o->results))
      throw UsageError("RESULTS: no " + o->results + "; run `flatmarch report` first");
    const json results = read_json("RESULTS", o->results);
    if (!results.contains("recommendation") || !results.contains("fingerprint"))
      throw UsageError("RESULTS: " + o->results + " is not a results file of `flatmarch report`");
    const std::string type = o->scene.empty() ? "" : surface_type(load_scene(o->scene));
    std::printf("%s", reports::describe_selection(results, type).c_str());
  });
}

}  // namespace flatmarch::cli
