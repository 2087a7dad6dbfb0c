// A render's life around the driver, written once for every front end that renders to the end:
// the CLI, the job service's embedded backend and its scale-out server. Each brings its own pass
// source (a session here, workers' passes merged there) and its own sinks for the events.
#pragma once

#include <atomic>
#include <exception>
#include <functional>

#include "checkpoint.h"
#include "driver.h"

namespace pt {

struct RenderJobEvents {
  // Once, before the first pass: whether the source was restored from a checkpoint.
  std::function<void(bool resumed)> started;
  TileCallback tile;  // a tile of the film changed; on the render threads
  // After each pass, the last partial one included; after a restore, once for the restored film.
  std::function<void(const PassReport&)> pass;
  std::function<void()> checkpointed;  // a checkpoint was written
  // A checkpoint that could not be restored (another render's, damaged) or written (a full disk).
  // Unset, the exception leaves run_render_job; set, the render goes on, from the start after a
  // failed restore (the source is left as it was).
  std::function<void(const std::exception&)> restore_failed, save_failed;
};

// Restores the source from `checkpoints` (may be null) where it holds this render, steps the driver
// until the render ends or `stop` is set, checkpoints between passes at the checkpointer's
// interval and always at the end (a cancel, a time limit or a restart resumes it exactly), and,
// where a pass was cut short, reports every tile once more so that the last picture shown is the
// final film. A source with nothing to keep (PassSource::anything_to_keep) writes no checkpoint.
StopReason run_render_job(PassSource& source, const RunLimits& limits, Checkpointer* checkpoints,
                          const std::atomic<bool>* stop, const RenderJobEvents& events);

}  // namespace pt
