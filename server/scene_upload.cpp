// Uploaded scenes (PUT /api/scenes/{name}): loaded before they are stored, stored atomically in
// the data folder beside the jobs, replaceable and deletable; the bundled folders stay read-only.
#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "job_store.h"
#include "scene_file.h"
#include "scene_library.h"

namespace srv {

void SceneLibrary::set_upload_dir(const std::string& dir) { m_upload_dir = canonical_path(dir); }

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
  // The format by content, not by what the client calls it. Loaded before it is stored: a file
  // that does not load is never offered as a scene. Loaded without a folder: a glTF that names
  // external buffers or images is refused, as workers receive one file's bytes.
  const std::string file = pt::scene_file_name(name, bytes);
  json summary = summarize_desc(pt::parse_scene(bytes, file));
  write_file_atomic(m_upload_dir + "/" + file, bytes);
  // The same name in another format goes: a name is one scene.
  for (const char* ext : pt::kSceneExtensions)
    if (file.compare(name.size(), std::string::npos, ext) != 0) std::remove((m_upload_dir + "/" + name + ext).c_str());
  return {summary, created};
}

void SceneLibrary::remove_upload(const std::string& name) {
  if (resolve(name).empty()) throw unknown(name, "name");
  if (!is_uploaded(name)) throw JobError(JobErrorKind::read_only, "'" + name + "' is a bundled scene: it cannot be deleted", "name");
  for (const char* ext : pt::kSceneExtensions) std::remove((m_upload_dir + "/" + name + ext).c_str());
  std::lock_guard<std::mutex> lock(m_mutex);
  m_file_summaries.erase(name);
  m_last_hash.erase(name);
  forget_unused();
}

}  // namespace srv
