// A terminal progress bar with ETA (only drawn when stderr is a terminal), for long work.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace pt {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label, bool enabled = true)
      : m_label(std::move(label)), m_enabled(enabled && isatty(STDERR_FILENO)),
        m_start(std::chrono::steady_clock::now()) {}
  ~ProgressBar() { finish(); }

  // fraction in [0, 1]; redraws at most 10 times a second. Safe from several threads. The ETA is
  // `eta` seconds where that is given (>= 0), else the time the remaining fraction would take ("?"
  // before any).
  void update(double fraction, const std::string& extra = "", double eta = -1) {
    if (!m_enabled) return;
    std::lock_guard<std::mutex> lock(m_mutex);
    auto now = std::chrono::steady_clock::now();
    if (fraction < 1 && now - m_last < std::chrono::milliseconds(100)) return;
    m_last = now;
    double elapsed = std::chrono::duration<double>(now - m_start).count();
    if (eta < 0 && fraction > 1e-6) eta = elapsed * (1 - fraction) / fraction;
    const int width = 30;
    int filled = int(fraction * width + 0.5);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(width - filled), '.');
    char eta_text[32] = "?";  // nothing done yet, nothing known
    if (eta >= 0) std::snprintf(eta_text, sizeof eta_text, "%.1fs", eta);
    std::fprintf(stderr, "\r%s [%s] %5.1f%%  %.1fs elapsed, ETA %s %s\x1b[K", m_label.c_str(), bar.c_str(),
                 100 * fraction, elapsed, eta_text, extra.c_str());
    std::fflush(stderr);
    m_drawn = true;
  }
  void finish() {
    if (m_enabled && m_drawn) {
      std::fprintf(stderr, "\r\x1b[K");
      std::fflush(stderr);
      m_drawn = false;
    }
  }

 private:
  std::string m_label;
  bool m_enabled;
  bool m_drawn = false;
  std::chrono::steady_clock::time_point m_start, m_last;
  std::mutex m_mutex;
};

}  // namespace pt
