// glTF before tinygltf: the .glb container, the JSON parsed within our limits and checked against
// the glTF 2.0 schema where the reader relies on it, every error located by its JSON path.
// tinygltf 2.7.0 trusts parts of its input (an image's bufferView range is read unchecked, extras
// nest recursively, the BIN chunk's header is not counted against the file's length), and its own
// messages name no index: it only sees files these checks passed.
#include <nlohmann/json.hpp>

#include <sys/stat.h>

#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "gltf_check.h"

namespace pt::gltf_detail {

namespace {

constexpr uint32_t kGlbMagic = 0x46546C67, kChunkJson = 0x4E4F534A, kChunkBin = 0x004E4942;

uint32_t read_u32(const std::string& b, size_t at) {
  return uint32_t(uint8_t(b[at])) | uint32_t(uint8_t(b[at + 1])) << 8 | uint32_t(uint8_t(b[at + 2])) << 16 |
         uint32_t(uint8_t(b[at + 3])) << 24;
}

const char* const kSupportedExtensions[] = {
    "KHR_lights_punctual",     "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
    "KHR_materials_specular",  "KHR_materials_clearcoat",         "KHR_materials_sheen",        "KHR_materials_volume",
    "KHR_materials_unlit",     "KHR_texture_transform",           "KHR_mesh_quantization"};

bool supported_extension(const std::string& name) {
  for (const char* e : kSupportedExtensions)
    if (name == e) return true;
  return false;
}

// The decoded length of a base64 payload (RFC 4648, section 4), or -1 when it is not base64.
int64_t base64_length(const std::string& s, size_t from) {
  size_t n = s.size() - from, pad = 0;
  while (pad < 2 && n > pad && s[from + n - 1 - pad] == '=') ++pad;
  for (size_t i = from; i < s.size() - pad; ++i) {
    char c = s[i];
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/')) return -1;
  }
  size_t digits = n - pad;
  if (digits % 4 == 1) return -1;
  return int64_t(digits / 4 * 3 + (digits % 4 ? digits % 4 - 1 : 0));
}


}  // namespace

void Checker::asset_and_extensions() {
  const json* asset = object(m_doc, "asset", "", true);
  std::string version = string(*asset, "version", "/asset", true);
  if (version.compare(0, 2, "2.") != 0) fail("/asset/version", "'" + clip(version) + "' is not glTF 2.x");
  std::string min = string(*asset, "minVersion", "/asset");
  if (!min.empty() && min != "2.0") fail("/asset/minVersion", "'" + clip(min) + "' is newer than 2.0");
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    const json* list = array(m_doc, key, "", false);
    if (!list) continue;
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string at = std::string("/") + key + "/" + std::to_string(i);
      if (!(*list)[i].is_string()) fail(at, "must be a string");
      const std::string name = (*list)[i].get<std::string>();
      if (supported_extension(name)) continue;
      if (key[10] == 'R')
      {
        std::string list;
        for (const char* e : kSupportedExtensions) list += std::string(list.empty() ? "" : ", ") + e;
        fail(at, "extension '" + clip(name) + "' is required and not supported (supported: " + list + ")");
      }
      m_ctx.warn("extension " + name, at, "extension '" + clip(name) + "' is not supported and is ignored");
    }
  }
}

