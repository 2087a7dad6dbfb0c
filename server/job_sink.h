// JobStateSink: carries a render backend's reports (start, tiles, passes) into a Job's state under
// its mutex, and wakes the job's watchers.
#pragma once

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>

#include "image.h"
#include "jobs.h"
#include "render_backend.h"

namespace srv {

class JobStateSink : public JobSink {
 public:
  JobStateSink(Job& job, std::function<void(Job&)> persist) : m_job(job), m_persist(std::move(persist)) {}

  void started(int width, int height, const std::vector<std::string>& features, double resumed_seconds) override {
    Job& j = m_job;
    {
      std::lock_guard<std::mutex> lock(j.mutex);
      if (j.cancel) throw JobError(JobErrorKind::conflict, "cancelled");
      j.state = JobState::running;
      if (j.started_at <= 0 || resumed_seconds <= 0) j.started_at = now_unix_seconds();
      j.width = width;
      j.height = height;
      j.tile_size = j.spec.params.tile_size;
      j.region_size = stream_tile_size(j.tile_size);
      j.regions_x = (width + j.region_size - 1) / j.region_size;
      j.regions_y = (height + j.region_size - 1) / j.region_size;
      size_t n = size_t(width) * height;
      j.linear.assign(n * 3, 0.0f);
      j.display.assign(n * 3, 0);
      j.counts.assign(n, 0);
      j.region_version.assign(size_t(j.regions_x) * j.regions_y, 0);
      // A resumed render keeps its history up to the checkpoint, and its counts (its first pass()
      // brings the checkpoint's): spp_done never drops to 0 on the way.
      if (resumed_seconds <= 0) j.samples = 0;
      while (!j.history.empty() && !(j.history.back().seconds <= resumed_seconds)) j.history.pop_back();
      j.has_image = false;
      j.features = features;
      j.denoised.final = false;  // a continued job renders on: its last picture is no longer the finished one
      j.denoised.noise = -1;
      j.denoised.warning.clear();
      ++j.version;
      m_persist(j);
    }
    m_offset = resumed_seconds;
    m_start = std::chrono::steady_clock::now();
    m_last_persist = m_start;
    j.changed.notify_all();
  }

  void tile(const pt::Tile& t, const std::vector<pt::Vec3>& mean, const std::vector<uint32_t>& count) override {
    Job& j = m_job;
    {
      std::lock_guard<std::mutex> lock(j.mutex);
      size_t k = 0;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x, ++k) {
          j.counts[size_t(y) * j.width + x] = count[k];
          size_t i = (size_t(y) * j.width + x) * 3;
          for (int c = 0; c < 3; ++c) {
            j.linear[i + c] = mean[k][c];
            j.display[i + c] = pt::tonemap_course(mean[k][c]);
          }
        }
      j.region_version[size_t(t.y0 / j.region_size) * j.regions_x + t.x0 / j.region_size] = ++j.version;
      j.has_image = true;
      const double now = seconds();
      if (j.eta > 0) j.eta = std::max(0.0, j.eta - (now - j.elapsed));  // the last pass's, counted down
      j.elapsed = now;
    }
    // Every notify wakes every watcher, and each takes the job's mutex the render threads need:
    // tile updates wake them at most every kTileNotifyGap (watchers batch tiles over 40 ms rounds
    // anyway); pass() and state changes, which always follow the tiles, wake them at once.
    int64_t now = std::chrono::steady_clock::now().time_since_epoch().count(), last = m_last_notify.load();
    if (now - last >= kTileNotifyGap && m_last_notify.compare_exchange_strong(last, now)) j.changed.notify_all();
  }

  void pass(const RenderReport& r) override {
    Job& j = m_job;
    {
      std::lock_guard<std::mutex> lock(j.mutex);
      j.samples = r.samples;
      j.rays = r.rays;
      j.nonfinite = r.nonfinite;
      j.elapsed = seconds();
      j.progress = r.progress;
      if (std::isfinite(r.error)) {
        j.error_estimate = r.error;
        j.history.push_back({j.elapsed, double(r.samples) / (double(j.width) * j.height), r.error});
      }
      j.eta = r.eta;
      ++j.version;
      ++j.passes;
      if (std::chrono::steady_clock::now() - m_last_persist > std::chrono::seconds(1)) {
        m_persist(j);
        m_last_persist = std::chrono::steady_clock::now();
      }
    }
    j.changed.notify_all();
  }

  void denoised(const pt::DenoisedFilm& d, double spp, bool final) override {
    // The picture's linear and tone-mapped copies are made before taking the job's mutex, which
    // watchers and the render threads' tiles also take.
    std::vector<float> linear;
    std::vector<uint8_t> display;
    if (d.ok) {
      const size_t n = d.image.pixels.size();
      linear.resize(n * 3);
      display.resize(n * 3);
      for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
          linear[i * 3 + c] = d.image.pixels[i][c];
          display[i * 3 + c] = pt::tonemap_course(d.image.pixels[i][c]);
        }
    }
    Job& j = m_job;
    {
      std::lock_guard<std::mutex> lock(j.mutex);
      Job::Denoised& out = j.denoised;
      if (!d.ok) {
        out.warning = d.error + "; the picture is the raw render";
      } else if (d.image.width == j.width && d.image.height == j.height) {
        out.linear.swap(linear);
        out.display.swap(display);
        out.spp = spp;
        out.seconds = d.seconds;
        ++out.frames;
        out.final = final;
        out.noise = final && std::isfinite(d.noise) ? d.noise : -1;
      }
      out.spent_seconds += d.seconds + d.noise_seconds;
      out.version = ++j.version;
    }
    j.changed.notify_all();
  }

  void checkpointed(uint64_t samples, double seconds) override {
    std::lock_guard<std::mutex> lock(m_job.mutex);
    m_job.checkpoint_samples = samples;
    m_job.checkpoint_seconds = seconds;
    m_persist(m_job);
  }

 private:
  // Rendering time: a resumed render's counts on from its checkpoint's.
  double seconds() const {
    return m_offset + std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
  }
  double m_offset = 0;
  Job& m_job;
  std::function<void(Job&)> m_persist;
  std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now(), m_last_persist = m_start;
  static constexpr int64_t kTileNotifyGap =
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::milliseconds(20)).count();
  std::atomic<int64_t> m_last_notify{0};
};

}  // namespace srv
