// The OpenImageIO module (image_module.h): every image read and write, loaded on first use so that
// processes that never touch an image skip OpenImageIO's dependency tree. Files are written
// atomically: temp file, fsync, then rename.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "image_module.h"

// Named apart from image.h's functions of the same names, which forward here.
namespace pt::oiio_module {

namespace OIIO = OIIO_NAMESPACE;

std::string temp_name(const std::string& path) {
  static std::atomic<int> counter{0};
  std::string dir, base = path;
  size_t slash = path.find_last_of('/');
  if (slash != std::string::npos) {
    dir = path.substr(0, slash + 1);
    base = path.substr(slash + 1);
  }
  return dir + "." + base + ".tmp" + std::to_string(getpid()) + "-" + std::to_string(counter++);
}

// A PNG's last 12 bytes are its IEND chunk (length 0, type, CRC): a file cut short lacks them.
bool ends_with_iend(const std::string& path) {
  static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  unsigned char tail[12];
  off_t size = ::lseek(fd, 0, SEEK_END);
  bool ok = size >= 12 && ::pread(fd, tail, 12, size - 12) == 12 && std::memcmp(tail, iend, 12) == 0;
  ::close(fd);
  return ok;
}

std::string extension(const std::string& path) {
  std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  for (char& c : ext) c = char(std::tolower((unsigned char)c));
  return ext;
}
bool is_png(const std::string& path) { return extension(path) == ".png"; }

// Reads the file at `path` whole as `type` ("" when it holds width x height x channels pixels),
// into `pixels` when given.
std::string read_back(const std::string& path, bool png, int width, int height, int channels, OIIO::TypeDesc type,
                      std::vector<unsigned char>* pixels) {
  if (png && !ends_with_iend(path)) return "the file is cut short (no IEND chunk)";
  auto in = OIIO::ImageInput::open(path);
  if (!in) return "cannot be read back (" + OIIO::geterror() + ")";
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width != width || spec.height != height || spec.nchannels < channels)
    return "reads back as " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " with " +
           std::to_string(spec.nchannels) + " channels, not " + std::to_string(width) + "x" + std::to_string(height);
  std::vector<unsigned char> buf(size_t(width) * height * channels * type.size());
  if (!in->read_image(0, 0, 0, channels, type, buf.data())) return "its pixels cannot be read back (" + in->geterror() + ")";
  if (pixels) *pixels = std::move(buf);
  return "";
}

// Reads a written temp file back and compares it with what was meant: a writer that reported
// success on a full disk (seen with PNG) must not put a truncated image in place.
void verify_written(const std::string& path, const std::string& tmp, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                    const void* data) {
  std::vector<unsigned char> back;
  std::string why = read_back(tmp, is_png(path), spec.width, spec.height, spec.nchannels, type, &back);
  bool lossless = is_png(path) || extension(path) == ".exr";  // a JPEG reads back other pixels by design
  if (why.empty() && lossless && std::memcmp(back.data(), data, back.size()) != 0) why = "its pixels differ from those written";
  if (!why.empty()) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write image: the written file " + why +
                             " (a short write: is the disk full?)");
  }
}

void write_atomic(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type, const void* data) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::runtime_error(path + ": cannot write this image format (" + OIIO::geterror() + ")");
  std::string tmp = temp_name(path);
  errno = 0;
  if (!out->open(tmp, spec) || !out->write_image(type, data) || !out->close()) {
    // OpenImageIO's message does not say why a write failed: the system's reason does (full disk,
    // file-size limit, read-only or vanished folder).
    int why = errno;
    std::string err = out->geterror();
    if (why == ENOSPC || why == EFBIG || why == EDQUOT || why == EROFS || why == EIO || why == ENOENT || why == ENOTDIR ||
        why == EACCES || why == EMFILE || why == ENFILE)
      err += std::string(err.empty() ? "" : " ") + "(" + std::strerror(why) + ")";
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write image: " + err);
  }
  // On the disk before the rename: after a crash the name holds the old file or the whole new one.
  int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    std::string err = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write image: " + err);
  }
  ::close(fd);
  verify_written(path, tmp, spec, type, data);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot move the finished image into place");
  }
}

// One EXR header for the file and the in-memory copy: linear float RGB, zip, our metadata.
OIIO::ImageSpec exr_spec(const ImageRGB& img, const Metadata& meta) {
  OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::FLOAT);
  spec.attribute("compression", "zip");
  for (const auto& kv : meta) spec.attribute(kv.first, kv.second);
  return spec;
}

