// The subcommands of `flatmarch` (DESIGN.md section 5), one file each.
#pragma once

#include <CLI/CLI.hpp>

namespace flatmarch::cli {

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

}  // namespace flatmarch::cli
