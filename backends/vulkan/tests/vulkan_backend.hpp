// The Vulkan backend as the Vulkan test programs share it: one per program (its device and
// compiled pipelines are reused), under the validation layer, any message of which fails the call
// that caused it; and a visible skip where it is unavailable.
#pragma once

#include <gtest/gtest.h>

#include "backends/vulkan/vulkan.hpp"

namespace flatmarch::test {

inline const VulkanBackend& vulkan() {
  static const VulkanBackend backend = [] {
    BackendOptions options;
    options.validation = true;
    return VulkanBackend(options);
  }();
  return backend;
}

}  // namespace flatmarch::test

#define SKIP_WITHOUT_VULKAN()                                             \
  if (const Availability a = test::vulkan().availability(); !a.available) \
  GTEST_SKIP() << "the vulkan backend is unavailable here: " << a.reason