void write_exr(const ImageRGB& img, const ExrLayers& unsorted, const std::string& path, const Metadata& meta) {
  if (unsorted.empty()) return write_atomic(path, exr_spec(img, meta), OIIO::TypeDesc::FLOAT, img.pixels.data());
  // In the order OpenImageIO reads them back (R, G, B, then the layers by name), which the
  // verification compares against.
  ExrLayers layers = unsorted;
  std::stable_sort(layers.begin(), layers.end(), [](const ExrLayer& a, const ExrLayer& b) { return a.name < b.name; });
  OIIO::ImageSpec spec = exr_spec(img, meta);
  const size_t nc = 3 + 3 * layers.size(), n = img.pixels.size();
  spec.nchannels = int(nc);
  spec.channelnames = {"R", "G", "B"};
  for (const ExrLayer& l : layers)
    for (const char* c : l.xyz ? std::vector<const char*>{"X", "Y", "Z"} : std::vector<const char*>{"R", "G", "B"})
      spec.channelnames.push_back(l.name + "." + c);
  std::vector<float> data(n * nc);  // interleaved, pixel by pixel
  for (size_t i = 0; i < n; ++i) {
    float* px = &data[i * nc];
    px[0] = img.pixels[i].x, px[1] = img.pixels[i].y, px[2] = img.pixels[i].z;
    for (size_t k = 0; k < layers.size(); ++k) {
      const Vec3 v = layers[k].image->pixels[i];
      px[3 + 3 * k] = v.x, px[4 + 3 * k] = v.y, px[5 + 3 * k] = v.z;
    }
  }
  write_atomic(path, spec, OIIO::TypeDesc::FLOAT, data.data());
}

void write_rgb8(const std::vector<uint8_t>& rgb, int width, int height, const std::string& path,
                const Metadata& meta) {
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  for (const auto& kv : meta) spec.attribute(kv.first, kv.second);
  write_atomic(path, spec, OIIO::TypeDesc::UINT8, rgb.data());
}

std::string encode_png8(const std::vector<uint8_t>& rgb, int width, int height) {
  std::vector<unsigned char> buffer;
  OIIO::Filesystem::IOVecOutput vec(buffer);
  auto out = OIIO::ImageOutput::create("tile.png");
  if (!out) throw std::runtime_error("PNG encoder unavailable");
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  OIIO::Filesystem::IOProxy* proxy = &vec;
  spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  spec.attribute("png:compressionLevel", 3);
  if (!out->open("tile.png", spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) || !out->close())
    throw std::runtime_error("PNG encoding failed: " + out->geterror());
  return std::string(buffer.begin(), buffer.end());
}

std::string encode_exr(const ImageRGB& img, const Metadata& meta) {
  std::vector<unsigned char> buffer;
  OIIO::Filesystem::IOVecOutput vec(buffer);
  auto out = OIIO::ImageOutput::create("image.exr");
  if (!out) throw std::runtime_error("EXR encoder unavailable");
  OIIO::ImageSpec spec = exr_spec(img, meta);
  OIIO::Filesystem::IOProxy* proxy = &vec;
  spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  if (!out->supports("ioproxy")) throw std::runtime_error("this OpenImageIO cannot write EXR to memory");
  if (!out->open("image.exr", spec) || !out->write_image(OIIO::TypeDesc::FLOAT, img.pixels.data()) || !out->close())
    throw std::runtime_error("EXR encoding failed: " + out->geterror());
  return std::string(buffer.begin(), buffer.end());
}

ImageRGB read_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error(path + ": cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || int64_t(spec.width) * spec.height > (int64_t(1) << 28))
    throw std::runtime_error(path + ": image size is not usable");
  std::vector<float> data(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data()))
    throw std::runtime_error(path + ": cannot read pixels: " + in->geterror());
  int ch[3] = {0, spec.nchannels > 1 ? 1 : 0, spec.nchannels > 2 ? 2 : 0};
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < spec.nchannels; ++i)
      if (spec.channelnames.size() > size_t(i) && spec.channelnames[i] == names[c]) ch[c] = i;
  ImageRGB img;
  img.width = spec.width;
  img.height = spec.height;
  img.pixels.resize(size_t(spec.width) * spec.height);
  for (size_t p = 0; p < img.pixels.size(); ++p)
    img.pixels[p] = Vec3(data[p * spec.nchannels + ch[0]], data[p * spec.nchannels + ch[1]], data[p * spec.nchannels + ch[2]]);
  return img;
}

