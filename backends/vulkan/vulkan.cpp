#include "backends/vulkan/vulkan.hpp"

// Vulkan-Hpp's RAII classes; the loader (libvulkan.so.1) is opened at run time, so that a machine
// without it still runs the other backends and is told why this one is unavailable.
#include <vulkan/vulkan_raii.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>

#ifdef FLATMARCH_SANITIZE_BUILD
#include <dlfcn.h>
#include <link.h>
#endif

#include "backends/bands.hpp"
#include "backends/kernel_trace.hpp"
#include "backends/lru_cache.hpp"
#include "backends/process_exit.hpp"
#include "backends/readback.hpp"
#include "backends/vulkan/spirv.hpp"
#include "kernels/camera.hpp"
#include "kernels/scene_shader.hpp"

namespace flatmarch {

namespace {

// Compiled pipelines kept (a pipeline is a scene, its march parameters and a variant).
constexpr size_t kPipelineCache = 16;
// How long one band may take before the device is given up on, and a whole frame in one
// submission on a software rasteriser (Banding::none), which has no watchdog and may march a
// large frame for minutes.
constexpr uint64_t kBandTimeoutNs = 120'000'000'000;
constexpr uint64_t kWholeFrameTimeoutNs = 3'600'000'000'000;
// Timestamps a submission writes: before its dispatch, after it, after the copy to staging.
constexpr uint32_t kTimestamps = 3;
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
// The storage buffers of kernels/scene_shader.hpp.
constexpr uint32_t kEventsBinding = 4, kPixelsBinding = 5,
                   kTableBinding = static_cast<uint32_t>(kernel::kTableBinding);

std::mutex& messages_mutex() {
  static std::mutex m;
  return m;
}
std::vector<std::string>& messages() {
  static std::vector<std::string> m;
  return m;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  const std::string text =
      std::string(severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning") +
      ": " + (data && data->pMessage ? data->pMessage : "(no message)");
  const std::lock_guard<std::mutex> lock(messages_mutex());
  messages().push_back(text);
  return VK_FALSE;  // the call goes on
}

size_t message_count() {
  const std::lock_guard<std::mutex> lock(messages_mutex());
  return messages().size();
}

#ifdef FLATMARCH_SANITIZE_BUILD
// Sanitizer builds keep the Vulkan loader, drivers and layers loaded once the loader has opened
// them: the loader closes them when its instance is destroyed, and LeakSanitizer can then neither
// name nor suppress (ci/lsan.supp) the allocations they keep for the life of the process.
void keep_vulkan_libraries_loaded() {
  std::vector<std::string> names;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* out) {
        // The loader (libvulkan.so.1), the drivers (libvulkan_lvp.so, ...) and the layers, by
        // file name: not this backend's own library (libflatmarch_backend_vulkan.so in a
        // sanitizer build), whose reopening glibc records in an allocation that LeakSanitizer
        // reports and, unwinding fast, cannot name.
        const std::string path = info->dlpi_name ? info->dlpi_name : "";
        const std::string name = path.substr(path.find_last_of('/') + 1);
        if (name.rfind("libvulkan", 0) == 0 || name.find("VkLayer") != std::string::npos)
          static_cast<std::vector<std::string>*>(out)->push_back(path);
        return 0;
      },
      &names);
  for (const std::string& name : names) dlopen(name.c_str(), RTLD_LAZY | RTLD_NOLOAD);
}
#endif

bool env_validation() {
  const char* v = std::getenv("FLATMARCH_VULKAN_VALIDATION");
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}

std::string version_text(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
         "." + std::to_string(VK_API_VERSION_PATCH(v));
}

const char* type_name(vk::PhysicalDeviceType t) {
  switch (t) {
    case vk::PhysicalDeviceType::eDiscreteGpu:
      return "discrete GPU";
    case vk::PhysicalDeviceType::eIntegratedGpu:
      return "integrated GPU";
    case vk::PhysicalDeviceType::eVirtualGpu:
      return "virtual GPU";
    case vk::PhysicalDeviceType::eCpu:
      return "CPU";
    default:
      return "other";
  }
}

// Which device to prefer when none is named: GPUs before the CPU.
int type_rank(vk::PhysicalDeviceType t) {
  switch (t) {
    case vk::PhysicalDeviceType::eDiscreteGpu:
      return 0;
    case vk::PhysicalDeviceType::eIntegratedGpu:
      return 1;
    case vk::PhysicalDeviceType::eVirtualGpu:
      return 2;
    case vk::PhysicalDeviceType::eCpu:
      return 3;
    default:
      return 4;
  }
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// A buffer with its own memory, mapped while it lives if its memory is host-visible.
struct Buffer {
  vk::raii::DeviceMemory memory = nullptr;  // freed after the buffer is destroyed
  vk::raii::Buffer buffer = nullptr;
  void* mapped = nullptr;
  vk::DeviceSize size = 0;
};

}  // namespace

std::vector<std::string> vulkan::validation_messages() {
  const std::lock_guard<std::mutex> lock(messages_mutex());
  return messages();
}

struct VulkanBackend::Context {
  vk::raii::Context loader;
  vk::raii::Instance instance = nullptr;
  vk::raii::DebugUtilsMessengerEXT messenger = nullptr;
  std::vector<vulkan::Device> devices;
  int chosen = -1;
  vk::raii::PhysicalDevice physical = nullptr;
  vk::PhysicalDeviceLimits limits;
  vk::PhysicalDeviceMemoryProperties memory_types;
  uint32_t queue_family = 0;
  vk::raii::Device device = nullptr;
  vk::raii::Queue queue = nullptr;
  vk::raii::CommandPool pool = nullptr;
  vk::raii::CommandBuffer commands = nullptr;
  vk::raii::Fence fence = nullptr;
  vk::raii::DescriptorSetLayout set_layout = nullptr;
  vk::raii::PipelineLayout layout = nullptr;
  vk::raii::DescriptorPool descriptor_pool = nullptr;
  vk::raii::DescriptorSet set = nullptr;
  // The pixels (written by the shader; read back directly where the device's memory is
  // host-visible and cached, else copied to `staging`), the trace's events and the scene's
  // tables where they are not baked in (kernels/scene_shader.hpp's tables_in_buffer).
  Buffer pixels, staging, events, table_buffer;
  bool read_directly = false;
  bool force_staging = false;  // BackendOptions::vk_staging
  bool software = false;       // the device is a CPU (lavapipe)
  KernelShape shape = KernelShape::software;
  // The device's clock: a pool of kTimestamps queries, its tick in ns and the bits it counts;
  // or why there is none.
  vk::raii::QueryPool timestamps = nullptr;
  double tick_ns = 1.0;
  uint64_t tick_mask = ~uint64_t{0};
  std::string no_timestamps;
  DeviceTiming timing;  // of the last frame
  std::mutex mutex;     // one frame or trace at a time
  struct CachedPipeline {
    vk::raii::Pipeline pipeline;
    double pace = 0.0;  // of its last frame (BandPacer::pace)
  };
  LruCache<std::string, CachedPipeline> pipelines{kPipelineCache};  // by their source

