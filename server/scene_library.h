// Scene files the server may render: names resolved only inside the configured directories
// (no paths, no symlinks out), parsed once per distinct file content and shared between jobs.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "job_spec.h"
#include "scene.h"

namespace srv {

class SceneLibrary {
 public:
  explicit SceneLibrary(std::vector<std::string> dirs);
  // The file for a scene name, or "" when no configured directory holds it.
  std::string resolve(const std::string& name) const;
  // Loads (or reuses) a scene; throws ApiError(404) for an unknown name, pt::SceneError for a bad file.
  std::shared_ptr<const pt::SceneDesc> load(const std::string& name);
  // Every scene with a summary (counts, materials, lights, the course camera's focus distance).
  json list();

 private:
  struct Entry {
    std::shared_ptr<const pt::SceneDesc> desc;
    json summary;
  };
  std::vector<std::string> m_dirs;  // canonical
  std::mutex m_mutex;
  std::map<uint64_t, Entry> m_cache;            // by content hash
  std::map<std::string, uint64_t> m_last_hash;  // scene name -> hash of its last loaded content
};

}  // namespace srv