// A buffer's or image's uri: a base64 data URI whose length is what the file says, or a file name
// inside the scene's folder (only where external files are allowed).
void Checker::check_uri(const json& o, const std::string& path, int64_t byte_length, bool image) {
  const std::string uri = string(o, "uri", path), at = path + "/uri";
  if (uri.compare(0, 5, "data:") == 0) {
    size_t comma = uri.find(',');
    std::string head = uri.substr(0, std::min(comma, size_t(80)));
    // tinygltf decodes these media types only (IsDataURI); anything else it would open as a file.
    static const char* const kTypes[] = {"application/octet-stream", "application/gltf-buffer", "image/png",
                                         "image/jpeg", "image/bmp", "image/gif", "text/plain"};
    bool known = false;
    for (const char* t : kTypes) known |= head == std::string("data:") + t + ";base64";
    if (comma == std::string::npos || !known)
      fail(at, "data URI '" + clip(printable(head, 80)) + "' is not a base64 buffer or PNG / JPEG image");
    int64_t n = base64_length(uri, comma + 1);
    if (n < 0) fail(at, "the data URI's payload is not base64");
    if (n == 0) fail(at, "the data URI holds no bytes");
    if (!image && n != byte_length)
      fail(at, "the data URI holds " + std::to_string(n) + " bytes, byteLength says " + std::to_string(byte_length));
    return;
  }
  std::string file = local_file_name(uri);
  if (file.empty()) fail(at, "'" + clip(printable(uri)) + "' is not a file in the scene's folder (a relative path without '..')");
  if (m_ctx.base_dir.empty())
    fail(at, "refers to the file '" + clip(printable(file)) + "'; only self-contained glTF is read here (.glb, or data: URIs)");
  // Symbolic links may not lead out of the folder either (tinygltf's reads check it again).
  char folder[PATH_MAX], real[PATH_MAX];
  const std::string full = m_ctx.base_dir + "/" + file;
  const bool found = realpath(m_ctx.base_dir.c_str(), folder) && realpath(full.c_str(), real);
  if (found && std::string(real).compare(0, std::strlen(folder) + 1, std::string(folder) + "/") != 0)
    fail(at, "'" + clip(printable(file)) + "' leads out of the scene's folder");
  if (image) return;  // missing images fail where a material reads them
  struct stat st {};
  if (!found || stat(real, &st) != 0 || !S_ISREG(st.st_mode)) fail(at, "cannot read '" + clip(printable(file)) + "'");
  if (int64_t(st.st_size) != byte_length)
    fail(at, "'" + clip(printable(file)) + "' is " + std::to_string(st.st_size) + " bytes, byteLength says " +
                 std::to_string(byte_length));
}

void Checker::buffers() {
  const int64_t max_bytes = int64_t(m_ctx.limits.max_file_bytes);
  if (const json* bufs = array(m_doc, "buffers", "")) {
    for (size_t i = 0; i < bufs->size(); ++i) {
      const json& b = (*bufs)[i];
      const std::string path = "/buffers/" + std::to_string(i);
      int64_t len = integer(b, "byteLength", path, true, 1, max_bytes);
      m_buffer_length.push_back(len);
      if (b.contains("uri")) {
        check_uri(b, path, len, false);
      } else if (!m_ctx.binary || i != 0) {
        fail(path, "has no uri (only the first buffer of a .glb may use its BIN chunk)");
      } else if (size_t(len) > m_bin_size) {
        fail(path + "/byteLength", std::to_string(len) + " bytes, the BIN chunk holds " + std::to_string(m_bin_size));
      }
    }
  }
  if (const json* views = array(m_doc, "bufferViews", "")) {
    for (size_t i = 0; i < views->size(); ++i) {
      const json& v = (*views)[i];
      const std::string path = "/bufferViews/" + std::to_string(i);
      int64_t b = index(v, "buffer", path, "buffers", true);
      int64_t offset = integer(v, "byteOffset", path, false, 0, max_bytes);
      int64_t len = integer(v, "byteLength", path, true, 1, max_bytes);
      if (offset + len > m_buffer_length[size_t(b)])
        fail(path, "bytes " + std::to_string(offset) + " to " + std::to_string(offset + len) + " lie outside buffer " +
                       std::to_string(b) + " (" + std::to_string(m_buffer_length[size_t(b)]) + " bytes)");
      int64_t stride = integer(v, "byteStride", path, false, 4, 252, 0);
      if (stride % 4) fail(path + "/byteStride", "must be a multiple of 4");
      integer(v, "target", path, false, 0, INT32_MAX);
      m_view_length.push_back(len);
    }
  }
}

