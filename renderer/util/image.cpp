// Tone mapping, error measures, and the door to the image I/O module (image_module.h), loaded on
// the first read or write. Not earlier on a thread: dlopen holds the loader's lock throughout, and
// every thread created meanwhile (render threads, a server's pool) stalled for all of it.
#include "image.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstring>
#include <stdexcept>

#include "image_module.h"

namespace pt {

uint8_t tonemap_course(float v) {
  if (!(v > 0)) return 0;  // also maps NaN to black
  float t = std::pow(1.41421356f * v, 1.0f / 2.2f);
  return uint8_t(clampf(t, 0.0f, 1.0f) * 255.0f);
}

double relative_mse(const ImageRGB& img, const ImageRGB& ref) {
  if (img.pixels.size() != ref.pixels.size() || img.pixels.empty()) return INFINITY;
  double s = 0;
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    double a = luminance(img.pixels[i]), b = luminance(ref.pixels[i]);
    s += (a - b) * (a - b) / (b * b + kRelMseEpsilon);
  }
  return s / double(img.pixels.size());
}

double rmse(const ImageRGB& img, const ImageRGB& ref) {
  if (img.pixels.size() != ref.pixels.size() || img.pixels.empty()) return INFINITY;
  double s = 0;
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      double d = double(img.pixels[i][c]) - ref.pixels[i][c];
      s += d * d;
    }
  return std::sqrt(s / (3.0 * img.pixels.size()));
}

std::vector<uint8_t> to_srgb8_course(const ImageRGB& img) {
  std::vector<uint8_t> out(img.pixels.size() * 3);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) out[3 * i + c] = tonemap_course(img.pixels[i][c]);
  return out;
}

namespace {

std::string executable_dir() {
  char buf[PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return "";
  std::string exe(buf, size_t(n));
  return exe.substr(0, exe.find_last_of('/') + 1);
}

// The module files that exist, next to the executable first (a copied pair of files works), then
// where the build put it; each absent one adds a line to `tried`, for the error.
std::vector<std::string> present_module_paths(std::string& tried) {
  std::vector<std::string> candidates, present;
  std::string dir = executable_dir();  // empty if /proc is not mounted: never a path relative to the cwd
  if (!dir.empty() && dir + "pt_imageio.so" != PT_IMAGEIO_MODULE) candidates.push_back(dir + "pt_imageio.so");
  candidates.push_back(PT_IMAGEIO_MODULE);
  for (const std::string& path : candidates) {
    if (access(path.c_str(), R_OK) == 0) present.push_back(path);
    else tried += "\n  " + path + ": absent";
  }
  return present;
}

const char* kUnavailable = "image I/O is unavailable: cannot load the OpenImageIO module pt_imageio.so";

const ImageModule* load_module() {
  std::string tried;
  for (const std::string& path : present_module_paths(tried)) {
    void* handle = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (!handle) {
      tried += "\n  " + path + ": " + dlerror();
      continue;
    }
    auto entry = reinterpret_cast<const ImageModule* (*)()>(dlsym(handle, "pt_image_module"));
    const ImageModule* m = entry ? entry() : nullptr;
    if (m && m->abi == kImageModuleAbi) return m;  // never closed: OpenImageIO keeps state
    tried += "\n  " + path + ": not a pt_imageio module of this build (rebuild it)";
  }
  throw std::runtime_error(kUnavailable + tried);
}

const ImageModule& module() {
  static const ImageModule* m = load_module();  // a failed load throws and is retried next call
  return *m;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower((unsigned char)s[s.size() - suffix.size() + i]) != suffix[i]) return false;
  return true;
}

}  // namespace

void require_image_io() {
  std::string tried;
  if (present_module_paths(tried).empty()) throw std::runtime_error(kUnavailable + tried);
}

void check_image_output(const std::string& path) {
  std::string why = module().writer_problem(path);
  if (!why.empty()) throw std::runtime_error(path + ": " + why);
  size_t slash = path.find_last_of('/');
  std::string dir = slash == std::string::npos ? "." : path.substr(0, std::max<size_t>(slash, 1));
  // The image goes to a temporary file in this folder, then is renamed: it must take new files. A
  // probe file, not access(), which root passes on some read-only mounts (docs/reliability.md).
  std::string probe = dir + "/.pathtracer-probe-" + std::to_string(getpid());
  int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw std::runtime_error(path + ": cannot write into the folder " + dir + " (" + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

void write_png8(const std::vector<uint8_t>& rgb, int width, int height, const std::string& path) {
  module().write_rgb8(rgb, width, height, path, {});
}

void write_image(const ImageRGB& img, const std::string& path, const Metadata& meta, const ExrLayers& layers) {
  for (const ExrLayer& l : layers)
    if (!l.image || l.image->width != img.width || l.image->height != img.height)
      throw std::invalid_argument(path + ": layer '" + l.name + "' is not the image's size");
  if (ends_with(path, ".exr")) module().write_exr(img, layers, path, meta);
  else module().write_rgb8(to_srgb8_course(img), img.width, img.height, path, meta);
}

std::string encode_png8(const std::vector<uint8_t>& rgb, int width, int height) {
  return module().encode_png8(rgb, width, height);
}

std::string encode_exr(const ImageRGB& img, const Metadata& meta) { return module().encode_exr(img, meta); }

ImageRGB read_image(const std::string& path) { return module().read_image(path); }

std::vector<uint8_t> decode_image_rgb8(const uint8_t* data, size_t size, size_t max_pixels, int& width, int& height,
                                       std::vector<uint8_t>* alpha) {
  std::vector<uint8_t> ignored;
  return module().decode_rgb8(data, size, max_pixels, &width, &height, alpha ? alpha : &ignored);
}

std::string check_image_file(const std::string& path, int width, int height) {
  return module().check_image_file(path, width, height);
}

}  // namespace pt
