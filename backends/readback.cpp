#include "backends/readback.hpp"

#include <cstdint>
#include <cstring>

namespace flatmarch {

Frame colour_frame(const void* words, int width, int height) {
  Frame frame = Frame::colour_only(width, height);
  std::memcpy(frame.srgb.data(), words, frame.srgb.size());
  return frame;
}

Frame whole_frame(const void* words, int width, int height) {
  Frame frame(width, height);
  const size_t n = frame.hit.size();
  const auto* w = static_cast<const uint32_t*>(words);
  for (size_t px = 0; px < n; ++px) {
    const uint32_t* colour = w + 4 * px;
    const uint32_t* aov = w + 4 * (n + px);
    std::memcpy(&frame.rgb[3 * px], colour, 3 * sizeof(float));
    frame.steps[px] = static_cast<float>(aov[0]);
    frame.crossings[px] = static_cast<float>(aov[1]);
    frame.hit[px] = static_cast<float>(static_cast<int32_t>(aov[2]));
    std::memcpy(&frame.t[px], &aov[3], sizeof(float));
  }
  return frame;
}

}  // namespace flatmarch
