#include "scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace flatmarch {

double Object::footprint_radius() const {
  switch (type) {
    case ObjectType::hollow_cube:
      return std::sqrt(2.0) * size;
    case ObjectType::sphere:
    case ObjectType::cylinder:
      return radius;
    case ObjectType::box:
      return std::hypot(half.x, half.y);
  }
  return 0.0;
}

double Object::z_min() const {
  switch (type) {
    case ObjectType::hollow_cube:
      return center.z - size;
    case ObjectType::sphere:
      return center.z - radius;
    case ObjectType::box:
      return center.z - half.z;
    case ObjectType::cylinder:
      return z0;
  }
  return 0.0;
}

double Object::z_max() const {
  switch (type) {
    case ObjectType::hollow_cube:
      return center.z + size;
    case ObjectType::sphere:
      return center.z + radius;
    case ObjectType::box:
      return center.z + half.z;
    case ObjectType::cylinder:
      return z1;
  }
  return 0.0;
}

const std::vector<const char*>& gluing_palette() {
  static const std::vector<const char*> palette{"#4e79a7", "#f28e2b", "#59a14f", "#e15759",
                                                "#76b7b2", "#edc948", "#b07aa1", "#17becf",
                                                "#9c755f", "#bab0ac"};
  return palette;
}

Vec3 linear_from_hex(const char* hex) {
  const unsigned long rgb = std::strtoul(hex + 1, nullptr, 16);
  Vec3 c;
  for (int i = 0; i < 3; ++i)
    c[i] = decode_srgb(static_cast<double>((rgb >> (8 * (2 - i))) & 0xffu) / 255.0);
  return c;
}

double decode_srgb(double encoded) {
  const double v = std::clamp(encoded, 0.0, 1.0);
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

double encode_srgb(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

std::string hex_from_linear(Vec3 c) {
  int byte[3];
  for (int i = 0; i < 3; ++i) byte[i] = static_cast<int>(std::lround(255.0 * encode_srgb(c[i])));
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", byte[0], byte[1], byte[2]);
  return buf;
}

Vec3 Look::gluing_colour(int k) const {
  if (k >= 0 && k < static_cast<int>(gluings.size())) return gluings[static_cast<size_t>(k)];
  const auto& palette = gluing_palette();
  return kPaletteShade * linear_from_hex(palette[static_cast<size_t>(k) % palette.size()]);
}

int Scene::marker_at(int polygon, int vertex) const {
  const int c = corner_class[static_cast<size_t>(polygon)][static_cast<size_t>(vertex)];
  for (size_t m = 0; m < markers.size(); ++m)
    if (markers[m].vertex_class == c) return static_cast<int>(m);
  return -1;
}

const char* to_string(GluingType t) {
  switch (t) {
    case GluingType::translation:
      return "translation";
    case GluingType::half_translation:
      return "half-translation";
    case GluingType::rotation:
      return "rotation";
    case GluingType::reflection:
      return "reflection";
    case GluingType::similarity:
      return "similarity";
    case GluingType::affine:
      return "affine";
  }
  return "?";
}

const char* to_string(EdgeKind k) {
  switch (k) {
    case EdgeKind::glued:
      return "glued";
    case EdgeKind::mirror:
      return "mirror";
    case EdgeKind::wall:
      return "wall";
    case EdgeKind::infinity:
      return "infinity";
  }
  return "?";
}

const char* to_string(EdgeShape s) {
  switch (s) {
    case EdgeShape::segment:
      return "segment";
    case EdgeShape::ray_out:
      return "ray_out";
    case EdgeShape::ray_in:
      return "ray_in";
    case EdgeShape::at_infinity:
      return "at_infinity";
  }
  return "?";
}

const char* to_string(ObjectType t) {
  switch (t) {
    case ObjectType::hollow_cube:
      return "hollow_cube";
    case ObjectType::sphere:
      return "sphere";
    case ObjectType::box:
      return "box";
    case ObjectType::cylinder:
      return "cylinder";
  }
  return "?";
}

}  // namespace flatmarch
