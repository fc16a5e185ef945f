#include "output/dynamic_library.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
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

std::string install_folder(const InstallFolder& folder) {
  if (const char* dir = std::getenv(folder.environment); dir != nullptr && *dir != '\0') return dir;
  const std::string exe = program_directory();
  if (exe.empty()) return {};
  std::filesystem::path up = std::filesystem::path(exe).parent_path();
  for (int level = 0; level < 3 && !up.empty(); ++level, up = up.parent_path()) {
    std::error_code error;
    if (std::filesystem::is_directory(up / folder.relative, error))
      return (up / folder.relative).string();
    if (up == up.parent_path()) break;  // the root
  }
  return {};
}

std::string data_file(const std::string& file) {
  const std::string dir = install_folder(kDataFolder);
  if (dir.empty())
    throw std::runtime_error("flatmarch's data folder (" + std::string(kDataFolder.relative) +
                             " beside the program's folder, or $" + kDataFolder.environment +
                             ") is not there: install flatmarch (cmake --install) or run it from "
                             "its build folder");
  return (std::filesystem::path(dir) / file).string();
}

}  // namespace flatmarch