namespace {

int component_bytes(int64_t type) {
  switch (type) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
  }
  return 0;
}

int type_components(const std::string& t) {
  if (t == "SCALAR") return 1;
  if (t == "VEC2") return 2;
  if (t == "VEC3") return 3;
  if (t == "VEC4") return 4;
  if (t == "MAT2") return 4;
  if (t == "MAT3") return 9;
  if (t == "MAT4") return 16;
  return 0;
}

}  // namespace

void Checker::accessors() {
  const json* list = array(m_doc, "accessors", "");
  if (!list) return;
  const json* views = m_doc.contains("bufferViews") ? &m_doc["bufferViews"] : nullptr;
  for (size_t i = 0; i < list->size(); ++i) {
    const json& a = (*list)[i];
    const std::string path = "/accessors/" + std::to_string(i);
    int64_t ctype = integer(a, "componentType", path, true, 0, INT32_MAX);
    int csize = component_bytes(ctype);
    if (!csize) fail(path + "/componentType", std::to_string(ctype) + " is not a glTF component type");
    int ncomp = type_components(string(a, "type", path, true));
    if (!ncomp) fail(path + "/type", "'" + clip(printable(a["type"].get<std::string>())) + "' is not an accessor type");
    int64_t n = integer(a, "count", path, true, 1, int64_t(m_ctx.limits.max_values));
    boolean(a, "normalized", path);
    numbers(a, "min", path, 0);
    numbers(a, "max", path, 0);
    int64_t offset = integer(a, "byteOffset", path, false, 0, int64_t(m_ctx.limits.max_file_bytes));
    int64_t view = index(a, "bufferView", path, "bufferViews");
    if (view >= 0) {
      const int64_t elem = int64_t(csize) * ncomp;
      int64_t stride = (*views)[size_t(view)].value("byteStride", int64_t(0));
      if (stride == 0) stride = elem;
      // Every element lies inside the view (n <= max_values and stride <= 252: no overflow).
      int64_t end = offset + stride * (n - 1) + elem;
      if (end > m_view_length[size_t(view)])
        fail(path, std::to_string(n) + " elements of " + std::to_string(elem) + " bytes from byte " + std::to_string(offset) +
                       " (stride " + std::to_string(stride) + ") end at byte " + std::to_string(end) + ", past bufferView " +
                       std::to_string(view) + " (" + std::to_string(m_view_length[size_t(view)]) + " bytes)");
    } else if (offset != 0) {
      fail(path + "/byteOffset", "given without a bufferView");
    }
    if (const json* sparse = object(a, "sparse", path)) {
      const std::string at = path + "/sparse";
      integer(*sparse, "count", at, true, 1, n);
      const json* idx = object(*sparse, "indices", at, true);
      index(*idx, "bufferView", at + "/indices", "bufferViews", true);
      integer(*idx, "byteOffset", at + "/indices", false, 0, INT32_MAX);
      int64_t it = integer(*idx, "componentType", at + "/indices", true, 0, INT32_MAX);
      if (it != 5121 && it != 5123 && it != 5125) fail(at + "/indices/componentType", "must be an unsigned integer type");
      const json* val = object(*sparse, "values", at, true);
      index(*val, "bufferView", at + "/values", "bufferViews", true);
      integer(*val, "byteOffset", at + "/values", false, 0, INT32_MAX);
    }
  }
}

