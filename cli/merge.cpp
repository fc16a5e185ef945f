// `flatmarch merge`: the shards of a run, each run apart (`--shard I/N`, on a Slurm job array or
// a CI matrix), put back together (reports/shard.hpp).
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "reports/gallery.hpp"
#include "reports/report.hpp"
#include "reports/shard.hpp"
#include "reports/sweep.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;
using nlohmann::json;
using Files = std::vector<std::pair<std::string, json>>;

namespace {

// A file name's safe form: letters, digits, '-', '_' and '.', the rest '_'.
std::string file_word(const std::string& text) {
  std::string word;
  for (char c : text)
    word += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' ? c : '_';
  return word.empty() ? "machine" : word;
}

// The folder of a file named on the command line ("." for a bare name).
fs::path folder_of(const fs::path& file) {
  return file.has_parent_path() ? file.parent_path() : fs::path(".");
}

// Each shard's images (beside its results.json) into `images`.
void gather_images(const Files& files, const fs::path& images) {
  for (const auto& [file, doc] : files) {
    const fs::path from = folder_of(file) / "images";
    if (!fs::is_directory(from) || (fs::exists(images) && fs::equivalent(from, images))) continue;
    fs::create_directories(images);
    fs::copy(from, images, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  }
}

// The recommended choice's gallery, drawn here (the shards cannot: the choice needs them all);
// none, with the reason on stderr, where its scenes or backend are not here.
void draw_gallery(json& results, const std::vector<std::string>& galleries,
                  const fs::path& images) {
  try {
    std::vector<std::string> names;
    for (const json& s : results["options"]["scenes"]) names.push_back(s);
    const std::vector<Scene> scenes = load_scenes(names, galleries);
    reports::GalleryOptions g;
    std::tie(g.width, g.height) = parse_size("size", results["options"]["size"]);
    g.params.max_steps = results["options"]["max_steps"];
    g.params.max_distance = results["options"]["max_distance"];
    g.images = images;
    results["gallery"] = reports::recommended_gallery(scenes, results["recommendation"], g);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "merge: the recommended gallery is not drawn: %s\n", e.what());
  }
}

// A machine's shards of `flatmarch report`, merged into `out` with the images, the gallery, the
// regression section (and the gate), and the page.
void merge_report_shards(const Files& files, const fs::path& out, const std::string& baseline,
                         const std::vector<std::string>& galleries, bool html,
                         const std::string& python, bool one_machine) {
  json results = reports::merge_report(files);
  const fs::path images = folder_of(out) / "images";
  // A machine's page shows its images; machines compared, none (nor could one folder hold each
  // machine's frames of the same case).
  if (one_machine) gather_images(files, images);
  if (html) draw_gallery(results, galleries, images);
  results["regression"] = regression_section(results, baseline);
  write_json(out, results);
  std::fprintf(stderr, "merge: %zu shards of `flatmarch report`, %zu matrix cases; wrote %s\n",
               files.size(), results["matrix"]["cases"].size(), out.c_str());
  std::printf("%s", reports::describe_selection(results, "").c_str());
  if (html) {
    make_report_page(python, {out.string()}, folder_of(out), "");
    std::printf("merge: open %s\n", (folder_of(out) / "index.html").c_str());
  }
  if (!baseline.empty()) gate(results, baseline, folder_of(out));
}

// One whole run of `flatmarch report`, not sharded (one measured where the images could not be
// drawn, say: a GPU machine without OpenImageIO), into `out` with what is drawn here: the
// recommended gallery, the regression section (and the gate) and the page.
void finish_report(const Files& files, const fs::path& out, const std::string& baseline,
                   const std::vector<std::string>& galleries, bool html,
                   const std::string& python) {
  json results = files.front().second;
  for (const char* key : {"fingerprint", "matrix", "ranking", "recommendation"})
    if (!results.contains(key))
      throw UsageError(files.front().first + ": has no \"" + std::string(key) +
                       "\": not the results of a whole `flatmarch report`");
  const fs::path images = folder_of(out) / "images";
  gather_images(files, images);
  if (html) {
    draw_gallery(results, galleries, images);
    if (results.contains("left_out") && results.contains("gallery"))
      results["left_out"]["drawn_by_merge"] = {{"gallery",
                                                "the recommended gallery, by this "
                                                "machine's backends"},
                                               {"host", reports::machine_of(results)}};
  }
  results["regression"] = regression_section(results, baseline);
  write_json(out, results);
  std::fprintf(stderr, "merge: one whole run of `flatmarch report`, %zu matrix cases; wrote %s\n",
               results["matrix"]["cases"].size(), out.c_str());
  std::printf("%s", reports::describe_selection(results, "").c_str());
  if (html) {
    make_report_page(python, {out.string()}, folder_of(out), "");
    std::printf("merge: open %s\n", (folder_of(out) / "index.html").c_str());
  }
  if (!baseline.empty()) gate(results, baseline, folder_of(out));
}

// Shards of `flatmarch report`: one machine's merged into `out`; several kinds of machine's each
// into OUT-MACHINE.json (no gate: it judges one machine) and a page comparing them.
void merge_reports(Files docs, const fs::path& out, const std::string& baseline,
                   const std::vector<std::string>& galleries, bool html,
                   const std::string& python) {
  std::vector<Files> machines;  // the shards by machine, in the order first given
  std::vector<json> kinds;
  for (auto& doc : docs) {
    const json kind = reports::machine_of(doc.second);
    const size_t k =
        static_cast<size_t>(std::find(kinds.begin(), kinds.end(), kind) - kinds.begin());
    if (k == kinds.size()) {
      kinds.push_back(kind);
      machines.emplace_back();
    }
    machines[k].push_back(std::move(doc));
  }
  if (machines.size() == 1) {
    merge_report_shards(machines.front(), out, baseline, galleries, html, python, true);
    return;
  }
  if (!baseline.empty())
    throw UsageError("--baseline gates one machine's results: these shards come from " +
                     std::to_string(machines.size()) + " kinds of machine");
  std::vector<std::string> merged;
  for (const Files& machine : machines) {
    const json& fingerprint = machine.front().second["fingerprint"];
    const std::string host = fingerprint.value("host", "");
    const std::string word = file_word(
        host.empty() ? fingerprint.value(json::json_pointer("/cpu/model"), std::string()) : host);
    fs::path file = folder_of(out) / (out.stem().string() + "-" + word + ".json");
    for (int k = 2; std::find(merged.begin(), merged.end(), file.string()) != merged.end(); ++k)
      file =
          folder_of(out) / (out.stem().string() + "-" + word + "-" + std::to_string(k) + ".json");
    merge_report_shards(machine, file, "", galleries, false, python, false);
    merged.push_back(file.string());
  }
  if (html) {
    make_report_page(python, merged, folder_of(out), "");
    std::printf("merge: %zu machines compared: open %s\n", merged.size(),
                (folder_of(out) / "index.html").c_str());
  }
}

}  // namespace

