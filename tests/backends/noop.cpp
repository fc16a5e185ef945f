// A backend registered only in the test programs (Filament's no-op driver in spirit): it shows
// that every list of backends reads the registry, since it appears, skipped with its reason, in
// the contract and conformance tests with no edit but this file. It marches nothing, so it says
// it is unavailable; render and trace refuse.
#include <stdexcept>

#include "backends/backend.hpp"

namespace flatmarch::test {
namespace {

class NoopBackend final : public Backend {
 public:
  std::string name() const override { return "noop"; }
  std::string description() const override { return "a test backend that marches nothing"; }
  Availability availability() const override {
    return {false, "a test backend: it marches nothing (registered only in the test programs)"};
  }
  std::vector<Method> methods() const override {
    return {kKernelMethods.begin(), kKernelMethods.end()};
  }
  Frame render(const Scene&, const Camera&, int, int, const MarchParams&,
               const Progress&) const override {
    throw std::runtime_error("the noop backend marches nothing");
  }
  Trace trace(const Scene&, const Ray&, const MarchParams&, int) const override {
    throw std::runtime_error("the noop backend marches nothing");
  }
};

[[maybe_unused]] const bool registered =
    register_backend({.name = "noop", .make = [](const BackendOptions&) {
                        return std::make_unique<NoopBackend>();
                      }});

}  // namespace
}  // namespace flatmarch::test
