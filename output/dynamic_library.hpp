// Shared libraries opened at run time (dlopen) rather than linked: a command pays for loading a
// library (OpenImageIO with its 250 dependencies, LLVM through OSMesa, EGL, GLFW) only when it
// uses it, and a machine without one still runs everything else and is told why that part is
// unavailable. Libraries are never closed: drivers register exit handlers that must find them.
#pragma once

#include <initializer_list>
#include <stdexcept>
#include <string>

namespace flatmarch {

class DynamicLibrary {
 public:
  // Opens the first of `names` (sonames or paths) that loads. Throws std::runtime_error naming
  // `what` (what the library is for), the names tried and the loader's reason.
  DynamicLibrary(std::initializer_list<const char*> names, const std::string& what);

  // A symbol, or null when the library has none of that name.
  void* symbol(const char* name) const;
  // A function; throws std::runtime_error naming it when the library lacks it.
  template <typename F>
  F function(const char* name) const {
    void* p = symbol(name);
    if (p == nullptr) missing(name);
    return reinterpret_cast<F>(p);
  }
  const std::string& name() const { return name_; }

 private:
  [[noreturn]] void missing(const char* symbol) const;
  void* handle_ = nullptr;
  std::string name_;
};

// The directory of the running program (/proc/self/exe), "" when it cannot be read.
std::string program_directory();

// Where flatmarch's files lie beside its program, found from the program's own folder and never
// from the source tree: an installed PREFIX/bin/flatmarch has PREFIX/lib/flatmarch (the image
// module) and PREFIX/share/flatmarch (the gallery, the report's script, the baseline); a build
// tree has BUILD/lib/flatmarch and BUILD/share/flatmarch (links into the source), looked for
// from every program's folder in it (BUILD/cli, BUILD/tests, BUILD/conformance/tests).
struct InstallFolder {
  const char* relative;     // "share/flatmarch"
  const char* environment;  // "FLATMARCH_DATA_DIR": set, this folder and no other
};
inline constexpr InstallFolder kModuleFolder{"lib/flatmarch", "FLATMARCH_MODULE_DIR"};
inline constexpr InstallFolder kDataFolder{"share/flatmarch", "FLATMARCH_DATA_DIR"};
// The folder: its environment variable's, else the first of the program's folder's parent and
// the two above it that holds `relative`; "" when none does.
std::string install_folder(const InstallFolder& folder);
// `file` in the data folder (kDataFolder), or, when there is none, the reason as an error
// naming where it was looked for.
std::string data_file(const std::string& file);

}  // namespace flatmarch
