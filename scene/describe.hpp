// The derived structure of a scene in words, for people: titles of floor plans, the gallery.
#pragma once

#include <string>

#include "scene/scene.hpp"

namespace flatmarch {

// "6π", "3π/2", "π/3" for simple multiples of π (denominator up to 12), else "1.0000 rad".
std::string cone_angle_text(double radians);

// e.g. "χ = -2, orientable, genus 2; cone points: 6π".
std::string surface_summary(const Scene& scene);

}  // namespace flatmarch
