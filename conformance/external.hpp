// Renderers we did not write, judged as the backends are (docs/external.md, protocol
// `flatmarch-external/1`): a manifest says what a renderer gives; the renderer is called as a
// command with one JSON argument a frame and writes an EXR or a PNG, which the suite reads back
// and measures against the oracle in the renderer's declared look. `--external NAME=MANIFEST`
// registers one as a backend (external_entry) for `conform` and `report`.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "conformance/expectations.hpp"

namespace flatmarch::conformance {

inline constexpr const char* kExternalProtocol = "flatmarch-external/1";

// A manifest as read: what the renderer gives (ExternalInfo) and how it is called.
struct ExternalManifest {
  std::string name;
  ExternalInfo info;
  std::vector<std::string> command;  // resolved: files beside the manifest made absolute
  std::string unavailable;           // why its command cannot run here (not found), if so
  std::vector<Method> methods;
  std::vector<std::string> parameters;  // those it takes from the request
  std::vector<Precision> precisions;
  double timeout_s = 120.0;
  double frame_seconds = 1.0;
};

// Reads a manifest; `name`, where not empty, replaces the manifest's. Throws
// std::invalid_argument "MANIFEST: /key: what is wrong" for a manifest that cannot be used.
ExternalManifest read_manifest(const std::filesystem::path& file, const std::string& name = {});

// "NAME=MANIFEST" (or "MANIFEST", named by its manifest) as --external takes it: the registry's
// entry of that renderer. Throws std::invalid_argument saying what is wrong.
BackendEntry external_entry(const std::string& spec);

// What results say of a renderer we did not write: its manifest, version, look, the channels it
// gives, the parameters it has built in, and that its time is its command's.
nlohmann::json external_json(const ExternalInfo& info);

// The backend that calls the renderer.
std::unique_ptr<Backend> make_external(const ExternalManifest& manifest);

// The request of one frame (docs/external.md), for `scene` seen from `camera`; `folder` is the
// frame's own folder, where the scene file and the outputs go.
nlohmann::json external_request(const Scene& scene, const Camera& camera, int width, int height,
                                const MarchParams& params, const ExternalInfo& info,
                                const std::filesystem::path& folder);

// The oracle's colours of a frame in `look` ("peer-app": the web app's, docs/external.md), as
// linear colour, 3 floats a pixel; std::nullopt for "flatmarch", whose colours are the oracle's
// frame's own.
std::optional<Channel> look_colours(const std::string& look, const Scene& scene,
                                    const Camera& camera, int width, int height,
                                    const MarchParams& params);

// Why a renderer we did not write does not render a case: a method its manifest lacks, a scene it
// cannot read, a `skip` line of its expectation file; empty for a case it renders and for every
// case of our backends. `conform` and `report` skip such a case, saying why.
class ExternalSkips {
 public:
  ExternalSkips() = default;
  // Reads each external renderer's expectation file once; throws std::invalid_argument
  // "--external NAME: FILE:LINE: what is wrong" for one that cannot be used.
  explicit ExternalSkips(const std::vector<std::unique_ptr<Backend>>& backends);
  std::string why(const Backend& backend, Method m, const Scene& scene) const;
  // The expectation files read, by renderer.
  const std::map<std::string, Expectations>& files() const { return files_; }

 private:
  std::map<std::string, Expectations> files_;
};

}  // namespace flatmarch::conformance