void add_merge(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "merge",
      "Put the shards of a sharded run back together: the JSON each shard of `flatmarch conform\n"
      "--shard I/N`, `flatmarch sweep --shard I/N`, `flatmarch report --shard I/N` or a benchmark\n"
      "program's --shard=I/N (its --benchmark_out) wrote, into one results file with the cases in\n"
      "the run's order, as one unsharded run writes it.\n"
      "Checks that the files are the shards 1..N of one run (the same flatmarch build, machine,\n"
      "parameters and case list; none missing, none twice) and names the file and why when they\n"
      "are not (exit 2). Shards of a report also get what needs them all: the ranking, the\n"
      "recommendation and the sweep's analysis; their images gathered beside -o, the\n"
      "recommended gallery drawn, the regression gate (--baseline: exit 1 on a regression) and\n"
      "the page. Report shards from several kinds of machine merge per machine, into\n"
      "OUTPUT-MACHINE.json each and a page comparing the machines. One whole run's results.json\n"
      "(not sharded) gets the same: a run measured where the images could not be drawn (no\n"
      "OpenImageIO there) is finished here, the recommended gallery drawn by this machine's\n"
      "backends.");
  struct Options {
    std::vector<std::string> files;
    // The run's scenes, named in its results: in the gallery.
    std::vector<std::string> galleries = {data_folder("scenes")};
    std::string out, baseline, python = default_python();
    bool no_html = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("FILE", o->files, "The shards' results (JSON)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->out, "Where to write the merged results")->required();
  cmd->add_option("--baseline", o->baseline,
                  "Report shards: check the merged results against this baseline "
                  "(reports/baseline.json): exit 1 on a regression")
      ->check(CLI::ExistingFile);
  cmd->add_option("--gallery", o->galleries,
                  "Report shards: folders of the run's scenes, for the recommended gallery")
      ->capture_default_str();
  cmd->add_flag("--no-html", o->no_html, "Report shards: no gallery, no page");
  cmd->add_option("--python", o->python,
                  "python3 with matplotlib and jinja2 (env FLATMARCH_PYTHON)")
      ->capture_default_str();
  cmd->callback([o] {
    Files docs;
    for (const std::string& file : o->files) {
      std::ifstream in(file);
      std::stringstream text;
      text << in.rdbuf();
      json doc = json::parse(text.str(), nullptr, false);
      if (doc.is_discarded()) {
        // Google Benchmark writes NaN for a coefficient of variation of zeros (a counter that is
        // 0 in every repetition), which JSON has not: read as null.
        static const std::regex not_a_number(R"((:\s*)-?(NaN|nan|inf)\b)");
        doc = json::parse(std::regex_replace(text.str(), not_a_number, "$1null"), nullptr, false);
      }
      if (doc.is_discarded()) throw UsageError(file + ": not JSON");
      docs.emplace_back(file, std::move(doc));
    }
    const std::string format =
        docs.front().second.is_object() ? docs.front().second.value("format", "") : "";
    const fs::path out(o->out);
    try {
      if (format == "flatmarch-report/1" && docs.size() == 1 &&
          !docs.front().second.contains("shard")) {
        finish_report(docs, out, o->baseline, o->galleries, !o->no_html, o->python);
        return;
      }
      if (format == "flatmarch-report/1") {
        merge_reports(std::move(docs), out, o->baseline, o->galleries, !o->no_html, o->python);
        return;
      }
      if (!o->baseline.empty() || o->no_html)
        throw UsageError("--baseline and --no-html are for the shards of `flatmarch report`");
      if (reports::is_benchmark_shard(docs.front().second)) {
        const json merged = reports::merge_benchmarks(docs);
        write_json(out, merged);
        std::fprintf(stderr, "merge: %zu shards of %s, %zu runs; wrote %s\n", docs.size(),
                     merged["context"].value("executable", "a benchmark program").c_str(),
                     merged["benchmarks"].size(), o->out.c_str());
        return;
      }
      const json merged = format == "flatmarch-sweep/1" ? reports::merge_sweep(docs)
                                                        : reports::merge_conformance(docs);
      write_json(out, merged);
      std::fprintf(stderr, "merge: %zu shards, %zu %s; wrote %s\n", docs.size(),
                   merged[format == "flatmarch-sweep/1" ? "points" : "cases"].size(),
                   format == "flatmarch-sweep/1" ? "points" : "cases", o->out.c_str());
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    } catch (const json::exception& e) {
      throw UsageError(std::string("a shard's results are not as flatmarch writes them: ") +
                       e.what());
    }
  });
}

}  // namespace flatmarch::cli
