// The image I/O module's interface. OpenImageIO on Debian 12 pulls in about 260 shared libraries
// (OpenCV, GDAL, FFmpeg, GStreamer, ...), and loading them took 0.35-0.45 s at every process start:
// `pathtracer --help` spent that long, and so did every test process and the server. So all
// OpenImageIO code lives in a module, pt_imageio.so (image_oiio.cpp), that image.cpp loads with
// dlopen on the first read or write (not earlier on a thread: see image.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "image.h"

namespace pt {

// Bumped whenever the table below changes, so a stale module is refused by name, not called.
constexpr uint32_t kImageModuleAbi = 6;

struct ImageModule {
  uint32_t abi;
  // Linear float EXR with metadata and further layers, written atomically (temp file, fsync, rename).
  void (*write_exr)(const ImageRGB& img, const ExrLayers& layers, const std::string& path, const Metadata& meta);
  // 8-bit RGB rows (top first) in whatever format the extension names, written atomically.
  void (*write_rgb8)(const std::vector<uint8_t>& rgb, int width, int height, const std::string& path,
                     const Metadata& meta);
  std::string (*encode_png8)(const std::vector<uint8_t>& rgb, int width, int height);
  std::string (*encode_exr)(const ImageRGB& img, const Metadata& meta);
  ImageRGB (*read_image)(const std::string& path);
  // Empty when there is a writer for the path's format, else why not (nothing is written).
  std::string (*writer_problem)(const std::string& path);
  // Empty when the file reads back whole as a width x height image, else what is wrong.
  std::string (*check_image_file)(const std::string& path, int width, int height);
  // A PNG or JPEG in memory as 8-bit RGB (top row first) and its alpha; see decode_image_rgb8 in image.h.
  std::vector<uint8_t> (*decode_rgb8)(const uint8_t* data, size_t size, size_t max_pixels, int* width, int* height,
                                      std::vector<uint8_t>* alpha);
};

}  // namespace pt

// The module's one exported symbol.
extern "C" const pt::ImageModule* pt_image_module();