  std::string device_text() const {
    const vulkan::Device& d = devices[static_cast<size_t>(chosen)];
    return d.name + ", " + d.type + ", Vulkan " + d.api + (d.driver.empty() ? "" : ", " + d.driver);
  }

  // A memory type of `bits` with every flag of `required`, and as many of `preferred` as can be.
  std::optional<uint32_t> memory_type(uint32_t bits, vk::MemoryPropertyFlags required,
                                      vk::MemoryPropertyFlags preferred = {}) const {
    std::optional<uint32_t> found;
    for (uint32_t k = 0; k < memory_types.memoryTypeCount; ++k) {
      const vk::MemoryPropertyFlags flags = memory_types.memoryTypes[k].propertyFlags;
      if (!(bits & (1u << k)) || (flags & required) != required) continue;
      if ((flags & preferred) == preferred) return k;
      if (!found) found = k;
    }
    return found;
  }

  Buffer make_buffer(vk::DeviceSize size, vk::BufferUsageFlags usage,
                     vk::MemoryPropertyFlags required, vk::MemoryPropertyFlags preferred = {}) {
    Buffer b;
    b.size = size;
    b.buffer = vk::raii::Buffer(device,
                                vk::BufferCreateInfo({}, size, usage, vk::SharingMode::eExclusive));
    const vk::MemoryRequirements needs = b.buffer.getMemoryRequirements();
    const std::optional<uint32_t> type = memory_type(needs.memoryTypeBits, required, preferred);
    if (!type) throw std::runtime_error("the vulkan device has no memory type for a buffer here");
    b.memory = vk::raii::DeviceMemory(device, vk::MemoryAllocateInfo(needs.size, *type));
    b.buffer.bindMemory(*b.memory, 0);
    if (memory_types.memoryTypes[*type].propertyFlags & vk::MemoryPropertyFlagBits::eHostVisible)
      b.mapped = b.memory.mapMemory(0, VK_WHOLE_SIZE);
    return b;
  }

