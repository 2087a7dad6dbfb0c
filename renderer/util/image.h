// Film images, the course's tone mapping, and all image I/O through OpenImageIO (loaded on the
// first read or write: image_module.h).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "math.h"

namespace pt {

struct ImageRGB {
  int width = 0, height = 0;
  std::vector<Vec3> pixels;  // top row first
  Vec3& at(int x, int y) { return pixels[size_t(y) * width + x]; }
  const Vec3& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

// A width x height image whose pixel i (top row first) is pixel(i): how films hand out their means.
template <class PixelAt>
ImageRGB make_image(int width, int height, PixelAt pixel) {
  ImageRGB img;
  img.width = width;
  img.height = height;
  img.pixels.resize(size_t(width) * size_t(height));
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = pixel(i);
  return img;
}

using Metadata = std::vector<std::pair<std::string, std::string>>;

// An EXR file's further layer beside its RGB: "albedo" writes channels albedo.R, albedo.G, albedo.B
// (OpenEXR's layer.channel naming; `xyz`: .X, .Y, .Z, for a normal).
struct ExrLayer {
  std::string name;
  const ImageRGB* image;
  bool xyz = false;
};
using ExrLayers = std::vector<ExrLayer>;

// Relative MSE on luminance, mean of (a - ref)^2 / (ref^2 + eps): the error measure the renderer
// estimates and the benchmarks report (eps keeps black pixels from dominating).
constexpr double kRelMseEpsilon = 1e-2;
double relative_mse(const ImageRGB& img, const ImageRGB& ref);
// Root mean square error over all pixels and channels.
double rmse(const ImageRGB& img, const ImageRGB& ref);

// The course's look: clamp((sqrt(2) v)^(1/2.2), 0, 1) * 255, truncated.
uint8_t tonemap_course(float v);
std::vector<uint8_t> to_srgb8_course(const ImageRGB& img);
// Writes PNG (course tone mapping, 8-bit) or EXR (linear float + metadata) by extension.
// Writes go to a temporary file in the same directory, then rename: never a partial file.
// `layers` (each img's size) go into an EXR beside its RGB; a PNG leaves them out.
void write_image(const ImageRGB& img, const std::string& path, const Metadata& meta = {}, const ExrLayers& layers = {});
// Writes 8-bit RGB rows (top first) as PNG, atomically.
void write_png8(const std::vector<uint8_t>& rgb, int width, int height, const std::string& path);
// Encodes 8-bit RGB rows as PNG bytes in memory (for streaming tiles).
std::string encode_png8(const std::vector<uint8_t>& rgb, int width, int height);
// Encodes a float image as EXR bytes in memory (linear, with metadata).
std::string encode_exr(const ImageRGB& img, const Metadata& meta = {});
// Reads any image OpenImageIO can read as linear RGB float (top row first); throws on failure.
ImageRGB read_image(const std::string& path);
// Decodes a PNG or JPEG held in memory (recognised by its signature) as 8-bit RGB, top row first:
// grey is replicated, 16-bit samples rounded. An image of more than max_pixels is refused from its
// header, before its pixels are decoded. Throws std::runtime_error saying why. `alpha`, when
// given, receives the alpha channel (one byte a texel), or stays empty when the image has none or
// every texel is opaque.
std::vector<uint8_t> decode_image_rgb8(const uint8_t* data, size_t size, size_t max_pixels, int& width, int& height,
                                       std::vector<uint8_t>* alpha = nullptr);
// Empty when the image file reads back whole as a width x height image (a PNG also ends with its
// IEND chunk), else what is wrong with it. Files written by write_image are checked so before
// they take their name; this checks files written earlier.
std::string check_image_file(const std::string& path, int width, int height);
// Throws, naming where it looked, when the image module is not there, without loading it: called
// before renders whose images would otherwise be lost to a missing module at the end.
void require_image_io();
// Throws, naming the path, unless an image can be written there: a known format and a folder that
// takes files. Loads the module (before any render thread exists: image_module.h), so that a
// render never runs for hours only to find it cannot be saved.
void check_image_output(const std::string& path);

}  // namespace pt