void Checker::images_and_textures() {
  m_checked.decode_image.assign(count("images"), false);
  if (const json* list = array(m_doc, "images", "")) {
    for (size_t i = 0; i < list->size(); ++i) {
      const json& im = (*list)[i];
      const std::string path = "/images/" + std::to_string(i);
      bool has_uri = im.contains("uri"), has_view = im.contains("bufferView");
      if (has_uri == has_view) fail(path, "needs either 'uri' or 'bufferView'");
      if (has_uri) check_uri(im, path, 0, true);
      else index(im, "bufferView", path, "bufferViews", true);
      string(im, "mimeType", path);
    }
  }
  if (const json* list = array(m_doc, "samplers", "")) {
    for (size_t i = 0; i < list->size(); ++i) {
      const json& s = (*list)[i];
      const std::string path = "/samplers/" + std::to_string(i);
      for (const char* key : {"wrapS", "wrapT"}) {
        int64_t w = integer(s, key, path, false, 0, INT32_MAX, 10497);
        if (w != 33071 && w != 33648 && w != 10497)
          fail(path + "/" + key, std::to_string(w) + " is not CLAMP_TO_EDGE, MIRRORED_REPEAT or REPEAT");
      }
      integer(s, "magFilter", path, false, 0, INT32_MAX);
      integer(s, "minFilter", path, false, 0, INT32_MAX);
    }
  }
  if (const json* list = array(m_doc, "textures", "")) {
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string path = "/textures/" + std::to_string(i);
      index((*list)[i], "source", path, "images");
      index((*list)[i], "sampler", path, "samplers");
    }
  }
}

std::string local_file_name(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) && std::isxdigit((unsigned char)uri[i + 2])) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  // No scheme, no absolute path, no parent folder, nothing a path cannot hold.
  if (out.empty() || out[0] == '/' || out.find(':') != std::string::npos || out.find('\\') != std::string::npos ||
      out.find('\0') != std::string::npos || out.find('?') != std::string::npos || out.find('#') != std::string::npos)
    return "";
  size_t start = 0;
  while (start <= out.size()) {
    size_t end = out.find('/', start);
    if (end == std::string::npos) end = out.size();
    const std::string seg = out.substr(start, end - start);
    if (seg == ".." || seg.empty()) return "";
    start = end + 1;
  }
  return out;
}

Parts split_file(const Context& ctx, const std::string& bytes) {
  Parts parts;
  if (!ctx.binary) {
    parts.json = bytes;
    return parts;
  }
  // 12-byte header, then chunks of (length, type, data), each 4-byte aligned (glTF 2.0, 4.4).
  auto bad = [&](const std::string& why) { throw SceneError(ctx.name + ": not a valid .glb: " + why); };
  if (bytes.size() < 20 || read_u32(bytes, 0) != kGlbMagic) bad("no 'glTF' header");
  if (read_u32(bytes, 4) != 2) bad("container version " + std::to_string(read_u32(bytes, 4)) + ", not 2");
  if (read_u32(bytes, 8) != bytes.size())
    bad("the header says " + std::to_string(read_u32(bytes, 8)) + " bytes, the file has " + std::to_string(bytes.size()));
  const uint64_t json_len = read_u32(bytes, 12);
  if (read_u32(bytes, 16) != kChunkJson) bad("the first chunk is not JSON");
  if (json_len == 0 || 20 + json_len > bytes.size()) bad("the JSON chunk's length runs past the file");
  parts.json = bytes.substr(20, size_t(json_len));
  uint64_t at = 20 + json_len;
  if (at % 4) bad("the JSON chunk does not end on a 4-byte boundary");
  if (at < bytes.size()) {
    if (at + 8 > bytes.size()) bad("a chunk header is cut short");
    const uint64_t bin_len = read_u32(bytes, size_t(at));
    if (read_u32(bytes, size_t(at) + 4) != kChunkBin) bad("the second chunk is not BIN");
    if (at + 8 + bin_len > bytes.size()) bad("the BIN chunk's length runs past the file");
    if (bin_len == 0 || bin_len % 4) bad("the BIN chunk is empty or does not end on a 4-byte boundary");
    parts.bin = reinterpret_cast<const uint8_t*>(bytes.data()) + at + 8;
    parts.bin_size = size_t(bin_len);
  }
  return parts;
}

}  // namespace pt::gltf_detail
