// Small scenes written out by hand for the tests, with the facts the tests check worked out in
// the comments.
#pragma once

#include <string>

namespace flatmarch::test {

// The torus: the square [0, 4]^2, bottom (edge 0) glued to top (edge 2) by the translation
// (0, 4), right (edge 1) to left (edge 3) by (-4, 0).
inline std::string torus_json(const std::string& extra = "") {
  return R"({"polygons": [[[0, 0], [4, 0], [4, 4], [0, 4]]],
             "gluings": [[[0, 0], [0, 2]], [[0, 1], [0, 3]]])" +
         (extra.empty() ? "" : ", " + extra) + "}";
}

// The unfolded cube as six unit squares in a cross net; each square lists its corners from the
// bottom left counterclockwise, so edge 0 is its bottom, 1 right, 2 top, 3 left.
//   polygon 0 [0,1]x[0,1] centre, 1 [1,2]x[0,1] right, 2 [2,3]x[0,1] back, 3 [-1,0]x[0,1] left,
//   4 [0,1]x[1,2] top, 5 [0,1]x[-1,0] bottom.
// Net neighbours are glued by the zero translation; the belt 3-0-1-2 closes by (-4, 0); the top
// and bottom faces meet the belt by rotations of -90, +90 and 180 degrees.
inline std::string cube_json() {
  return R"({"polygons": [
      [[0, 0], [1, 0], [1, 1], [0, 1]], [[1, 0], [2, 0], [2, 1], [1, 1]],
      [[2, 0], [3, 0], [3, 1], [2, 1]], [[-1, 0], [0, 0], [0, 1], [-1, 1]],
      [[0, 1], [1, 1], [1, 2], [0, 2]], [[0, -1], [1, -1], [1, 0], [0, 0]]],
    "gluings": [
      [[0, 1], [1, 3]], [[1, 1], [2, 3]], [[3, 1], [0, 3]], [[0, 2], [4, 0]], [[0, 0], [5, 2]],
      [[2, 1], [3, 3]],
      [[4, 1], [1, 2]], [[4, 3], [3, 2]], [[4, 2], [2, 2]],
      [[5, 1], [1, 0]], [[5, 3], [3, 0]], [[5, 0], [2, 0]]]})";
}

}  // namespace flatmarch::test
