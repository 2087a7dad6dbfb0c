// Uploaded scenes (PUT /api/scenes/{name}): loaded before they are stored, stored atomically in
// the data folder beside the jobs, replaceable and deletable; the bundled folders stay read-only.
#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "collada.h"
#include "job_store.h"
#include "scene_library.h"

namespace srv {

namespace {

// The format by content, not by what the client calls it: a GLB starts with "glTF", a glTF file
// is a JSON object, anything else is read as COLLADA (whose parser names what is wrong).
const char* sniff_extension(const std::string& bytes) {
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) return ".glb";
  for (unsigned char c : bytes) {
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;
    return c == '{' ? ".gltf" : ".dae";
  }
  return ".dae";
}

std::string canonical_dir(const std::string& path) {
  char buf[PATH_MAX];
  return realpath(path.c_str(), buf) ? std::string(buf) : std::string();
}

}  // namespace

void SceneLibrary::set_upload_dir(const std::string& dir) { m_upload_dir = canonical_dir(dir); }

bool SceneLibrary::is_uploaded(const std::string& name) const {
  const std::string path = resolve(name);
  return !m_upload_dir.empty() && path.compare(0, m_upload_dir.size() + 1, m_upload_dir + "/") == 0;
}

std::pair<json, bool> SceneLibrary::store_upload(const std::string& name, const std::string& bytes) {
  if (!valid_scene_name(name))
    throw JobError(JobErrorKind::invalid, "a scene name is letters, digits, '_', '-' and '.' (no paths)", "name");
  if (m_upload_dir.empty()) throw JobError(JobErrorKind::no_storage, "this server stores no uploaded scenes");
  const std::string existing = resolve(name);
  const bool created = existing.empty();
  if (!created && !is_uploaded(name))
    throw JobError(JobErrorKind::read_only, "'" + name + "' is a bundled scene: choose another name", "name");
  const char* ext = sniff_extension(bytes);
  // Loaded before it is stored: a file that does not load is never offered as a scene.
  json summary = summarize_desc(parse_scene_bytes(bytes, name + std::string(ext)));
  write_file_atomic(m_upload_dir + "/" + name + ext, bytes);
  // The same name in another format goes: a name is one scene.
  for (const char* other : kSceneExtensions)
    if (std::strcmp(other, ext) != 0) std::remove((m_upload_dir + "/" + name + other).c_str());
  return {summary, created};
}

void SceneLibrary::remove_upload(const std::string& name) {
  if (resolve(name).empty()) throw JobError(JobErrorKind::not_found, "unknown scene '" + name + "'", "name");
  if (!is_uploaded(name)) throw JobError(JobErrorKind::read_only, "'" + name + "' is a bundled scene: it cannot be deleted", "name");
  for (const char* ext : kSceneExtensions) std::remove((m_upload_dir + "/" + name + ext).c_str());
  std::lock_guard<std::mutex> lock(m_mutex);
  m_file_summaries.erase(name);
  m_last_hash.erase(name);
  forget_unused();
}

}  // namespace srv