  // Room for `bytes` of pixels (and as much staging), and the descriptor pointing at it.
  void reserve_pixels(vk::DeviceSize bytes) {
    if (pixels.size >= bytes) return;
    // Grown by half again at least (frames of growing sizes), within what one descriptor covers.
    const vk::DeviceSize size = std::max<vk::DeviceSize>(
        bytes,
        std::min<vk::DeviceSize>(pixels.size + pixels.size / 2, limits.maxStorageBufferRange));
    const auto host = vk::MemoryPropertyFlagBits::eHostVisible |
                      vk::MemoryPropertyFlagBits::eHostCoherent |
                      vk::MemoryPropertyFlagBits::eHostCached;
    const auto usage =
        vk::BufferUsageFlagBits::eStorageBuffer | vk::BufferUsageFlagBits::eTransferSrc;
    pixels = Buffer();
    staging = Buffer();
    // Read back directly where device memory is host-visible and cached (lavapipe, integrated
    // GPUs); reading uncached memory from the CPU is slow, so a discrete GPU copies to staging.
    if (force_staging) {
      read_directly = false;
    } else {
      vk::raii::Buffer probe(device, vk::BufferCreateInfo({}, size, usage));
      read_directly = memory_type(probe.getMemoryRequirements().memoryTypeBits,
                                  vk::MemoryPropertyFlagBits::eDeviceLocal | host)
                          .has_value();
    }
    if (read_directly) {
      pixels = make_buffer(size, usage, vk::MemoryPropertyFlagBits::eDeviceLocal | host);
    } else {
      pixels = make_buffer(size, usage, vk::MemoryPropertyFlagBits::eDeviceLocal);
      staging = make_buffer(
          size, vk::BufferUsageFlagBits::eTransferDst,
          vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent,
          vk::MemoryPropertyFlagBits::eHostCached);
    }
    write_descriptors();
  }

  void reserve_events(vk::DeviceSize bytes) {
    if (events.size >= bytes) return;
    events = make_buffer(
        std::max<vk::DeviceSize>(bytes, 2 * events.size), vk::BufferUsageFlagBits::eStorageBuffer,
        vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent,
        vk::MemoryPropertyFlagBits::eHostCached);
    write_descriptors();
  }

  // The scene's tables where its frame's program, or its trace's, reads them from the table
  // buffer (kernel::table_buffer); read by the device from host-visible memory (device-local too
  // where there is such memory).
  void load_tables(const kernel::SceneTables<float>& scene, bool trace = false) {
    const std::string bytes = kernel::table_buffer(scene, trace);
    if (bytes.empty()) return;
    reserve_tables(bytes.size());
    std::memcpy(table_buffer.mapped, bytes.data(), bytes.size());
  }

  void reserve_tables(vk::DeviceSize bytes) {
    if (table_buffer.size >= bytes) return;
    table_buffer = make_buffer(
        std::max<vk::DeviceSize>(bytes, 2 * table_buffer.size),
        vk::BufferUsageFlagBits::eStorageBuffer,
        vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent,
        vk::MemoryPropertyFlagBits::eDeviceLocal);
    write_descriptors();
  }

  void write_descriptors() {
    if (!*pixels.buffer || !*events.buffer || !*table_buffer.buffer) return;
    const vk::DescriptorBufferInfo events_info(*events.buffer, 0, VK_WHOLE_SIZE);
    const vk::DescriptorBufferInfo pixels_info(*pixels.buffer, 0, VK_WHOLE_SIZE);
    const vk::DescriptorBufferInfo tables_info(*table_buffer.buffer, 0, VK_WHOLE_SIZE);
    device.updateDescriptorSets(
        {vk::WriteDescriptorSet(*set, kEventsBinding, 0, vk::DescriptorType::eStorageBuffer, {},
                                events_info),
         vk::WriteDescriptorSet(*set, kPixelsBinding, 0, vk::DescriptorType::eStorageBuffer, {},
                                pixels_info),
         vk::WriteDescriptorSet(*set, kTableBinding, 0, vk::DescriptorType::eStorageBuffer, {},
                                tables_info)},
        {});
  }

  vk::raii::Pipeline make_pipeline(const std::string& source) {
    const std::vector<uint32_t> spirv = vulkan::compile_compute_cached(source);
    const vk::raii::ShaderModule shader(device, vk::ShaderModuleCreateInfo({}, spirv));
    const vk::ComputePipelineCreateInfo info(
        {},
        vk::PipelineShaderStageCreateInfo({}, vk::ShaderStageFlagBits::eCompute, *shader, "main"),
        *layout);
    return vk::raii::Pipeline(device, nullptr, info);
  }

