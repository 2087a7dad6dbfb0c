// What the path loop reads of the render options (PathSettings): the loop's every form
// (integrator.h, path_vertex.h, path_pool.cpp) takes it, so it sits below all of them.
#pragma once

#include "options.h"

namespace pt {

// Russian roulette starts at bounce 5, as Mitsuba 3's path integrator does (rr_depth = 5), on camera
// paths and light paths (caustics.cpp) alike; why not 3: docs/performance.md, "Russian roulette
// from bounce 5".
constexpr int kRouletteStart = 5;

// What the path loop reads of the render options, and the session's choice of who renders the
// caustic paths: a small value the loop's every form takes instead of all of RenderParams.
struct PathSettings {
  int max_depth = 1;       // -m
  int light_samples = 1;   // -l
  bool hemisphere = false; // -H
  // The session's light tracer renders the paths E D+ S+ L (caustics.h), so the loop leaves them out.
  bool caustics_light_traced = false;

  PathSettings() = default;
  explicit PathSettings(const RenderParams& p, bool light_traced = false)
      : max_depth(p.max_depth), light_samples(p.light_samples), hemisphere(p.hemisphere),
        caustics_light_traced(light_traced) {}
};

}  // namespace pt
