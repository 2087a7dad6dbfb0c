#include "farm_ledger.h"

#include <algorithm>
#include <cstdio>

#include <cmath>

namespace srv {

FarmLedger::Seen& FarmLedger::entry(const std::string& name) {
  auto it = m_workers.find(name);
  if (it != m_workers.end()) return it->second;
  if (m_workers.size() >= kWorkersKept) {  // a flood of made-up names must not grow the server
    auto oldest = std::min_element(m_workers.begin(), m_workers.end(),
                                   [](const auto& a, const auto& b) { return a.second.last < b.second.last; });
    m_workers.erase(oldest);
  }
  return m_workers[name];
}

void FarmLedger::heard(const std::vector<std::pair<std::string, int>>& live) {
  std::lock_guard<std::mutex> lock(m_mutex);
  for (auto& [name, seen] : m_workers) seen.live = false;
  const auto now = clock::now();
  for (const auto& [name, threads] : live) {
    Seen& s = entry(name);
    s.live = true;
    s.threads = threads;
    s.last = now;
  }
}

void FarmLedger::merged(const std::string& worker) {
  std::lock_guard<std::mutex> lock(m_mutex);
  Seen& s = entry(worker);
  ++s.passes;
  s.last = clock::now();
  ++m_merged;
}

void FarmLedger::rejected(const std::string& worker, const std::string& job, const std::string& reason) {
  std::lock_guard<std::mutex> lock(m_mutex);
  ++entry(worker).rejected;
  ++m_rejected;
  // Whoever floods the results stream must not flood the log too: the first kLogged, then every kLogged-th.
  if (m_rejected <= kLogged || m_rejected % kLogged == 0)
    std::fprintf(stderr, "render-server: job %s: refused a result from worker '%s': %s%s\n", job.c_str(), worker.c_str(),
                 reason.c_str(), m_rejected < kLogged ? "" : (" (" + std::to_string(m_rejected) + " refused so far)").c_str());
  m_rejections.push_front({worker, job, reason, clock::now()});
  if (m_rejections.size() > kRejectionsKept) m_rejections.pop_back();
}

nlohmann::json FarmLedger::to_json() const {
  std::lock_guard<std::mutex> lock(m_mutex);
  const auto now = clock::now();
  auto ago = [&](clock::time_point t) {
    return t == clock::time_point{} ? nullptr : nlohmann::json(std::round(std::chrono::duration<double>(now - t).count() * 10) / 10);
  };
  nlohmann::json workers = nlohmann::json::array(), rejections = nlohmann::json::array();
  for (const auto& [name, s] : m_workers)
    workers.push_back({{"name", name}, {"threads", s.threads}, {"live", s.live}, {"last_heard_seconds", ago(s.last)},
                       {"passes", s.passes}, {"rejected", s.rejected}});
  for (const Rejection& r : m_rejections)
    rejections.push_back({{"worker", r.worker}, {"job", r.job}, {"reason", r.reason}, {"seconds_ago", ago(r.at)}});
  return {{"workers", workers}, {"passes_merged", m_merged}, {"rejected", m_rejected}, {"rejections", rejections}};
}

}  // namespace srv
