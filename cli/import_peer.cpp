#include <fstream>
#include <iostream>
#include <map>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "interop/peer_import.hpp"

namespace flatmarch::cli {

namespace {

using Json = nlohmann::ordered_json;

std::string one_line(const Json& j) {
  if (!j.is_structured()) return j.dump();
  std::string out = j.is_array() ? "[" : "{";
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it != j.begin()) out += ", ";
    if (j.is_object()) out += Json(it.key()).dump() + ": ";
    out += one_line(it.value());
  }
  return out + (j.is_array() ? "]" : "}");
}

// Indented JSON that keeps what fits on a line (a vertex, a gluing, an object) on one line, as
// the hand-written scenes do.
std::string pretty(const Json& j, size_t indent = 0) {
  constexpr size_t width = 100;
  const std::string line = one_line(j);
  if (indent > 0 && indent + line.size() <= width) return line;
  if (!j.is_structured() || j.empty()) return line;
  const std::string inner(indent + 2, ' ');
  std::string out = j.is_array() ? "[\n" : "{\n";
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it != j.begin()) out += ",\n";
    out += inner + (j.is_object() ? Json(it.key()).dump() + ": " : "") +
           pretty(it.value(), indent + 2);
  }
  return out + "\n" + std::string(indent, ' ') + (j.is_array() ? "]" : "}");
}

void write_pretty_json(const std::string& path, const Json& doc) {
  std::ofstream out(path);
  out << pretty(doc) << "\n";
  if (!out.flush()) throw UsageError("cannot write " + path);
}

}  // namespace

void add_import_peer(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "import-peer",
      "Convert a geometry of the original web app (RayMarchingFlatSurfaces; the format is "
      "described in\n"
      "tests/data/peer-geometries/README.md) into a scene. The app's point (x, y, z), y up, "
      "becomes\n"
      "(x, z, y + wallHeight) here. Prints the scene, and on stderr one line per finding: where "
      "the\n"
      "file's redundant fields (normals, translation vectors, affine maps) disagree with the maps\n"
      "derived here, and what was converted approximately, moved, dropped or ignored.");
  struct Options {
    std::string file, out, report, view = "start", name;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("FILE", o->file, "The app's geometry (JSON)")->required();
  cmd->add_option("-o,--output", o->out, "Write the scene here instead of to stdout");
  cmd->add_option("--report-json", o->report, "Also write the findings as JSON here");
  cmd->add_option("--view", o->view,
                  "The camera: start (the app's initial view) or benchmark (the view its shaders "
                  "are timed from: its start + (0.5, 0, 0.5), looking along (1, 0, 0.3))")
      ->check(CLI::IsMember({"start", "benchmark"}))
      ->capture_default_str();
  cmd->add_option("--name", o->name, "The scene's name (default: the app's id, in snake case)");
  cmd->callback([o] {
    PeerImport result = import_peer_file(o->file);
    if (o->view == "benchmark") use_benchmark_view(result.scene);
    if (!o->name.empty()) result.scene["name"] = o->name;
    if (o->out.empty())
      std::cout << pretty(result.scene) << "\n";
    else
      write_pretty_json(o->out, result.scene);
    std::map<std::string, int> counts;
    for (const PeerFinding& f : result.findings) {
      std::cerr << o->file << ": " << f.pointer << ": " << to_string(f.severity) << ": "
                << f.message << "\n";
      ++counts[to_string(f.severity)];
    }
    std::string summary;
    for (const auto& [severity, count] : counts)
      summary += (summary.empty() ? "" : ", ") + std::to_string(count) + " " + severity;
    std::cerr << o->file << ": converted to scene \"" << result.scene["name"].get<std::string>()
              << "\"" << (summary.empty() ? "" : " (" + summary + ")") << "\n";
    if (!o->report.empty())
      write_pretty_json(o->report,
                        {{"file", o->file}, {"findings", findings_json(result.findings)}});
  });
}

}  // namespace flatmarch::cli
