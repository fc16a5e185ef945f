#include "backends/dynamic_library.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <system_error>

namespace flatmarch {

DynamicLibrary::DynamicLibrary(std::initializer_list<const char*> names, const std::string& what) {
  std::string tried, why;
  for (const char* name : names) {
    // RTLD_LOCAL: its symbols stay out of the global scope, so that two libraries loaded this way
    // (OSMesa and libGL both define glGetString) cannot bind each other's.
    handle_ = dlopen(name, RTLD_LAZY | RTLD_LOCAL);
    if (handle_ != nullptr) {
      name_ = name;
      return;
    }
    const char* e = dlerror();
    tried += (tried.empty() ? "" : ", ") + std::string(name);
    why = e != nullptr ? e : "unknown reason";
  }
  throw std::runtime_error(what + " cannot be loaded (tried " + tried + "): " + why);
}

void* DynamicLibrary::symbol(const char* name) const {
  return dlsym(handle_, name);
}

void DynamicLibrary::missing(const char* symbol) const {
  throw std::runtime_error(name_ + " has no " + symbol);
}

std::string program_directory() {
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string() : exe.parent_path().string();
}

}  // namespace flatmarch
