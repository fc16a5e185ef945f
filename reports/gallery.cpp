#include "reports/gallery.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "conformance/ambiguity.hpp"
#include "conformance/compare.hpp"
#include "output/image_io.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::reports {

using nlohmann::json;

namespace {

struct PixelClass {
  const char* name;
  std::array<int, 3> srgb;
  const char* meaning;
};

// Loud colours apart from the dimmed image, each failure class its own.
constexpr PixelClass kClasses[] = {
    {"agree", {0, 0, 0}, "hit, crossings and colour as the oracle's (its image, dimmed)"},
    {"ambiguous",
     {40, 90, 255},
     "the ambiguity mask (at the default eps and offset) leaves the pixel undecided"},
    {"colour",
     {255, 215, 0},
     "hit and crossings agree, a colour channel differs by more than 0.05"},
    {"stuck", {255, 0, 255}, "ran out of steps where the oracle ended"},
    {"wrong_edge", {255, 110, 0}, "another edge crossed, or another number of them"},
    {"missed_object", {255, 0, 0}, "the oracle hit an object, the ray did not (or another)"},
    {"phantom_hit", {0, 230, 60}, "hit an object the oracle did not"},
    {"early_escape", {0, 230, 230}, "escaped where the oracle met a wall or the floor"},
    {"late_escape", {255, 255, 255}, "met a wall or the floor where the oracle escaped"}};
constexpr size_t kAgree = 0, kAmbiguous = 1, kColour = 2;

float linear(int srgb) {
  const double c = srgb / 255.0;
  return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

size_t class_index(const std::string& name) {
  for (size_t k = 0; k < std::size(kClasses); ++k)
    if (name == kClasses[k].name) return k;
  return kAgree;  // not reached: classify() gives no leak, which only traces show
}

}  // namespace

json difference_legend() {
  json legend = json::array();
  for (const PixelClass& c : kClasses) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "#%02x%02x%02x", c.srgb[0], c.srgb[1], c.srgb[2]);
    legend.push_back({{"class", c.name}, {"colour", hex}, {"meaning", c.meaning}});
  }
  return legend;
}

json recommended_gallery(const std::vector<Scene>& scenes, const json& recommendation,
                         const GalleryOptions& o) {
  if (recommendation.value("backend", json(nullptr)).is_null()) return nullptr;
  const std::string backend_name = recommendation["backend"];
  const std::unique_ptr<Backend> backend = make_backend(backend_name, o.backend_options);
  const Method method = *parse_method(recommendation["method"]);
  const conformance::ImageThresholds image_thresholds;
  json out = {{"backend", backend_name},
              {"method", recommendation["method"]},
              {"size", std::to_string(o.width) + "x" + std::to_string(o.height)},
              {"legend", difference_legend()},
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
      Frame diff(o.width, o.height);
      std::array<size_t, std::size(kClasses)> counts{};
      for (size_t px = 0; px < got.hit.size(); ++px) {
        size_t k = kAgree;
        if (truth.ambiguity[px]) {
          k = kAmbiguous;
        } else if (const auto f = conformance::classify(
                       static_cast<int>(got.hit[px]), static_cast<int>(got.crossings[px]),
                       static_cast<int>(want.hit[px]), static_cast<int>(want.crossings[px]))) {
          k = class_index(conformance::to_string(*f));
        } else {
          for (size_t c = 0; c < 3; ++c)
            if (std::abs(got.rgb[3 * px + c] - want.rgb[3 * px + c]) > image_thresholds.fail)
              k = kColour;
        }
        ++counts[k];
        std::array<float, 3> rgb;
        if (k == kAgree) {
          // The oracle's image at a quarter of its luminance, so the scene stays recognisable.
          const float y = 0.25f * (0.2126f * want.rgb[3 * px] + 0.7152f * want.rgb[3 * px + 1] +
                                   0.0722f * want.rgb[3 * px + 2]);
          rgb = {y, y, y};
        } else {
          for (size_t c = 0; c < 3; ++c) rgb[c] = linear(kClasses[k].srgb[c]);
        }
        diff.set(px, rgb[0], rgb[1], rgb[2], 0.0f, 0.0f, want.hit[px], want.t[px]);
      }
      const std::string image = "recommended/" + scene.name + ".png";
      const std::string diff_image = "recommended/" + scene.name + ".diff.png";
      write_png(got, o.images / image);
      write_png(diff, o.images / diff_image);
      json by_class = json::object();
      for (size_t k = 0; k < std::size(kClasses); ++k) by_class[kClasses[k].name] = counts[k];
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
