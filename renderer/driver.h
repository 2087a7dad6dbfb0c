// The progressive driver, the one loop every render runs: the CLI, the window, the embedded job
// backend and the scale-out's server. It asks a PassSource for passes of growing sample counts
// and stops on the sample budget, the error target, the time limit or a cancel.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <vector>

#include "film.h"
#include "options.h"
#include "binary_io.h"

namespace pt {

using TileCallback = std::function<void(const Tile&)>;

// What a render has taken so far, for reports and logs.
struct RenderCounts {
  uint64_t samples = 0, rays = 0, nonfinite = 0;
};

// What a progressive render runs on: a session rendering passes here (session.h), or the
// scale-out's server gathering workers' passes (server/redis_backend.cpp).
class PassSource {
 public:
  virtual ~PassSource() = default;
  // Takes every unfinished pixel towards `target_spp` samples: a pass over the frame here, or the
  // workers' passes merged since the last call. `on_tile` after each tile that changed. False
  // when it stopped early: `cancel` set, or the deadline passed.
  virtual bool advance(int target_spp, const std::atomic<bool>* cancel, const TileCallback& on_tile) = 0;
  // Passes stop, as if cancelled, once this time has passed.
  virtual void set_deadline(std::chrono::steady_clock::time_point t) = 0;
  virtual const Film& film() const = 0;
  virtual double seconds() const = 0;  // rendering time so far
  virtual double error_estimate() const { return film().error_estimate(); }
  // The work left (Film::work), weighted by what a sample cost where the source knows it.
  virtual Film::Work work() const { return film().work(); }
  // Of seconds(), the time spent tracing caustic light paths; 0 where not timed apart.
  virtual double light_seconds() const { return 0; }
  // Nothing left to render: every pixel done (gathered: also every pass asked for merged).
  virtual bool finished() const { return film().finished(); }
  virtual RenderCounts counts() const = 0;
  // Whether a checkpoint now would keep anything: a session always (even a film cancelled before
  // its first sample is a render that can be continued); the scale-out server not before its first
  // merged pass, whose worker names the scene's features.
  virtual bool anything_to_keep() const { return true; }
  // The tiles on_tile reports, covering the film: what a front end republishes in full.
  virtual const std::vector<Tile>& tiles() const = 0;
  // Checkpoints (checkpoint.h): everything the render has taken, its film included. save() between
  // passes; restore() before the first pass, into a source of the same render.
  virtual void save(BinaryWriter& out) const = 0;
  virtual void restore(BinaryReader& in) = 0;
};

enum class StopReason { finished, target_error, time_limit, cancelled };
const char* stop_reason_name(StopReason r);

struct PassReport {
  int target_spp;   // samples per pixel this pass aimed for
  double seconds;   // rendering time so far
  double error;     // the error estimate after the pass
  bool completed;   // false: cut short by a cancel or the time limit
};

// The render's progress and time to go, for every front end (the CLI's bar and log, the window's
// title, the job service's progress and ETA). The work left is the samples the running pixels are
// expected to take still, each by the adaptive rule on its own statistics (Film::work), not the
// sample budget: the cheap pixels stop first, and the noisy ones are left. Its time is those
// samples at the camera sample rate of the last passes (at least a fifth of the time so far, not
// the whole run, which early passes over cheap pixels inflate), each weighted by its tile's cost
// per sample in the last pass where the source times tiles (the noisy pixels left may be dearer or
// cheaper than the pass's mean); plus the caustic light paths, which go on for the whole frame
// until the last pixel stops (passes of 2x, as the driver runs them), at their own rate. The error
// target (an unbiased estimator's relative MSE falls as 1/time) or the time limit end it sooner
// where they come first. Updated between passes; read at any time until the next update.
class ProgressEstimate {
 public:
  explicit ProgressEstimate(const RunLimits& limits = {}) : m_limits(limits) {}
  // After a pass: the source `seconds` into the render, the pass's error estimate. A render that
  // does not start from nothing (a checkpoint) calls it once before its first pass.
  void update(const PassSource& source, double seconds, double error);
  // Fraction done at `seconds`: samples taken / (taken + left), counting on at the recent rate
  // since the update; where a limit ends the render first, the share of its expected time. 1 when
  // finished, 0 before the first update.
  double progress(double seconds) const;
  // Seconds left at `seconds`: 0 when finished; negative while nothing says (no rate, no limit).
  double remaining_seconds(double seconds) const;
  const Film::Work& work() const { return m_work; }
  double rate() const { return m_rate; }  // camera samples a second over the last passes; 0: unknown

 private:
  double work_seconds(double seconds) const;  // the work left's time, or -1

  struct Point {
    double seconds;
    uint64_t taken, light_paths;
    double light_seconds;
  };
  RunLimits m_limits;
  std::vector<Point> m_history;
  Film::Work m_work;
  bool m_finished = false;
  double m_seconds = 0, m_error = INFINITY;
  double m_rate = 0, m_light_rate = 0;  // camera samples, light paths a second (0: unknown)
  double m_light_left = 0;
};

// The samples per pixel the pass after one that reached `target` aims for: twice as many (1, 2, 4,
// ... spp), or, towards an error target, where the estimate's 1/spp decay meets it when that comes
// sooner (a doubling could overshoot it by up to the render's whole time so far).
int next_pass_target(int target, int spp, double error, double target_error);

// The driver, a pass at a time: the window runs it step by step, pausing (cancelling a pass) to
// handle input between steps; run_progressive runs it to the end.
class ProgressiveDriver {
 public:
  ProgressiveDriver(PassSource& source, const RunLimits& limits) : m_source(source), m_limits(limits) {}
  // Runs the next pass. A pass cut short by `cancel` leaves the render resumable (the next step
  // resumes it); one cut short by the time limit ends it. The time limit counts rendering time
  // (PassSource::seconds), so pauses between steps do not use it up.
  PassReport step(const std::atomic<bool>* cancel = nullptr, const TileCallback& on_tile = {});
  bool done() const { return m_done; }
  StopReason reason() const { return m_reason; }
  int target() const { return m_target; }
  // Checkpoints (checkpoint.h): the next pass's target and whether the render has ended.
  void save(BinaryWriter& out) const;
  void restore(BinaryReader& in);
  // After a restore into a larger budget (a render continued): a render that had finished its old
  // budget takes the next pass towards the new one.
  void reopen();

 private:
  PassSource& m_source;
  RunLimits m_limits;
  int m_target = 1;
  bool m_done = false;
  StopReason m_reason = StopReason::finished;
};

// Steps the driver until the render ends; `on_pass` after each pass (also the last, partial one).
// A cancel ends it (StopReason::cancelled).
StopReason run_progressive(PassSource& source, const RunLimits& limits, const std::atomic<bool>* cancel = nullptr,
                           const TileCallback& on_tile = {}, const std::function<void(const PassReport&)>& on_pass = {});

}  // namespace pt
