// The derived structure of a scene as JSON (`flatmarch inspect`, DESIGN.md section 5).
#pragma once

#include <nlohmann/json.hpp>

#include "scene/scene.hpp"

namespace flatmarch {

nlohmann::ordered_json inspect(const Scene& scene);

}  // namespace flatmarch
