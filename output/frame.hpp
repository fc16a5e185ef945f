// A rendered frame (DESIGN.md section 4): its colour and AOVs as every backend writes them and the
// PNG and EXR writers (image_io.hpp) write them out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include "kernels/constants.hpp"
#include "scene/geometry.hpp"

namespace flatmarch {

// An allocator whose new elements are left uninitialised (default-initialised), for buffers
// that are written in full before they are read, and which start on a cache line: threads that
// write neighbouring blocks of a frame's rows then share no line where the blocks' widths are
// whole lines (simd::TileBlocks).
template <typename T>
struct UninitialisedAllocator : std::allocator<T> {
  static constexpr std::align_val_t kAlignment{64};
  template <typename U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <typename U>
  explicit UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  T* allocate(size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlignment)); }
  void deallocate(T* p, size_t) noexcept { ::operator delete(p, kAlignment); }
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// One channel of a frame. A new frame's channels are not zeroed: every backend writes every
// pixel, and a large frame's memory is then first touched (its pages faulted in) by the
// threads that render it, in parallel, rather than zeroed beforehand by one.
using Channel = std::vector<float, UninitialisedAllocator<float>>;

// A rendered frame: colour and the AOVs, row-major with row 0 at the top. A frame of its colour
// alone (Backend::render_colour, from a GPU backend) has `srgb` instead, and no other channel.
struct Frame {
  int width = 0, height = 0;
  Channel rgb;  // linear colour, 3 floats a pixel
  Channel steps, crossings, hit, t;
  // The colour as a PNG holds it: tone-mapped, sRGB-encoded, 8 bits a channel, 4 bytes a pixel
  // (r, g, b, 255); empty but in a frame of the colour alone.
  std::vector<uint8_t, UninitialisedAllocator<uint8_t>> srgb;

  Frame() = default;
  // A frame of the colour alone: only `srgb`, to be written in full.
  static Frame colour_only(int w, int h) {
    Frame f;
    f.width = w;
    f.height = h;
    f.srgb.resize(4 * static_cast<size_t>(w) * static_cast<size_t>(h));
    return f;
  }
  // Every pixel must then be written (set). Inline: the image module (output/image_library.hpp)
  // makes frames without linking the backends.
  Frame(int w, int h)
      : width(w),
        height(h),
        rgb(3 * static_cast<size_t>(w) * static_cast<size_t>(h)),
        steps(static_cast<size_t>(w) * static_cast<size_t>(h)),
        crossings(steps.size()),
        hit(steps.size()),
        t(steps.size()) {}
  size_t pixel(int i, int j) const {
    return static_cast<size_t>(j) * static_cast<size_t>(width) + static_cast<size_t>(i);
  }
  // Writes pixel (i, j): its linear colour and how its ray ended.
  void set(int i, int j, Vec3 color, int ray_steps, int ray_crossings, int ray_hit, double ray_t) {
    set(pixel(i, j), static_cast<float>(color.x), static_cast<float>(color.y),
        static_cast<float>(color.z), static_cast<float>(ray_steps),
        static_cast<float>(ray_crossings), static_cast<float>(ray_hit), static_cast<float>(ray_t));
  }
  // The same for pixel index `px` (pixel()), with every value already a channel's float.
  void set(size_t px, float red, float green, float blue, float ray_steps, float ray_crossings,
           float ray_hit, float ray_t) {
    rgb[3 * px] = red;
    rgb[3 * px + 1] = green;
    rgb[3 * px + 2] = blue;
    steps[px] = ray_steps;
    crossings[px] = ray_crossings;
    hit[px] = ray_hit;
    t[px] = ray_t;
  }
  // Paints the pixels whose rays failed (max_steps, max_distance, vertex) in `loud`, for people
  // studying the methods (render --show-failures); returns how many. The kernel shades them
  // as fog.
  int paint_failures(Vec3 loud) {
    int painted = 0;
    for (size_t px = 0; px < hit.size(); ++px) {
      const int h = static_cast<int>(hit[px]);
      if (h != kHitMaxSteps && h != kHitMaxDistance && h != kHitVertex) continue;
      rgb[3 * px] = static_cast<float>(loud.x);
      rgb[3 * px + 1] = static_cast<float>(loud.y);
      rgb[3 * px + 2] = static_cast<float>(loud.z);
      ++painted;
    }
    return painted;
  }
};

}  // namespace flatmarch
