// Scene name resolution, the cache of shared render-scene bases, and the scene list for
// GET /api/scenes.
#include "scene_library.h"

#include <dirent.h>
#include <sys/stat.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "camera.h"
#include "nearest.h"
#include "scene_file.h"

namespace srv {

std::string canonical_path(const std::string& path) {
  char buf[PATH_MAX];
  return realpath(path.c_str(), buf) ? std::string(buf) : std::string();
}

json summarize_desc(const pt::SceneDesc& d) {
  std::set<std::string> mats, lights;
  for (const pt::MeshDesc& m : d.meshes)
    for (int t : m.tri_material) mats.insert(pt::material_type_name(d.materials[t].type));
  for (const pt::SphereDesc& s : d.spheres) mats.insert(pt::material_type_name(d.materials[s.material].type));
  for (const pt::LightDesc& l : d.lights) lights.insert(pt::light_type_name(l.type));
  pt::Camera cam = pt::make_camera(d, pt::CameraParams());
  pt::Bounds3 b = d.geometry_bounds();
  float focus = b.empty() ? 0.0f : pt::length(b.center() - cam.position);
  return json{{"triangles", d.triangle_count()},
              {"spheres", d.spheres.size()},
              {"lights", std::vector<std::string>(lights.begin(), lights.end())},
              {"materials", std::vector<std::string>(mats.begin(), mats.end())},
              {"has_camera", d.camera.present},
              {"center_distance", focus},
              {"warnings", d.warnings}};
}

SceneLibrary::SceneLibrary(std::vector<std::string> dirs, size_t cache_bytes) : m_cache_bytes(cache_bytes) {
  for (const std::string& d : dirs) {
    std::string c = canonical_path(d);
    if (!c.empty()) m_dirs.push_back(c);
  }
}

std::string SceneLibrary::resolve(const std::string& name) const {
  if (!valid_scene_name(name)) return "";
  std::vector<std::string> dirs = m_dirs;
  if (!m_upload_dir.empty()) dirs.push_back(m_upload_dir);
  for (const std::string& dir : dirs)
    for (const char* ext : pt::kSceneExtensions) {
      std::string real = canonical_path(dir + "/" + name + ext);
      // The real file must lie inside the directory: a symlink pointing out is refused.
      if (!real.empty() && real.compare(0, dir.size() + 1, dir + "/") == 0) {
        struct stat st;
        if (stat(real.c_str(), &st) == 0 && S_ISREG(st.st_mode)) return real;
      }
    }
  return "";
}

std::string SceneLibrary::file_name(const std::string& name) const {
  const std::string path = resolve(name);
  const size_t dot = path.rfind('.');
  return name + (dot == std::string::npos ? std::string(".dae") : path.substr(dot));
}

std::string SceneLibrary::read_scene(const std::string& name, uint64_t* hash) const {
  std::string path = resolve(name);
  if (path.empty()) throw unknown(name, "scene");
  // Checked before reading: the whole file is held in memory while it parses.
  struct stat st;
  if (stat(path.c_str(), &st) == 0 && size_t(st.st_size) > pt::LoadLimits().max_file_bytes)
    throw pt::SceneError(file_name(name) + ": " + std::to_string(st.st_size) + " bytes, over the limit of " +
                         std::to_string(pt::LoadLimits().max_file_bytes));
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw JobError(JobErrorKind::not_found, "scene '" + name + "' cannot be read", "scene");
  std::string bytes = text.str();
  // FNV-1a over the content: an edited file is parsed again; identical files share one parse.
  uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : bytes) h = (h ^ ch) * 1099511628211ull;
  *hash = h;
  return bytes;
}

void SceneLibrary::forget_unused() {
  // Contents no scene name points to any more (running jobs keep their own reference).
  for (auto it = m_cache.begin(); it != m_cache.end();) {
    bool used = false;
    for (const auto& kv : m_last_hash) used |= kv.second == it->first;
    it = used ? std::next(it) : m_cache.erase(it);
  }
}

