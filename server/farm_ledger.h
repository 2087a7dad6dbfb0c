// What the server knows of its render farm, for /api/health and the page: the workers it has seen
// (name, threads, last heard, passes merged), and the results it refused and why.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace srv {

class FarmLedger {
 public:
  // The workers whose presence keys exist now (each name's threads); others are no longer live.
  void heard(const std::vector<std::pair<std::string, int>>& live);
  // A pass of `worker` merged into a job.
  void merged(const std::string& worker);
  // A result refused: logged to stderr with the worker's name and counted. The name is the one the
  // result claims; on a signed farm a result that fails its check may claim any name.
  void rejected(const std::string& worker, const std::string& job, const std::string& reason);

  // {"workers": [...], "passes_merged", "rejected", "rejections": [... newest first]}.
  nlohmann::json to_json() const;

  static constexpr size_t kWorkersKept = 256, kRejectionsKept = 20;
  static constexpr uint64_t kLogged = 100;  // refusals logged one by one; then every 100th

 private:
  using clock = std::chrono::steady_clock;
  struct Seen {
    int threads = 0;
    bool live = false;
    clock::time_point last{};
    uint64_t passes = 0, rejected = 0;
  };
  struct Rejection {
    std::string worker, job, reason;
    clock::time_point at;
  };
  Seen& entry(const std::string& name);  // with m_mutex held; evicts the longest-silent name when full

  mutable std::mutex m_mutex;
  std::map<std::string, Seen> m_workers;
  std::deque<Rejection> m_rejections;  // newest first
  uint64_t m_merged = 0, m_rejected = 0;
};

}  // namespace srv
