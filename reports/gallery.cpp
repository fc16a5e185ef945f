#include "reports/gallery.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "conformance/ambiguity.hpp"
#include "conformance/compare.hpp"
#include "conformance/suite.hpp"
#include "conformance/vocabulary.hpp"
#include "output/image_io.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::reports {

using nlohmann::json;

json recommended_gallery(const std::vector<Scene>& scenes, const json& recommendation,
                         const GalleryOptions& o) {
  if (recommendation.value("backend", json(nullptr)).is_null()) return nullptr;
  const std::string backend_name = recommendation["backend"];
  const std::unique_ptr<Backend> backend = make_backend(backend_name, o.backend_options);
  const Method method = *parse_method(recommendation["method"]);
  json out = {{"backend", backend_name},
              {"method", recommendation["method"]},
              {"size", std::to_string(o.width) + "x" + std::to_string(o.height)},
              {"scenes", json::array()}};
  const std::filesystem::path dir = o.images / "recommended";
  std::filesystem::create_directories(dir);
  for (const Scene& scene : scenes) {
    MarchParams params = o.params;
    params.method = method;
    const std::string type = surface_type(scene);
    const json& chosen = recommendation["parameters"];
    if (chosen.contains(type)) {
      params.eps = chosen[type]["eps"];
      params.offset = chosen[type]["offset"];
    }
    json entry = {{"scene", scene.name},
                  {"surface_type", type},
                  {"eps", params.eps},
                  {"offset", params.offset}};
    try {
      const Frame got = backend->render(scene, scene.camera, o.width, o.height, params, {});
      // Masked as for the default eps and offset, as the sweep that chose the parameters judged
      // them (Suite::fix_mask): a large eps cannot widen the mask over the pixels it gets wrong.
      MarchParams masked = params;
      masked.eps = MarchParams{}.eps;
      masked.offset = MarchParams{}.offset;
      const conformance::FrameTruth truth =
          conformance::frame_truth(scene, scene.camera, o.width, o.height, masked);
      const Frame& want = truth.frame;
      // Classed as a conformance case's error image (Suite::run): colour against each region's
      // tolerance, at the default colour thresholds.
      std::vector<uint8_t> colour_failing;
      conformance::compare_regions(got, want, truth.ambiguity, conformance::ColourThresholds{},
                                   static_cast<int>(scene.objects.size()), &colour_failing);
      const std::vector<uint8_t> classes =
          conformance::classify_pixels(got, want, truth.ambiguity, colour_failing);
      const auto words = conformance::pixel_class_words();
      std::vector<size_t> counts(words.size(), 0);
      for (const uint8_t c : classes) ++counts[std::min<size_t>(c, words.size() - 1)];
      const Frame diff = conformance::error_image(classes, want);
      const std::string image = "recommended/" + scene.name + ".png";
      const std::string diff_image = "recommended/" + scene.name + ".diff.png";
      write_png(got, o.images / image);
      write_png(diff, o.images / diff_image);
      json by_class = json::object();
      for (size_t k = 0; k < words.size(); ++k)
        if (!words[k].traces_only) by_class[words[k].name] = counts[k];
      entry["image"] = image;
      entry["diff"] = diff_image;
      entry["pixels"] = got.hit.size();
      entry["counts"] = by_class;
    } catch (const std::exception& e) {
      entry["error"] = e.what();
    }
    out["scenes"].push_back(std::move(entry));
  }
  return out;
}

}  // namespace flatmarch::reports
