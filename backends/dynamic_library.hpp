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

}  // namespace flatmarch
