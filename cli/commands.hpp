// The subcommands of `flatmarch` (DESIGN.md section 5), one file each.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace flatmarch::cli {

// Runs the command line `argv` (argv[0] the program's name) and returns its exit status. `self`:
// the command that runs this command line again, for the workers of supervised runs (the
// flatmarch program: itself; a test program: itself and the argument that makes it a CLI).
int run(int argc, char** argv, std::vector<std::string> self);
// This program's own file (/proc/self/exe), else `argv0`.
std::string this_program(const char* argv0);

void add_inspect(CLI::App& app);
void add_render(CLI::App& app);
void add_trace(CLI::App& app);
void add_backends(CLI::App& app);
void add_gallery(CLI::App& app);
void add_plan(CLI::App& app);
void add_import_peer(CLI::App& app);
void add_shader(CLI::App& app);
void add_export_web(CLI::App& app);
void add_view(CLI::App& app);
void add_conform(CLI::App& app);
void add_merge(CLI::App& app);
void add_report(CLI::App& app);
void add_select(CLI::App& app);
void add_sweep(CLI::App& app);
void add_history(CLI::App& app);

}  // namespace flatmarch::cli
