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

void ProgressEstimate::update(const PassSource& source, double seconds, double error) {
  if (m_history.empty()) m_history.push_back({0, 0, 0, 0});
  const Film& film = source.film();
  const double light_seconds = source.light_seconds();
  m_work = source.work();
  m_finished = source.finished();
  m_seconds = seconds, m_error = error;
  // Light paths so far are light_paths_for(the pass's count): the passes to the last stop, doubling
  // from the count reached, trace as many again per sample.
  const double light_paths = double(film.light_paths());
  m_light_left = 0;
  if (light_paths > 0 && m_work.reached > 0 && m_work.last_stop > m_work.reached) {
    uint32_t to = m_work.reached;
    while (to < m_work.last_stop) to = uint32_t(std::min<uint64_t>(film.spp(), 2ull * to));
    m_light_left = light_paths * double(to - m_work.reached) / m_work.reached;
  }
  // The rates since the latest earlier update at least a fifth of the time so far back: the last
  // pass alone, unless it was short.
  for (size_t k = m_history.size(); k-- > 0;) {
    const Point& p = m_history[k];
    const double dt = seconds - p.seconds;
    if (!(dt > 0 && (dt >= 0.2 * seconds || k == 0))) continue;
    const double samples = double(m_work.taken) - double(p.taken);
    const double paths = light_paths - double(p.light_paths), light_dt = light_seconds - p.light_seconds;
    if (paths > 0 && light_dt > 0 && light_dt < dt) {
      m_light_rate = paths / light_dt;
      if (samples > 0) m_rate = samples / (dt - light_dt);
    } else if (samples > 0) {  // light paths, if any, untimed: folded into the samples' rate
      m_light_rate = 0;
      m_rate = samples / dt;
    }
    break;
  }
  m_history.push_back({seconds, m_work.taken, film.light_paths(), light_seconds});
}

double ProgressEstimate::work_seconds(double seconds) const {
  if (m_finished) return 0;
  if (!(m_rate > 0)) return -1;
  double t = m_work.cost_left / m_rate;
  if (m_light_rate > 0) t += m_light_left / m_light_rate;
  return std::max(0.0, t - std::max(0.0, seconds - m_seconds));
}

double ProgressEstimate::remaining_seconds(double seconds) const {
  if (m_finished) return 0;
  double eta = work_seconds(seconds);
  auto sooner = [&eta](double t) { eta = eta < 0 ? t : std::min(eta, t); };
  if (m_limits.target_error > 0 && std::isfinite(m_error) && m_error > 0)
    sooner(std::max(0.0, m_seconds * m_error / m_limits.target_error - seconds));
  if (m_limits.time_limit > 0) sooner(std::max(0.0, m_limits.time_limit - seconds));
  return eta;
}

double ProgressEstimate::progress(double seconds) const {
  if (m_finished) return 1;
  const double work = work_seconds(seconds), eta = remaining_seconds(seconds);
  if (eta >= 0 && (work < 0 || eta < work)) return seconds + eta > 0 ? seconds / (seconds + eta) : 0;  // a limit decides
  const double taken = double(m_work.taken), left = double(m_work.left);
  if (!(taken + left > 0)) return 0;
  // Samples since the update at the recent rate, short of the last one until the source says done.
  const double since = std::min(m_rate * std::max(0.0, seconds - m_seconds), std::max(0.0, left - 1));
  return (taken + since) / (taken + left);
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
