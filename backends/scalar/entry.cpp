// The scalar backend's entry in the registry: the kernel's reference, the slowest CPU backend.
#include "backends/scalar/scalar.hpp"

namespace flatmarch {

BackendEntry scalar_backend_entry() {
  return {.name = "scalar",
          .reference_for =
              "the kernel's steps: the other kernel backends' traces and frames are "
              "compared with its",
          .make = [](const BackendOptions&) { return std::make_unique<ScalarBackend>(); },
          .cost = {.frame_seconds = 0.07},
          .cpu_rank = 1};
}

}  // namespace flatmarch