std::string check_image_file(const std::string& path, int width, int height) {
  return read_back(path, is_png(path), width, height, 3, OIIO::TypeDesc::FLOAT, nullptr);
}

std::vector<uint8_t> decode_rgb8(const uint8_t* data, size_t size, size_t max_pixels, int* width, int* height,
                                 std::vector<uint8_t>* alpha) {
  // The signature decides the decoder (glTF 2.0 core images are PNG or JPEG), not a MIME type.
  static const uint8_t png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}, jpeg[3] = {0xff, 0xd8, 0xff};
  const char* name = nullptr;
  if (size >= 8 && std::memcmp(data, png, 8) == 0) name = "texture.png";
  else if (size >= 3 && std::memcmp(data, jpeg, 3) == 0) name = "texture.jpg";
  else throw std::runtime_error("not a PNG or JPEG image");
  // A PNG's chunks must all be there up to IEND: OpenImageIO 2.4's read callback reports a short
  // read by a longjmp through libpng that skips its own C++ destructors (a leak the fuzzer found).
  if (name[8] == 'p') {
    size_t at = 8;
    for (;;) {
      if (size - at < 12) throw std::runtime_error("the PNG is cut short");
      const size_t len = size_t(data[at]) << 24 | size_t(data[at + 1]) << 16 | size_t(data[at + 2]) << 8 | data[at + 3];
      if (len > size - at - 12) throw std::runtime_error("the PNG is cut short");
      if (std::memcmp(data + at + 4, "IEND", 4) == 0) break;
      at += 12 + len;
    }
  }
  OIIO::Filesystem::IOMemReader reader(data, size);
  // glTF's colours are not premultiplied by alpha (glTF 2.0, 3.9.2); OpenImageIO's PNG reader
  // would premultiply them, darkening every texel that is not opaque.
  // With a config, OpenImageIO 2.4 takes the proxy from it, not from the argument.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  OIIO::Filesystem::IOProxy* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open(name, &config, &reader);
  if (!in) throw std::runtime_error("cannot decode the image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
    throw std::runtime_error("the image has no usable size");
  const uint64_t pixels = uint64_t(spec.width) * uint64_t(spec.height);
  if (pixels > max_pixels)
    throw std::runtime_error(std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels, over the limit of " +
                             std::to_string(max_pixels));
  const int nc = spec.nchannels;
  std::vector<uint8_t> raw(size_t(pixels) * size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, raw.data()))
    throw std::runtime_error("cannot decode the image's pixels: " + in->geterror());
  std::vector<uint8_t> rgb(size_t(pixels) * 3);
  for (size_t i = 0; i < size_t(pixels); ++i)
    for (int c = 0; c < 3; ++c) rgb[3 * i + size_t(c)] = raw[i * size_t(nc) + size_t(nc >= 3 ? c : 0)];
  alpha->clear();
  const int ac = spec.alpha_channel >= 0 ? spec.alpha_channel : nc == 2 || nc == 4 ? nc - 1 : -1;
  if (ac >= 3 || (ac >= 1 && nc == 2)) {
    bool opaque = true;
    for (size_t i = 0; i < size_t(pixels) && opaque; ++i) opaque = raw[i * size_t(nc) + size_t(ac)] == 255;
    if (!opaque) {
      alpha->resize(size_t(pixels));
      for (size_t i = 0; i < size_t(pixels); ++i) (*alpha)[i] = raw[i * size_t(nc) + size_t(ac)];
    }
  }
  *width = spec.width;
  *height = spec.height;
  return rgb;
}

std::string writer_problem(const std::string& path) {
  if (OIIO::ImageOutput::create(path)) return "";
  return "cannot write this image format (" + OIIO::geterror() + ")";
}

}  // namespace pt::oiio_module

extern "C" __attribute__((visibility("default"))) const pt::ImageModule* pt_image_module() {
  namespace m = pt::oiio_module;
  static const pt::ImageModule table = {pt::kImageModuleAbi, m::write_exr,  m::write_rgb8,    m::encode_png8,
                                        m::encode_exr,       m::read_image, m::writer_problem,
                                        m::check_image_file, m::decode_rgb8};
  return &table;
}
