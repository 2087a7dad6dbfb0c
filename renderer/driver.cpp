// The progressive driver (driver.h).
#include "driver.h"

#include <algorithm>
#include <cmath>

namespace pt {

const char* stop_reason_name(StopReason r) {
  switch (r) {
    case StopReason::finished: return "finished";
    case StopReason::target_error: return "error target reached";
    case StopReason::time_limit: return "time limit reached";
    case StopReason::cancelled: return "cancelled";
  }
  return "?";
}

double remaining_seconds(double elapsed, double progress, double error, double error_seconds, const RunLimits& limits) {
  double eta = progress > 0 ? elapsed * (1 - progress) / progress : -1;
  auto sooner = [&eta](double t) { eta = eta < 0 ? t : std::min(eta, t); };
  if (limits.target_error > 0 && std::isfinite(error) && error > 0)
    sooner(std::max(0.0, error_seconds * error / limits.target_error - elapsed));
  if (limits.time_limit > 0) sooner(std::max(0.0, limits.time_limit - elapsed));
  return eta;
}

int next_pass_target(int target, int spp, double error, double target_error) {
  int next = std::min(spp, target * 2);
  if (target_error > 0 && std::isfinite(error) && error > target_error) {
    // error ~ 1/spp: the count where it meets the target, 5% past it so that noise in the estimate
    // rarely needs one more pass, and at least a quarter more than now so that passes stay few.
    const double needed = std::ceil(double(target) * (error / target_error) * 1.05);
    const double least = double(target) + std::max(1.0, std::floor(target / 4.0));
    if (needed < double(next)) next = int(std::max(needed, least));
  }
  return std::min(next, spp);
}

PassReport ProgressiveDriver::step(const std::atomic<bool>* cancel, const TileCallback& on_tile) {
  using clock = std::chrono::steady_clock;
  auto deadline = clock::time_point::max();
  if (m_limits.time_limit > 0)
    deadline = clock::now() + std::chrono::duration_cast<clock::duration>(
                                  std::chrono::duration<double>(std::max(0.0, m_limits.time_limit - m_source.seconds())));
  m_source.set_deadline(deadline);
  const bool completed = m_source.advance(m_target, cancel, on_tile);
  m_source.set_deadline(clock::time_point::max());
  const double err = m_source.error_estimate();
  PassReport report{m_target, m_source.seconds(), err, completed};
  if (!completed) {
    const bool cancelled = cancel && cancel->load();
    if (!cancelled) m_done = true, m_reason = StopReason::time_limit;
    else m_reason = StopReason::cancelled;  // resumable: the next step takes the same target
    return report;
  }
  if (m_limits.target_error > 0 && err <= m_limits.target_error) {
    m_done = true, m_reason = StopReason::target_error;
  } else if (m_source.finished()) {  // a session is, after a whole pass at the full count
    m_done = true, m_reason = StopReason::finished;
  } else {
    m_target = next_pass_target(m_target, m_source.film().spp(), err, m_limits.target_error);
  }
  return report;
}

void ProgressiveDriver::save(BinaryWriter& out) const {
  out.pod(int32_t(m_target)), out.pod(uint8_t(m_done)), out.pod(uint8_t(m_reason));
}

void ProgressiveDriver::restore(BinaryReader& in) {
  const int32_t target = in.pod<int32_t>();
  const uint8_t done = in.pod<uint8_t>(), reason = in.pod<uint8_t>();
  // A target past this film's budget is the film's to refuse (Film::restore names the budgets).
  if (target < 1 || target > (1 << 24) || done > 1 || reason > uint8_t(StopReason::cancelled))
    in.fail("an impossible pass target or stop");
  // A render that spent its budget stays done; one that stopped at a limit runs its last pass
  // again (a pass with nothing to add) and lets the limits it runs under now decide.
  m_target = target, m_reason = StopReason(reason);
  m_done = done != 0 && m_reason == StopReason::finished;
}

void ProgressiveDriver::reopen() {
  if (!m_done || m_source.finished()) return;
  m_done = false;
  m_target = next_pass_target(m_target, m_source.film().spp(), INFINITY, 0);
}

StopReason run_progressive(PassSource& source, const RunLimits& limits, const std::atomic<bool>* cancel,
                           const TileCallback& on_tile, const std::function<void(const PassReport&)>& on_pass) {
  ProgressiveDriver driver(source, limits);
  while (!driver.done()) {
    const PassReport r = driver.step(cancel, on_tile);
    if (on_pass) on_pass(r);
    if (!r.completed && !driver.done()) return StopReason::cancelled;
  }
  return driver.reason();
}

}  // namespace pt
