// Checkpoint files (checkpoint.h).
#include "checkpoint.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "options.h"

namespace pt {

namespace {

constexpr char kMagic[8] = {'P', 'T', 'C', 'H', 'E', 'C', 'K', '2'};
constexpr size_t kMaxFingerprint = 1 << 16;

// FNV-1a, 64 bits: a scene's identity, not a defence against forgery (a checkpoint is our own file).
constexpr uint64_t kFnvOffset = 1469598103934665603ull;
uint64_t fnv1a(const char* bytes, size_t n, uint64_t h = kFnvOffset) {
  for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<unsigned char>(bytes[i])) * 1099511628211ull;
  return h;
}
uint64_t fnv1a(const std::string& bytes) { return fnv1a(bytes.data(), bytes.size()); }

[[noreturn]] void fail_io(const std::string& path, const char* doing) {
  throw std::runtime_error(path + ": cannot " + doing + " the checkpoint (" + std::strerror(errno) + ")");
}

// "HASH (N bytes)" of a file's contents, or "unreadable". Read in chunks: a glTF buffer or an
// environment map may be large, and only its hash is kept.
std::string file_digest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "unreadable";
  uint64_t h = kFnvOffset, size = 0;
  std::vector<char> chunk(1 << 16);
  while (in) {
    in.read(chunk.data(), std::streamsize(chunk.size()));
    const size_t got = size_t(in.gcount());
    h = fnv1a(chunk.data(), got, h);
    size += got;
  }
  if (in.bad()) return "unreadable";
  char hash[20];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(h));
  return std::string(hash) + " (" + std::to_string(size) + " bytes)";
}

}  // namespace

std::string render_fingerprint(const std::string& scene_bytes, const RenderParams& p,
                               const std::vector<std::string>& input_files) {
  std::ostringstream f;
  char hash[20];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a(scene_bytes)));
  f << "scene " << hash << " (" << scene_bytes.size() << " bytes)";
  // Each file by name, so that a refusal shows which changed; past a few dozen, one digest of all
  // (the fingerprint stays far below kMaxFingerprint).
  constexpr size_t kFilesNamed = 32;
  if (input_files.size() <= kFilesNamed) {
    for (const std::string& file : input_files) f << ", file '" << file << "' " << file_digest(file);
  } else {
    std::string all;
    for (const std::string& file : input_files) all += file + '\n' + file_digest(file) + '\n';
    std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a(all)));
    f << ", " << input_files.size() << " files " << hash;
  }
  if (!p.env_map.empty()) f << ", environment " << file_digest(p.env_map);
  if (!p.camera_file.empty()) f << ", camera file " << file_digest(p.camera_file);
  const RunLimits none;
  for (const RenderOption& o : render_options()) {
    const std::string name = o.name;
    // Limits decide when a render stops, not its samples; a larger spp continues it (Film::restore).
    if (name == "time_limit" || name == "target_error" || name == "tile_size" || name == "spp") continue;
    f << ", " << name << " " << option_text(o, o.get(p, none));
  }
  f << ", sampler " << int(p.sampler) << ", environment '" << p.env_map << "', camera file '" << p.camera_file
    << "', cell " << p.cell_x << " " << p.cell_y << " " << p.cell_w << " " << p.cell_h;
  if (p.features) f << ", denoising features";
  if (p.camera.set) {
    const CameraPose& c = p.camera;
    f.precision(9);  // a float's every digit: two poses a hair apart are two films
    f << ", camera " << c.position.x << " " << c.position.y << " " << c.position.z << " " << c.target.x << " "
      << c.target.y << " " << c.target.z << " " << c.up.x << " " << c.up.y << " " << c.up.z << " " << c.vfov_deg;
  }
  return f.str();
}

void save_checkpoint(const std::string& path, const std::string& fingerprint, const PassSource& source,
                     const ProgressiveDriver& driver) {
  BinaryWriter out;
  for (char c : kMagic) out.pod(c);
  out.text(fingerprint);
  driver.save(out);
  source.save(out);
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail_io(tmp, "create");
  const std::string& bytes = out.bytes();
  for (size_t at = 0; at < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + at, bytes.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ::close(fd);
      ::unlink(tmp.c_str());
      fail_io(tmp, "write");
    }
    at += size_t(n);
  }
  // On disk before the rename: a crash leaves the old checkpoint or the new one, never a torn file.
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    ::unlink(tmp.c_str());
    fail_io(tmp, "flush");
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    ::unlink(tmp.c_str());
    fail_io(path, "replace");
  }
}

bool restore_checkpoint(const std::string& path, const std::string& fingerprint, PassSource& source,
                        ProgressiveDriver& driver) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    if (errno == ENOENT) return false;
    fail_io(path, "read");
  }
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw std::runtime_error(path + ": not a pathtracer checkpoint");
  BinaryReader in(bytes, path);
  for (size_t k = 0; k < sizeof kMagic; ++k) in.pod<char>();
  const std::string theirs = in.text(kMaxFingerprint);
  if (theirs != fingerprint)
    throw std::runtime_error(path + ": a checkpoint of another render (its scene file or an option that changes the "
                             "image differs); delete it or name another file.\n  checkpoint: " + theirs +
                             "\n  this run:   " + fingerprint);
  // A damaged file fails part way through: the state before it is put back, so that a caller that
  // goes on (the job service renders from the start) has a fresh source, whichever source it is.
  BinaryWriter before;
  driver.save(before);
  source.save(before);
  try {
    driver.restore(in);
    source.restore(in);
    if (!in.at_end()) in.fail("bytes past the end");
  } catch (...) {
    BinaryReader back(before.bytes(), path);
    driver.restore(back);
    source.restore(back);
    throw;
  }
  driver.reopen();
  return true;
}

bool Checkpointer::after_pass(const PassSource& source, const ProgressiveDriver& driver, bool force) {
  using clock = std::chrono::steady_clock;
  const auto now = clock::now();
  if (!force && std::chrono::duration<double>(now - m_last).count() < m_interval) return false;
  save_checkpoint(m_path, m_fingerprint, source, driver);
  m_last = clock::now();
  m_save_seconds += std::chrono::duration<double>(m_last - now).count();
  ++m_saves;
  return true;
}

}  // namespace pt
