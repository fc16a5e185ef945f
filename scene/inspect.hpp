// The derived structure of a scene as JSON (`flatmarch inspect`, DESIGN.md section 5).
#pragma once

#include <nlohmann/json.hpp>

#include "scene/scene.hpp"

namespace flatmarch {

nlohmann::ordered_json inspect(const Scene& scene);

// A camera as scene files and `inspect` write it: polygon, position, yaw_deg, pitch_deg, fov_deg
// (also the web page's and the browser benchmark's).
nlohmann::ordered_json camera_json(const Camera& camera);

}  // namespace flatmarch