  CachedPipeline& pipeline(const kernel::SceneTables<float>& tables,
                           const kernel::ShaderVariant& variant) {
    const std::string source = kernel::scene_compute_shader(tables, variant);
    return pipelines.get(source, [&] { return CachedPipeline{make_pipeline(source)}; });
  }

  // Records commands with `record`, runs them and waits for them, at most `timeout_ns`.
  template <typename F>
  void run(F&& record, uint64_t timeout_ns = kBandTimeoutNs) {
    commands.reset();
    commands.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
    record(commands);
    commands.end();
    const vk::CommandBuffer buffer = *commands;
    queue.submit(vk::SubmitInfo({}, {}, buffer), *fence);
    const vk::Result waited = device.waitForFences(*fence, VK_TRUE, timeout_ns);
    if (waited == vk::Result::eTimeout)
      throw std::runtime_error("the vulkan device did not finish a dispatch in " +
                               std::to_string(timeout_ns / 1'000'000'000) + " s");
    device.resetFences(*fence);
  }

  // The seconds between timestamps `from` and `to` of the last submission (wrapping at the
  // clock's valid bits).
  double between(const std::vector<uint64_t>& ticks, uint32_t from, uint32_t to) const {
    return static_cast<double>((ticks[to] - ticks[from]) & tick_mask) * tick_ns * 1e-9;
  }
};

VulkanBackend::VulkanBackend(const BackendOptions& options)
    : options_(options), validation_(options.validation || env_validation()) {}

VulkanBackend::~VulkanBackend() {
  release_context(context_);
}

// The instance and device are made on first use, not when the backend is listed: every command
// builds the backend registry, and few run Vulkan.
VulkanBackend::Context* VulkanBackend::context() const {
  std::call_once(made_, [this] { make_context(); });
  return context_ && context_->chosen >= 0 && *context_->device ? context_.get() : nullptr;
}

namespace {

// The loader's and the driver's errors, as a reason a user can act on.
std::string reason(const vk::SystemError& e) {
  if (e.code() == vk::Result::eErrorIncompatibleDriver)
    return "the Vulkan loader finds no driver (install one: a GPU's, or Mesa's lavapipe from "
           "mesa-vulkan-drivers) (" +
           std::string(e.what()) + ")";
  return e.what();
}

}  // namespace

void VulkanBackend::make_context() const {
  std::unique_ptr<Context> c;
  try {
    c = std::make_unique<Context>();
  } catch (const std::exception& e) {
    unavailable_ = std::string("the Vulkan loader (libvulkan.so.1) cannot be loaded: ") + e.what();
    return;
  }
  try {
    std::vector<const char*> layers, extensions;
    const vk::DebugUtilsMessengerCreateInfoEXT messenger_info(
        {},
        vk::DebugUtilsMessageSeverityFlagBitsEXT::eWarning |
            vk::DebugUtilsMessageSeverityFlagBitsEXT::eError,
        vk::DebugUtilsMessageTypeFlagBitsEXT::eGeneral |
            vk::DebugUtilsMessageTypeFlagBitsEXT::eValidation |
            vk::DebugUtilsMessageTypeFlagBitsEXT::ePerformance,
        on_validation_message);
    if (validation_) {
      const auto available = c->loader.enumerateInstanceLayerProperties();
      if (std::none_of(available.begin(), available.end(), [](const vk::LayerProperties& l) {
            return std::strcmp(l.layerName.data(), kValidationLayer) == 0;
          })) {
        unavailable_ = std::string("validation is asked for, but the Vulkan layer ") +
                       kValidationLayer + " is not installed (Debian: vulkan-validationlayers)";
        return;
      }
      layers.push_back(kValidationLayer);
      extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
    const vk::ApplicationInfo app("flatmarch", 1, "flatmarch", 1, VK_API_VERSION_1_3);
    vk::InstanceCreateInfo info({}, &app, layers, extensions);
    // Chained, the messenger hears the instance's creation and destruction too.
    if (validation_) info.pNext = &messenger_info;
    c->instance = vk::raii::Instance(c->loader, info);
    if (validation_) c->messenger = c->instance.createDebugUtilsMessengerEXT(messenger_info);

    const std::vector<vk::raii::PhysicalDevice> physical = c->instance.enumeratePhysicalDevices();
    driver_loaded();  // the drivers and layers are loaded now (and again once the device is made)
#ifdef FLATMARCH_SANITIZE_BUILD
    keep_vulkan_libraries_loaded();
#endif
    for (size_t k = 0; k < physical.size(); ++k) {
      const vk::PhysicalDeviceProperties p = physical[k].getProperties();
      vulkan::Device d;
      d.index = static_cast<int>(k);
      d.name = p.deviceName.data();
      d.type = type_name(p.deviceType);
      d.api = version_text(p.apiVersion);
      if (p.apiVersion >= VK_API_VERSION_1_2) {
        const auto chain = physical[k]
                               .getProperties2<vk::PhysicalDeviceProperties2,
                                               vk::PhysicalDeviceDriverProperties>();
        const auto& driver = chain.get<vk::PhysicalDeviceDriverProperties>();
        d.driver = std::string(driver.driverName.data()) + " " + driver.driverInfo.data();
      }
      const auto families = physical[k].getQueueFamilyProperties();
      d.usable = p.apiVersion >= VK_API_VERSION_1_1 &&
                 std::any_of(families.begin(), families.end(), [](const auto& f) {
                   return static_cast<bool>(f.queueFlags & vk::QueueFlagBits::eCompute);
                 });
      c->devices.push_back(d);
    }
    std::string listed;
    for (const vulkan::Device& d : c->devices)
      listed += (listed.empty() ? "" : "; ") + std::to_string(d.index) + " " + d.name;
    if (listed.empty()) listed = "none";

    const std::string& want = options_.device;
    if (want.empty()) {
      for (const vulkan::Device& d : c->devices)
        if (d.usable &&
            (c->chosen < 0 ||
             type_rank(physical[static_cast<size_t>(d.index)].getProperties().deviceType) <
                 type_rank(physical[static_cast<size_t>(c->chosen)].getProperties().deviceType)))
          c->chosen = d.index;
    } else {
      for (const vulkan::Device& d : c->devices)
        if (std::to_string(d.index) == want ||
            lower(d.name).find(lower(want)) != std::string::npos) {
          c->chosen = d.index;
          break;
        }
    }
    if (c->chosen < 0) {
      unavailable_ =
          want.empty()
              ? "no Vulkan device with Vulkan 1.1 and a compute queue (devices: " + listed + ")"
              : "no Vulkan device matches --device \"" + want + "\" (devices: " + listed + ")";
      context_ = std::move(c);  // its device list stays readable
      return;
    }
    const vulkan::Device& chosen = c->devices[static_cast<size_t>(c->chosen)];
    if (!chosen.usable) {
      unavailable_ = "Vulkan device " + std::to_string(chosen.index) + " (" + chosen.name +
                     ") has no Vulkan 1.1 or no compute queue";
      c->chosen = -1;
      context_ = std::move(c);
      return;
    }
    c->physical = physical[static_cast<size_t>(c->chosen)];
    c->limits = c->physical.getProperties().limits;
    c->memory_types = c->physical.getMemoryProperties();
    const auto families = c->physical.getQueueFamilyProperties();
    for (uint32_t k = 0; k < families.size(); ++k)
      if (families[k].queueFlags & vk::QueueFlagBits::eCompute) {
        c->queue_family = k;
        break;
      }
    const float priority = 1.0f;
    const vk::DeviceQueueCreateInfo queue_info({}, c->queue_family, 1, &priority);
    c->device = vk::raii::Device(c->physical, vk::DeviceCreateInfo({}, queue_info));
    c->queue = c->device.getQueue(c->queue_family, 0);
    c->pool = vk::raii::CommandPool(
        c->device, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                             c->queue_family));
    c->commands = std::move(vk::raii::CommandBuffers(
        c->device,
        vk::CommandBufferAllocateInfo(*c->pool, vk::CommandBufferLevel::ePrimary, 1))[0]);
    c->fence = vk::raii::Fence(c->device, vk::FenceCreateInfo());

    const std::array<vk::DescriptorSetLayoutBinding, 3> bindings{
        vk::DescriptorSetLayoutBinding(kEventsBinding, vk::DescriptorType::eStorageBuffer, 1,
                                       vk::ShaderStageFlagBits::eCompute),
        vk::DescriptorSetLayoutBinding(kPixelsBinding, vk::DescriptorType::eStorageBuffer, 1,
                                       vk::ShaderStageFlagBits::eCompute),
        vk::DescriptorSetLayoutBinding(kTableBinding, vk::DescriptorType::eStorageBuffer, 1,
                                       vk::ShaderStageFlagBits::eCompute)};
    c->set_layout =
        vk::raii::DescriptorSetLayout(c->device, vk::DescriptorSetLayoutCreateInfo({}, bindings));
    const vk::PushConstantRange push(vk::ShaderStageFlagBits::eCompute, 0,
                                     sizeof(kernel::ComputeConstants));
    const vk::DescriptorSetLayout set_layout = *c->set_layout;
    c->layout =
        vk::raii::PipelineLayout(c->device, vk::PipelineLayoutCreateInfo({}, set_layout, push));
    const vk::DescriptorPoolSize pool_size(vk::DescriptorType::eStorageBuffer, 3);
    c->descriptor_pool = vk::raii::DescriptorPool(
        c->device, vk::DescriptorPoolCreateInfo(
                       vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, pool_size));
    c->set = std::move(vk::raii::DescriptorSets(
        c->device, vk::DescriptorSetAllocateInfo(*c->descriptor_pool, set_layout))[0]);
    c->force_staging = options_.vk_staging;
    c->software = c->physical.getProperties().deviceType == vk::PhysicalDeviceType::eCpu;
    const std::optional<KernelShape> shape = parse_kernel_shape(options_.kernel_shape, c->software);
    if (!shape) {
      unavailable_ = kernel_shape_error(options_.kernel_shape);
      return;
    }
    c->shape = *shape;
    if (const uint32_t bits = families[c->queue_family].timestampValidBits; bits == 0) {
      c->no_timestamps = "the device's compute queue keeps no timestamps (timestampValidBits 0)";
    } else {
      c->timestamps = vk::raii::QueryPool(
          c->device, vk::QueryPoolCreateInfo({}, vk::QueryType::eTimestamp, kTimestamps));
      c->tick_ns = c->limits.timestampPeriod;
      c->tick_mask = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
    }
    c->reserve_tables(4096);  // the cube's 3 KB
    c->reserve_events(shader_trace_bytes(64));
    c->reserve_pixels(64 * 64 * kWholeReadbackBytes);
    context_ = std::move(c);
    driver_loaded();  // after the driver has made its device, threads and exit handlers
  } catch (const vk::SystemError& e) {
    unavailable_ = reason(e);
  } catch (const std::exception& e) {
    unavailable_ = e.what();
  }
}

namespace {

[[noreturn]] void unavailable(const std::string& why) {
  throw std::runtime_error("the vulkan backend is unavailable: " + why);
}

void check_precision(const MarchParams& params) {
  if (params.precision != Precision::f32)
    throw std::invalid_argument(
        "the vulkan backend marches in f32 only (the scalar backend runs f64)");
}

// Fails the call if the validation layer spoke during it (or since the last check).
class ValidationCheck {
 public:
  explicit ValidationCheck(bool on) : on_(on), before_(on ? message_count() : 0) {}
  void done() const {
    if (!on_) return;
    const std::vector<std::string> all = vulkan::validation_messages();
    if (all.size() == before_) return;
    std::string text = "the vulkan validation layer reports:";
    for (size_t k = before_; k < all.size(); ++k) text += "\n  " + all[k];
    throw std::runtime_error(text);
  }

 private:
  bool on_;
  size_t before_;
};

}  // namespace

std::string VulkanBackend::description() const {
  return "the kernel as a Vulkan compute shader (glslang to SPIR-V at run time), specialised per "
         "scene (" +
         (context() ? context_->device_text() : std::string("unavailable")) + "); f32" +
         (validation_ ? "; validation layer on" : "");
}

Availability VulkanBackend::availability() const {
  if (!context()) return {false, unavailable_};
  return {};
}

std::optional<DeviceInfo> VulkanBackend::device() const {
  if (!context()) return std::nullopt;
  const vulkan::Device& d = context_->devices[static_cast<size_t>(context_->chosen)];
  return DeviceInfo{
      .name = d.name,
      .type = d.type,
      .api = "Vulkan " + d.api,
      .driver = d.driver,
      .platform = std::string("Vulkan") + (context_->read_directly ? "" : ", staging read-back"),
      .software = context_->software,
      .kernel_shape = to_string(context_->shape)};
}

bool VulkanBackend::reads_through_staging() const {
  return context() && !context_->read_directly;
}

std::vector<vulkan::Device> VulkanBackend::devices() const {
  context();
  return context_ ? context_->devices : std::vector<vulkan::Device>{};
}

int VulkanBackend::device_index() const {
  return context() ? context_->chosen : -1;
}

void VulkanBackend::compile(const std::string& source) const {
  if (!context()) unavailable(unavailable_);
  const ValidationCheck check(validation_);
  const std::lock_guard<std::mutex> lock(context_->mutex);
  context_->make_pipeline(source);
  check.done();
}

Frame VulkanBackend::render(const Scene& scene, const Camera& camera, int width, int height,
                            const MarchParams& params, const Progress& progress) const {
  return draw(scene, camera, width, height, params, progress, false);
}

Frame VulkanBackend::render_colour(const Scene& scene, const Camera& camera, int width, int height,
                                   const MarchParams& params, const Progress& progress) const {
  return draw(scene, camera, width, height, params, progress, true);
}

std::optional<DeviceTiming> VulkanBackend::last_device_timing() const {
  if (!context()) return std::nullopt;
  const std::lock_guard<std::mutex> lock(context_->mutex);
  return context_->timing;
}

Frame VulkanBackend::draw(const Scene& scene, const Camera& camera, int width, int height,
                          const MarchParams& params, const Progress& progress,
                          bool colour_only) const {
  check_precision(params);
  if (!context()) unavailable(unavailable_);
  Context& c = *context_;
  if (width <= 0 || height <= 0) throw std::invalid_argument("the image has no pixels");
  const size_t pixel_bytes = colour_only ? kColourReadbackBytes : kWholeReadbackBytes;
  const vk::DeviceSize bytes =
      static_cast<vk::DeviceSize>(width) * static_cast<vk::DeviceSize>(height) * pixel_bytes;
  const uint32_t groups_x =
      static_cast<uint32_t>((width + kernel::kComputeTile - 1) / kernel::kComputeTile);
  if (bytes > c.limits.maxStorageBufferRange || groups_x > c.limits.maxComputeWorkGroupCount[0])
    throw std::invalid_argument("the vulkan device renders at most " +
                                std::to_string(c.limits.maxStorageBufferRange / pixel_bytes) +
                                " pixels" + (colour_only ? "" : " with their AOVs") + " and " +
                                std::to_string(c.limits.maxComputeWorkGroupCount[0] *
                                               static_cast<uint64_t>(kernel::kComputeTile)) +
                                " a row");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  const ValidationCheck check(validation_);
  const std::lock_guard<std::mutex> lock(c.mutex);
  Context::CachedPipeline& cached = c.pipeline(
      tables, {.from_band = kernel::within_band(tables, camera.position),
               .shape = c.shape,
               .readback = colour_only ? kernel::Readback::colour : kernel::Readback::all});
  const vk::Pipeline pipeline = *cached.pipeline;
  c.reserve_pixels(bytes);
  c.load_tables(tables);

  const CameraBasis<float> basis = camera_basis<float>(
      float(camera.yaw_deg), float(camera.pitch_deg), float(camera.fov_deg), width, height);
  const glm::vec3 from(camera.position);
  kernel::ComputeConstants constants{
      .from = glm::vec4(from, 0.0f),
      .forward = glm::vec4(basis.forward, 0.0f),
      .right = glm::vec4(basis.right, 0.0f),
      .up = glm::vec4(basis.up, 0.0f),
      .scale = glm::vec4(basis.aspect * basis.tan_half_fov, basis.tan_half_fov, 0.0f, 0.0f),
      .frame = glm::ivec4(width, height, 0, camera.polygon),
      .order = glm::ivec4(1, colour_only ? 1 : 0, 0, 0)};  // x: each band's, below
  const Banding why = banding(static_cast<bool>(progress), c.software);
  BandPacer bands(cached.pace, width, height, kernel::kComputeTile, why);
  const bool timed = *c.timestamps;
  DeviceTiming timing{.measured = timed, .why = c.no_timestamps};
  for (int row = 0, rows = 0; row < height; row += rows) {
    rows = bands.rows(row);
    const bool last = row + rows == height;
    const auto start = std::chrono::steady_clock::now();
    const auto tile_rows =
        static_cast<uint32_t>((rows + kernel::kComputeTile - 1) / kernel::kComputeTile);
    constants.frame.z = row;
    constants.order.x = kernel::row_stride(static_cast<int>(tile_rows));
    const bool copied = last && !c.read_directly;
    c.run(
        [&](const vk::raii::CommandBuffer& cmd) {
          if (timed) {
            cmd.resetQueryPool(*c.timestamps, 0, kTimestamps);
            cmd.writeTimestamp(vk::PipelineStageFlagBits::eTopOfPipe, *c.timestamps, 0);
          }
          cmd.bindPipeline(vk::PipelineBindPoint::eCompute, pipeline);
          cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *c.layout, 0, *c.set, {});
          cmd.pushConstants<kernel::ComputeConstants>(*c.layout, vk::ShaderStageFlagBits::eCompute,
                                                      0, constants);
          cmd.dispatch(groups_x, tile_rows, 1);
          if (timed)
            cmd.writeTimestamp(vk::PipelineStageFlagBits::eComputeShader, *c.timestamps, 1);
          if (!last) return;
          // The shader's writes, made visible to the host (through a copy to staging where the
          // pixels are not host-visible).
          if (c.read_directly) {
            const vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite,
                                            vk::AccessFlagBits::eHostRead);
            cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader,
                                vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
            return;
          }
          const vk::MemoryBarrier to_copy(vk::AccessFlagBits::eShaderWrite,
                                          vk::AccessFlagBits::eTransferRead);
          cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader,
                              vk::PipelineStageFlagBits::eTransfer, {}, to_copy, {}, {});
          cmd.copyBuffer(*c.pixels.buffer, *c.staging.buffer, vk::BufferCopy(0, 0, bytes));
          if (timed) cmd.writeTimestamp(vk::PipelineStageFlagBits::eTransfer, *c.timestamps, 2);
          const vk::MemoryBarrier to_host(vk::AccessFlagBits::eTransferWrite,
                                          vk::AccessFlagBits::eHostRead);
          cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer,
                              vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
        },
        why == Banding::none ? kWholeFrameTimeoutNs : kBandTimeoutNs);
    bands.done(rows,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (timed) {
      const uint32_t written = copied ? 3 : 2;
      const auto [result, ticks] = c.timestamps.getResults<uint64_t>(
          0, written, written * sizeof(uint64_t), sizeof(uint64_t),
          vk::QueryResultFlagBits::e64 | vk::QueryResultFlagBits::eWait);
      if (result == vk::Result::eSuccess) {
        timing.march_s += c.between(ticks, 0, 1);
        if (copied) timing.readback_s += c.between(ticks, 1, 2);
      } else {
        timing = {.why = "the device's timestamps were not ready (" + vk::to_string(result) + ")"};
      }
    }
    if (progress) progress(static_cast<double>(row + rows) / height);
  }
  cached.pace = bands.pace();
  c.timing = timing;

