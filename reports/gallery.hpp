// The gallery of the recommended choice: each scene rendered by the recommended backend and
// method, with the eps and offset recommended for its surface type, and a map of where that
// image differs from the oracle's (the oracle's image is the matrix's, images/oracle/).
#pragma once

#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"

namespace flatmarch::reports {

struct GalleryOptions {
  int width = 256, height = 144;
  MarchParams params;  // max_steps, max_distance; method, eps and offset: the recommendation's
  BackendOptions backend_options;
  std::filesystem::path images;  // writes images/recommended/SCENE.png and SCENE.diff.png
};

// The difference map's pixel classes, each with its colour (sRGB, "#rrggbb") and meaning:
// "agree" (the oracle's image, dimmed), "ambiguous" (the ambiguity mask at the default eps and
// offset leaves it undecided, as the sweep judges), "colour" (hit and crossings agree, a
// channel differs by more than the image check's 0.05), then the failure classes of
// conformance/compare.hpp that a frame can show.
nlohmann::json difference_legend();

// Renders the gallery for `recommendation` (recommend()'s answer). Returns {"backend",
// "method", "size", "legend", "scenes": [{scene, surface_type, eps, offset, image, diff (paths
// relative to images), pixels, counts per legend class}, or {scene, error}]}; null when there is
// no recommendation.
nlohmann::json recommended_gallery(const std::vector<Scene>& scenes,
                                   const nlohmann::json& recommendation,
                                   const GalleryOptions& options);

}  // namespace flatmarch::reports
