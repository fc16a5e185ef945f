#include "output/image_io.hpp"

#include <stdexcept>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

namespace flatmarch {

namespace {

constexpr const char* kAovChannels[] = {"R", "G", "B", "steps", "crossings", "hit", "t"};
constexpr int kAovCount = 7;

void check(bool ok, const OIIO::ImageBuf& buf, const std::filesystem::path& path,
           const char* doing) {
  if (!ok)
    throw std::runtime_error("cannot " + std::string(doing) + " " + path.string() + ": " +
                             buf.geterror());
}

}  // namespace

std::filesystem::path aov_path(const std::filesystem::path& png) {
  std::filesystem::path exr = png;
  return exr.replace_extension(".exr");
}

void write_png(const Frame& frame, const std::filesystem::path& png) {
  const OIIO::ImageSpec spec(frame.width, frame.height, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf linear(spec, const_cast<float*>(frame.rgb.data()));
  OIIO::ImageBuf srgb = OIIO::ImageBufAlgo::colorconvert(linear, "linear", "sRGB");
  check(!srgb.has_error(), srgb, png, "convert the colours of");
  srgb = OIIO::ImageBufAlgo::clamp(srgb, 0.0f, 1.0f);
  srgb.set_write_format(OIIO::TypeDesc::UINT8);
  check(srgb.write(png.string()), srgb, png, "write");
}

void write_aov_exr(const Frame& frame, const std::filesystem::path& exr) {
  OIIO::ImageSpec spec(frame.width, frame.height, kAovCount, OIIO::TypeDesc::FLOAT);
  spec.channelnames.assign(std::begin(kAovChannels), std::end(kAovChannels));
  spec.attribute("compression", "zip");
  OIIO::ImageBuf buf(spec);
  std::vector<float> pixel(kAovCount);
  for (int j = 0; j < frame.height; ++j)
    for (int i = 0; i < frame.width; ++i) {
      const size_t px = frame.pixel(i, j);
      pixel = {frame.rgb[3 * px], frame.rgb[3 * px + 1], frame.rgb[3 * px + 2],
               frame.steps[px],   frame.crossings[px],   frame.hit[px],
               frame.t[px]};
      buf.setpixel(i, j, pixel.data());
    }
  check(buf.write(exr.string()), buf, exr, "write");
}

Frame read_aov_exr(const std::filesystem::path& exr) {
  OIIO::ImageBuf buf(exr.string());
  check(buf.read(0, 0, true, OIIO::TypeDesc::FLOAT), buf, exr, "read");
  // OpenEXR keeps channels sorted by name, so look each one up.
  const OIIO::ImageSpec& spec = buf.spec();
  int index[kAovCount];
  for (int k = 0; k < kAovCount; ++k) {
    index[k] = spec.channelindex(kAovChannels[k]);
    if (index[k] < 0) throw std::runtime_error(exr.string() + ": no channel " + kAovChannels[k]);
  }
  Frame frame(spec.width, spec.height);
  std::vector<float> pixel(static_cast<size_t>(spec.nchannels));
  for (int j = 0; j < frame.height; ++j)
    for (int i = 0; i < frame.width; ++i) {
      buf.getpixel(i, j, pixel.data(), spec.nchannels);
      const auto channel = [&](int k) { return pixel[static_cast<size_t>(index[k])]; };
      const size_t px = frame.pixel(i, j);
      for (int k = 0; k < 3; ++k) frame.rgb[3 * px + static_cast<size_t>(k)] = channel(k);
      frame.steps[px] = channel(3);
      frame.crossings[px] = channel(4);
      frame.hit[px] = channel(5);
      frame.t[px] = channel(6);
    }
  return frame;
}

}  // namespace flatmarch
