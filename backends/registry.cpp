// The registry of backends (backend.hpp): the entries this build has (built_in_backends, from
// backends/registered.cpp), then any a program adds.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "backends/backend.hpp"

namespace flatmarch {

namespace {

std::vector<BackendEntry>& registry() {
  static std::vector<BackendEntry> entries = built_in_backends();
  return entries;
}

}  // namespace

const std::vector<BackendEntry>& backend_registry() {
  return registry();
}

bool register_backend(BackendEntry entry) {
  for (const BackendEntry& e : registry())
    if (e.name == entry.name)
      throw std::logic_error("register_backend: a backend named " + entry.name + " exists");
  registry().push_back(std::move(entry));
  return true;
}

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const BackendEntry& e : registry()) names.push_back(e.name);
  return names;
}

std::vector<std::string> kernel_backend_names() {
  std::vector<std::string> names;
  for (const BackendEntry& e : registry())
    if (e.kernel) names.push_back(e.name);
  return names;
}

const BackendEntry* find_backend_entry(const std::string& name) {
  for (const BackendEntry& e : registry())
    if (e.name == name) return &e;
  return nullptr;
}

std::unique_ptr<Backend> make_backend(const std::string& name, const BackendOptions& options) {
  for (const BackendEntry& e : registry())
    if (e.name == name) return e.make(options);
  return nullptr;
}

const std::vector<std::unique_ptr<Backend>>& backends() {
  // Made as entries come: a backend registered late (an external renderer, from the command
  // line once the commands' options are made) joins the list on the next call.
  static std::vector<std::unique_ptr<Backend>> all;
  while (all.size() < registry().size()) all.push_back(registry()[all.size()].make({}));
  return all;
}

const Backend* find_backend(const std::string& name) {
  for (const auto& b : backends())
    if (b->name() == name) return b.get();
  return nullptr;
}

std::vector<std::string> cpu_backend_names() {
  std::vector<const BackendEntry*> cpu;
  for (const BackendEntry& e : registry())
    if (e.cpu_rank > 0) cpu.push_back(&e);
  std::stable_sort(cpu.begin(), cpu.end(), [](const BackendEntry* a, const BackendEntry* b) {
    return a->cpu_rank > b->cpu_rank;
  });
  std::vector<std::string> names;
  for (const BackendEntry* e : cpu) names.push_back(e->name);
  return names;
}

std::string fastest_cpu_backend(const BackendOptions& options) {
  for (const std::string& name : cpu_backend_names())
    if (make_backend(name, options)->availability().available) return name;
  return reference_cpu_backend();
}

std::string reference_cpu_backend() {
  const BackendEntry* reference = nullptr;
  for (const BackendEntry& e : registry())
    if (e.cpu_rank > 0 && (!reference || e.cpu_rank < reference->cpu_rank)) reference = &e;
  return reference ? reference->name : std::string();
}

}  // namespace flatmarch