void SceneLibrary::evict_over_budget(uint64_t keep, std::vector<std::shared_future<Base>>& dropped) {
  // bytes > 0 only once the base's future holds it (set after set_value, reset on eviction).
  auto built = [](const Entry& e) { return e.bytes > 0 && e.base.valid(); };
  size_t total = 0;
  for (const auto& kv : m_cache)
    if (built(kv.second)) total += kv.second.bytes;
  while (total > m_cache_bytes) {
    Entry* oldest = nullptr;
    for (auto& kv : m_cache) {
      Entry& e = kv.second;
      // use_count 1: only the cache holds the base (a running job's view holds another).
      if (kv.first == keep || !built(e) || e.base.get().use_count() > 1) continue;
      if (!oldest || e.used_at < oldest->used_at) oldest = &e;
    }
    if (!oldest) return;  // everything left is in use
    total -= oldest->bytes;
    std::fprintf(stderr, "render-server: scene '%s' dropped from the cache (%.2f MiB, unused; %.2f MiB kept, budget %.2f MiB)\n",
                 oldest->name.c_str(), oldest->bytes / 1048576.0, total / 1048576.0, m_cache_bytes / 1048576.0);
    dropped.push_back(std::move(oldest->base));  // leaves oldest->base invalid: rebuilt when asked
    oldest->bytes = 0;
  }
}

std::shared_ptr<const pt::SceneBase> SceneLibrary::load(const std::string& name) {
  uint64_t hash = 0;
  std::string bytes = read_scene(name, &hash);
  std::promise<Base> promise;
  std::shared_future<Base> result;
  uint64_t build_id = 0;
  std::vector<std::shared_future<Base>> dropped;  // freed after the lock: a big BVH takes a while
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_last_hash[name] = hash;
    Entry& e = m_cache[hash];
    if (!e.base.valid()) {  // the first to ask builds; the others wait on its future
      e.base = promise.get_future().share();
      e.build_id = build_id = ++m_next_build;
    }
    e.used_at = ++m_clock;
    e.name = name;
    result = e.base;
    forget_unused();
    evict_over_budget(hash, dropped);  // bases whose jobs have ended since the last build
  }
  dropped.clear();
  if (build_id == 0) return result.get();  // rethrows the builder's error
  // Parse and build outside the lock: a big scene must not block status requests. Messages name
  // the scene, not the server's paths.
  Base base;
  json summary;
  Framing framing;
  try {
    auto t0 = std::chrono::steady_clock::now();
    pt::SceneDesc desc = pt::parse_scene(bytes, pt::scene_file_name(name, bytes));
    std::string().swap(bytes);
    summary = summarize_desc(desc);
    framing = Framing{desc.camera, desc.geometry_bounds()};
    base = std::make_shared<const pt::SceneBase>(pt::make_scene_base(desc));
    desc = pt::SceneDesc();  // from here on only the base holds the scene
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr, "render-server: scene '%s' built in %.3f s (%zu triangles, %zu spheres, %.2f MiB), shared by its jobs\n",
                 name.c_str(), s, base->triangle_count, base->sphere_count, base->memory_bytes() / 1048576.0);
  } catch (...) {
    {  // not cached: the next request tries again
      std::lock_guard<std::mutex> lock(m_mutex);
      auto it = m_cache.find(hash);
      if (it != m_cache.end() && it->second.build_id == build_id) it->second.base = {};
    }
    promise.set_exception(std::current_exception());
    return result.get();  // rethrows
  }
  promise.set_value(base);  // before its bytes count: the cache evicts only ready bases
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    auto it = m_cache.find(hash);
    if (it != m_cache.end() && it->second.build_id == build_id) {
      it->second.summary = summary;
      it->second.framing = framing;
      it->second.bytes = std::max<size_t>(1, base->memory_bytes());
    }
    evict_over_budget(hash, dropped);
  }
  return base;
}

std::vector<std::string> SceneLibrary::names() const {
  std::set<std::string> names;
  std::vector<std::string> dirs = m_dirs;
  if (!m_upload_dir.empty()) dirs.push_back(m_upload_dir);
  for (const std::string& dir : dirs) {
    DIR* d = opendir(dir.c_str());
    if (!d) continue;
    while (dirent* e = readdir(d)) {
      std::string f = e->d_name;
      for (const char* ext : pt::kSceneExtensions) {
        const size_t n = std::strlen(ext);
        if (f.size() > n && f.compare(f.size() - n, n, ext) == 0 && valid_scene_name(f.substr(0, f.size() - n)))
          names.insert(f.substr(0, f.size() - n));
      }
    }
    closedir(d);
  }
  std::vector<std::string> out;
  for (const std::string& name : names)
    if (!resolve(name).empty()) out.push_back(name);  // a link out of the folder is no scene
  return out;
}

