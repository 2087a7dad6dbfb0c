// Checkpoints of a long render: the pass source's state (a session's film and counts, or the
// scale-out server's merged film and passes) and the driver's next pass, written atomically between
// passes. A render restored from one continues exactly where it stood: each sample's random
// numbers depend only on the seed, the pixel and the sample index, and the film holds every
// statistic the stop rules and the error estimate read, so the finished image is the
// uninterrupted render's, bit for bit.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "driver.h"
#include "options.h"

namespace pt {

// What a checkpoint must match to be resumed: the scene file's bytes, the contents of the other
// files the image depends on (`input_files`: SceneDesc::input_files; and the environment map and
// camera file the options name), and every option that changes the image (not the thread count,
// tile size or the limits, which only decide when it stops).
std::string render_fingerprint(const std::string& scene_bytes, const RenderParams& params,
                               const std::vector<std::string>& input_files = {});

// Writes the checkpoint to `path` (a temporary file, flushed to disk, then renamed over it).
void save_checkpoint(const std::string& path, const std::string& fingerprint, const PassSource& source,
                     const ProgressiveDriver& driver);
// Restores a fresh source and its driver from `path`: false when there is no file there; throws
// std::runtime_error naming the file when it is not a checkpoint of this render or is damaged, and
// then leaves both as they were.
bool restore_checkpoint(const std::string& path, const std::string& fingerprint, PassSource& source,
                        ProgressiveDriver& driver);

// Checkpoints of one render at pass ends: the CLI's --checkpoint and the job service's jobs.
class Checkpointer {
 public:
  // Saves to `path` at most every `interval` seconds (0: after every pass).
  Checkpointer(std::string path, std::string fingerprint, double interval)
      : m_path(std::move(path)), m_fingerprint(std::move(fingerprint)), m_interval(interval) {}
  // restore_checkpoint into a fresh source and driver.
  bool restore(PassSource& source, ProgressiveDriver& driver) const {
    return restore_checkpoint(m_path, m_fingerprint, source, driver);
  }
  // After a pass: saves when `force` is set or the interval has passed since the last save.
  // Returns whether it saved.
  bool after_pass(const PassSource& source, const ProgressiveDriver& driver, bool force = false);
  const std::string& path() const { return m_path; }
  int saves() const { return m_saves; }
  double save_seconds() const { return m_save_seconds; }  // time spent saving, in all

 private:
  std::string m_path, m_fingerprint;
  double m_interval;
  std::chrono::steady_clock::time_point m_last = std::chrono::steady_clock::now();
  int m_saves = 0;
  double m_save_seconds = 0;
};

}  // namespace pt
