// The benchmarks' probes inside Accel (renderer/accel.h: record_rays_on_this_thread,
// time_accel_on_this_thread): the thread's ray recorder and timer, and the scope that times an
// Embree call. Used by accel.cpp only; nothing here knows Embree. Unset (the default), each probe is
// one thread-local load and a branch.
#pragma once

#include <cstdint>

#include "accel.h"

namespace pt::probe {

inline thread_local RayRecorder* t_recorder = nullptr;
inline thread_local AccelTimer* t_timer = nullptr;

// Out of line and cold, so that the unset case stays a load and a branch.
[[gnu::noinline, gnu::cold]] void append_ray(const Ray& ray, uint8_t shadow);

inline void record(const Ray& ray, uint8_t shadow) {
  if (__builtin_expect(t_recorder != nullptr, 0)) append_ray(ray, shadow);
}

// Adds the time from its construction to the end of its scope to one field of the thread's
// timer, where one is set.
class TimeInto {
 public:
  explicit TimeInto(uint64_t AccelTimer::*field)
      : m_into(__builtin_expect(t_timer != nullptr, 0) ? &(t_timer->*field) : nullptr),
        m_t0(m_into ? accel_ticks() : 0) {}
  ~TimeInto() {
    if (__builtin_expect(m_into != nullptr, 0)) *m_into += accel_ticks() - m_t0;
  }
  TimeInto(const TimeInto&) = delete;
  TimeInto& operator=(const TimeInto&) = delete;

 private:
  uint64_t* m_into;
  uint64_t m_t0;
};

}  // namespace pt::probe
