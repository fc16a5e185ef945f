#include "backends/vulkan/spirv.hpp"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <mutex>

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

}  // namespace flatmarch::vulkan
