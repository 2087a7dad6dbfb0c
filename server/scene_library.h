// Scene files the server may render: names resolved only inside the configured directories
// (no paths, no symlinks out); per distinct file content, one summary and one shared render-scene
// base (BVH, lights, materials) that every job on it views. The file's vertex arrays are not kept.
// Built bases stay cached for later jobs within a byte budget: past it, the least recently used
// base no job holds is dropped (its summary stays) and is built again when a job next asks.
#pragma once

#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "job_spec.h"
#include "render_scene.h"

namespace srv {

// The real path of `path` with every symlink resolved, or "" when it does not exist.
std::string canonical_path(const std::string& path);
// What GET /api/scenes says of a scene: counts, materials, lights, the course camera's focus distance.
json summarize_desc(const pt::SceneDesc& desc);

class SceneLibrary {
 public:
  static constexpr size_t kDefaultCacheBytes = size_t(1) << 30;
  explicit SceneLibrary(std::vector<std::string> dirs, size_t cache_bytes = kDefaultCacheBytes);
  // The file for a scene name, or "" when no configured directory holds it.
  std::string resolve(const std::string& name) const;

  // ---- uploaded scenes (scene_upload.cpp) ----
  // Where PUT /api/scenes/{name} stores scenes (an existing folder, in the data folder). Uploaded
  // scenes can be replaced and deleted; bundled ones (--scenes) cannot.
  void set_upload_dir(const std::string& dir);
  bool is_uploaded(const std::string& name) const;
  // Loads `bytes` (COLLADA, or a self-contained glTF / GLB) and, when it loads, stores it as
  // scene `name`, atomically. Returns the summary and whether the name is new. Throws
  // pt::SceneError with the loader's message for a file that does not load, JobError(read_only)
  // for a bundled scene's name, JobError(invalid) for a bad name.
  std::pair<json, bool> store_upload(const std::string& name, const std::string& bytes);
  // Deletes an uploaded scene; JobError(read_only) for a bundled one, JobError(not_found).
  void remove_upload(const std::string& name);
  // The scene's shared render base (a job makes its view with pt::make_view), built at most once
  // per file content however many jobs ask at the same time. Throws JobError(not_found) for an unknown
  // name, pt::SceneError for a bad file.
  std::shared_ptr<const pt::SceneBase> load(const std::string& name);
  // A scene's summary (counts, materials, lights, the course camera's focus distance); parses a
  // file it has not seen but builds nothing, so it also validates cheaply. Throws as load() does.
  // `content_hash`, when given, receives the hash of the file's content the summary is of.
  json summary(const std::string& name, uint64_t* content_hash = nullptr);
  // The camera a job with `params` renders the scene from (its framing, or the params' pose),
  // without building the scene. Throws as check() does.
  pt::Camera view(const std::string& name, const pt::RenderParams& params);
  // Every scene's name, sorted.
  std::vector<std::string> names() const;
  // Every scene with its summary, or its load error, and the bytes of its built base while the
  // cache holds one.
  json list();
  // One scene as list() shows it; JobError(not_found) for an unknown name.
  json entry(const std::string& name);
  // Throws JobError(not_found) for an unknown name, JobError(scene_broken) naming the loader's
  // message for a file that does not load (parsed once per file version). Returns the hash of the
  // file's content, which a job keeps to know its scene is the one its film was rendered from.
  // `warnings`, when given, receives what the loader ignored or defaulted.
  uint64_t check(const std::string& name, std::vector<std::string>* warnings = nullptr);

 private:
  using Base = std::shared_ptr<const pt::SceneBase>;
  // What the course framing reads of a file: its camera and the geometry bounds.
  struct Framing {
    pt::CameraDesc camera;
    pt::Bounds3 bounds;
  };
  json summary(const std::string& name, uint64_t* content_hash, Framing* framing);
  struct Entry {
    json summary;                   // null until the content was parsed once
    Framing framing;                // with the summary
    std::shared_future<Base> base;  // valid once a build started; ready when it ended
    uint64_t build_id = 0;          // which load() is building it
    size_t bytes = 0;               // the built base's memory_bytes(); 0 until built
    uint64_t used_at = 0;           // m_clock at its last load(): the least recent goes first
    std::string name;               // the last name it was loaded under, for the log
  };
  // The file's bytes and their FNV-1a hash; throws as load() does.
  std::string read_scene(const std::string& name, uint64_t* hash) const;
  void forget_unused();  // with m_mutex held
  // Drops the least recently used built bases that no job holds while the cached bytes exceed the
  // budget; never `keep`. With m_mutex held; the dropped bases go to `dropped`, for the caller to
  // free once it has released the lock.
  void evict_over_budget(uint64_t keep, std::vector<std::shared_future<Base>>& dropped);

  // What list() last found in a scene file, valid while the file keeps its path, size and time.
  struct FileStamp {
    std::string path;
    long long size = 0, mtime_s = 0, mtime_ns = 0;
    bool operator==(const FileStamp& o) const {
      return path == o.path && size == o.size && mtime_s == o.mtime_s && mtime_ns == o.mtime_ns;
    }
  };
  struct FileSummary {
    FileStamp stamp;
    json summary;       // when it loads
    Framing framing;    // with the summary
    std::string error;  // when it does not
    uint64_t hash = 0;
  };

  // The cached summary or error of a scene file's current version.
  FileSummary file_summary(const std::string& name);

  // "unknown scene 'cornel' (did you mean 'cornell'?)", naming `field`.
  JobError unknown(const std::string& name, const char* field) const;
  // The scene file's name as messages show it ("cornell.dae"), from its resolved path.
  std::string file_name(const std::string& name) const;

  std::vector<std::string> m_dirs;  // canonical; the bundled folders
  std::string m_upload_dir;         // canonical; "" when uploads are off
  std::map<std::string, FileSummary> m_file_summaries;  // by scene name
  size_t m_cache_bytes;
  std::mutex m_mutex;
  std::map<uint64_t, Entry> m_cache;            // by content hash
  std::map<std::string, uint64_t> m_last_hash;  // scene name -> hash of its last loaded content
  uint64_t m_next_build = 0;
  uint64_t m_clock = 0;
};

}  // namespace srv
