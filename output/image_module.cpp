// The image module (see image_library.hpp): everything flatmarch does with OpenImageIO.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <limits>
#include <stdexcept>

#include "output/image_library.hpp"

namespace flatmarch {

namespace {

constexpr const char* kAovChannels[] = {"R", "G", "B", "steps", "crossings", "hit", "t"};
constexpr int kAovCount = 7;

void check(bool ok, const OIIO::ImageBuf& buf, const std::string& path, const char* doing) {
  if (!ok)
    throw std::runtime_error("cannot " + std::string(doing) + " " + path + ": " + buf.geterror());
}

const char* version() {
  return OIIO_VERSION_STRING;
}

void write_png(const Frame& frame, const std::string& png) {
  const OIIO::ImageSpec spec(frame.width, frame.height, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf linear(spec, const_cast<float*>(frame.rgb.data()));
  OIIO::ImageBuf srgb = OIIO::ImageBufAlgo::colorconvert(linear, "linear", "sRGB");
  check(!srgb.has_error(), srgb, png, "convert the colours of");
  srgb = OIIO::ImageBufAlgo::clamp(srgb, 0.0f, 1.0f);
  srgb.set_write_format(OIIO::TypeDesc::UINT8);
  check(srgb.write(png), srgb, png, "write");
}

void write_aov_exr(const Frame& frame, const std::string& exr) {
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
  check(buf.write(exr), buf, exr, "write");
}

void read_aov_exr(const std::string& exr, Frame& frame, unsigned* present) {
  OIIO::ImageBuf buf(exr);
  check(buf.read(0, 0, true, OIIO::TypeDesc::FLOAT), buf, exr, "read");
  // OpenEXR keeps channels sorted by name, so look each one up.
  const OIIO::ImageSpec& spec = buf.spec();
  int index[kAovCount];
  for (int k = 0; k < kAovCount; ++k) {
    index[k] = spec.channelindex(kAovChannels[k]);
    if (index[k] < 0 && !present) throw std::runtime_error(exr + ": no channel " + kAovChannels[k]);
  }
  if (present) {
    *present = 0;
    for (int k = 0; k < kAovCount; ++k) *present |= index[k] >= 0 ? 1u << k : 0u;
  }
  frame = Frame(spec.width, spec.height);
  std::vector<float> pixel(static_cast<size_t>(spec.nchannels));
  for (int j = 0; j < frame.height; ++j)
    for (int i = 0; i < frame.width; ++i) {
      buf.getpixel(i, j, pixel.data(), spec.nchannels);
      const auto channel = [&](int k) {
        return index[k] < 0 ? std::numeric_limits<float>::quiet_NaN()
                            : pixel[static_cast<size_t>(index[k])];
      };
      const size_t px = frame.pixel(i, j);
      for (int k = 0; k < 3; ++k) frame.rgb[3 * px + static_cast<size_t>(k)] = channel(k);
      frame.steps[px] = channel(3);
      frame.crossings[px] = channel(4);
      frame.hit[px] = channel(5);
      frame.t[px] = channel(6);
    }
}

void read_png(const std::string& png, std::vector<uint8_t>& rgb, int& width, int& height) {
  OIIO::ImageBuf buf(png);
  check(buf.read(0, 0, true, OIIO::TypeDesc::UINT8), buf, png, "read");
  const OIIO::ImageSpec& spec = buf.spec();
  if (spec.nchannels < 3) throw std::runtime_error(png + ": not an RGB image");
  width = spec.width;
  height = spec.height;
  rgb.resize(3 * static_cast<size_t>(width) * static_cast<size_t>(height));
  check(
      buf.get_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, 3), OIIO::TypeDesc::UINT8, rgb.data()),
      buf, png, "read the pixels of");
}

OIIO::ImageBuf colour_image(const Frame& f) {
  OIIO::ImageBuf image(OIIO::ImageSpec(f.width, f.height, 3, OIIO::TypeDesc::FLOAT));
  image.set_pixels(OIIO::ROI(0, f.width, 0, f.height, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT,
                   f.rgb.data());
  return image;
}

size_t perceptual(const Frame& got, const Frame& truth) {
  const OIIO::ImageBuf a = colour_image(got), b = colour_image(truth);
  OIIO::ImageBufAlgo::CompareResults yee;
  return static_cast<size_t>(std::max(0, OIIO::ImageBufAlgo::compare_Yee(a, b, yee)));
}

const ImageLibrary kLibrary{.abi = kImageLibraryAbi,
                            .version = version,
                            .write_png = write_png,
                            .write_aov_exr = write_aov_exr,
                            .read_aov_exr = read_aov_exr,
                            .read_png = read_png,
                            .perceptual = perceptual};

}  // namespace

}  // namespace flatmarch

extern "C" const flatmarch::ImageLibrary* flatmarch_image_library() {
  return &flatmarch::kLibrary;
}
