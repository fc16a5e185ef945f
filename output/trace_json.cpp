#include "output/trace_json.hpp"

namespace flatmarch {

namespace {

nlohmann::ordered_json point(Vec3 p) {
  return {p.x + 0.0, p.y + 0.0, p.z + 0.0};
}

}  // namespace

nlohmann::ordered_json trace_to_json(const std::string& scene, const std::string& backend,
                                     Method method, const Ray& ray, const Trace& trace) {
  nlohmann::ordered_json events = nlohmann::ordered_json::array();
  for (const Event& e : trace.events) {
    nlohmann::ordered_json j = {{"kind", to_string(e.kind)}, {"polygon", e.polygon}};
    if (e.kind == EventKind::gluing || e.kind == EventKind::mirror || e.kind == EventKind::wall)
      j["edge"] = e.edge;
    if (e.kind == EventKind::gluing) {
      j["to_polygon"] = e.to_polygon;
      j["to_edge"] = e.to_edge;
    }
    if (e.kind == EventKind::object) j["object"] = e.object;
    j["t"] = e.t;
    j["at"] = point(e.at);
    events.push_back(std::move(j));
  }
  return {{"scene", scene},
          {"backend", backend},
          {"method", to_string(method)},
          {"ray", {{"polygon", ray.polygon}, {"from", point(ray.from)}, {"dir", point(ray.dir)}}},
          {"events", std::move(events)},
          {"steps", trace.steps}};
}

}  // namespace flatmarch
