#include "scene/describe.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace flatmarch {

std::string cone_angle_text(double radians) {
  for (int den = 1; den <= 12; ++den) {
    const double num = radians / kPi * den;
    if (std::abs(num - std::round(num)) < 1e-9) {
      const long n = std::lround(num);
      return (n == 1 ? "" : std::to_string(n)) + "π" + (den == 1 ? "" : "/" + std::to_string(den));
    }
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f rad", radians);
  return buf;
}

std::string surface_summary(const Scene& scene) {
  const Topology& t = scene.topology;
  std::string s = (t.euler_characteristic ? "χ = " + std::to_string(*t.euler_characteristic)
                                          : std::string("infinite")) +
                  (t.orientable ? ", orientable" : ", non-orientable");
  if (t.genus) s += (t.orientable ? ", genus " : ", cross-cap genus ") + std::to_string(*t.genus);
  if (t.boundary_components)
    s += ", " + std::to_string(t.boundary_components) + " boundary component(s)";
  // Equal angles are counted: "8 × 3π/2".
  std::vector<std::pair<std::string, int>> angles;
  for (const VertexClass& vc : scene.vertex_classes) {
    if (!vc.singular) continue;
    const std::string text = cone_angle_text(vc.cone_angle) + (vc.boundary ? " (boundary)" : "");
    const auto it =
        std::find_if(angles.begin(), angles.end(), [&](const auto& a) { return a.first == text; });
    if (it == angles.end())
      angles.push_back({text, 1});
    else
      ++it->second;
  }
  std::string cones;
  for (const auto& [text, count] : angles)
    cones += (cones.empty() ? "" : ", ") + (count > 1 ? std::to_string(count) + " × " : "") + text;
  s += cones.empty() ? "; no cone points" : "; cone points: " + cones;
  if (scene.period) s += "; translation prism";
  return s;
}

}  // namespace flatmarch
