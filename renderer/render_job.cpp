// A render's life around the driver (render_job.h).
#include "render_job.h"

namespace pt {

namespace {

// A checkpoint between passes (or `force`d at the end), where the source has anything to keep.
void checkpoint(Checkpointer* checkpoints, const PassSource& source, const ProgressiveDriver& driver, bool force,
                const RenderJobEvents& events) {
  if (!checkpoints || !source.anything_to_keep()) return;
  try {
    if (checkpoints->after_pass(source, driver, force) && events.checkpointed) events.checkpointed();
  } catch (const std::exception& e) {
    if (!events.save_failed) throw;
    events.save_failed(e);
  }
}

}  // namespace

StopReason run_render_job(PassSource& source, const RunLimits& limits, Checkpointer* checkpoints,
                          const std::atomic<bool>* stop, const RenderJobEvents& events) {
  ProgressiveDriver driver(source, limits);
  bool resumed = false;
  if (checkpoints) {
    try {
      resumed = checkpoints->restore(source, driver);
    } catch (const std::exception& e) {
      if (!events.restore_failed) throw;
      events.restore_failed(e);  // restore_checkpoint left the source and driver fresh
    }
  }
  if (events.started) events.started(resumed);
  if (resumed) {  // the checkpoint's picture and counts, before the first new pass
    if (events.tile)
      for (const Tile& t : source.tiles()) events.tile(t);
    if (events.pass) events.pass({driver.target(), source.seconds(), source.error_estimate(), true});
  }
  bool cut = false;
  while (!driver.done()) {
    const PassReport r = driver.step(stop, events.tile);
    if (events.pass) events.pass(r);
    if (!r.completed) {  // stopped (the next step would resume it) or the time limit
      cut = true;
      break;
    }
    if (!driver.done()) checkpoint(checkpoints, source, driver, false, events);
  }
  // However it ended, the film is kept: a pause, a restart or a continue takes it from here.
  checkpoint(checkpoints, source, driver, true, events);
  // A cut pass's unfinished tiles never reached events.tile: the last picture is the film's.
  if (cut && events.tile)
    for (const Tile& t : source.tiles()) events.tile(t);
  return driver.done() ? driver.reason() : StopReason::cancelled;
}

}  // namespace pt
