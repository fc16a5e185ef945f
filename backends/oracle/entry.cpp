// The oracle's entry in the registry (backends/registered.cpp lists it first).
#include "backends/oracle/oracle.hpp"

namespace flatmarch {

BackendEntry oracle_backend_entry() {
  return {.name = "oracle",
          .kernel = false,
          .reference_for = "the true image and every ray's path (exact, analytic)",
          .make = [](const BackendOptions&) { return std::make_unique<OracleBackend>(); }};
}

}  // namespace flatmarch
