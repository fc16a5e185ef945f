#include "viewer/glfw_api.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "output/dynamic_library.hpp"

namespace flatmarch::viewer {

namespace {

GlfwApi load() {
  static const DynamicLibrary library({"libglfw.so.3"}, "GLFW (Debian: libglfw3)");
  GlfwApi api;
#define FLATMARCH_GLFW_LOAD(name) \
  api.name = library.function<decltype(&::glfw##name)>("glfw" #name);
  FLATMARCH_GLFW_FUNCTIONS(FLATMARCH_GLFW_LOAD)
#undef FLATMARCH_GLFW_LOAD
  return api;
}

}  // namespace

const GlfwApi& glfw() {
  static const std::pair<GlfwApi, std::string> loaded = []() {
    try {
      return std::pair<GlfwApi, std::string>(load(), "");
    } catch (const std::exception& e) {
      return std::pair<GlfwApi, std::string>(GlfwApi{}, e.what());
    }
  }();
  if (!loaded.second.empty()) throw std::runtime_error(loaded.second);
  return loaded.first;
}

}  // namespace flatmarch::viewer
