// `flatmarch merge`: the shards of a run, each run apart (`--shard I/N`, on a Slurm job array or
// a CI matrix), put back together (reports/shard.hpp).
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "reports/shard.hpp"

namespace flatmarch::cli {

void add_merge(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "merge",
      "Put the shards of a sharded run back together: the JSON each shard of `flatmarch conform\n"
      "--shard I/N` wrote, into one results file with the cases in the run's order, as one\n"
      "unsharded run writes it. Checks that the files are the shards 1..N of one run (the same\n"
      "flatmarch build, machine, parameters and case list; none missing, none twice) and names\n"
      "the file and why when they are not (exit 2).");
  struct Options {
    std::vector<std::string> files;
    std::string out;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("FILE", o->files, "The shards' results (JSON)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->out, "Where to write the merged results")->required();
  cmd->callback([o] {
    std::vector<std::pair<std::string, nlohmann::json>> docs;
    for (const std::string& file : o->files) {
      std::ifstream in(file);
      std::stringstream text;
      text << in.rdbuf();
      nlohmann::json doc = nlohmann::json::parse(text.str(), nullptr, false);
      if (doc.is_discarded()) throw UsageError(file + ": not JSON");
      docs.emplace_back(file, std::move(doc));
    }
    nlohmann::json merged;
    try {
      merged = reports::merge_conformance(docs);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    } catch (const nlohmann::json::exception& e) {
      throw UsageError(std::string("a shard's results are not as conform writes them: ") +
                       e.what());
    }
    std::ofstream out(o->out);
    out << merged.dump(1) << "\n";
    if (!out) throw UsageError("-o: cannot write " + o->out);
    std::fprintf(stderr, "merge: %zu shards, %zu cases; wrote %s\n", docs.size(),
                 merged["cases"].size(), o->out.c_str());
  });
}

}  // namespace flatmarch::cli
