// A minimal PNG writer for tests: 8-bit RGBA, zlib "stored" blocks (RFC 1950/1951), no filter.
// The product decodes PNGs through OpenImageIO and encodes only RGB; tests of alpha textures need
// an RGBA file, and a few dozen lines here keep a test-only format out of the image module.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace pt::test {

inline uint32_t png_crc(const std::string& bytes) {  // the CRC-32 of ISO 3309, as PNG chunks use
  uint32_t c = 0xffffffffu;
  for (unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

inline void put_be32(std::string& s, uint32_t v) {
  for (int k = 3; k >= 0; --k) s += char((v >> (8 * k)) & 0xff);
}

// `rgba`: 4 bytes a texel, the top row first.
inline std::string encode_png_rgba(const std::vector<uint8_t>& rgba, int width, int height) {
  std::string raw;
  for (int y = 0; y < height; ++y) {
    raw += '\0';  // filter type 0 for each row
    raw.append(reinterpret_cast<const char*>(rgba.data()) + size_t(4 * width * y), size_t(4 * width));
  }
  std::string z = "\x78\x01";
  uint32_t a = 1, b = 0;  // Adler-32
  for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  for (size_t at = 0; at < raw.size() || at == 0; at += 65535) {
    const size_t n = std::min<size_t>(65535, raw.size() - at);
    z += char(at + n >= raw.size() ? 1 : 0);
    z += char(n & 0xff), z += char(n >> 8), z += char(~n & 0xff), z += char((~n >> 8) & 0xff);
    z += raw.substr(at, n);
    if (raw.empty()) break;
  }
  put_be32(z, (b << 16) | a);
  auto chunk = [](std::string& out, const char* type, const std::string& data) {
    put_be32(out, uint32_t(data.size()));
    const std::string body = std::string(type) + data;
    out += body;
    put_be32(out, png_crc(body));
  };
  std::string ihdr;
  put_be32(ihdr, uint32_t(width));
  put_be32(ihdr, uint32_t(height));
  ihdr += std::string("\x08\x06\x00\x00\x00", 5);  // 8 bits, RGBA, deflate, no filter set, no interlace
  std::string png = "\x89PNG\r\n\x1a\n";
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", "");
  return png;
}

}  // namespace pt::test
