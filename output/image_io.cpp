#include "output/image_io.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "output/dynamic_library.hpp"
#include "output/image_library.hpp"

namespace flatmarch {

namespace {

// Where the module may be, in the order tried.
std::vector<std::string> module_paths() {
  std::vector<std::string> paths;
  // $FLATMARCH_MODULE_DIR set, it is the only place looked in: a test makes the module
  // unloadable so.
  if (const std::string dir = install_folder(kModuleFolder); !dir.empty())
    paths.push_back(dir + "/flatmarch_image.so");
  else
    paths.push_back(std::string(kModuleFolder.relative) +
                    "/flatmarch_image.so beside the program's folder");
  return paths;
}

const ImageLibrary* load() {
  std::string why;
  for (const std::string& path : module_paths()) {
    if (!std::filesystem::exists(path)) {
      why += "\n  " + path + ": no such file";
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);  // never closed
    if (handle == nullptr) {
      const char* e = dlerror();
      why += "\n  " + path + ": " + (e ? e : "cannot be loaded");
      continue;
    }
    const auto entry = reinterpret_cast<decltype(&flatmarch_image_library)>(
        dlsym(handle, "flatmarch_image_library"));
    const ImageLibrary* library = entry ? entry() : nullptr;
    if (library == nullptr || library->abi != kImageLibraryAbi) {
      why += "\n  " + path + ": not this build's image module (rebuild flatmarch)";
      continue;
    }
    return library;
  }
  throw std::runtime_error(
      "image input and output need flatmarch's image module (OpenImageIO), "
      "which cannot be loaded:" +
      why);
}

}  // namespace

const ImageLibrary* image_library_if_loadable(std::string* why) {
  static const std::pair<const ImageLibrary*, std::string> loaded = []() {
    try {
      return std::pair<const ImageLibrary*, std::string>(load(), "");
    } catch (const std::exception& e) {
      return std::pair<const ImageLibrary*, std::string>(nullptr, e.what());
    }
  }();
  if (why) *why = loaded.second;
  return loaded.first;
}

const ImageLibrary& image_library() {
  std::string why;
  const ImageLibrary* library = image_library_if_loadable(&why);
  if (library == nullptr) throw std::runtime_error(why);
  return *library;
}

std::filesystem::path aov_path(const std::filesystem::path& png) {
  std::filesystem::path exr = png;
  return exr.replace_extension(".exr");
}

void write_png(const Frame& frame, const std::filesystem::path& png) {
  image_library().write_png(frame, png.string());
}

void write_aov_exr(const Frame& frame, const std::filesystem::path& exr) {
  image_library().write_aov_exr(frame, exr.string());
}

Frame read_aov_exr(const std::filesystem::path& exr) {
  Frame frame;
  image_library().read_aov_exr(exr.string(), frame, nullptr);
  return frame;
}

Frame read_exr_channels(const std::filesystem::path& exr, unsigned& present) {
  Frame frame;
  image_library().read_aov_exr(exr.string(), frame, &present);
  return frame;
}

Png read_png(const std::filesystem::path& png) {
  Png image;
  image_library().read_png(png.string(), image.rgb, image.width, image.height);
  return image;
}

}  // namespace flatmarch
