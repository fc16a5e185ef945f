// Transport traces as JSON (DESIGN.md section 4).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "output/trace.hpp"

namespace flatmarch {

nlohmann::ordered_json trace_to_json(const std::string& scene, const std::string& backend,
                                     Method method, const Ray& ray, const Trace& trace);

}  // namespace flatmarch