  const void* mapped = c.read_directly ? c.pixels.mapped : c.staging.mapped;
  Frame frame =
      colour_only ? colour_frame(mapped, width, height) : whole_frame(mapped, width, height);
  check.done();
  return frame;
}

Trace VulkanBackend::trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                           int max_events) const {
  check_precision(params);
  if (!context()) unavailable(unavailable_);
  Context& c = *context_;
  max_events = std::max(max_events, 0);
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  const ValidationCheck check(validation_);
  const std::lock_guard<std::mutex> lock(c.mutex);
  const vk::Pipeline pipeline = *c.pipeline(tables, {.trace = true, .shape = c.shape}).pipeline;
  const size_t bytes = shader_trace_bytes(max_events);
  c.reserve_events(bytes);
  c.load_tables(tables, /*trace=*/true);
  const ShaderEventHeader header{0, max_events, 0, 0};
  std::memcpy(c.events.mapped, &header, sizeof header);
  const kernel::ComputeConstants constants{.from = glm::vec4(glm::vec3(ray.from), 0.0f),
                                           .forward = glm::vec4(glm::vec3(ray.dir), 0.0f),
                                           .right = glm::vec4(0.0f),
                                           .up = glm::vec4(0.0f),
                                           .scale = glm::vec4(0.0f),
                                           .frame = glm::ivec4(1, 1, 0, ray.polygon),
                                           .order = glm::ivec4(1, 0, 0, 0)};
  c.run([&](const vk::raii::CommandBuffer& cmd) {
    // (The host's write of the header is visible to the device: the submission orders it.)
    cmd.bindPipeline(vk::PipelineBindPoint::eCompute, pipeline);
    cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *c.layout, 0, *c.set, {});
    cmd.pushConstants<kernel::ComputeConstants>(*c.layout, vk::ShaderStageFlagBits::eCompute, 0,
                                                constants);
    cmd.dispatch(1, 1, 1);
    const vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite,
                                    vk::AccessFlagBits::eHostRead);
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost,
                        {}, to_host, {}, {});
  });
  Trace trace = shader_trace(static_cast<const unsigned char*>(c.events.mapped), max_events);
  check.done();
  return trace;
}

}  // namespace flatmarch
