#include "scene/scene.hpp"

#include <cmath>

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
