// The benchmarks' probes inside Accel: see accel_probe.h.
#include "accel_probe.h"

#include <chrono>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

namespace pt {

void record_rays_on_this_thread(RayRecorder* r) { probe::t_recorder = r; }

void time_accel_on_this_thread(AccelTimer* t) { probe::t_timer = t; }

uint64_t accel_ticks() {
#if defined(__x86_64__) || defined(__i386__)
  return __rdtsc();
#else
  return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count());
#endif
}

namespace probe {

void append_ray(const Ray& ray, uint8_t shadow) {
  t_recorder->rays.push_back(ray);
  t_recorder->shadow.push_back(shadow);
}

}  // namespace probe

}  // namespace pt
