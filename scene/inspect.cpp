#include "scene/inspect.hpp"

namespace flatmarch {

namespace {

// Adding 0.0 prints -0.0 as 0.
nlohmann::ordered_json point(Vec2 p) {
  return {p.x + 0.0, p.y + 0.0};
}
nlohmann::ordered_json point(Vec3 p) {
  return {p.x, p.y, p.z};
}

nlohmann::ordered_json map_json(const Affine2& m) {
  // Row-major, as scene files write matrices.
  return {
      {"linear",
       {point(Vec2(m.linear[0][0], m.linear[1][0])), point(Vec2(m.linear[0][1], m.linear[1][1]))}},
      {"translation", point(m.translation)}};
}

const char* map_name(GluingMap m) {
  switch (m) {
    case GluingMap::isometry:
      return "isometry";
    case GluingMap::reflection:
      return "reflection";
    case GluingMap::similarity:
      return "similarity";
    case GluingMap::matrix:
      return "matrix";
  }
  return "?";
}

nlohmann::ordered_json vertex_json(const Polygon& polygon, int v) {
  if (polygon.is_ideal(v)) return {{"to", point(polygon.vertex(v))}};
  return point(polygon.vertex(v));
}

}  // namespace

nlohmann::ordered_json inspect(const Scene& scene) {
  nlohmann::ordered_json out;
  out["scene"] = scene.name;

  nlohmann::ordered_json polygons = nlohmann::ordered_json::array();
  nlohmann::ordered_json edges = nlohmann::ordered_json::array();
  for (size_t p = 0; p < scene.polygons.size(); ++p) {
    const Polygon& polygon = scene.polygons[p];
    nlohmann::ordered_json vertices = nlohmann::ordered_json::array(),
                           angles = nlohmann::ordered_json::array();
    // An ideal vertex is written as in the scene file, {"to": direction}; it has no corner.
    for (int v = 0; v < polygon.size(); ++v) {
      vertices.push_back(vertex_json(polygon, v));
      angles.push_back(polygon.is_ideal(v) ? nlohmann::ordered_json()
                                           : nlohmann::ordered_json(polygon.corner_angle(v)));
    }
    polygons.push_back({{"vertices", vertices},
                        {"corner_angles", angles},
                        {"area", polygon.infinite() ? nlohmann::ordered_json()
                                                    : nlohmann::ordered_json(polygon.area())}});
    for (int i = 0; i < polygon.size(); ++i) {
      const Edge& e = polygon.edges[static_cast<size_t>(i)];
      nlohmann::ordered_json edge = {{"polygon", p},
                                     {"edge", i},
                                     {"from", vertex_json(polygon, i)},
                                     {"to", vertex_json(polygon, i + 1)},
                                     {"shape", to_string(e.shape)},
                                     {"length", e.ray() || e.shape == EdgeShape::at_infinity
                                                    ? nlohmann::ordered_json()
                                                    : nlohmann::ordered_json(e.length)},
                                     {"normal", point(e.normal)},
                                     {"kind", to_string(e.kind)}};
      if (e.kind == EdgeKind::glued) {
        edge["gluing"] = e.gluing;
        edge["to_polygon"] = e.to.polygon;
        edge["to_edge"] = e.to.edge;
        edge["map"] = map_json(e.map);
      }
      edges.push_back(edge);
    }
  }

  nlohmann::ordered_json gluings = nlohmann::ordered_json::array();
  for (const Gluing& g : scene.gluings)
    gluings.push_back({{"edges", {{g.a.polygon, g.a.edge}, {g.b.polygon, g.b.edge}}},
                       {"written_as", map_name(g.map)},
                       {"type", to_string(g.type)},
                       {"map", map_json(g.g)}});

  nlohmann::ordered_json classes = nlohmann::ordered_json::array();
  for (const VertexClass& vc : scene.vertex_classes) {
    nlohmann::ordered_json corners = nlohmann::ordered_json::array();
    for (const Corner& c : vc.corners) corners.push_back({c.polygon, c.vertex});
    classes.push_back({{"corners", corners},
                       {"cone_angle", vc.cone_angle},
                       {"cone_angle_over_pi", vc.cone_angle / kPi},
                       {"singular", vc.singular},
                       {"boundary", vc.boundary}});
  }

  out["polygons"] = std::move(polygons);
  out["edges"] = std::move(edges);
  out["gluings"] = std::move(gluings);
  out["vertex_classes"] = std::move(classes);

  const Topology& t = scene.topology;
  out["infinite"] = t.infinite;
  out["euler_characteristic"] = t.euler_characteristic
                                    ? nlohmann::ordered_json(*t.euler_characteristic)
                                    : nlohmann::ordered_json();
  out["orientable"] = t.orientable;
  out["genus"] = t.genus ? nlohmann::ordered_json(*t.genus) : nlohmann::ordered_json();
  out["components"] = t.components;
  out["boundary_components"] = t.boundary_components;

  out["height"] = scene.height;
  out["period"] = scene.period ? nlohmann::ordered_json(*scene.period) : nlohmann::ordered_json();
  out["floor"] = scene.floor;
  nlohmann::ordered_json objects = nlohmann::ordered_json::array();
  for (size_t k = 0; k < scene.objects.size(); ++k) {
    const Object& o = scene.objects[k];
    objects.push_back({{"index", k},
                       {"type", to_string(o.type)},
                       {"polygon", o.polygon},
                       {"center", point(o.center)}});
  }
  nlohmann::ordered_json markers = nlohmann::ordered_json::array();
  for (size_t m = 0; m < scene.markers.size(); ++m)
    markers.push_back({{"index", scene.objects.size() + m},
                       {"vertex_class", scene.markers[m].vertex_class},
                       {"radius", scene.markers[m].radius}});
  out["objects"] = std::move(objects);
  out["markers"] = std::move(markers);
  out["camera"] = camera_json(scene.camera);
  return out;
}

nlohmann::ordered_json camera_json(const Camera& c) {
  return {{"polygon", c.polygon},
          {"position", point(c.position)},
          {"yaw_deg", c.yaw_deg},
          {"pitch_deg", c.pitch_deg},
          {"fov_deg", c.fov_deg}};
}

}  // namespace flatmarch
