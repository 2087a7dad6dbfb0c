// The scene entry point: pick the loader by content and name, read files with the size limit.
#include "scene_file.h"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "collada.h"
#include "gltf.h"
#include "nearest.h"

namespace pt {

namespace {

bool has_extension(const std::string& name, const char* ext) {
  const std::string e(ext);
  if (name.size() < e.size()) return false;
  for (size_t i = 0; i < e.size(); ++i)
    if (std::tolower((unsigned char)name[name.size() - e.size() + i]) != e[i]) return false;
  return true;
}

// What a file that is no scene looks like, by its first bytes, for the message.
std::string what_it_is(const std::string& bytes) {
  static const struct { const char* magic; size_t size; const char* kind; } kMagic[] = {
      {"\x89PNG", 4, "a PNG image"},      {"\xFF\xD8\xFF", 3, "a JPEG image"},
      {"\x76\x2F\x31\x01", 4, "an OpenEXR image"}, {"PK\x03\x04", 4, "a ZIP archive"},
      {"\x1F\x8B", 2, "a gzip file"},      {"%PDF", 4, "a PDF document"},
      {"\x7F" "ELF", 4, "a program"}};
  for (const auto& m : kMagic)
    if (bytes.size() >= m.size && bytes.compare(0, m.size, m.magic, m.size) == 0) return m.kind;
  if (bytes.empty()) return "an empty file";
  return "";
}

// COLLADA is XML: after a byte order mark and white space, its first character is '<'.
bool looks_like_xml(const std::string& bytes) {
  size_t i = bytes.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  if (bytes.compare(0, 2, "\xFF\xFE") == 0 || bytes.compare(0, 2, "\xFE\xFF") == 0) return true;  // UTF-16
  while (i < bytes.size() && std::isspace((unsigned char)bytes[i])) ++i;
  return i < bytes.size() && bytes[i] == '<';
}

std::string folder_of(const std::string& path) {
  size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

const char* scene_format_name(SceneFormat format) {
  switch (format) {
    case SceneFormat::collada: return "COLLADA";
    case SceneFormat::gltf: return "glTF";
    case SceneFormat::glb: return "binary glTF";
  }
  return "?";
}

const char* const kSceneExtensions[3] = {".dae", ".gltf", ".glb"};

std::string scene_file_name(const std::string& name, const std::string& bytes) {
  return name + kSceneExtensions[int(detect_scene_format(bytes, ""))];
}

SceneFormat detect_scene_format(const std::string& bytes, const std::string& name) {
  if (bytes.compare(0, 4, "glTF") == 0) return SceneFormat::glb;
  if (has_extension(name, ".dae")) return SceneFormat::collada;
  if (has_extension(name, ".gltf")) return SceneFormat::gltf;
  if (has_extension(name, ".glb")) return SceneFormat::glb;
  size_t i = 0;
  if (bytes.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;  // a UTF-8 byte order mark
  while (i < bytes.size() && std::isspace((unsigned char)bytes[i])) ++i;
  return i < bytes.size() && bytes[i] == '{' ? SceneFormat::gltf : SceneFormat::collada;
}

namespace {

// The scene files in `dir` (by extension), sorted.
std::vector<std::string> scene_files_in(const std::string& dir) {
  std::vector<std::string> names;
  DIR* d = opendir(dir.empty() ? "." : dir.c_str());
  if (!d) return names;
  for (int n = 0; n < 100000; ++n) {  // a huge folder is not worth a suggestion
    const dirent* e = readdir(d);
    if (!e) break;
    const std::string f = e->d_name;
    for (const char* ext : kSceneExtensions)
      if (has_extension(f, ext)) names.push_back(f);
  }
  closedir(d);
  std::sort(names.begin(), names.end());
  return names;
}

// Why `path` cannot be opened, in a newcomer's terms: a folder, or a missing file with the
// nearest scene file's name in its folder (CBsphere.dae: "did you mean CBspheres.dae?").
std::string cannot_open(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    const std::vector<std::string> inside = scene_files_in(path);
    std::string text = path + ": is a folder, not a scene file";
    if (!inside.empty()) {
      text += " (it holds " + inside[0];
      for (size_t i = 1; i < inside.size() && i < 4; ++i) text += ", " + inside[i];
      text += inside.size() > 4 ? ", ...)" : ")";
    }
    return text;
  }
  const int err = errno;
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash);
  const std::string file = slash == std::string::npos ? path : path.substr(slash + 1);
  std::string text = path + ": cannot open file";
  if (err == ENOENT) {
    text += " (no such file";
    const std::string near = nearest_name(file, scene_files_in(dir));
    if (!near.empty()) text += "; did you mean " + (dir.empty() ? near : dir + "/" + near) + "?";
    text += ")";
  } else if (err != 0) {
    text += std::string(" (") + std::strerror(err) + ")";
  }
  return text;
}

}  // namespace

std::string read_scene_bytes(const std::string& path, const LoadLimits& limits) {
  struct stat st {};
  if (stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) throw SceneError(cannot_open(path));  // opens, reads nothing
  errno = 0;
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw SceneError(cannot_open(path));
  std::streamoff size = in.tellg();
  if (size < 0) throw SceneError(path + ": cannot read file");
  if (size_t(size) > limits.max_file_bytes)
    throw SceneError(path + ": file is " + std::to_string(size) + " bytes, over the limit of " +
                     std::to_string(limits.max_file_bytes));
  std::string bytes(size_t(size), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), size)) throw SceneError(path + ": cannot read file");
  return bytes;
}

namespace {

SceneDesc parse_any(const std::string& bytes, const std::string& name, const LoadLimits& limits,
                    const std::string& base_dir) {
  switch (detect_scene_format(bytes, name)) {
    case SceneFormat::collada:
      if (!looks_like_xml(bytes)) {
        const std::string kind = what_it_is(bytes);
        throw SceneError(name + ": not a COLLADA or glTF scene" + (kind.empty() ? "" : " (" + kind + ")"));
      }
      return parse_collada(bytes, name, limits);
    case SceneFormat::gltf: return parse_gltf(bytes, name, false, limits, base_dir);
    case SceneFormat::glb: return parse_gltf(bytes, name, true, limits, base_dir);
  }
  throw SceneError(name + ": unknown scene format");
}

}  // namespace

SceneDesc parse_scene(const std::string& bytes, const std::string& name, const LoadLimits& limits,
                      const std::string& base_dir) {
  return parse_any(bytes, name, limits, base_dir);
}

SceneDesc load_scene(const std::string& path, const LoadLimits& limits) {
  return parse_scene(read_scene_bytes(path, limits), path, limits, folder_of(path));
}

}  // namespace pt
