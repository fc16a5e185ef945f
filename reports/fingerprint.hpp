// The machine a result was measured on, carried by every result file: CPU model and instruction
// sets, GPUs and drivers (OpenGL's renderer, the Vulkan device), the operating system, the
// libraries' versions and the build.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace flatmarch::reports {

nlohmann::json hardware_fingerprint();

// The report page's machine table, a label and a text a row: the CPU, what each backend says
// (BackendEntry::fingerprint_rows), the OS, the libraries and the build.
std::vector<std::pair<std::string, std::string>> fingerprint_rows(
    const nlohmann::json& fingerprint);

// One line: CPU model, cores, ISA; then what each backend says (OpenGL's renderer, the Vulkan
// device: BackendEntry::describe_machine).
std::string describe_machine(const nlohmann::json& fingerprint);

// Adds the fingerprint's fields to Google Benchmark's context ("fingerprint.cpu.model", ...), so
// that the JSON of the benchmark programs carries it too; once a process (later calls do nothing).
void add_to_benchmark_context(const nlohmann::json& fingerprint);

}  // namespace flatmarch::reports
