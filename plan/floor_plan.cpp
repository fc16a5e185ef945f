#include "plan/floor_plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "backends/oracle/oracle.hpp"
#include "scene/describe.hpp"

namespace flatmarch {

namespace {

// Glued edge pairs are drawn in their gluing's colour (the scene's look: the colour the rooms
// tint crossing rays with). Beyond the palette's colours they repeat with a dash pattern.
constexpr std::array<const char*, 4> kDashes{"", "9 4", "3 3", "12 3 3 3"};
constexpr std::array<const char*, 8> kConeColours{"#1b1b1b", "#7f3c8d", "#11a579", "#3969ac",
                                                  "#f2b701", "#e73f74", "#80ba5a", "#e68310"};
constexpr const char* kRayColour = "#d81b60";
constexpr const char* kMirrorColour = "#9bb7c9";
constexpr const char* kWallColour = "#3d3d3d";
constexpr const char* kObjectColour = "#6a3d9a";

// Writes numbers with two decimals: pixels need no more.
class Svg {
 public:
  Svg& operator<<(const std::string& s) {
    out_ << s;
    return *this;
  }
  Svg& operator<<(const char* s) {
    out_ << s;
    return *this;
  }
  Svg& operator<<(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", v + 0.0);
    out_ << buf;
    return *this;
  }
  Svg& operator<<(int v) {
    out_ << v;
    return *this;
  }
  Svg& operator<<(size_t v) {
    out_ << v;
    return *this;
  }
  Svg& point(Vec2 p) { return *this << p.x << "," << p.y; }
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

// Unit vector into the polygon that splits the corner at vertex v (pixel frame, y down).
Vec2 inward_bisector(const Polygon& polygon, int v) {
  const Vec2 in = glm::normalize(polygon.heading(v - 1));
  const Vec2 out = glm::normalize(polygon.heading(v));
  Vec2 b = perp(in) + perp(out);  // the interior lies to the left of both edges
  b = glm::length(b) > 1e-9 ? glm::normalize(b) : perp(out);
  return {b.x, -b.y};
}

void draw_polygons(Svg& svg, const Scene& scene, const PlanLayout& layout) {
  svg << "<defs>";
  for (size_t p = 0; p < scene.polygons.size(); ++p) {
    svg << "<clipPath id=\"polygon-" << p << "\"><polygon points=\"";
    for (const Vec2& v : layout.outline(scene.polygons[p])) svg.point(layout.to_pixels(v)) << " ";
    svg << "\"/></clipPath>";
  }
  svg << "</defs>\n";
  for (size_t p = 0; p < scene.polygons.size(); ++p) {
    const Polygon& polygon = scene.polygons[p];
    svg << "<polygon class=\"polygon\" data-polygon=\"" << p
        << "\" fill=\"#f4f1e8\" stroke=\"#d8d2c2\" points=\"";
    for (const Vec2& v : layout.outline(polygon)) svg.point(layout.to_pixels(v)) << " ";
    svg << "\"/>\n";
    if (scene.polygons.size() > 1) {
      const Vec2 c = layout.to_pixels(polygon.centroid());
      svg << "<text class=\"polygon-label\" x=\"" << c.x << "\" y=\"" << c.y
          << "\" font-size=\"11\" fill=\"#b5ad98\" text-anchor=\"middle\">P" << p << "</text>\n";
    }
  }
}

// A chevron at the middle of the segment from `a` to `b` (pixels), pointing from a to b.
void draw_arrow(Svg& svg, Vec2 a, Vec2 b, const char* colour) {
  const Vec2 mid = 0.5 * (a + b), d = glm::normalize(b - a), n = perp(d);
  svg << "<path class=\"arrow\" d=\"M";
  svg.point(mid - 5.0 * d + 5.0 * n) << " L";
  svg.point(mid + 4.0 * d) << " L";
  svg.point(mid - 5.0 * d - 5.0 * n)
      << "\" fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2\"/>\n";
}

void draw_edges(Svg& svg, const Scene& scene, const PlanLayout& layout) {
  for (size_t p = 0; p < scene.polygons.size(); ++p) {
    const Polygon& polygon = scene.polygons[p];
    for (int i = 0; i < polygon.size(); ++i) {
      const Edge& e = polygon.edges[static_cast<size_t>(i)];
      const PlanEdge drawn = plan_edge(polygon, i, layout.radius());
      if (!drawn.drawn) continue;  // at infinity: the outline's cut-off arc shows where it lies
      const Vec2 a = layout.to_pixels(drawn.a), b = layout.to_pixels(drawn.b);
      const auto line = [&](const char* cls, const std::string& colour, double width,
                            const char* dash) {
        svg << "<line class=\"" << cls << "\" data-polygon=\"" << p << "\" data-edge=\"" << i
            << "\"";
        if (e.kind == EdgeKind::glued) svg << " data-gluing=\"" << e.gluing << "\"";
        svg << " x1=\"" << a.x << "\" y1=\"" << a.y << "\" x2=\"" << b.x << "\" y2=\"" << b.y
            << "\" stroke=\"" << colour << "\" stroke-width=\"" << width
            << "\" stroke-linecap=\"round\"";
        if (*dash) svg << " stroke-dasharray=\"" << dash << "\"";
        svg << "/>\n";
      };
      if (e.kind == EdgeKind::wall) {
        line("edge wall", kWallColour, 5.0, "");
      } else if (e.kind == EdgeKind::mirror) {
        line("edge mirror", kMirrorColour, 6.0, "");
        line("edge mirror-core", "#ffffff", 1.5, "");
      } else {
        const size_t k = static_cast<size_t>(e.gluing);
        const std::string colour = hex_from_linear(scene.look.gluing_colour(e.gluing));
        const size_t palette = gluing_palette().size();
        line("edge glued", colour, 4.0,
             k < scene.look.gluings.size() ? "" : kDashes[(k / palette) % kDashes.size()]);
        // Arrows that correspond under the map: A -> B on edge a; on edge b (C -> D) the images,
        // D -> C for orientation-preserving maps and C -> D for reversing ones.
        const Gluing& g = scene.gluings[k];
        const bool is_a = g.a == EdgeRef{static_cast<int>(p), i};
        const bool along = is_a || g.g.determinant() < 0.0;
        draw_arrow(svg, along ? a : b, along ? b : a, colour.c_str());
        const Vec2 label = 0.5 * (a + b) - 13.0 * glm::normalize(perp(b - a));
        svg << "<text class=\"gluing-label\" x=\"" << label.x << "\" y=\"" << label.y + 4.0
            << "\" font-size=\"11\" fill=\"" << colour << "\" text-anchor=\"middle\">"
            << static_cast<int>(k) << "</text>\n";
      }
    }
  }
}

void draw_vertices(Svg& svg, const Scene& scene, const PlanLayout& layout) {
  // Marker cylinders first, clipped to their polygon: the sector around each corner.
  for (size_t p = 0; p < scene.polygons.size(); ++p)
    for (int v = 0; v < scene.polygons[p].size(); ++v) {
      const int m = scene.marker_at(static_cast<int>(p), v);
      if (m < 0) continue;
      const Vec2 c = layout.to_pixels(scene.polygons[p].vertex(v));
      svg << "<circle class=\"marker\" data-object=\""
          << scene.objects.size() + static_cast<size_t>(m) << "\" cx=\"" << c.x << "\" cy=\"" << c.y
          << "\" r=\"" << layout.to_pixels(scene.markers[static_cast<size_t>(m)].radius)
          << "\" fill=\"#8d99ae\" fill-opacity=\"0.55\" clip-path=\"url(#polygon-" << p
          << ")\"/>\n";
    }
  int singular_index = 0;
  for (size_t c = 0; c < scene.vertex_classes.size(); ++c) {
    const VertexClass& vc = scene.vertex_classes[c];
    const char* colour =
        vc.singular ? kConeColours[static_cast<size_t>(singular_index++) % kConeColours.size()]
                    : "#a0a0a0";
    const std::string label = cone_angle_text(vc.cone_angle);
    std::vector<Vec2> drawn;  // corners of this class that coincide in the plan get one dot
    for (const Corner& k : vc.corners) {
      const Polygon& polygon = scene.polygons[static_cast<size_t>(k.polygon)];
      const Vec2 at = layout.to_pixels(polygon.vertex(k.vertex));
      if (std::any_of(drawn.begin(), drawn.end(),
                      [&](Vec2 p) { return glm::length(p - at) < 1.0; }))
        continue;
      drawn.push_back(at);
      svg << "<circle class=\"" << (vc.singular ? "cone-point" : "vertex") << "\" data-class=\""
          << c << "\" cx=\"" << at.x << "\" cy=\"" << at.y << "\" r=\"" << (vc.singular ? 5.0 : 2.5)
          << "\" fill=\"" << colour << "\"/>\n";
      if (!vc.singular) continue;
      const Vec2 text = at + 20.0 * inward_bisector(polygon, k.vertex);
      svg << "<text class=\"cone-angle\" data-class=\"" << c << "\" x=\"" << text.x << "\" y=\""
          << text.y + 4.0 << "\" font-size=\"12\" font-weight=\"bold\" fill=\"" << colour
          << "\" text-anchor=\"middle\">" << xml_escape(label) << "</text>\n";
    }
  }
}

void draw_objects(Svg& svg, const Scene& scene, const PlanLayout& layout) {
  for (size_t k = 0; k < scene.objects.size(); ++k) {
    const Object& o = scene.objects[k];
    const Vec2 c = layout.to_pixels(Vec2(o.center));
    const std::string colour = o.color ? hex_from_linear(*o.color) : kObjectColour;
    const std::string style = "\" fill=\"" + colour + "\" fill-opacity=\"0.45\" stroke=\"" +
                              colour + "\" stroke-width=\"1.5\"";
    const auto rect = [&](Vec2 half) {
      const Vec2 h(layout.to_pixels(half.x), layout.to_pixels(half.y));
      svg << "<rect class=\"object\" data-object=\"" << k << "\" x=\"" << c.x - h.x << "\" y=\""
          << c.y - h.y << "\" width=\"" << 2.0 * h.x << "\" height=\"" << 2.0 * h.y << style
          << "/>\n";
    };
    switch (o.type) {
      case ObjectType::sphere:
      case ObjectType::cylinder:
        svg << "<circle class=\"object\" data-object=\"" << k << "\" cx=\"" << c.x << "\" cy=\""
            << c.y << "\" r=\"" << layout.to_pixels(o.radius) << style << "/>\n";
        break;
      case ObjectType::box:
        rect(Vec2(o.half));
        break;
      case ObjectType::hollow_cube: {
        // The cross-section at the cube's mid-height: the square minus the hole's disk.
        rect(Vec2(o.size));
        const double s = layout.to_pixels(o.size);
        svg << "<clipPath id=\"object-" << k << "\"><rect x=\"" << c.x - s << "\" y=\"" << c.y - s
            << "\" width=\"" << 2.0 * s << "\" height=\"" << 2.0 * s << "\"/></clipPath>\n";
        svg << "<circle class=\"hole\" cx=\"" << c.x << "\" cy=\"" << c.y << "\" r=\""
            << layout.to_pixels(o.hole) << "\" fill=\"#f4f1e8\" stroke=\"" << colour
            << "\" stroke-dasharray=\"3 2\" clip-path=\"url(#object-" << k << ")\"/>\n";
        break;
      }
    }
  }
}

void draw_camera(Svg& svg, const Scene& scene, const PlanLayout& layout) {
  const Camera& cam = scene.camera;
  const Vec2 at = layout.to_pixels(Vec2(cam.position));
  const double yaw = glm::radians(cam.yaw_deg);
  // The horizontal field of view of a 16:9 image.
  const double half = std::atan(std::tan(glm::radians(cam.fov_deg) / 2.0) * 16.0 / 9.0);
  const auto towards = [&](double angle, double length) {
    return at + length * Vec2(std::cos(angle), -std::sin(angle));
  };
  svg << "<path class=\"camera-fov\" d=\"M";
  svg.point(at) << " L";
  svg.point(towards(yaw + half, 34.0)) << " A34,34 0 0,1 ";
  svg.point(towards(yaw - half, 34.0))
      << " Z\" fill=\"#2a9d8f\" fill-opacity=\"0.18\" stroke=\"none\"/>\n";
  const Vec2 tip = towards(yaw, 26.0);
  svg << "<line class=\"camera-direction\" x1=\"" << at.x << "\" y1=\"" << at.y << "\" x2=\""
      << tip.x << "\" y2=\"" << tip.y << "\" stroke=\"#2a9d8f\" stroke-width=\"2\"/>\n";
  svg << "<circle class=\"camera\" data-polygon=\"" << cam.polygon << "\" cx=\"" << at.x
      << "\" cy=\"" << at.y
      << "\" r=\"4.5\" fill=\"#2a9d8f\" stroke=\"#ffffff\" stroke-width=\"1.5\"/>\n";
}

void draw_ray(Svg& svg, const Scene& scene, const PlanLayout& layout, const PlanOptions& options) {
  const OracleResult r = oracle_trace(scene, *options.ray, options.params,
                                      {.max_events = options.max_events, .record_path = true});
  const size_t n = std::min(r.path.size(), static_cast<size_t>(std::max(options.max_events, 1)));
  for (size_t k = 0; k < n; ++k) {
    const PathSegment& s = r.path[k];
    const Vec2 a = layout.to_pixels(Vec2(s.from)), b = layout.to_pixels(Vec2(s.to));
    // Later segments fade, so the order reads from the start.
    const double opacity =
        1.0 - 0.65 * static_cast<double>(k) / static_cast<double>(std::max<size_t>(n, 2) - 1);
    svg << "<line class=\"ray\" data-segment=\"" << k << "\" data-polygon=\"" << s.polygon
        << "\" x1=\"" << a.x << "\" y1=\"" << a.y << "\" x2=\"" << b.x << "\" y2=\"" << b.y
        << "\" stroke=\"" << kRayColour << "\" stroke-width=\"2\" stroke-opacity=\"" << opacity
        << "\"/>\n";
    if (k + 1 < n)
      svg << "<circle class=\"ray-crossing\" cx=\"" << b.x << "\" cy=\"" << b.y
          << "\" r=\"2.2\" fill=\"" << kRayColour << "\"/>\n";
  }
  if (n == 0) return;
  const Vec2 start = layout.to_pixels(Vec2(r.path.front().from));
  svg << "<circle class=\"ray-start\" cx=\"" << start.x << "\" cy=\"" << start.y
      << "\" r=\"4\" fill=\"#ffffff\" stroke=\"" << kRayColour << "\" stroke-width=\"2\"/>\n";
  if (n < r.path.size() || r.trace.events.empty()) return;  // cut short: no final event to show
  const Event& last = r.trace.events.back();
  const Vec2 end = layout.to_pixels(Vec2(r.path[n - 1].to));
  std::string label = to_string(last.kind);
  // append(), not " " + std::string: GCC 12 at -O3 (the Release build) warns falsely on that.
  if (last.kind == EventKind::object) label.append(" ").append(std::to_string(last.object));
  svg << "<circle class=\"ray-end\" cx=\"" << end.x << "\" cy=\"" << end.y << "\" r=\"4\" fill=\""
      << kRayColour << "\"/>\n";
  svg << "<text class=\"ray-end-label\" x=\"" << end.x + 7.0 << "\" y=\"" << end.y - 7.0
      << "\" font-size=\"11\" fill=\"" << kRayColour << "\">" << xml_escape(label) << "</text>\n";
}

}  // namespace

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

double plan_radius(const Scene& scene) {
  double r = scene.scale;
  for (const Polygon& p : scene.polygons)
    for (int v = 0; v < p.size(); ++v)
      if (!p.is_ideal(v)) r = std::max(r, glm::length(p.vertex(v)));
  for (const Object& o : scene.objects)
    r = std::max(r, glm::length(Vec2(o.center)) + o.footprint_radius());
  r = std::max(r, glm::length(Vec2(scene.camera.position)));
  return 1.25 * r;
}

PlanEdge plan_edge(const Polygon& polygon, int i, double radius) {
  const Edge& e = polygon.edges[static_cast<size_t>(i)];
  switch (e.shape) {
    case EdgeShape::segment:
      return {polygon.vertex(i), polygon.vertex(i + 1)};
    case EdgeShape::ray_out:
      return {e.start, e.start + radius * e.along};
    case EdgeShape::ray_in:
      return {e.start + radius * e.along, e.start};
    case EdgeShape::at_infinity:
      break;
  }
  return {Vec2(0.0), Vec2(0.0), false};
}

std::vector<Vec2> PlanLayout::outline(const Polygon& polygon) const {
  return polygon.outline(radius_, 96);
}

PlanLayout::PlanLayout(const Scene& scene, double width)
    : radius_(plan_radius(scene)), width_(width) {
  Vec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const Polygon& p : scene.polygons)
    for (const Vec2& v : outline(p)) lo = glm::min(lo, v), hi = glm::max(hi, v);
  const double margin = kMarginFraction * std::max(hi.x - lo.x, hi.y - lo.y);
  min_ = lo - Vec2(margin);
  max_ = hi + Vec2(margin);
  scale_ = width / (max_.x - min_.x);
  height_ = kTitleHeight + (max_.y - min_.y) * scale_;
}

std::string floor_plan_svg(const Scene& scene, const PlanOptions& options) {
  const PlanLayout layout(scene, options.width);
  Svg svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
         "width=\""
      << layout.width() << "\" height=\"" << layout.height() << "\" viewBox=\"0 0 "
      << layout.width() << " " << layout.height() << "\" font-family=\"sans-serif\">\n";
  svg << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  svg << "<text class=\"title\" x=\"10\" y=\"18\" font-size=\"15\" font-weight=\"bold\">"
      << xml_escape(scene.name) << "</text>\n";
  svg << "<text class=\"summary\" x=\"10\" y=\"34\" font-size=\"11\" fill=\"#555\">"
      << xml_escape(surface_summary(scene)) << "</text>\n";
  svg << "<text class=\"legend\" x=\"10\" y=\"49\" font-size=\"10\" fill=\"#777\">"
      << "edges of one colour are glued, their arrows matching · pale blue: mirror · dark grey: "
         "wall"
      << " · dots: cone points with their angle" << (options.ray ? " · pink: a light ray" : "")
      << "</text>\n";
  draw_polygons(svg, scene, layout);
  draw_objects(svg, scene, layout);
  draw_edges(svg, scene, layout);
  draw_vertices(svg, scene, layout);
  draw_camera(svg, scene, layout);
  if (options.ray) draw_ray(svg, scene, layout, options);
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace flatmarch
