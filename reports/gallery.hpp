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

// Renders the gallery for `recommendation` (recommend()'s answer): each scene's image and its
// difference map, a conformance case's error image (the pixel classes of
// conformance/vocabulary.hpp, masked at the default eps and offset as the sweep judges).
// Returns {"backend", "method", "size", "scenes": [{scene, surface_type, eps, offset, image,
// diff (paths relative to images), pixels, counts per pixel class}, or {scene, error}]}; null
// when there is no recommendation.
nlohmann::json recommended_gallery(const std::vector<Scene>& scenes,
                                   const nlohmann::json& recommendation,
                                   const GalleryOptions& options);

}  // namespace flatmarch::reports