JobError SceneLibrary::unknown(const std::string& name, const char* field) const {
  const std::string near = pt::nearest_name(name, names());
  return JobError(JobErrorKind::not_found,
                  "unknown scene '" + name + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)"), field);
}

json SceneLibrary::list() {
  json out = json::array();
  for (const std::string& name : names()) out.push_back(entry(name));
  return out;
}

json SceneLibrary::entry(const std::string& name) {
  if (resolve(name).empty()) throw unknown(name, "name");
  json item{{"name", name}, {"source", is_uploaded(name) ? "uploaded" : "bundled"}};
  FileSummary cached = file_summary(name);
  if (!cached.error.empty()) {
    item["error"] = cached.error;
  } else {
    item["summary"] = cached.summary;
    std::lock_guard<std::mutex> lock(m_mutex);
    auto it = m_cache.find(cached.hash);
    if (it != m_cache.end() && it->second.bytes > 0) item["memory_bytes"] = it->second.bytes;
  }
  return item;
}

SceneLibrary::FileSummary SceneLibrary::file_summary(const std::string& name) {
  // Each file is parsed once per (path, size, modification time): a broken scene of 86 MB must
  // not be parsed again on every listing or submission.
  std::string path = resolve(name);
  struct stat st {};
  bool known = !path.empty() && stat(path.c_str(), &st) == 0;
  FileStamp stamp{path, st.st_size, st.st_mtim.tv_sec, st.st_mtim.tv_nsec};
  if (known) {
    std::lock_guard<std::mutex> lock(m_mutex);
    auto it = m_file_summaries.find(name);
    if (it != m_file_summaries.end() && it->second.stamp == stamp) return it->second;
  }
  FileSummary cached;
  cached.stamp = stamp;
  try {
    cached.summary = summary(name, &cached.hash, &cached.framing);
  } catch (const std::exception& e) {  // JobError too: a name whose file cannot be read
    cached.error = e.what();
  }
  if (known) {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_file_summaries[name] = cached;
  }
  return cached;
}

uint64_t SceneLibrary::check(const std::string& name, std::vector<std::string>* warnings) {
  if (resolve(name).empty()) throw unknown(name, "scene");
  const FileSummary file = file_summary(name);
  if (!file.error.empty()) throw JobError(JobErrorKind::scene_broken, "scene '" + name + "' does not load: " + file.error, "scene");
  if (warnings && file.summary.contains("warnings"))
    for (const json& w : file.summary["warnings"]) warnings->push_back(w.get<std::string>());
  return file.hash;
}

json SceneLibrary::summary(const std::string& name, uint64_t* content_hash) {
  return summary(name, content_hash, nullptr);
}

pt::Camera SceneLibrary::view(const std::string& name, const pt::RenderParams& params) {
  check(name);
  const FileSummary file = file_summary(name);
  return pt::make_camera(file.framing.camera, file.framing.bounds, pt::camera_params(params));
}

json SceneLibrary::summary(const std::string& name, uint64_t* content_hash, Framing* framing) {
  uint64_t hash = 0;
  std::string bytes = read_scene(name, &hash);
  if (content_hash) *content_hash = hash;
  json summary;
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_last_hash[name] = hash;
    auto it = m_cache.find(hash);
    if (it != m_cache.end()) {
      summary = it->second.summary;
      if (framing) *framing = it->second.framing;
    }
    forget_unused();
  }
  if (summary.is_null()) {  // parsed for its summary only: the base is built by the first job
    const pt::SceneDesc desc = pt::parse_scene(bytes, pt::scene_file_name(name, bytes));
    summary = summarize_desc(desc);
    const Framing parsed{desc.camera, desc.geometry_bounds()};
    if (framing) *framing = parsed;
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_last_hash[name] == hash) {
      m_cache[hash].summary = summary;
      m_cache[hash].framing = parsed;
    }
  }
  return summary;
}

}  // namespace srv
