// The OpenGL backend as the OpenGL test programs share it: one per program (its context and
// compiled programs are reused), and a visible skip where it is unavailable.
#pragma once

#include <gtest/gtest.h>

#include "backends/opengl/opengl.hpp"

namespace flatmarch::test {

inline const OpenGlBackend& opengl() {
  static const OpenGlBackend backend;
  return backend;
}

}  // namespace flatmarch::test

#define SKIP_WITHOUT_OPENGL()                                             \
  if (const Availability a = test::opengl().availability(); !a.available) \
  GTEST_SKIP() << "the opengl backend is unavailable here: " << a.reason
