#include "backends/vulkan/spirv.hpp"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/build_info.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <optional>
#include <system_error>

#include "kernels/shader_log.hpp"

namespace flatmarch::vulkan {

namespace {

// glslang keeps process-wide state (its symbol tables): set up once, kept for the process's
// life. Its compiler is not safe to run from two threads at once in this version.
std::mutex& glslang_mutex() {
  static std::mutex m;
  static std::once_flag initialised;
  std::call_once(initialised, [] { glslang::InitializeProcess(); });
  return m;
}

}  // namespace

std::vector<uint32_t> compile_compute(const std::string& source) {
  const std::lock_guard<std::mutex> lock(glslang_mutex());
  const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  glslang::TShader shader(EShLangCompute);
  const char* text = source.c_str();
  shader.setStrings(&text, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_1);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_3);
  if (!shader.parse(GetDefaultResources(), 450, false, messages))
    throw kernel::ShaderError(std::string("compute shader does not compile (glslang):\n") +
                              kernel::annotate_log(source, shader.getInfoLog()));
  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages))
    throw kernel::ShaderError(std::string("compute shader does not link (glslang):\n") +
                              program.getInfoLog());
  std::vector<uint32_t> spirv;
  spv::SpvBuildLogger logger;
  glslang::SpvOptions options;
  // SPIRV-Tools' optimiser: it merges glslang's copies of the table arrays, which makes lavapipe
  // compile a gallery scene in a tenth of the time.
  options.disableOptimizer = false;
  options.validate = true;  // SPIRV-Tools' validator: an invalid module is our bug, caught here
  glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), spirv, &logger, &options);
  if (const std::string log = logger.getAllMessages();
      spirv.empty() || log.find("error") != std::string::npos)
    throw kernel::ShaderError("compute shader does not translate to SPIR-V (glslang):\n" + log);
  return spirv;
}

namespace fs = std::filesystem;

namespace {

// The modules kept; past it the oldest go, down to three quarters (a first report writes about
// 150, a gallery scene's some 90 KB).
constexpr size_t kKeptModules = 512;

// What a module depends on besides its source: the compiler and compile_compute's options.
std::string compiler_tag() {
  return "glslang " + std::to_string(GLSLANG_VERSION_MAJOR) + "." +
         std::to_string(GLSLANG_VERSION_MINOR) + "." + std::to_string(GLSLANG_VERSION_PATCH) +
         GLSLANG_VERSION_FLAVOR + ", GLSL 450 compute, Vulkan 1.1, SPIR-V 1.3, optimised\n";
}

// 64-bit FNV-1a from `basis`: two bases give the file's name and the check inside it.
uint64_t fnv1a(const std::string& text, uint64_t basis) {
  uint64_t h = basis;
  for (const unsigned char c : text) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

// A module file: this header, then the SPIR-V words.
struct ModuleHeader {
  char magic[8] = {'f', 'm', 's', 'p', 'i', 'r', 'v', '1'};
  uint64_t source_bytes = 0;
  uint64_t check = 0;  // fnv1a of the keyed text from a second basis
};
constexpr uint64_t kNameBasis = 0xcbf29ce484222325ull, kCheckBasis = 0x84222325cbf29ce4ull;

std::optional<std::vector<uint32_t>> read_module(const fs::path& file, const ModuleHeader& want) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  ModuleHeader got;
  if (!in.read(reinterpret_cast<char*>(&got), sizeof got) ||
      std::memcmp(got.magic, want.magic, sizeof got.magic) != 0 ||
      got.source_bytes != want.source_bytes || got.check != want.check)
    return std::nullopt;
  std::error_code error;
  const uintmax_t bytes = fs::file_size(file, error);
  if (error || bytes < sizeof got + 20 || (bytes - sizeof got) % 4 != 0) return std::nullopt;
  std::vector<uint32_t> words((bytes - sizeof got) / 4);
  if (!in.read(reinterpret_cast<char*>(words.data()),
               static_cast<std::streamsize>(4 * words.size())) ||
      words[0] != 0x07230203u)  // SPIR-V's magic number
    return std::nullopt;
  return words;
}

void write_module(const fs::path& file, const ModuleHeader& header,
                  const std::vector<uint32_t>& words) {
  std::error_code error;
  fs::create_directories(file.parent_path(), error);
  if (error) return;
  // Written aside and renamed: a process reading it meanwhile sees all of it or none.
  static std::atomic<unsigned> written{0};
  const fs::path part =
      file.string() + "." + std::to_string(getpid()) + "." + std::to_string(written++) + ".part";
  {
    std::ofstream out(part, std::ios::binary);
    out.write(reinterpret_cast<const char*>(&header), sizeof header);
    out.write(reinterpret_cast<const char*>(words.data()),
              static_cast<std::streamsize>(4 * words.size()));
    if (!out) {
      out.close();
      fs::remove(part, error);
      return;
    }
  }
  fs::rename(part, file, error);
  if (error) fs::remove(part, error);
}

}  // namespace

fs::path spirv_cache_folder() {
  if (const char* on = std::getenv("FLATMARCH_SPIRV_CACHE"); on && std::string(on) == "0")
    return {};
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return fs::path(xdg) / "flatmarch" / "spirv";
  if (const char* home = std::getenv("HOME"); home && *home)
    return fs::path(home) / ".cache" / "flatmarch" / "spirv";
  return {};
}

void keep_newest_modules(const fs::path& folder, size_t most, size_t keep) {
  std::error_code error;
  std::vector<std::pair<fs::file_time_type, fs::path>> modules;
  // Stepped with an error_code: another process may remove a module meanwhile.
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    std::error_code gone;
    const fs::file_time_type used = it->last_write_time(gone);
    if (it->path().extension() == ".spv" && !gone) modules.emplace_back(used, it->path());
  }
  if (modules.size() <= most) return;
  std::sort(modules.begin(), modules.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t k = keep; k < modules.size(); ++k) fs::remove(modules[k].second, error);
}

std::vector<uint32_t> compile_compute_cached(const std::string& source) {
  const fs::path folder = spirv_cache_folder();
  if (folder.empty()) return compile_compute(source);
  const std::string keyed = compiler_tag() + source;
  ModuleHeader header;
  header.source_bytes = keyed.size();
  header.check = fnv1a(keyed, kCheckBasis);
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.spv",
                static_cast<unsigned long long>(fnv1a(keyed, kNameBasis)));
  const fs::path file = folder / name;
  if (std::optional<std::vector<uint32_t>> words = read_module(file, header)) {
    std::error_code error;  // its last use, which keep_newest_modules goes by
    fs::last_write_time(file, fs::file_time_type::clock::now(), error);
    return *words;
  }
  std::vector<uint32_t> words = compile_compute(source);
  write_module(file, header, words);
  keep_newest_modules(folder, kKeptModules, kKeptModules * 3 / 4);
  return words;
}

}  // namespace flatmarch::vulkan
